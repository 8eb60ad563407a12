//! Pose calibration with heading correction (docs/method.md section 14; OpenSense's
//! IMU placer, Lavikainen et al.).
//!
//! At a chosen instant (or averaged over a chosen span) the subject holds the
//! model's default pose. First every IMU is rotated about the global vertical
//! (+Z) by the heading correction `H = Rz(psi)`, chosen so that the base IMU's
//! forward axis, projected on the horizontal plane, points along the model's
//! forward axis. Then each IMU's offset on its segment is taken from that
//! instant: `O_i = (S_i^0)^-1 * H * G_R_imu_i(t0)`, where `S_i^0` is the
//! segment's orientation in the default pose (base at identity, every joint at
//! its `default_pose_deg`). The calibrated trial holds segment orientations
//! `G'_R_seg_i(t) = H * G_R_imu_i(t) * O_i^-1`, which equal `S_i^0` at `t0`.
//!
//! Rotating a whole trial about the vertical changes `H` by the opposite
//! rotation and leaves the calibrated trial unchanged: joint angles after pose
//! calibration do not depend on which way the subject faced.

use crate::model::{Model, PoseSetup};
use crate::rotation::{canonical, quat_axis_angle_deg, wxyz, Quat};
use crate::trial::Trial;
use nalgebra::{Matrix4, Quaternion, Vector3};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The forward axis may not be closer to the vertical than this, degrees:
/// its horizontal projection (the heading) is meaningless there.
pub const MIN_FORWARD_TILT_FROM_VERTICAL_DEG: f64 = 10.0;

/// When the calibration pose is held, seconds from the first sample.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum PoseTime {
    /// The sample nearest this time.
    At(f64),
    /// The mean orientation of the samples in `[start, end]`.
    Span(f64, f64),
}

impl std::str::FromStr for PoseTime {
    type Err = String;
    /// `TIME` or `START..END`, seconds from the first sample.
    fn from_str(s: &str) -> Result<PoseTime, String> {
        let num = |t: &str| -> Result<f64, String> {
            let v: f64 = t.trim().parse().map_err(|_| {
                format!("'{s}': expected TIME or START..END in seconds from the first sample")
            })?;
            if v.is_finite() && v >= 0.0 {
                Ok(v)
            } else {
                Err(format!("'{s}': times must be finite and >= 0 seconds"))
            }
        };
        match s.split_once("..") {
            Some((a, b)) => {
                let (a, b) = (num(a)?, num(b)?);
                if a < b {
                    Ok(PoseTime::Span(a, b))
                } else {
                    Err(format!("'{s}': the span's start must be before its end"))
                }
            }
            None => Ok(PoseTime::At(num(s)?)),
        }
    }
}

impl TryFrom<String> for PoseTime {
    type Error = String;
    fn try_from(s: String) -> Result<PoseTime, String> {
        s.parse()
    }
}

impl From<PoseTime> for String {
    fn from(t: PoseTime) -> String {
        t.to_string()
    }
}

impl std::fmt::Display for PoseTime {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            PoseTime::At(t) => write!(f, "{t}"),
            PoseTime::Span(a, b) => write!(f, "{a}..{b}"),
        }
    }
}

/// A pose calibration to perform: when, and which axes define the heading.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PoseCalibration {
    pub at: PoseTime,
    #[serde(flatten)]
    pub setup: PoseSetup,
}

/// The offset of one IMU on its segment.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImuOffset {
    pub imu: String,
    /// `O_i`, the IMU's frame in its segment's frame, `[w, x, y, z]`, w >= 0.
    pub offset: [f64; 4],
}

/// What a pose calibration found (recorded in the sidecar).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PoseRecord {
    pub calibration: PoseCalibration,
    /// Samples averaged (1 for a single instant).
    pub samples: usize,
    /// The heading correction `psi` of `H = Rz(psi)`, degrees.
    pub heading_deg: f64,
    /// Per model IMU present in the trial, in trial order.
    pub offsets: Vec<ImuOffset>,
}

impl PoseTime {
    /// The last time of the calibration, seconds from the first sample: once
    /// a sample later than it was read, the calibration's samples are all in.
    pub fn end_s(self) -> f64 {
        match self {
            PoseTime::At(t) => t,
            PoseTime::Span(_, b) => b,
        }
    }
}

impl PoseRecord {
    /// Applies what this calibration found to more samples, as [`calibrate`]
    /// applied it to the trial it was found on: every orientation turned by
    /// the heading correction about global +Z (`G_R' = Rz(psi) G_R`), and the
    /// IMUs with an offset turned into their segment's frame (`G_R' G_R'
    /// O_i^-1`, gyroscope readings `w' = O_i w`, rad/s).
    pub fn apply(&self, trial: &mut Trial) {
        let h = quat_axis_angle_deg([0.0, 0.0, 1.0], self.heading_deg);
        for series in &mut trial.imus {
            let offset_inv = self.offsets.iter().find(|o| o.imu == series.name).map(|o| {
                let [w, x, y, z] = o.offset;
                Quat::new_normalize(Quaternion::new(w, x, y, z)).inverse()
            });
            for q in &mut series.orientation {
                let g = h * *q;
                *q = match offset_inv {
                    Some(oi) => Quat::new_normalize((g * oi).into_inner()),
                    None => g,
                };
            }
            if let Some(oi) = offset_inv {
                series.turn_gyro(&oi);
            }
        }
    }
}

/// Why a pose calibration cannot be done.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("pose calibration: {0}")]
pub struct PoseError(pub String);

/// Segment orientations in the model's default pose (base at identity, each
/// joint at its `default_pose_deg`), keyed by IMU.
pub fn default_pose(model: &Model) -> BTreeMap<String, Quat> {
    let mut pose = BTreeMap::from([(model.base.clone(), Quat::identity())]);
    for j in &model.joints {
        let parent = pose
            .get(&j.proximal)
            .copied()
            .unwrap_or_else(Quat::identity);
        pose.insert(j.distal.clone(), parent * j.rotation(j.default_pose_deg));
    }
    pose
}

/// The mean of rotations (Markley et al. 2007): the unit quaternion maximising
/// the sum of squared dot products with the samples (sign-invariant), the
/// principal eigenvector of `sum q q^T`.
pub fn mean_orientation(qs: &[Quat]) -> Quat {
    let mut m = Matrix4::<f64>::zeros();
    for q in qs {
        let v = q.into_inner().coords;
        m += v * v.transpose();
    }
    let eig = m.symmetric_eigen();
    let k = eig.eigenvalues.imax();
    let v = eig.eigenvectors.column(k);
    // coords are [x, y, z, w].
    canonical(&Quat::new_normalize(Quaternion::new(
        v[3], v[0], v[1], v[2],
    )))
}

/// Heading correction `psi` (degrees) that turns `base`'s forward axis onto the
/// model's forward axis about global +Z.
pub fn heading_deg(base: &Quat, setup: &PoseSetup) -> Result<f64, PoseError> {
    let [a, b, c] = setup.base_forward.vector();
    let f = base * Vector3::new(a, b, c);
    let horizontal = f.x.hypot(f.y);
    if horizontal < MIN_FORWARD_TILT_FROM_VERTICAL_DEG.to_radians().sin() {
        return Err(PoseError(format!(
            "the base IMU's forward axis {} is within {MIN_FORWARD_TILT_FROM_VERTICAL_DEG} deg of the vertical at the calibration time; choose another axis (--base-forward)",
            setup.base_forward
        )));
    }
    let [mx, my, _] = setup.forward.vector();
    Ok((my.atan2(mx) - f.y.atan2(f.x)).to_degrees())
}

/// Sample indices of the calibration time or span.
fn samples(trial: &Trial, at: PoseTime) -> Result<Vec<usize>, PoseError> {
    let t = &trial.time_s;
    let (Some(&first), Some(&last)) = (t.first(), t.last()) else {
        return Err(PoseError("the trial has no samples".into()));
    };
    let end = last - first + 0.5 * trial.median_dt();
    match at {
        PoseTime::At(ts) => {
            if ts > end {
                return Err(PoseError(format!(
                    "time {ts} s is after the trial's end ({:.3} s)",
                    last - first
                )));
            }
            let i = t.partition_point(|&x| x - first < ts);
            let nearest = match i {
                0 => 0,
                i if i >= t.len() => t.len() - 1,
                i if ts - (t[i - 1] - first) <= t[i] - first - ts => i - 1,
                i => i,
            };
            Ok(vec![nearest])
        }
        PoseTime::Span(a, b) => {
            let idx: Vec<usize> = (0..t.len())
                .filter(|&i| (a..=b).contains(&(t[i] - first)))
                .collect();
            if idx.is_empty() {
                return Err(PoseError(format!(
                    "no sample between {a} and {b} s (the trial lasts {:.3} s)",
                    last - first
                )));
            }
            Ok(idx)
        }
    }
}

/// Calibrates `trial` to `model`'s default pose: returns the calibrated trial
/// (segment orientations, heading-corrected; IMUs the model does not know are
/// only heading-corrected) and the record of what was found. Gyroscope
/// readings, if any, are re-expressed in the segment frames (`w' = O w`, O the
/// IMU's offset; the heading turn leaves sensor-frame rates unchanged).
pub fn calibrate(
    trial: &Trial,
    model: &Model,
    calibration: &PoseCalibration,
) -> Result<(Trial, PoseRecord), PoseError> {
    let idx = samples(trial, calibration.at)?;
    let mean = |q: &[Quat]| -> Quat {
        let picked: Vec<Quat> = idx.iter().map(|&i| q[i]).collect();
        if picked.len() == 1 {
            picked[0]
        } else {
            mean_orientation(&picked)
        }
    };
    let base = trial.imu(&model.base).ok_or_else(|| {
        PoseError(format!(
            "the base IMU '{}' is not in the trial; the heading needs it",
            model.base
        ))
    })?;
    let psi = heading_deg(&mean(&base.orientation), &calibration.setup)?;
    let h = quat_axis_angle_deg([0.0, 0.0, 1.0], psi);
    let pose = default_pose(model);
    let mut out = trial.clone();
    let mut offsets = Vec::new();
    for series in &mut out.imus {
        let offset_inv = pose.get(&series.name).map(|s0| {
            let o = s0.inverse() * h * mean(&series.orientation);
            offsets.push(ImuOffset {
                imu: series.name.clone(),
                offset: wxyz(&canonical(&o)),
            });
            o.inverse()
        });
        for q in &mut series.orientation {
            let g = h * *q;
            *q = match offset_inv {
                Some(oi) => Quat::new_normalize((g * oi).into_inner()),
                None => g,
            };
        }
        // The heading turns the global frame (no change to sensor-frame
        // rates); the offset turns the sensor frame.
        if let Some(oi) = offset_inv {
            series.turn_gyro(&oi);
        }
    }
    Ok((
        out,
        PoseRecord {
            calibration: *calibration,
            samples: idx.len(),
            heading_deg: psi,
            offsets,
        },
    ))
}

pub mod centroid_check;
pub mod convention;

#[cfg(test)]
mod tests;
