//! Ground truth of simulated trials: the clean segment orientations and the
//! errors that were put into the sensors (see [`crate::simulate`] for frames).
//!
//! Beside a trial `NAME.csv` (or `NAME.csv.gz`, `NAME.sto`, ...) the truth is two files:
//! - `NAME.truth.csv.gz`: the segment orientations `G_R_segment` (what a perfectly
//!   aligned, drift-free sensor would report) as canonical quaternion CSV,
//!   header `time,<imu>_qw,<imu>_qx,<imu>_qy,<imu>_qz,...`, times in seconds;
//! - `NAME.truth.json`: [`TruthMeta`] (the simulation config, each IMU's
//!   misalignment `M` as `[w, x, y, z]`, the heading drifts).

use crate::model::{Joint, Model};
use crate::rotation::{self, Quat};
use crate::simulate::{HeadingDrift, SimConfig};
use crate::trial::{self, Trial, TrialError, TrialFormat};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// Suffix of the truth orientations file.
pub const TRUTH_CSV_SUFFIX: &str = ".truth.csv.gz";
/// Suffix of the truth meta file.
pub const TRUTH_JSON_SUFFIX: &str = ".truth.json";

/// What a simulated trial should have been.
#[derive(Debug, Clone, PartialEq)]
pub struct Truth {
    /// Clean segment orientations `G_R_segment`, same times and IMUs as the trial.
    pub segments: Trial,
    /// The errors applied to the sensors.
    pub meta: TruthMeta,
}

/// The simulation's settings and the errors it applied (`NAME.truth.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TruthMeta {
    /// Body model of the IMU and joint names.
    pub model: String,
    /// The configuration the trial was simulated from.
    pub config: SimConfig,
    /// Misalignment `M` of every simulated IMU (`G_R_imu = G_R_segment * M`),
    /// quaternion `[w, x, y, z]`, identity for the base and aligned IMUs.
    pub misalignments: BTreeMap<String, [f64; 4]>,
    /// Heading drifts applied (`Rz(h(t))` on the left of the segment orientation).
    pub drifts: Vec<HeadingDrift>,
}

impl TruthMeta {
    /// The misalignment `M` of `imu` (None when the IMU was not simulated).
    pub fn misalignment(&self, imu: &str) -> Option<Quat> {
        self.misalignments
            .get(imu)
            .map(|q| rotation::quat_from_wxyz(*q))
    }

    /// Pretty JSON text.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("truth meta serialises") + "\n"
    }

    /// Parses JSON text; `origin` names the file in errors (with line and column).
    pub fn from_json(text: &str, origin: &str) -> Result<TruthMeta, TrialError> {
        serde_json::from_str(text)
            .map_err(|e| TrialError::at(origin, e.line() as u64, e.column(), e.to_string()))
    }

    /// Writes the JSON atomically to `path`.
    pub fn save(&self, path: &Path) -> Result<(), crate::save::WriteError> {
        crate::save::atomic_write(path, self.to_json().as_bytes())
            .map_err(|e| crate::save::WriteError::io(path, &e))
    }
}

impl Truth {
    /// True angles of `joint` per sample, degrees, in the table's convention:
    /// [`Joint::angles`] of the true segments. Empty when either IMU is missing.
    pub fn true_joint_angles(&self, joint: &Joint) -> Vec<[f64; 3]> {
        let (Some(p), Some(d)) = (
            self.segments.imu(&joint.proximal),
            self.segments.imu(&joint.distal),
        ) else {
            return vec![];
        };
        p.orientation
            .iter()
            .zip(&d.orientation)
            .map(|(p, d)| joint.angles(p, d))
            .collect()
    }

    /// The true correction of `imu` per sample,
    /// `C_true(t) = G_R_imu_measured(t)^-1 * G_R_segment(t)`: the `C` for which
    /// `G_R_measured * C` is the segment orientation (`M^-1` without drift and
    /// noise). Samples pair by index; empty when either side lacks the IMU.
    pub fn true_correction(&self, measured: &Trial, imu: &str) -> Vec<Quat> {
        let (Some(m), Some(s)) = (measured.imu(imu), self.segments.imu(imu)) else {
            return vec![];
        };
        m.orientation
            .iter()
            .zip(&s.orientation)
            .map(|(m, s)| m.inverse() * s)
            .collect()
    }

    /// Checks that `measured` pairs with this truth sample by sample: same number
    /// of samples, same times (within 1 microsecond), and every measured IMU in
    /// the truth. The error says what differs.
    pub fn check_against(&self, measured: &Trial) -> Result<(), TruthMismatch> {
        if measured.len() != self.segments.len() {
            return Err(TruthMismatch::Samples {
                truth: self.segments.len(),
                trial: measured.len(),
            });
        }
        if let Some((i, (a, b))) = measured
            .time_s
            .iter()
            .zip(&self.segments.time_s)
            .enumerate()
            .find(|(_, (a, b))| (*a - *b).abs() > 1e-6)
        {
            return Err(TruthMismatch::Time {
                sample: i,
                trial_s: *a,
                truth_s: *b,
            });
        }
        if let Some(s) = measured
            .imus
            .iter()
            .find(|s| self.segments.imu(&s.name).is_none())
        {
            return Err(TruthMismatch::Imu(s.name.clone()));
        }
        Ok(())
    }

    /// Saves `NAME.truth.csv.gz` and `NAME.truth.json` beside `trial_path`;
    /// returns their paths.
    pub fn save_beside(
        &self,
        trial_path: &Path,
    ) -> Result<(PathBuf, PathBuf), crate::save::WriteError> {
        let (csv, json) = truth_paths(trial_path);
        trial::write_trial(&self.segments, &csv, TrialFormat::QuatCsv)?;
        self.meta.save(&json)?;
        Ok((csv, json))
    }
}

/// The trial file's name with `.gz` and then its format extension removed.
fn stem(trial_path: &Path) -> String {
    let name = trial_path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let name = name.strip_suffix(".gz").unwrap_or(&name);
    match name.rfind('.') {
        Some(i) if i > 0 => name[..i].to_string(),
        _ => name.to_string(),
    }
}

/// How a trial and the truth beside it do not pair ([`Truth::check_against`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TruthMismatch {
    #[error("the truth has {truth} samples, the trial {trial}")]
    Samples { truth: usize, trial: usize },
    /// Times of one sample further apart than 1 microsecond (seconds).
    #[error("sample {sample}: the trial's time is {trial_s} s, the truth's {truth_s} s")]
    Time {
        sample: usize,
        trial_s: f64,
        truth_s: f64,
    },
    /// An IMU of the trial the truth does not have.
    #[error("IMU '{0}' has no truth")]
    Imu(String),
}

/// The truth files beside a trial: `(NAME.truth.csv.gz, NAME.truth.json)`.
pub fn truth_paths(trial_path: &Path) -> (PathBuf, PathBuf) {
    let stem = stem(trial_path);
    (
        trial_path.with_file_name(format!("{stem}{TRUTH_CSV_SUFFIX}")),
        trial_path.with_file_name(format!("{stem}{TRUTH_JSON_SUFFIX}")),
    )
}

/// True for a truth file (`*.truth.csv.gz`, `*.truth.json`), which is not a trial.
pub fn is_truth_file(path: &Path) -> bool {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    name.ends_with(TRUTH_CSV_SUFFIX) || name.ends_with(TRUTH_JSON_SUFFIX)
}

/// Loads the truth beside `trial_path`: None when there is none (neither file),
/// an error when a file is missing, malformed, or does not match the model.
pub fn load_truth_beside(trial_path: &Path, model: &Model) -> Option<Result<Truth, TrialError>> {
    let (csv, json) = truth_paths(trial_path);
    if !csv.exists() && !json.exists() {
        return None;
    }
    Some(load(&csv, &json, model))
}

fn load(csv: &Path, json: &Path, model: &Model) -> Result<Truth, TrialError> {
    let json_name = json.display().to_string();
    if !json.exists() {
        return Err(TrialError::file(
            &json_name,
            "missing: a truth needs its .truth.json file (the .truth.csv.gz is optional)",
        ));
    }
    let text = crate::input::read_text(json)
        .map_err(|e| TrialError::file(&json_name, format!("cannot read: {e}")))?;
    let meta = TruthMeta::from_json(&text, &json_name)?;
    if meta.model != model.name {
        return Err(TrialError::file(
            &json_name,
            format!(
                "truth is for model '{}', the trial is read with model '{}'",
                meta.model, model.name
            ),
        ));
    }
    if !csv.exists() {
        // Only the configuration is stored: simulate it again (deterministic).
        let sim = crate::simulate::simulate(&meta.config)
            .map_err(|e| TrialError::file(&json_name, e.to_string()))?;
        return Ok(Truth {
            segments: sim.truth.segments,
            meta,
        });
    }
    let segments = trial::read_trial(csv, model)?;
    Ok(Truth { segments, meta })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulate::{preset, simulate};

    #[test]
    fn truth_paths_strip_gz_and_format() {
        let (c, j) = truth_paths(Path::new("dir/run1.csv.gz"));
        assert_eq!(c, Path::new("dir/run1.truth.csv.gz"));
        assert_eq!(j, Path::new("dir/run1.truth.json"));
        let (c, _) = truth_paths(Path::new("a.b.sto"));
        assert_eq!(c, Path::new("a.b.truth.csv.gz"));
        let (c, _) = truth_paths(Path::new("noext"));
        assert_eq!(c, Path::new("noext.truth.csv.gz"));
        assert!(is_truth_file(&c));
        assert!(!is_truth_file(Path::new("run1.csv.gz")));
    }

    #[test]
    fn truth_meta_json_round_trip_and_errors() {
        let mut cfg = preset("full_body_drift").unwrap();
        cfg.duration_s = 2.0;
        let sim = simulate(&cfg).unwrap();
        let text = sim.truth.meta.to_json();
        let back = TruthMeta::from_json(&text, "t.json").unwrap();
        assert_eq!(back.config, sim.truth.meta.config);
        assert_eq!(back.drifts, sim.truth.meta.drifts);
        assert_eq!(back.misalignments.len(), 13);
        sim.truth.check_against(&sim.trial).unwrap();
        let mut short = sim.trial.clone();
        short.time_s.pop();
        assert!(sim
            .truth
            .check_against(&short)
            .unwrap_err()
            .to_string()
            .contains("samples"));
        let mut shifted = sim.trial.clone();
        shifted.time_s[3] += 0.001;
        assert!(sim
            .truth
            .check_against(&shifted)
            .unwrap_err()
            .to_string()
            .contains("sample 3"));
        // serde_json parses floats to within an ulp, not always bit for bit.
        for imu in sim.truth.meta.misalignments.keys() {
            let (a, b) = (back.misalignment(imu), sim.truth.meta.misalignment(imu));
            assert!(rotation::angle_between_deg(&a.unwrap(), &b.unwrap()) < 1e-9);
        }
        let e = TruthMeta::from_json("{\n \"model\": 3\n}", "t.json").unwrap_err();
        assert_eq!((e.file.as_str(), e.line), ("t.json", 2), "{e}");
    }

    #[test]
    fn no_truth_beside_plain_trial_and_half_truth_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let trial = dir.path().join("t.csv");
        let model = Model::infant13();
        assert!(load_truth_beside(&trial, &model).is_none());
        std::fs::write(dir.path().join("t.truth.json"), "{}").unwrap();
        let e = load_truth_beside(&trial, &model).unwrap().unwrap_err();
        assert!(e.message.contains("missing"), "{e}");
    }

    #[test]
    fn truth_saves_and_loads_beside_a_trial() {
        let mut cfg = preset("full_body_clean").unwrap();
        cfg.duration_s = 2.0;
        let sim = simulate(&cfg).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let trial_path = dir.path().join("sim.csv.gz");
        let (csv, json) = sim.truth.save_beside(&trial_path).unwrap();
        assert!(csv.exists() && json.exists());
        let model = Model::infant13();
        let back = load_truth_beside(&trial_path, &model).unwrap().unwrap();
        assert_eq!(back.meta.config, sim.truth.meta.config);
        assert_eq!(back.segments.len(), sim.truth.segments.len());
        for s in &sim.truth.segments.imus {
            let b = back.segments.imu(&s.name).unwrap();
            for (q0, q1) in s.orientation.iter().zip(&b.orientation) {
                assert!(rotation::angle_between_deg(q0, q1) < 1e-6);
            }
        }
    }
}
