//! The Anatomical Constraint Method (docs/method.md sections 5-10).
//!
//! Per joint, the correction C of the distal IMU keeps the joint's Z-Y-X angles
//! inside their limits (and, with a centroid, near it) at the least rotation.
//! Corrections are solved per window and slerped between window centres, joint
//! by joint down the model's chain, each joint measured against its parent's
//! corrected orientation: `Rm = (G_R_prox')^T G_R_dist`, `G_R_dist' = G_R_dist C`.
//! The heading-drift variants fit `G_R_dist' = R_up(-h(t)) G_R_dist C` per IMU
//! instead ([`heading`]), looking ahead at the joints below it ([`lookahead`]).

pub mod auto;
pub mod auto_run;
pub mod chain;
pub mod circle_grid;
pub mod cost;
pub mod heading;
pub mod heading_cost;
pub mod hinge;
pub mod lookahead;
pub mod minimise;
pub mod parent_cost;
mod swing_cost;
/// The window layout, shared with the baselines (a leaf: [`crate::window`]).
pub use crate::window;

pub use crate::run::{Cancelled, RunControl, SkippedJoint, WindowSolution};
pub use crate::variant::{Kind, Variant};
pub use chain::{
    correct_chain, correct_joint, correct_joint_with, recorrect_chain, solve_window, uncorrected,
};

use crate::limits::Settings;
use crate::trial::Trial;
use crate::vertical::Vertical;
use serde::{Deserialize, Serialize};

/// The correction of one joint's distal IMU.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JointResult {
    pub joint: String,
    pub proximal: String,
    pub distal: String,
    /// The centroid weight used (0 without centroid term).
    pub lambda2: f64,
    /// Whether the parent IMU had been corrected (false when it is the base or
    /// its own joint was skipped).
    pub parent_corrected: bool,
    pub windows: Vec<WindowSolution>,
    /// What a baseline method found, for the joints a baseline variant
    /// corrects (`rivest`, `mueller`); absent for ACM joints.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub baseline: Option<crate::baselines::BaselineRecord>,
    /// The hinge axes this joint's estimate found (`hinge` variant, hinge
    /// joints only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hinge: Option<hinge::HingeRecord>,
    /// The hinge joint below whose proximal-frame axis fixed two degrees of
    /// freedom of this joint's correction (`hinge` variant), in the windows
    /// where that axis was observed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axis_from: Option<String>,
    /// How `auto` chose this joint's correction among the candidates.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub auto: Option<auto::AutoChoice>,
}

/// The heading correction of one window of a heading-drift variant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HeadingWindow {
    /// Window centre, seconds from the first sample.
    pub centre_s: f64,
    /// Estimated heading drift `h_k`, degrees about the global up axis (the
    /// rotation the sensor's orientation had turned by, and that was removed).
    pub heading_deg: f64,
    /// Drift rate since the previous window centre, degrees per second (none
    /// for the first window).
    pub rate_deg_s: Option<f64>,
}

/// The estimated heading drift of one IMU (heading-drift variants):
/// `G_R' = R_up(-h(t)) G_R C`, h linear between window centres.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImuHeading {
    pub imu: String,
    /// The joint whose correction fitted it (the IMU is its distal one).
    pub joint: String,
    /// The global frame's up axis the headings turn about.
    pub vertical: Vertical,
    /// The constant correction C (sensor frame), `[w, x, y, z]`, w >= 0.
    pub correction: [f64; 4],
    /// Rotation angle of C, degrees.
    pub correction_angle_deg: f64,
    pub windows: Vec<HeadingWindow>,
    /// Alternation rounds and C-step cost evaluations spent.
    pub rounds: usize,
    pub c_evaluations: usize,
}

impl ImuHeading {
    /// Least-squares slope of the window headings over their centres, degrees
    /// per second (0 with fewer than two windows).
    pub fn mean_rate_deg_s(&self) -> f64 {
        let n = self.windows.len() as f64;
        if self.windows.len() < 2 {
            return 0.0;
        }
        let mt = self.windows.iter().map(|w| w.centre_s).sum::<f64>() / n;
        let mh = self.windows.iter().map(|w| w.heading_deg).sum::<f64>() / n;
        let (num, den) = self.windows.iter().fold((0.0, 0.0), |(a, b), w| {
            let dt = w.centre_s - mt;
            (a + dt * (w.heading_deg - mh), b + dt * dt)
        });
        if den > 0.0 {
            num / den
        } else {
            0.0
        }
    }

    /// The largest absolute window heading, degrees.
    pub fn max_abs_heading_deg(&self) -> f64 {
        self.windows
            .iter()
            .map(|w| w.heading_deg.abs())
            .fold(0.0, f64::max)
    }
}

/// A whole-trial correction: the corrected trial plus what was done per joint.
#[derive(Debug, Clone, PartialEq)]
pub struct Correction {
    pub variant: Variant,
    pub settings: Settings,
    /// The trial with every corrected IMU replaced by `G_R_dist * C(t)`.
    pub corrected: Trial,
    /// Corrected joints in model order.
    pub joints: Vec<JointResult>,
    /// Joints of the model that were not corrected.
    pub skipped: Vec<SkippedJoint>,
    /// Estimated heading drift per corrected IMU, in model order (heading-drift
    /// variants only; empty otherwise).
    pub headings: Vec<ImuHeading>,
    /// The joint coordinates of the `ik` variant (None for the others).
    pub ik: Option<std::sync::Arc<crate::ik::IkRun>>,
}

impl Correction {
    /// The result for a joint.
    pub fn joint(&self, name: &str) -> Option<&JointResult> {
        self.joints.iter().find(|j| j.joint == name)
    }

    /// The estimated heading drift of an IMU (heading-drift variants).
    pub fn heading(&self, imu: &str) -> Option<&ImuHeading> {
        self.headings.iter().find(|h| h.imu == imu)
    }
}
