//! Smooth motion for the full-body simulation: the base orientation and the
//! joints' Z-Y-X angles as sums of a few sinusoids with random phases.
//!
//! All angles are degrees, times seconds.

use crate::limits::LimitTable;
use crate::model::Joint;
use crate::rotation::{self, Quat};
use rand::Rng;
use rand_chacha::ChaCha8Rng;
use std::f64::consts::TAU;

/// Shortest and longest period of a joint's sinusoids, seconds.
const JOINT_PERIOD_S: [f64; 2] = [1.0, 10.0];
/// Sinusoids per joint axis.
const WAVES_PER_AXIS: usize = 3;
/// How far the peak amplitude reaches past the nearer limit: this fraction of
/// the half-width, at most [`MAX_OVERSHOOT_DEG`]. The peak is reached only when
/// all sinusoids align, so the limits are left now and then, by a few degrees.
const OVERSHOOT_FRACTION: f64 = 0.1;
/// Upper bound of the overshoot, degrees.
const MAX_OVERSHOOT_DEG: f64 = 3.0;
/// The Y angle (the middle Z-Y-X angle) is kept within this bound, degrees, so
/// that the angles stay away from the Euler singularity at +-90 and come back
/// unchanged when extracted from the rotation (the knee's 0..130 flexion range is
/// simulated as 0..80).
pub(super) const MAX_ABS_Y_DEG: f64 = 80.0;

/// One sinusoid `amp * sin(omega * t + phase)`.
#[derive(Debug, Clone, Copy)]
struct Wave {
    amp_deg: f64,
    omega_rad_s: f64,
    phase_rad: f64,
}

/// A centre plus a sum of sinusoids, degrees.
#[derive(Debug, Clone)]
pub(super) struct Signal {
    centre_deg: f64,
    waves: Vec<Wave>,
}

impl Signal {
    /// A signal of `count` sinusoids with periods log-uniform in `periods_s`,
    /// random phases, and amplitudes (random weights) summing to `peak_deg`.
    fn random(
        rng: &mut ChaCha8Rng,
        centre_deg: f64,
        peak_deg: f64,
        count: usize,
        periods_s: [f64; 2],
    ) -> Signal {
        let raw: Vec<(f64, f64, f64)> = (0..count)
            .map(|_| {
                let weight = rng.random_range(0.5..=1.0);
                let period = rng
                    .random_range(periods_s[0].ln()..=periods_s[1].ln())
                    .exp();
                let phase = rng.random_range(0.0..TAU);
                (weight, period, phase)
            })
            .collect();
        let total: f64 = raw.iter().map(|w| w.0).sum();
        let waves = raw
            .into_iter()
            .map(|(weight, period, phase)| Wave {
                amp_deg: peak_deg * weight / total,
                omega_rad_s: TAU / period,
                phase_rad: phase,
            })
            .collect();
        Signal { centre_deg, waves }
    }

    /// The value at time `t_s`, degrees.
    pub(super) fn at(&self, t_s: f64) -> f64 {
        self.centre_deg
            + self
                .waves
                .iter()
                .map(|w| w.amp_deg * (w.omega_rad_s * t_s + w.phase_rad).sin())
                .sum::<f64>()
    }
}

/// Z-Y-X angle trajectories of one joint.
#[derive(Debug, Clone)]
pub(super) struct JointMotion {
    pub(super) axes: [Signal; 3],
}

impl JointMotion {
    /// Angles `[x, y, z]` at time `t_s`, degrees.
    pub(super) fn angles_at(&self, t_s: f64) -> [f64; 3] {
        [
            self.axes[0].at(t_s),
            self.axes[1].at(t_s),
            self.axes[2].at(t_s),
        ]
    }
}

/// A joint's motion: centred on its Table 3-3 centroid where the table sets one,
/// else on the middle of its range; reaching a little past the nearer limit.
pub(super) fn joint_motion(rng: &mut ChaCha8Rng, table: &LimitTable, joint: &Joint) -> JointMotion {
    let limits = table.joint_limits(&joint.name, &joint.kind, true);
    let axes = std::array::from_fn(|axis| {
        let (mut lo, mut hi) = limits.map_or((-10.0, 10.0), |l| {
            (l.range_deg[axis][0], l.range_deg[axis][1])
        });
        // The middle (Y) angle of Z-Y-X in the table's axes stays clear of
        // its singularity (docs/method.md section 2.5).
        if axis == crate::model::Axis::Y.index() {
            lo = lo.max(-MAX_ABS_Y_DEG);
            hi = hi.min(MAX_ABS_Y_DEG);
        }
        let centre = limits
            .and_then(|l| l.centroid_deg)
            .map_or(0.5 * (lo + hi), |c| c[axis])
            .clamp(lo, hi);
        let half_width = (hi - centre).min(centre - lo).max(0.0);
        let overshoot = (OVERSHOOT_FRACTION * half_width).min(MAX_OVERSHOOT_DEG);
        Signal::random(
            rng,
            centre,
            half_width + overshoot,
            WAVES_PER_AXIS,
            JOINT_PERIOD_S,
        )
    });
    JointMotion { axes }
}

/// Hip flexion of [`crawl_motion`]: centre and peak deviation, degrees
/// (reaches 62-98 deg; Table 3-2's hip Y is -30..100).
pub(super) const CRAWL_HIP_Y_DEG: [f64; 2] = [80.0, 18.0];
/// Knee flexion of [`crawl_motion`]: centre and peak deviation, degrees
/// (reaches 96-126 deg; Table 3-2's knee Y is 0..130). It stays clear of
/// 90 deg, where Z-Y-X angles are singular (docs/method.md section 2.3): a
/// knee's +-5 deg X and Z limits are crossed by noise alone there (0.3 deg
/// of orientation noise reads as several degrees of X and Z within about
/// 6 deg of 90 deg), whichever triplet is read.
pub(super) const CRAWL_KNEE_Y_DEG: [f64; 2] = [111.0, 15.0];

/// A joint's motion on hands and knees: `motion` with a hip's or a knee's
/// flexion (table Y) replaced by a deep one, mostly beyond 90 deg
/// ([`CRAWL_HIP_Y_DEG`], [`CRAWL_KNEE_Y_DEG`]); other joints unchanged.
pub(super) fn crawl_motion(
    rng: &mut ChaCha8Rng,
    joint: &Joint,
    motion: JointMotion,
) -> JointMotion {
    let [centre, peak] = match joint.kind.as_str() {
        "hip" => CRAWL_HIP_Y_DEG,
        "knee" => CRAWL_KNEE_Y_DEG,
        _ => return motion,
    };
    let [x, _, z] = motion.axes;
    let y = Signal::random(rng, centre, peak, WAVES_PER_AXIS, JOINT_PERIOD_S);
    JointMotion { axes: [x, y, z] }
}

/// Motion of the base segment (lower back) of a crawling infant: slow heading
/// changes about the global vertical, small pitch and roll.
#[derive(Debug, Clone)]
pub(super) struct BaseMotion {
    heading: Signal,
    pitch: Signal,
    roll: Signal,
}

impl BaseMotion {
    pub(super) fn random(rng: &mut ChaCha8Rng) -> BaseMotion {
        BaseMotion {
            heading: Signal::random(rng, 0.0, 90.0, 2, [20.0, 90.0]),
            pitch: Signal::random(rng, 0.0, 10.0, 2, [2.0, 8.0]),
            roll: Signal::random(rng, 0.0, 8.0, 2, [1.0, 5.0]),
        }
    }

    /// `G_R_base` at time `t_s`: `Rz(heading) * Ry(pitch) * Rx(roll)`.
    pub(super) fn orientation_at(&self, t_s: f64) -> Quat {
        rotation::quat_from_euler_zyx_deg([
            self.roll.at(t_s),
            self.pitch.at(t_s),
            self.heading.at(t_s),
        ])
    }
}
