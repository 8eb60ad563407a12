//! Do a trial's joint angles follow the limit table's sign conventions?
//!
//! The tables count flexion one way (hip and knee flexion positive on Y, the
//! elbow's on X): an axis whose range reaches at least twice as far one way as
//! the other has an expected sense of motion. After a pose calibration every
//! joint angle is 0 in the calibration pose, so motion goes mostly the
//! expected way from 0: the 98th percentile beyond 0 in that sense should not
//! be outweighed by the 2nd percentile the other way. Three checks, each a
//! warning naming the joint and axis:
//!
//! * **mirrored** (calibrated trials only): on such an axis the angles reach
//!   at least [`MIN_MOTION_DEG`] the unexpected way and more than
//!   [`MIRROR_RATIO`] times as far as the expected way. On a knee (every
//!   built-in model's `angle_axes` count knee flexion positive in the frames of
//!   its pose) that points at the heading, i.e. `--base-forward`: a heading
//!   off by 180 deg turns the segment frames' X and Y round; on other joints,
//!   at the model's `angle_axes` counting that joint the other way.
//! * **offset**: more than [`OFFSET_SHARE`] of the samples beyond one limit
//!   while none reach the other: an offset calibration pose, or none.
//! * **axes swapped** (calibrated): a narrow axis (range within +-10 deg)
//!   moving more than twice the expected flexion axis.
//!
//! The checks read Z-Y-X angles against Euler ranges whatever the table's
//! model: with a swing-twist table ([`crate::limits::swing_twist`]) they read
//! its Euler view, each axis' range the region's extent along it (the twist
//! axis' the twist range: [`crate::limits::swing_twist::SwingTwistRow::euler_rows`]).
//! A sign convention is a property of each axis' sense of motion, which that
//! box states as the region does; the singularity the swing-twist model
//! avoids lies at Y = +-90 deg, beyond the motions these checks look at.

use crate::limits::LimitTable;
use crate::metrics::model_joint_angles;
use crate::model::{Axis, Joint, Model};
use crate::trial::Trial;

/// Motion smaller than this (degrees, either way) says nothing about the sense.
pub const MIN_MOTION_DEG: f64 = 10.0;
/// The unexpected way must outreach the expected way by this factor.
pub const MIRROR_RATIO: f64 = 1.5;
/// Share of samples beyond one limit that counts as offset.
pub const OFFSET_SHARE: f64 = 0.5;

/// The `p`-th percentile (0..1) of `v` (nearest rank).
fn percentile(v: &mut [f64], p: f64) -> f64 {
    let k = ((v.len() - 1) as f64 * p).round() as usize;
    let (_, x, _) = v.select_nth_unstable_by(k, f64::total_cmp);
    *x
}

/// +1 or -1 when the range reaches twice as far one way as the other.
fn expected_sense(lo: f64, hi: f64) -> Option<f64> {
    if hi > 0.0 && hi >= 2.0 * (-lo).max(0.0) && hi - lo > 2.0 * MIN_MOTION_DEG {
        Some(1.0)
    } else if lo < 0.0 && -lo >= 2.0 * hi.max(0.0) && hi - lo > 2.0 * MIN_MOTION_DEG {
        Some(-1.0)
    } else {
        None
    }
}

/// Warnings about `trial`'s angles against `limits`; `calibrated` says the
/// trial went through a pose calibration (angles 0 in the pose).
pub fn check_conventions(
    trial: &Trial,
    model: &Model,
    limits: &LimitTable,
    calibrated: bool,
) -> Vec<String> {
    check_conventions_of(&model_joint_angles(trial, model), model, limits, calibrated)
}

/// As [`check_conventions`], from the trial's joint angles
/// ([`model_joint_angles`]: one entry per joint of `model`, in its order).
/// The joints are checked in parallel; the warnings come in the model's order.
pub fn check_conventions_of(
    angles: &[Option<Vec<[f64; 3]>>],
    model: &Model,
    limits: &LimitTable,
    calibrated: bool,
) -> Vec<String> {
    use rayon::prelude::*;
    let per_joint: Vec<Vec<String>> = (model.joints.par_iter().zip(angles))
        .map(|(joint, angles)| joint_warnings(joint, angles.as_deref(), limits, calibrated))
        .collect();
    per_joint.concat()
}

/// [`check_conventions`]' warnings about one joint with angles `angles`.
fn joint_warnings(
    joint: &Joint,
    angles: Option<&[[f64; 3]]>,
    limits: &LimitTable,
    calibrated: bool,
) -> Vec<String> {
    let mut out = Vec::new();
    let (Some(angles), Some(lim)) = (angles, limits.joint_limits(&joint.name, &joint.kind, false))
    else {
        return out;
    };
    if angles.len() < 10 {
        return out;
    }
    let mut reach = [[0.0f64; 2]; 3];
    for axis in Axis::ALL {
        let k = axis.index();
        let [lo, hi] = lim.range_deg[k];
        let mut v: Vec<f64> = angles.iter().map(|a| a[k]).collect();
        let n = v.len() as f64;
        // Within 1e-9 deg of a limit is on it (rounding of a joint held there).
        let below = v.iter().filter(|&&x| x < lo - 1e-9).count() as f64 / n;
        let above = v.iter().filter(|&&x| x > hi + 1e-9).count() as f64 / n;
        let (p2, p98) = (percentile(&mut v, 0.02), percentile(&mut v, 0.98));
        reach[k] = [(-p2).max(0.0), p98.max(0.0)];
        let name = format!("{} {}", joint.name, axis.name());
        if below > OFFSET_SHARE && p98 < hi {
            out.push(format!(
                "{name}: {:.0}% of the samples are below the table's {lo} deg (98% below {p98:.1}): the angles look offset; likely the calibration pose differs from the model's default pose, or the trial is not pose-calibrated (--pose-calibration)",
                100.0 * below
            ));
        } else if above > OFFSET_SHARE && p2 > lo {
            out.push(format!(
                "{name}: {:.0}% of the samples are above the table's {hi} deg (98% above {p2:.1}): the angles look offset; likely the calibration pose differs from the model's default pose, or the trial is not pose-calibrated (--pose-calibration)",
                100.0 * above
            ));
        }
        let Some(sense) = expected_sense(lo, hi).filter(|_| calibrated) else {
            continue;
        };
        let (expected, other) = if sense > 0.0 {
            (reach[k][1], reach[k][0])
        } else {
            (reach[k][0], reach[k][1])
        };
        if other >= MIN_MOTION_DEG && other > MIRROR_RATIO * expected {
            let way = |s: f64| if s > 0.0 { "positive" } else { "negative" };
            let cause = if joint.kind == "knee" {
                "the heading of the pose calibration is likely 180 deg off: check --base-forward (the base IMU's forward axis in the pose)".to_string()
            } else {
                format!(
                    "the model's angle_axes for {} likely count this axis the other way, or its pose is not the one held (or the heading is off: --base-forward)",
                    joint.name
                )
            };
            out.push(format!(
                "{name}: moves {other:.1} deg {} but only {expected:.1} deg {} from the calibration pose, while the table ({lo}..{hi} deg) expects the {} sense: the angles look mirrored; {cause}",
                way(-sense),
                way(sense),
                way(sense)
            ));
        }
    }
    if !calibrated {
        return out;
    }
    // A narrow axis that moves more than the flexion axis.
    let flexion = Axis::ALL.into_iter().find(|a| {
        let [lo, hi] = lim.range_deg[a.index()];
        expected_sense(lo, hi).is_some()
    });
    if let Some(f) = flexion {
        let flex_motion = reach[f.index()][0].max(reach[f.index()][1]);
        for axis in Axis::ALL.into_iter().filter(|a| *a != f) {
            let [lo, hi] = lim.range_deg[axis.index()];
            let motion = reach[axis.index()][0].max(reach[axis.index()][1]);
            if hi - lo <= 20.0 && motion >= 2.0 * MIN_MOTION_DEG && motion > 2.0 * flex_motion {
                out.push(format!(
                    "{} {}: moves {motion:.1} deg, more than twice the {} axis ({flex_motion:.1} deg) the table lets move: the axes look swapped; likely the heading of the pose calibration is 90 deg off (--base-forward)",
                    joint.name,
                    axis.name(),
                    f.name()
                ));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{quat_axis_angle_deg, Quat};
    use crate::trial::ImuSeries;

    /// Pelvis still in the standing pose's frame (x forward, y left, z up),
    /// the right hip flexing by `hip(t)` (the thigh swinging forward, about
    /// -y) and the knee by `knee(t)` (the shank folding back, about +y).
    fn trial(hip: impl Fn(f64) -> f64, knee: impl Fn(f64) -> f64) -> Trial {
        let time_s: Vec<f64> = (0..500).map(|i| i as f64 / 50.0).collect();
        let thigh: Vec<Quat> = time_s
            .iter()
            .map(|&t| quat_axis_angle_deg([0.0, -1.0, 0.0], hip(t)))
            .collect();
        let shank: Vec<Quat> = thigh
            .iter()
            .zip(&time_s)
            .map(|(q, &t)| q * quat_axis_angle_deg([0.0, 1.0, 0.0], knee(t)))
            .collect();
        Trial {
            name: "t".to_string(),
            imus: vec![
                ImuSeries::new("pelvis_imu", vec![Quat::identity(); time_s.len()]),
                ImuSeries::new("femur_r_imu", thigh),
                ImuSeries::new("tibia_r_imu", shank),
            ],
            time_s,
            warnings: vec![],
            orientation_decimals: None,
        }
    }

    #[test]
    fn gait_in_the_tables_convention_passes_and_mirrors_are_named() {
        let model = Model::builtin("opensense_lower").unwrap();
        let table = LimitTable::default_table();
        let hip = |t: f64| 10.0 + 20.0 * (t * 6.0).sin();
        let knee = |t: f64| 30.0 - 30.0 * (t * 6.0).cos();
        let ok = check_conventions(&trial(hip, knee), &model, &table, true);
        assert!(ok.is_empty(), "{ok:?}");
        let w = check_conventions(&trial(|t| -hip(t), knee), &model, &table, true);
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(
            w[0].starts_with("r_hip y:") && w[0].contains("mirrored"),
            "{w:?}"
        );
        let w = check_conventions(&trial(hip, |t| -knee(t)), &model, &table, true);
        assert!(
            w.iter()
                .any(|w| w.starts_with("r_knee y:") && w.contains("--base-forward")),
            "{w:?}"
        );
        // Uncalibrated: no sense check, but an offset is still seen.
        let w = check_conventions(&trial(hip, |t| knee(t) - 80.0), &model, &table, false);
        assert!(
            w.len() == 1 && w[0].starts_with("r_knee y:") && w[0].contains("offset"),
            "{w:?}"
        );
    }
}
