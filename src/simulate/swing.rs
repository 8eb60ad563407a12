//! Swing motion: clean trials whose ranges and centroids are known exactly,
//! to check what is derived from clean trials (limit suggestions, centroids).
//!
//! Every joint axis of `infant13` swings as one sinusoid
//! `c + A sin(2 pi k t / 30 s + phase)` across its true range
//! [`range_deg`] = `[c - A, c + A]` (degrees): Table 3-2's range less
//! [`SHRINK_FRACTION`] of its width at each end (so that it differs from the
//! shipped table), with the Y angle kept within +-80 degrees (the Euler
//! singularity). `k`, a whole number of cycles per 30 s drawn from
//! [`CYCLES_PER_30_S`], and the phase are random per axis from the seed; the
//! base moves as in the full-body simulation. Over any whole 30 s at a rate
//! with a whole number of samples per 30 s, the mean of each angle is `c`
//! exactly, and a sinusoid's samples crowd at its extremes: 90% of the
//! samples on each side of the mean lie within `A sin(81 deg) = 0.988 A` of it.

use super::motion::{BaseMotion, MAX_ABS_Y_DEG};
use super::{chain_segments, rng, Stream};
use crate::limits::LimitTable;
use crate::model::{Joint, Model};
use crate::rotation::Quat;
use rand::Rng;
use std::f64::consts::TAU;

/// Share of a Table 3-2 range left out at each end.
pub const SHRINK_FRACTION: f64 = 0.1;
/// Fewest and most whole cycles per 30 s (periods of 10 s to 2 s).
pub const CYCLES_PER_30_S: [u32; 2] = [3, 15];
/// The span over which every axis completes whole cycles, seconds.
pub const PERIOD_BLOCK_S: f64 = 30.0;

/// The true range `[lower, upper]` of a joint axis (0 = X), degrees.
pub fn range_deg(table: &LimitTable, joint: &Joint, axis: usize) -> [f64; 2] {
    let [lo, hi] = table
        .joint_limits(&joint.name, &joint.kind, false)
        .map_or([-10.0, 10.0], |l| l.range_deg[axis]);
    let cut = SHRINK_FRACTION * (hi - lo);
    let (mut lo, mut hi) = (lo + cut, hi - cut);
    // The middle (Y) angle of Z-Y-X in the table's axes stays clear of
    // its singularity (docs/method.md section 2.5).
    if axis == crate::model::Axis::Y.index() {
        lo = lo.max(-MAX_ABS_Y_DEG);
        hi = hi.min(MAX_ABS_Y_DEG);
    }
    [lo, hi]
}

/// The true centroid of a joint axis (the middle of its range), degrees.
pub fn centre_deg(table: &LimitTable, joint: &Joint, axis: usize) -> f64 {
    let [lo, hi] = range_deg(table, joint, axis);
    0.5 * (lo + hi)
}

/// Segment orientations of every IMU of `model` at `time_s` (seconds).
pub(super) fn segments(model: &Model, seed: u64, time_s: &[f64]) -> Vec<(String, Vec<Quat>)> {
    let table = LimitTable::default_table();
    let mut r = rng(seed, Stream::Motion);
    let base = BaseMotion::random(&mut r);
    // Per joint and axis: centre, amplitude, angular rate (rad/s), phase.
    let waves: Vec<[(f64, f64, f64, f64); 3]> = model
        .joints
        .iter()
        .map(|j| {
            std::array::from_fn(|axis| {
                let [lo, hi] = range_deg(&table, j, axis);
                let k = r.random_range(CYCLES_PER_30_S[0]..=CYCLES_PER_30_S[1]);
                let phase = r.random_range(0.0..TAU);
                let omega = TAU * f64::from(k) / PERIOD_BLOCK_S;
                (0.5 * (lo + hi), 0.5 * (hi - lo), omega, phase)
            })
        })
        .collect();
    chain_segments(model, &base, time_s, |k, t| {
        waves[k].map(|(c, a, w, p)| c + a * (w * t + p).sin())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulate::{preset, simulate};

    #[test]
    fn angles_stay_in_the_true_range_and_average_to_the_centre() {
        let mut cfg = preset("full_body_swing").unwrap();
        cfg.noise_deg = 0.0;
        let sim = simulate(&cfg).unwrap();
        let model = Model::infant13();
        let table = LimitTable::default_table();
        let n30 = 1500; // 30 s at 50 Hz
        for j in &model.joints {
            let a = crate::metrics::joint_angles(&sim.trial, j).unwrap();
            for axis in 0..3 {
                let [lo, hi] = range_deg(&table, j, axis);
                let v: Vec<f64> = a.iter().map(|x| x[axis]).collect();
                let (min, max) = v
                    .iter()
                    .fold((f64::MAX, f64::MIN), |m, &x| (m.0.min(x), m.1.max(x)));
                // Whole cycles of 2-10 s in 60 s reach the extremes within
                // the sampling step (at most 0.3 deg for these amplitudes).
                assert!(min >= lo - 1e-6 && max <= hi + 1e-6, "{} {axis}", j.name);
                assert!(min - lo < 0.5 && hi - max < 0.5, "{} {axis}", j.name);
                for block in [&v[..n30], &v[n30..]] {
                    let mean = block.iter().sum::<f64>() / n30 as f64;
                    let c = centre_deg(&table, j, axis);
                    assert!((mean - c).abs() < 1e-6, "{} {axis}: {mean} vs {c}", j.name);
                }
            }
        }
        // The ranges differ from the shipped table: narrower, Y within +-80.
        let knee = model.joint("l_knee").unwrap();
        assert_eq!(range_deg(&table, knee, 1), [13.0, 80.0]);
        assert_eq!(range_deg(&table, knee, 0), [-4.0, 4.0]);
    }
}
