//! Functional calibration after Ricci et al. 2014 (docs/method.md section 13): from a
//! recording of still postures and mono-axial movements, the rotation between
//! each IMU's sensor frame (SF) and the functional frame (FF) of its segment.
//!
//! * [`recording`]: the calibration recording (CSV: time, movement label,
//!   accelerometer and gyroscope per IMU);
//! * [`protocol`]: which label gives which FF axis of which IMU (TOML);
//! * [`axis`]: per movement, normalise, SVD, axis estimate and reliability rho;
//! * [`fit`]: per IMU, the weighted Levenberg-Marquardt fit and TRIAD;
//! * [`simulate`]: recordings with a known SF -> FF rotation;
//! * this module: the whole calibration, its file, and applying it to a trial.
//!
//! Frames: the calibration quaternion `q` of an IMU maps sensor-frame vectors
//! into the functional frame, `v_FF = R(q) * v_SF` (the paper's `R_SF^FF`).
//! Applied to a trial, `G_R_FF = G_R_SF * R(q)^-1`: the IMU's orientation
//! becomes its segment's. In the simulator's terms (`IMU = segment * M`),
//! `R(q)` is the misalignment `M`.

pub mod axis;
pub mod error;
pub mod fit;
pub mod protocol;
pub mod recording;
pub mod simulate;

pub use error::CalibrationError;
pub use protocol::{
    Movement, MovementKind, Protocol, SignedAxis, DEFAULT_PROTOCOL as DEFAULT_PROTOCOL_NAME,
};
pub use recording::{is_calibration_recording, Recording};

use crate::model::Model;
use crate::rotation::{quat_from_wxyz, wxyz, Quat};
use crate::trial::Trial;
use fit::{AxisPair, LmOptions};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// One movement's axis for one IMU: estimate, reliability and residuals.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AxisResult {
    /// The movement's label.
    pub movement: String,
    pub kind: MovementKind,
    /// The functional-frame axis it gives, e.g. `-y`.
    pub axis: String,
    /// Readings used.
    pub samples: usize,
    /// Reliability `s1 / (s1 + s2 + s3)` (the paper's Table 1).
    pub rho: f64,
    /// Unit axis estimate in the sensor frame `[x, y, z]`.
    pub estimate: [f64; 3],
    /// Angle between the FF axis and the estimate before the fit (identity), degrees.
    pub residual_before_deg: f64,
    /// The same after the LM fit, degrees (the paper's Figure 5).
    pub residual_lm_deg: f64,
    /// The same with the TRIAD rotation, degrees (when TRIAD could be formed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub residual_triad_deg: Option<f64>,
}

/// The calibration of one IMU.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SegmentResult {
    /// IMU name (as in the protocol).
    pub imu: String,
    /// The LM rotation SF -> FF, `[w, x, y, z]`, `w >= 0`. This is what is applied.
    pub q: [f64; 4],
    /// LM iterations until the relative cost change fell below 1e-4.
    pub iterations: usize,
    /// Cost `e^T W e` at the identity start and at the end.
    pub cost_start: f64,
    pub cost_end: f64,
    /// TRIAD's rotation from the first two movements (protocol order) with
    /// non-parallel axes, `[w, x, y, z]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub triad_q: Option<[f64; 4]>,
    /// The two movements TRIAD used (primary first).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub triad_movements: Vec<String>,
    /// Angle between the LM and the TRIAD rotations, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lm_triad_deg: Option<f64>,
    /// Per movement of the protocol found in the recording, in protocol order.
    pub axes: Vec<AxisResult>,
    /// Protocol movements of this IMU without usable rows in the recording.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub missing: Vec<String>,
}

impl SegmentResult {
    /// The LM rotation SF -> FF.
    pub fn rotation(&self) -> Quat {
        quat_from_wxyz(self.q)
    }

    /// The TRIAD rotation SF -> FF, if formed.
    pub fn triad_rotation(&self) -> Option<Quat> {
        self.triad_q.map(quat_from_wxyz)
    }

    /// The axis result of a movement.
    pub fn axis(&self, movement: &str) -> Option<&AxisResult> {
        self.axes.iter().find(|a| a.movement == movement)
    }
}

/// An IMU of the protocol that could not be calibrated, and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SkippedSegment {
    pub imu: String,
    pub reason: String,
}

/// A whole calibration: what it was computed from, and per IMU the result.
/// Saved as TOML (`<recording stem>.calibration.toml`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Calibration {
    pub program: String,
    pub version: String,
    /// The recording's file name.
    pub recording: String,
    /// Its rows, duration (s) and nominal rate (Hz).
    pub samples: usize,
    pub duration_s: f64,
    pub rate_hz: f64,
    /// The protocol's name and the SHA-256 of its text.
    pub protocol: String,
    pub protocol_sha256: String,
    /// Movement labels in the protocol's order (the rows of the rho table).
    pub movements: Vec<String>,
    #[serde(rename = "segment")]
    pub segments: Vec<SegmentResult>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub skipped: Vec<SkippedSegment>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
}

/// Calibrates every IMU of the protocol from a recording.
pub fn calibrate(rec: &Recording, protocol: &Protocol) -> Calibration {
    let mut segments = vec![];
    let mut skipped = vec![];
    for imu in &protocol.segments {
        match calibrate_segment(rec, protocol, imu) {
            Ok(s) => segments.push(s),
            Err(reason) => skipped.push(SkippedSegment {
                imu: imu.clone(),
                reason,
            }),
        }
    }
    let mut warnings = vec![];
    for l in &rec.labels {
        if protocol.movement(l).is_none() {
            warnings.push(format!(
                "label '{l}' is not a movement of protocol {}; its rows are ignored",
                protocol.name
            ));
        }
    }
    for i in &rec.imus {
        if !protocol
            .segments
            .iter()
            .any(|s| s.eq_ignore_ascii_case(&i.name))
        {
            warnings.push(format!(
                "IMU '{}' is not in protocol {}; ignored",
                i.name, protocol.name
            ));
        }
    }
    let t = &rec.time_s;
    Calibration {
        program: "acmw".into(),
        version: env!("CARGO_PKG_VERSION").into(),
        recording: rec.name.clone(),
        samples: rec.len(),
        duration_s: rec.len() as f64 * crate::trial::median_dt(t),
        rate_hz: rec.rate_hz(),
        protocol: protocol.name.clone(),
        protocol_sha256: protocol.sha256(),
        movements: protocol.movements.iter().map(|m| m.label.clone()).collect(),
        segments,
        skipped,
        warnings,
    }
}

/// The calibration of one IMU, or why it cannot be made.
fn calibrate_segment(
    rec: &Recording,
    protocol: &Protocol,
    imu: &str,
) -> Result<SegmentResult, String> {
    let readings = rec
        .imu(imu)
        .ok_or_else(|| "not in the recording".to_string())?;
    let mut found: Vec<(&Movement, SignedAxis, axis::AxisEstimate)> = vec![];
    let mut missing = vec![];
    for m in &protocol.movements {
        let Some(a) = m.axes.get(imu) else { continue };
        let rows = rec.rows(&m.label);
        let (data, min) = match m.kind {
            MovementKind::Static => (&readings.acc, 0.0),
            MovementKind::Functional => (&readings.gyro, protocol.min_rate_deg_s),
        };
        let sel: Vec<[f64; 3]> = rows.iter().map(|&r| data[r]).collect();
        match axis::estimate_axis(&sel, m.kind, min) {
            Some(e) => found.push((m, *a, e)),
            None => missing.push(m.label.clone()),
        }
    }
    let pairs: Vec<AxisPair> = found
        .iter()
        .map(|(_, a, e)| AxisPair {
            reference: a.vector(),
            estimate: e.axis,
            weight: e.rho,
        })
        .collect();
    let distinct = pairs
        .iter()
        .any(|p| p.reference.cross(&pairs[0].reference).norm() > 1e-9);
    if pairs.is_empty() || !distinct {
        return Err(format!(
            "needs two movements with non-parallel axes; found {} ({}){}",
            pairs.len(),
            found
                .iter()
                .map(|(m, _, _)| m.label.as_str())
                .collect::<Vec<_>>()
                .join(", "),
            if missing.is_empty() {
                String::new()
            } else {
                format!("; missing: {}", missing.join(", "))
            }
        ));
    }
    let lm = fit::fit_lm(&pairs, &LmOptions::default());
    let second = pairs
        .iter()
        .position(|p| p.reference.cross(&pairs[0].reference).norm() > 1e-9)
        .expect("checked above");
    let triad = fit::triad(&pairs[0], &pairs[second]);
    let identity = Quat::identity();
    let axes = found
        .iter()
        .zip(&pairs)
        .map(|((m, a, e), p)| AxisResult {
            movement: m.label.clone(),
            kind: m.kind,
            axis: a.name(),
            samples: e.samples,
            rho: e.rho,
            estimate: [e.axis[0], e.axis[1], e.axis[2]],
            residual_before_deg: fit::residual_deg(&identity, p),
            residual_lm_deg: fit::residual_deg(&lm.q, p),
            residual_triad_deg: triad.as_ref().map(|t| fit::residual_deg(t, p)),
        })
        .collect();
    Ok(SegmentResult {
        imu: imu.to_string(),
        q: wxyz(&crate::rotation::canonical(&lm.q)),
        iterations: lm.iterations,
        cost_start: lm.costs[0],
        cost_end: *lm.costs.last().expect("costs start with the initial one"),
        triad_q: triad.map(|t| wxyz(&crate::rotation::canonical(&t))),
        triad_movements: vec![found[0].0.label.clone(), found[second].0.label.clone()],
        lm_triad_deg: triad.map(|t| crate::rotation::angle_between_deg(&lm.q, &t)),
        axes,
        missing,
    })
}

/// The default calibration file of a recording: `<stem>.calibration.toml`
/// beside it (`walk.calib.csv.gz` -> `walk.calibration.toml`).
pub fn default_output(recording: &Path) -> PathBuf {
    let stem = crate::file_names::stem_without(recording, &crate::file_names::RECORDING_SUFFIXES);
    recording.with_file_name(format!("{stem}.calibration.toml"))
}

impl Calibration {
    /// The result of an IMU.
    pub fn segment(&self, imu: &str) -> Option<&SegmentResult> {
        self.segments
            .iter()
            .find(|s| s.imu.eq_ignore_ascii_case(imu))
    }

    /// TOML text of the calibration file.
    pub fn to_toml(&self) -> String {
        let body = toml::to_string(self).expect("calibration serialises");
        format!(
            "# acmw calibration (Ricci et al. 2014). Per IMU, q = [w, x, y, z] maps sensor-frame\n# vectors into the functional frame (R_SF^FF); `acmw correct --calibration` applies it.\n{body}"
        )
    }

    /// Parses a calibration file; errors name file, line and column.
    pub fn from_toml(text: &str, origin: &str) -> Result<Calibration, CalibrationError> {
        let c: Calibration =
            toml::from_str(text).map_err(|e| CalibrationError::toml(origin, text, &e))?;
        for (i, s) in c.segments.iter().enumerate() {
            let n = s.q.iter().map(|v| v * v).sum::<f64>().sqrt();
            if !(n.is_finite() && (n - 1.0).abs() < 1e-3) {
                let message = format!("IMU '{}': q is not a unit quaternion (norm {n})", s.imu);
                let (line, column) =
                    crate::input::locate::toml_key(text, &["segment", &i.to_string(), "q"])
                        .unwrap_or((0, 0));
                return Err(CalibrationError::at(origin, line, column, message));
            }
        }
        Ok(c)
    }

    /// Reads a calibration file.
    pub fn load(path: &Path) -> Result<Calibration, CalibrationError> {
        let origin = path.display().to_string();
        let text = crate::input::read_text_located(path).map_err(|e| {
            CalibrationError::at(
                &origin,
                e.line,
                e.column,
                format!("cannot read: {}", e.error),
            )
        })?;
        Calibration::from_toml(&text, &origin)
    }

    /// Writes the calibration file atomically (the previous one kept as `.bak`).
    pub fn save(&self, path: &Path) -> Result<(), crate::save::WriteError> {
        crate::save::atomic_write(path, self.to_toml().as_bytes())
            .map_err(|e| crate::save::WriteError::io(path, &e))
    }

    /// What applying it to a trial does: per IMU the rotation. `text` is the
    /// file's content, recorded so that a sidecar reproduces it bit for bit.
    pub fn applied(&self, file: &str, text: &str) -> AppliedCalibration {
        AppliedCalibration {
            file: file.to_string(),
            sha256: crate::input::sha256_hex(text.as_bytes()),
            text: text.to_string(),
            protocol: self.protocol.clone(),
            imus: self
                .segments
                .iter()
                .map(|s| AppliedRotation {
                    imu: s.imu.clone(),
                    q: s.q,
                })
                .collect(),
        }
    }
}

/// One IMU's calibration rotation as applied to a trial.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AppliedRotation {
    /// IMU name (mapped through the model's aliases when applied).
    pub imu: String,
    /// `R_SF^FF` as `[w, x, y, z]`.
    pub q: [f64; 4],
}

/// A calibration applied to a trial before the ACM, as the sidecar records it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AppliedCalibration {
    /// The calibration file as named.
    pub file: String,
    /// SHA-256 of its bytes.
    pub sha256: String,
    pub protocol: String,
    /// The rotations, for reading (applying uses `text`).
    pub imus: Vec<AppliedRotation>,
    /// The calibration file's text (TOML numbers read back exactly; JSON ones
    /// may not be).
    pub text: String,
}

impl AppliedCalibration {
    /// Reads a calibration file and records what applying it means.
    pub fn load(path: &Path) -> Result<AppliedCalibration, CalibrationError> {
        let origin = path.display().to_string();
        let text = crate::input::read_text(path)
            .map_err(|e| CalibrationError::file(&origin, format!("cannot read: {e}")))?;
        let c = Calibration::from_toml(&text, &origin)?;
        Ok(c.applied(&origin, &text))
    }

    /// The record read again from its text (as a sidecar holds it), checked
    /// against its hash; `origin` names the sidecar in errors.
    pub fn reread(&self, origin: &str) -> Result<AppliedCalibration, CalibrationError> {
        let c = Calibration::from_toml(&self.text, &format!("{origin} (calibration.text)"))?;
        let again = c.applied(&self.file, &self.text);
        if again.sha256 != self.sha256 {
            return Err(CalibrationError::file(
                origin,
                "calibration.text does not match calibration.sha256 (the sidecar was edited?)",
            ));
        }
        Ok(again)
    }

    /// Applies the rotations to the trial in place: `G_R_FF = G_R_SF * R^-1` for
    /// every calibrated IMU the trial has (names through the model's aliases),
    /// and its gyroscope readings, if any, re-expressed in the functional
    /// frame (`w_FF = R w_SF`, rad/s). Returns warnings for calibrated IMUs the trial lacks.
    pub fn apply(&self, trial: &mut Trial, model: &Model) -> Vec<String> {
        let mut warnings = vec![];
        for a in &self.imus {
            let name = model.canonical_imu(&a.imu).unwrap_or(&a.imu).to_string();
            let inv = quat_from_wxyz(a.q).inverse();
            match trial.imu_mut(&name) {
                Some(s) => {
                    s.orientation.iter_mut().for_each(|o| *o *= inv);
                    s.turn_gyro(&inv);
                }
                None => warnings.push(format!(
                    "calibration {}: IMU '{}' is not in trial {}",
                    self.file, a.imu, trial.name
                )),
            }
        }
        warnings
    }
}

#[cfg(test)]
mod tests;
