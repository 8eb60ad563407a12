//! What a correction run reports and is steered by, whichever solver runs
//! it: the per-window solutions, the joints left out, progress and
//! cancellation. A leaf: the solvers (`acm`, `baselines`, `ik`) share these
//! without importing each other.

use serde::{Deserialize, Serialize};
use std::sync::atomic::{AtomicBool, Ordering};

/// The solution of one window of one joint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WindowSolution {
    /// Window start and end (exclusive), seconds from the first sample.
    pub start_s: f64,
    pub end_s: f64,
    /// Window centre, seconds from the first sample.
    pub centre_s: f64,
    /// Samples inside the window.
    pub samples: usize,
    /// The correction C (sensor frame of the distal IMU), `[w, x, y, z]`, w >= 0.
    pub correction: [f64; 4],
    /// Rotation angle of C, degrees.
    pub angle_deg: f64,
    /// Cost at C.
    pub cost: f64,
    /// Cost without correction (C = identity).
    pub cost_uncorrected: f64,
    /// Cost evaluations spent.
    pub evaluations: usize,
}

/// A joint the engine did not correct, and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SkippedJoint {
    pub joint: String,
    pub reason: String,
}

/// The run was cancelled before it finished.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("correction cancelled")]
pub struct Cancelled;

/// Progress reporting and cancellation for a long run.
#[derive(Default, Clone, Copy)]
pub struct RunControl<'a> {
    /// Checked before each window; when set, the run stops with [`Cancelled`].
    pub cancel: Option<&'a AtomicBool>,
    /// Called with (windows done, windows in all) after each window.
    pub progress: Option<&'a (dyn Fn(usize, usize) + Sync)>,
}

impl RunControl<'_> {
    /// Whether the run was asked to stop.
    pub fn cancelled(&self) -> bool {
        self.cancel.is_some_and(|c| c.load(Ordering::Relaxed))
    }
}
