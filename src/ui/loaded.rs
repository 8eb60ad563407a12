//! A trial as read from disk, with what the screens need of it (figures,
//! glitches, joint angles computed on demand). A leaf: messages and the
//! workbench both carry it.

use crate::metrics::JointFigures;
use crate::model::Model;
use crate::trial::Trial;
use std::collections::BTreeMap;
use std::sync::Arc;

/// Joint angles per joint of one trial (raw or corrected), computed the first
/// time a screen asks: a 30-minute trial has 90,000 samples per joint, too many
/// to convert on every frame.
#[derive(Debug, Clone, Default)]
pub struct AngleCache(Arc<std::sync::Mutex<BTreeMap<String, JointAngles>>>);

/// Z-Y-X angles `[x, y, z]` in degrees, one per sample, shared between frames.
pub type JointAngles = Arc<Vec<[f64; 3]>>;

impl AngleCache {
    /// Z-Y-X angles (degrees) of `joint` in `trial`, cached by joint name.
    pub fn get(&self, trial: &Trial, joint: &crate::model::Joint) -> Option<JointAngles> {
        let mut map = self.0.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(a) = map.get(&joint.name) {
            return Some(a.clone());
        }
        let a = Arc::new(crate::metrics::joint_angles(trial, joint)?);
        map.insert(joint.name.clone(), a.clone());
        Some(a)
    }
}

/// A trial read from disk, with what the screens need of it.
#[derive(Debug, Clone)]
pub struct Loaded {
    pub trial: Trial,
    pub model: Model,
    /// Where the trial was read from: path, format, compression and the
    /// hash its saved corrections' sidecars record.
    pub source: crate::correct::pipeline::Source,
    /// True segment orientations when a truth sits beside the trial.
    pub truth: Option<Trial>,
    /// Why the truth beside the trial could not be used.
    pub truth_error: Option<String>,
    /// The optical reference beside the trial (`<trial stem>.reference.csv`,
    /// `.mot` or `.c3d`), aligned with the trial as read (lag found as
    /// `report --reference` finds it) and resampled onto its samples.
    pub reference: Option<Arc<crate::reference::ReferenceTrace>>,
    /// Why the reference beside the trial could not be used.
    pub reference_error: Option<String>,
    /// Figures of the uncorrected trial.
    pub before: Vec<JointFigures>,
    /// Joint angles of the uncorrected trial, filled on demand.
    pub angles: AngleCache,
    /// The pose calibration `trial` went through (None: as read).
    pub pose: Option<crate::pose::PoseRecord>,
    /// The trial as read, while `trial` is pose-calibrated.
    pub uncalibrated: Option<Arc<Loaded>>,
    /// Orientation jumps over the default threshold, by time (key `G`).
    pub glitches: Vec<crate::trial::glitch::Glitch>,
    /// Corrected outputs of this very input found on disk (by their sidecars).
    pub on_disk: BTreeMap<crate::acm::Variant, SavedOutput>,
}

/// A corrected output found beside a trial, as its sidecar records it.
#[derive(Debug, Clone, PartialEq)]
pub struct SavedOutput {
    /// The output's path relative to the trials folder.
    pub shown: String,
    /// The settings and the limit table's hash it was corrected with.
    pub settings: crate::limits::Settings,
    pub limits_hash: String,
}

/// The correction of a trial being followed while another program appends
/// to it: as many samples as the trial read so far, corrected by the newest
/// solve of the growing trial before `solved`, by the correction extrapolated
/// from that solve after it (see [`crate::follow`]).
#[derive(Debug, Clone)]
pub struct LiveTrace {
    /// The variant the rows are corrected with.
    pub variant: crate::acm::Variant,
    /// The corrected samples (same times as the trial read so far).
    pub corrected: Arc<Trial>,
    /// Joint angles of `corrected`, filled on demand.
    pub angles: AngleCache,
    /// Samples the newest solve covers (0: nothing solved yet, all extrapolated).
    pub solved: usize,
    /// Trial time the newest solve reaches, seconds from the first sample.
    pub solved_s: f64,
    /// A solve is under way.
    pub solving: bool,
    /// The file grew since following began.
    pub grew: bool,
    /// What went wrong last (a solve that failed, a restart), if anything.
    pub note: Option<String>,
}
