//! The elbow test for the Mueller et al. (2017) baseline: a static upper arm and
//! a forearm that flexes and pronates/supinates at once, both IMUs tilted off
//! their hinge axis.
//!
//! In the Z-Y-X convention the elbow's pronation/supination (Z) turns about an
//! axis fixed in the upper arm and its flexion (X) about one fixed in the
//! forearm: `G_R_forearm = G_R_upper_arm * Rz(pro(t)) * Rx(flex(t))`, Y = 0.
//! Angles are degrees, times seconds.

use super::{rng, Stream};
use crate::rotation::{self, Quat};
use rand::Rng;
use std::f64::consts::TAU;

/// The proximal and distal IMU (joint `l_elbow` of `infant13`).
pub const ELBOW_IMUS: [&str; 2] = ["l_upper_arm", "l_forearm"];

/// Flexion (X) at time `t_s`, degrees: two sinusoids, within 20..130.
pub fn flexion_deg(t_s: f64) -> f64 {
    75.0 + 40.0 * (TAU * t_s / 4.0).sin() + 15.0 * (TAU * t_s / 9.3 + 1.0).sin()
}

/// Pronation/supination (Z) at time `t_s`, degrees: two sinusoids, within +-28.
pub fn pronation_deg(t_s: f64) -> f64 {
    22.0 * (TAU * t_s / 5.7 + 0.5).sin() + 6.0 * (TAU * t_s / 2.3).sin()
}

/// Upper arm static at identity, forearm = upper arm * Rz(pro) * Rx(flex).
pub(super) fn segments(time_s: &[f64]) -> Vec<(String, Vec<Quat>)> {
    let upper = vec![Quat::identity(); time_s.len()];
    let forearm = time_s
        .iter()
        .map(|&t| rotation::quat_from_euler_zyx_deg([flexion_deg(t), 0.0, pronation_deg(t)]))
        .collect();
    vec![
        (ELBOW_IMUS[0].to_string(), upper),
        (ELBOW_IMUS[1].to_string(), forearm),
    ]
}

/// Each IMU turned `angle_deg` about an axis drawn uniformly from the directions
/// perpendicular to its hinge axis (upper arm: Z, forearm: X). Such a
/// misalignment tilts the hinge axis as the sensor sees it by the full angle and
/// leaves no turn about the axis itself (which would be an angle offset no
/// axis estimate can see; add one through the configuration's `misalignment`).
pub(super) fn misalignments(seed: u64, angle_deg: f64) -> [(&'static str, Quat); 2] {
    let mut r = rng(seed, Stream::ElbowMisalignment);
    let mut u = || r.random_range(0.0..TAU);
    let (ua, ub) = (u(), u());
    [
        (
            ELBOW_IMUS[0],
            rotation::quat_axis_angle_deg([ua.cos(), ua.sin(), 0.0], angle_deg),
        ),
        (
            ELBOW_IMUS[1],
            rotation::quat_axis_angle_deg([0.0, ub.cos(), ub.sin()], angle_deg),
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::super::{simulate, SimConfig};
    use super::*;
    use crate::model::Model;
    use crate::rotation::angle_deg;
    use nalgebra::Vector3;

    #[test]
    fn elbow_truth_moves_in_flexion_and_pronation_only() {
        let mut cfg = SimConfig::elbow(5, 20.0);
        cfg.duration_s = 20.0;
        let sim = simulate(&cfg).unwrap();
        let names: Vec<&str> = sim.trial.imus.iter().map(|i| i.name.as_str()).collect();
        assert_eq!(names, ELBOW_IMUS);
        let model = Model::infant13();
        let elbow = model.joint("l_elbow").unwrap();
        assert_eq!(
            (elbow.proximal.as_str(), elbow.distal.as_str()),
            (ELBOW_IMUS[0], ELBOW_IMUS[1])
        );
        let angles = crate::metrics::joint_angles(&sim.truth.segments, elbow).unwrap();
        let (mut lo, mut hi) = (f64::MAX, f64::MIN);
        for (a, &t) in angles.iter().zip(&sim.trial.time_s) {
            assert!((a[0] - flexion_deg(t)).abs() < 1e-9 && a[1].abs() < 1e-9);
            assert!((a[2] - pronation_deg(t)).abs() < 1e-9);
            lo = lo.min(a[0]);
            hi = hi.max(a[0]);
        }
        assert!(
            lo > 15.0 && hi < 135.0 && hi - lo > 80.0,
            "flexion {lo}..{hi}"
        );
        let upper = &sim.truth.segments.imu(ELBOW_IMUS[0]).unwrap().orientation;
        assert!(upper.iter().all(|q| angle_deg(q) < 1e-12));
    }

    #[test]
    fn elbow_misalignments_tilt_the_hinge_axes_by_the_full_angle() {
        for seed in 0..20 {
            let [(a, ma), (b, mb)] = misalignments(seed, 20.0);
            assert_eq!([a, b], ELBOW_IMUS);
            assert!((angle_deg(&ma) - 20.0).abs() < 1e-9 && (angle_deg(&mb) - 20.0).abs() < 1e-9);
            // The rotation axis is perpendicular to the hinge axis, so the axis
            // as the sensor sees it is tilted by the whole 20 degrees.
            let tilt = |m: &Quat, axis: Vector3<f64>| {
                (m.inverse() * axis)
                    .dot(&axis)
                    .clamp(-1.0, 1.0)
                    .acos()
                    .to_degrees()
            };
            assert!((tilt(&ma, Vector3::z()) - 20.0).abs() < 1e-9);
            assert!((tilt(&mb, Vector3::x()) - 20.0).abs() < 1e-9);
        }
        assert_ne!(misalignments(1, 20.0)[0].1, misalignments(2, 20.0)[0].1);
    }
}
