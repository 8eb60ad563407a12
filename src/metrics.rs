//! The figures a researcher reports (docs/method.md section 16, thesis 4.4-4.6).
//!
//! All angles are degrees; joint angles are the Z-Y-X Euler angles of
//! `(G_R_prox)^T * G_R_dist` taken from whichever trial is given (raw or corrected).
//! Excursions count by the limit table's own model: the Euler box on those
//! angles, or a swing-twist table's region and twist range on the rotations.

use crate::acm::cost::excursion;
use crate::limits::{JointLimits, LimitTable};
use crate::model::{Joint, Model};
use crate::rotation::{angle_deg, wrap180, Quat};
use crate::trial::Trial;
use serde::{Deserialize, Serialize};

/// The joint's angles `[x, y, z]` (degrees, the limit table's convention:
/// [`Joint::angles`]) per sample, if both IMUs are present.
pub fn joint_angles(trial: &Trial, joint: &Joint) -> Option<Vec<[f64; 3]>> {
    let p = &trial.imu(&joint.proximal)?.orientation;
    let d = &trial.imu(&joint.distal)?.orientation;
    let axes = joint.table_axes();
    let limit_box = joint.limit_box();
    Some(
        p.iter()
            .zip(d)
            .map(|(p, d)| {
                let r = p.inverse() * d;
                let principal = match &axes {
                    Some(t) => t.angles(&r),
                    None => crate::rotation::euler_zyx_deg(&r),
                };
                match &limit_box {
                    Some(b) => crate::rotation::read_in_box(principal, b),
                    None => principal,
                }
            })
            .collect(),
    )
}

/// [`joint_angles`] of every joint of `model` (none where the trial lacks
/// one of its IMUs), in the model's order; the joints in parallel.
pub fn model_joint_angles(trial: &Trial, model: &Model) -> Vec<Option<Vec<[f64; 3]>>> {
    use rayon::prelude::*;
    (model.joints.par_iter())
        .map(|joint| joint_angles(trial, joint))
        .collect()
}

/// Excursion figures of one joint (Tables 4-1, 4-2 and Figure 4-20).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ExcursionFigures {
    /// Percentage of samples outside the limits, per axis X, Y, Z.
    pub pct_outside: [f64; 3],
    /// Mean excursion beyond the limits per sample, per axis, degrees.
    pub mean_excursion_deg: [f64; 3],
    /// `(1/n) sum (Ex + Ey + Ez)`, degrees.
    pub joint_mean_excursion_deg: f64,
    /// Percentage of samples outside on any axis.
    pub pct_outside_any: f64,
}

/// An angle beyond a limit by at most this counts as inside, degrees: writing
/// and reading a trial moves angles by ~1e-13 deg, which must not move a
/// sample that sits on a limit (inverse kinematics clamps coordinates to their
/// hard limits, which may be a table's limits) across it.
pub const ON_LIMIT_DEG: f64 = 1e-9;

/// Excursion figures of joint angles against limits. Each sample's angles
/// are read in the limits' box first ([`crate::rotation::read_in_box`]: of its
/// two Z-Y-X triplets, the one the box reads), so the figures count what the
/// ACM's cost counts whichever table the angles were shown in.
pub fn excursion_figures(angles: &[[f64; 3]], limits: &JointLimits) -> ExcursionFigures {
    let n = angles.len().max(1) as f64;
    let mut out_count = [0usize; 3];
    let mut any = 0usize;
    let mut sum = [0.0; 3];
    for a in angles {
        let e = excursion(
            crate::rotation::read_in_box(*a, &limits.range_deg),
            &limits.range_deg,
        );
        for k in 0..3 {
            sum[k] += e[k];
            out_count[k] += usize::from(e[k] > ON_LIMIT_DEG);
        }
        any += usize::from(e.iter().any(|&x| x > ON_LIMIT_DEG));
    }
    ExcursionFigures {
        pct_outside: out_count.map(|c| 100.0 * c as f64 / n),
        mean_excursion_deg: sum.map(|s| s / n),
        joint_mean_excursion_deg: sum.iter().sum::<f64>() / n,
        pct_outside_any: 100.0 * any as f64 / n,
    }
}

/// Excursion figures of one joint against swing-twist limits, from each
/// sample's excursion in its parts ([`JointLimits::swing_twist_parts`]): a
/// sample is outside when its swing lies beyond the region or its twist
/// beyond its range, as the ACM's cost counts it. Per axis: the twist axis
/// (`twist_axis`, 0 = X) counts the twist's excursion, each swing axis the
/// size of the swing's offset from the region's nearest point along it (so
/// the per-axis means may add up to more than the joint's, which is the
/// offset's length plus the twist's excursion), degrees.
pub fn swing_twist_excursion_figures(
    parts: &[crate::limits::swing_twist::ExcursionParts],
    twist_axis: usize,
) -> ExcursionFigures {
    let n = parts.len().max(1) as f64;
    let mut out_count = [0usize; 3];
    let mut any = 0usize;
    let mut sum = [0.0; 3];
    let mut total = 0.0;
    for p in parts {
        let e = p.per_axis(twist_axis);
        for k in 0..3 {
            sum[k] += e[k];
            out_count[k] += usize::from(e[k] > ON_LIMIT_DEG);
        }
        total += p.swing_deg + p.twist_deg;
        any += usize::from(p.swing_deg > ON_LIMIT_DEG || p.twist_deg > ON_LIMIT_DEG);
    }
    ExcursionFigures {
        pct_outside: out_count.map(|c| 100.0 * c as f64 / n),
        mean_excursion_deg: sum.map(|s| s / n),
        joint_mean_excursion_deg: total / n,
        pct_outside_any: 100.0 * any as f64 / n,
    }
}

/// A joint's excursion figures against its limits in the table's own model:
/// the Euler box on `angles` ([`excursion_figures`]), or swing-twist limits
/// on the joint rotations of `trial` ([`swing_twist_excursion_figures`]).
pub fn joint_excursion_figures(
    trial: &Trial,
    joint: &Joint,
    angles: &[[f64; 3]],
    limits: &JointLimits,
) -> ExcursionFigures {
    let parts = limits.swing_twist.and_then(|st| {
        let p = &trial.imu(&joint.proximal)?.orientation;
        let d = &trial.imu(&joint.distal)?.orientation;
        let rotations = p.iter().zip(d).map(|(p, d)| p.inverse() * d);
        Some((limits.swing_twist_parts(joint, rotations)?, st.twist_axis))
    });
    match parts {
        Some((parts, axis)) => swing_twist_excursion_figures(&parts, axis),
        None => excursion_figures(angles, limits),
    }
}

/// What a correction did to a joint's angles (Table 4-3).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ShiftFigures {
    /// Mean of `|wrap(corrected - uncorrected)|` per axis, degrees.
    pub mean_shift_deg: [f64; 3],
    /// Mean rotation angle of the applied, time-dependent correction, degrees.
    pub mean_correction_angle_deg: f64,
}

/// Shift figures between raw and corrected angles; `applied` is the distal IMU's
/// per-sample correction `raw^-1 * corrected`.
pub fn shift_figures(raw: &[[f64; 3]], corrected: &[[f64; 3]], applied: &[Quat]) -> ShiftFigures {
    let n = raw.len().max(1) as f64;
    let mut sum = [0.0; 3];
    for (r, c) in raw.iter().zip(corrected) {
        for k in 0..3 {
            sum[k] += wrap180(c[k] - r[k]).abs();
        }
    }
    let angle: f64 = applied.iter().map(angle_deg).sum();
    ShiftFigures {
        mean_shift_deg: sum.map(|s| s / n),
        mean_correction_angle_deg: angle / applied.len().max(1) as f64,
    }
}

/// Figures against ground truth (simulated trials).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TruthFigures {
    /// RMS of the wrapped angle error per axis, degrees.
    pub rms_error_deg: [f64; 3],
    /// Mean angle between the distal IMU's orientation and its true segment
    /// orientation (the angle between applied and true correction), degrees.
    pub mean_correction_error_deg: f64,
}

/// Truth figures of a joint's angles and of its distal IMU's orientation.
pub fn truth_figures(
    angles: &[[f64; 3]],
    true_angles: &[[f64; 3]],
    distal: &[Quat],
    true_distal: &[Quat],
) -> TruthFigures {
    let n = angles.len().max(1) as f64;
    let mut sq = [0.0; 3];
    for (a, t) in angles.iter().zip(true_angles) {
        for k in 0..3 {
            sq[k] += wrap180(a[k] - t[k]).powi(2);
        }
    }
    let err: f64 = distal
        .iter()
        .zip(true_distal)
        .map(|(d, t)| angle_deg(&(d.inverse() * t)))
        .sum();
    TruthFigures {
        rms_error_deg: sq.map(|s| (s / n).sqrt()),
        mean_correction_error_deg: err / distal.len().max(1) as f64,
    }
}

/// The figures of one joint of one trial (raw or corrected).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JointFigures {
    pub joint: String,
    pub excursion: ExcursionFigures,
    /// Present for a corrected trial.
    pub shift: Option<ShiftFigures>,
    /// Present when a truth is known.
    pub truth: Option<TruthFigures>,
}

/// Figures of every joint of `model` present in `trial`.
///
/// `raw` is the uncorrected trial when `trial` is a corrected one (for the shift
/// figures); `truth` holds the true segment orientations when known.
pub fn trial_figures(
    trial: &Trial,
    raw: Option<&Trial>,
    truth: Option<&Trial>,
    model: &Model,
    limits: &LimitTable,
) -> Vec<JointFigures> {
    use rayon::prelude::*;
    // Each joint on its own, collected in the model's order.
    model
        .joints
        .par_iter()
        .filter_map(|joint| {
            let angles = joint_angles(trial, joint)?;
            let lim = limits.joint_limits(&joint.name, &joint.kind, false)?;
            let shift = raw.and_then(|raw| {
                let raw_angles = joint_angles(raw, joint)?;
                let r = &raw.imu(&joint.distal)?.orientation;
                let c = &trial.imu(&joint.distal)?.orientation;
                let applied: Vec<Quat> = r.iter().zip(c).map(|(r, c)| r.inverse() * c).collect();
                Some(shift_figures(&raw_angles, &angles, &applied))
            });
            let truth = truth.and_then(|t| {
                let true_angles = joint_angles(t, joint)?;
                let d = &trial.imu(&joint.distal)?.orientation;
                let td = &t.imu(&joint.distal)?.orientation;
                Some(truth_figures(&angles, &true_angles, d, td))
            });
            Some(JointFigures {
                joint: joint.name.clone(),
                excursion: joint_excursion_figures(trial, joint, &angles, &lim),
                shift,
                truth,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::quat_axis_angle_deg;

    fn knee() -> JointLimits {
        JointLimits {
            range_deg: [[-5.0, 5.0], [0.0, 130.0], [-5.0, 5.0]],
            centroid_deg: None,
            lambda2: 0.0,
            axes: None,
            swing_twist: None,
        }
    }

    #[test]
    fn excursion_figures_by_hand() {
        let a = [
            [0.0, 10.0, 0.0],
            [7.0, -2.0, 0.0],
            [0.0, 140.0, -6.0],
            [0.0, 50.0, 0.0],
        ];
        let f = excursion_figures(&a, &knee());
        assert_eq!(f.pct_outside, [25.0, 50.0, 25.0]);
        assert_eq!(f.mean_excursion_deg, [0.5, 3.0, 0.25]);
        assert_eq!(f.joint_mean_excursion_deg, 3.75);
        assert_eq!(f.pct_outside_any, 50.0);
    }

    #[test]
    fn shift_wraps_and_averages() {
        let raw = [[179.0, 0.0, 0.0], [0.0, 10.0, 0.0]];
        let cor = [[-179.0, 0.0, 0.0], [0.0, 14.0, -2.0]];
        let q = quat_axis_angle_deg([0.0, 1.0, 0.0], 4.0);
        let s = shift_figures(&raw, &cor, &[q, q]);
        assert!((s.mean_shift_deg[0] - 1.0).abs() < 1e-9);
        assert_eq!(s.mean_shift_deg[1], 2.0);
        assert_eq!(s.mean_shift_deg[2], 1.0);
        assert!((s.mean_correction_angle_deg - 4.0).abs() < 1e-9);
    }

    #[test]
    fn truth_rms_and_orientation_error() {
        let a = [[1.0, 0.0, 0.0], [-1.0, 2.0, 0.0]];
        let t = [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]];
        let q = quat_axis_angle_deg([1.0, 0.0, 0.0], 3.0);
        let f = truth_figures(&a, &t, &[q, q], &[Quat::identity(), Quat::identity()]);
        assert_eq!(f.rms_error_deg, [1.0, 2f64.sqrt(), 0.0]);
        assert!((f.mean_correction_error_deg - 3.0).abs() < 1e-9);
    }
}
