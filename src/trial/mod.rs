//! Recorded trials: IMU orientations over time, and their file formats.
//!
//! A [`Trial`] holds, per IMU, the orientation `G_R_imu` (sensor frame to global
//! frame G) at each sample time (seconds), and optionally the IMU's gyroscope
//! readings (angular rate, rad/s, sensor frame). Readers and writers for the supported
//! formats live in the submodules; [`read_trial`] and [`write_trial`] pick by
//! file name.

use crate::rotation::Quat;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

mod error;
pub mod format;
pub mod glitch;
mod io;
pub mod mapping;
pub mod precision;
pub mod timing;
pub mod xsens;
pub mod xsens_trial;

pub use error::TrialError;
pub use io::*;

/// Orientations (and optionally gyroscope readings) of one IMU over the
/// trial's samples.
#[derive(Debug, Clone, PartialEq)]
pub struct ImuSeries {
    /// Canonical IMU name (after the model's aliases).
    pub name: String,
    /// `G_R_imu` per sample, unit quaternions.
    pub orientation: Vec<Quat>,
    /// Gyroscope readings when the trial has them: the IMU's angular rate in
    /// rad/s, expressed in its own sensor frame (the body rate `w` of
    /// `d/dt G_R_imu = G_R_imu [w]x`), one per sample, same length as
    /// `orientation`. `None` when the trial has no gyroscope columns.
    pub gyro: Option<Vec<Vector3<f64>>>,
}

impl ImuSeries {
    /// A series of orientations without gyroscope readings.
    pub fn new(name: impl Into<String>, orientation: Vec<Quat>) -> ImuSeries {
        ImuSeries {
            name: name.into(),
            orientation,
            gyro: None,
        }
    }

    /// The same series with gyroscope readings (rad/s, sensor frame).
    pub fn with_gyro(mut self, gyro: Option<Vec<Vector3<f64>>>) -> ImuSeries {
        self.gyro = gyro;
        self
    }

    /// Re-expresses the gyroscope readings in the sensor frame turned by `r`
    /// (`G_R_imu' = G_R_imu * r`, `r` constant): `w' = r^-1 w`. The
    /// orientations are left to the caller. Nothing happens without gyros.
    pub fn turn_gyro(&mut self, r: &Quat) {
        let inv = r.inverse();
        if let Some(g) = &mut self.gyro {
            g.iter_mut().for_each(|w| *w = inv * *w);
        }
    }
}

/// A recorded (or corrected) trial.
#[derive(Debug, Clone, PartialEq)]
pub struct Trial {
    /// Display name (the file name without folder).
    pub name: String,
    /// Sample times in seconds, strictly increasing.
    pub time_s: Vec<f64>,
    /// IMUs in file order, each with one orientation per sample.
    pub imus: Vec<ImuSeries>,
    /// Things the reader noticed that are not errors (renormalised quaternions, ...).
    pub warnings: Vec<String>,
    /// The decimal places of the orientation numbers in the file the trial
    /// was read from, which writers keep ([`precision`]); `None` for full
    /// precision or unknown (simulated or computed trials). Trials made
    /// from a read one (cut, calibrated, corrected) keep it.
    pub orientation_decimals: Option<precision::Decimals>,
}

/// The file formats a trial can be read from and written to.
/// Every input the trial readers accept, in one phrase (for errors; the help
/// texts say the same).
pub const ACCEPTED_INPUTS: &str = "a canonical CSV (time,<imu>_qw,_qx,_qy,_qz,...), an Euler CSV (time,<imu>_roll,_pitch,_yaw,...) or an OpenSim .sto, each optionally .gz; an Xsens MT Manager export (.txt or .csv, tab, comma or semicolon separated; one IMU); a folder of such exports; or an OpenSense mapping .xml";

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TrialFormat {
    /// `time,<imu>_qw,<imu>_qx,<imu>_qy,<imu>_qz,...` (canonical CSV).
    QuatCsv,
    /// `time,<imu>_roll,<imu>_pitch,<imu>_yaw,...`, degrees, Z-Y-X (CHR-UM6).
    EulerCsv,
    /// OpenSim orientation `.sto` (OpenSense), tab-separated `w,x,y,z` cells.
    Sto,
    /// Xsens MT Manager exports, one `.txt` per sensor, named by a mapping XML or
    /// a folder (read only; corrected trials are written as `.sto`).
    Xsens,
}

impl Trial {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.time_s.len()
    }

    /// True when the trial has no samples.
    pub fn is_empty(&self) -> bool {
        self.time_s.is_empty()
    }

    /// The series of the IMU with this canonical name.
    pub fn imu(&self, name: &str) -> Option<&ImuSeries> {
        self.imus.iter().find(|s| s.name == name)
    }

    /// Mutable access to the series of the IMU with this canonical name.
    pub fn imu_mut(&mut self, name: &str) -> Option<&mut ImuSeries> {
        self.imus.iter_mut().find(|s| s.name == name)
    }

    /// The samples at `idx` (in that order, indices into this trial), every
    /// IMU's orientations and gyroscope readings picked alike: a thinned,
    /// cut or resampled-by-selection trial keeps its gyros aligned.
    ///
    /// # Panics
    /// When an index is out of range (callers pick from `0..len()`).
    pub fn select(&self, idx: &[usize], name: &str) -> Trial {
        Trial {
            name: name.to_string(),
            time_s: idx.iter().map(|&i| self.time_s[i]).collect(),
            imus: self
                .imus
                .iter()
                .map(|s| {
                    ImuSeries::new(
                        s.name.clone(),
                        idx.iter().map(|&i| s.orientation[i]).collect(),
                    )
                    .with_gyro(s.gyro.as_ref().map(|g| idx.iter().map(|&i| g[i]).collect()))
                })
                .collect(),
            warnings: self.warnings.clone(),
            orientation_decimals: self.orientation_decimals,
        }
    }

    /// True when any IMU carries gyroscope readings.
    pub fn has_gyros(&self) -> bool {
        self.imus.iter().any(|s| s.gyro.is_some())
    }

    /// Median interval between samples, seconds (0 for fewer than two samples).
    pub fn median_dt(&self) -> f64 {
        median_dt(&self.time_s)
    }

    /// Trial length, seconds: the span of the times times `n / (n - 1)` (`n * dt`
    /// for a regular stream; docs/method.md section 7), or with gaps the span plus
    /// one median interval ([`timing::trial_length_s`]).
    pub fn duration_s(&self) -> f64 {
        timing::trial_length_s(&self.time_s)
    }

    /// Nominal sampling rate in Hz (1 / median interval; 0 when unknown).
    pub fn rate_hz(&self) -> f64 {
        let dt = self.median_dt();
        if dt > 0.0 {
            1.0 / dt
        } else {
            0.0
        }
    }
}

/// The built-in model that fits the trial at `path` best
/// ([`TrialHead::detect_model`]; the first built-in model when the header
/// cannot be read). The header is read from disk once.
pub fn detect_model(path: &std::path::Path) -> crate::model::Model {
    best_model(TrialHead::read(path).ok().as_ref())
}

/// [`TrialHead::detect_model`] of `head`, or the first built-in model.
fn best_model(head: Option<&TrialHead>) -> crate::model::Model {
    use crate::model::{Model, BUILTIN_MODELS};
    let mut best: Option<((usize, usize), Model)> = None;
    for (name, _) in BUILTIN_MODELS {
        let model = Model::builtin(name).expect("built-in model is valid");
        let known = head
            .and_then(|h| h.header(&model).ok())
            .map(|h| h.imus.iter().filter(|i| model.imus.contains(i)).count())
            .unwrap_or(0);
        let lacking = model.imus.len() - known.min(model.imus.len());
        // Larger is better: most known first, then fewest lacking.
        let score = (known, usize::MAX - lacking);
        if best.as_ref().is_none_or(|(s, _)| known > 0 && score > *s) {
            best = Some((score, model));
        }
    }
    best.expect("there are built-in models").1
}

/// Median of the differences of consecutive times (0 for fewer than two).
pub fn median_dt(time_s: &[f64]) -> f64 {
    if time_s.len() < 2 {
        return 0.0;
    }
    let mut d: Vec<f64> = time_s.windows(2).map(|w| w[1] - w[0]).collect();
    let mid = d.len() / 2;
    let (_, m, _) = d.select_nth_unstable_by(mid, f64::total_cmp);
    let upper = *m;
    if d.len() % 2 == 1 {
        upper
    } else {
        let lower = d[..mid].iter().copied().fold(f64::MIN, f64::max);
        0.5 * (lower + upper)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_interval_and_duration() {
        assert_eq!(median_dt(&[0.0]), 0.0);
        assert_eq!(median_dt(&[0.0, 0.02, 0.04, 0.1]), 0.02);
        assert!((median_dt(&[0.0, 1.0, 3.0, 6.0, 10.0]) - 2.5).abs() < 1e-12);
        let t = Trial {
            name: "x".into(),
            time_s: (0..3000).map(|i| i as f64 * 0.02).collect(),
            imus: vec![],
            warnings: vec![],
            orientation_decimals: None,
        };
        assert!((t.duration_s() - 60.0).abs() < 1e-9);
        assert!((t.rate_hz() - 50.0).abs() < 1e-9);
    }

    #[test]
    fn turned_gyros_are_the_rates_of_the_turned_orientations() {
        use crate::rotation::quat_axis_angle_deg;
        // A constant body rate w: G_R(t) = G_R0 exp(w t); turned by r the
        // orientation G_R r turns at r^-1 w in the new frame.
        let w = Vector3::new(0.4, -1.1, 0.7);
        let g0 = quat_axis_angle_deg([0.2, 0.9, -0.3], 50.0);
        let at = |t: f64| g0 * Quat::from_scaled_axis(w * t);
        let mut s = ImuSeries::new("a", vec![at(0.0)]).with_gyro(Some(vec![w]));
        let r = quat_axis_angle_deg([1.0, 0.5, 0.0], 35.0);
        s.turn_gyro(&r);
        let h = 1e-6;
        let fd = ((at(-h) * r).inverse() * (at(h) * r)).scaled_axis() / (2.0 * h);
        assert!((s.gyro.as_ref().unwrap()[0] - fd).norm() < 1e-8);
        assert!((w - fd).norm() > 0.3, "the turn matters");
        let mut none = ImuSeries::new("b", vec![at(0.0)]);
        none.turn_gyro(&r);
        assert!(none.gyro.is_none());
    }
}
