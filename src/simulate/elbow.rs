//! The elbow test for the Mueller et al. (2017) baseline: a static upper arm and
//! a forearm that flexes and pronates/supinates at once, both IMUs tilted off
//! their hinge axis.
//!
//! In the Z-Y-X convention the elbow's pronation/supination (Z) turns about an
//! axis fixed in the upper arm and its flexion (X) about one fixed in the
//! forearm: `G_R_forearm = G_R_upper_arm * Rz(pro(t)) * Rx(flex(t))`, Y = 0.
//! Angles are degrees, times seconds, rates in deg/s unless named rad/s.

use super::{rng, Stream};
use crate::rotation::{self, Quat};
use nalgebra::Vector3;
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

/// Flexion rate `d/dt flexion_deg` at `t_s`, deg/s.
pub fn flexion_rate_deg_s(t_s: f64) -> f64 {
    40.0 * (TAU / 4.0) * (TAU * t_s / 4.0).cos()
        + 15.0 * (TAU / 9.3) * (TAU * t_s / 9.3 + 1.0).cos()
}

/// Pronation rate `d/dt pronation_deg` at `t_s`, deg/s.
pub fn pronation_rate_deg_s(t_s: f64) -> f64 {
    22.0 * (TAU / 5.7) * (TAU * t_s / 5.7 + 0.5).cos() + 6.0 * (TAU / 2.3) * (TAU * t_s / 2.3).cos()
}

/// Angular rate of the forearm segment at `t_s` in its own frame, rad/s, in
/// closed form: with `G_R_forearm = Rz(pro) Rx(flex)` and a static upper arm,
/// `w = Rx(flex)^T (pro' Z) + flex' X`. A forearm IMU misaligned by `M` reads
/// `M^-1 w` (the upper arm's reads zero).
pub fn forearm_rate(t_s: f64) -> Vector3<f64> {
    let flex = rotation::quat_axis_angle_deg([1.0, 0.0, 0.0], flexion_deg(t_s));
    flex.inverse() * (Vector3::z() * pronation_rate_deg_s(t_s).to_radians())
        + Vector3::x() * flexion_rate_deg_s(t_s).to_radians()
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
    fn simulated_elbow_gyros_are_the_closed_form_rates_in_the_sensor_frames() {
        let mut cfg = SimConfig::elbow(5, 20.0).with_gyro(0.0);
        cfg.duration_s = 20.0;
        let sim = simulate(&cfg).unwrap();
        let ma = sim.truth.meta.misalignment(ELBOW_IMUS[0]).unwrap();
        let mb = sim.truth.meta.misalignment(ELBOW_IMUS[1]).unwrap();
        assert!(angle_deg(&ma) > 19.0 && angle_deg(&mb) > 19.0);
        let upper = sim.trial.imu(ELBOW_IMUS[0]).unwrap().gyro.clone().unwrap();
        let fore = sim.trial.imu(ELBOW_IMUS[1]).unwrap().gyro.clone().unwrap();
        let mut peak = 0.0f64;
        for (i, &t) in sim.trial.time_s.iter().enumerate() {
            assert!(upper[i].norm() < 1e-9, "{t}: {:?}", upper[i]);
            let want = mb.inverse() * forearm_rate(t);
            assert!(
                (fore[i] - want).norm() < 1e-7,
                "{t}: {:?} vs {want:?}",
                fore[i]
            );
            peak = peak.max(want.norm());
        }
        // Flexion peaks near 63 + 10 deg/s: the test compares real motion.
        assert!(peak.to_degrees() > 60.0, "{}", peak.to_degrees());
        // The closed-form rates match the angles' derivatives.
        let h = 1e-6;
        for t in [0.3, 4.1, 17.0] {
            let d = (flexion_deg(t + h) - flexion_deg(t - h)) / (2.0 * h);
            assert!((d - flexion_rate_deg_s(t)).abs() < 1e-5);
            let d = (pronation_deg(t + h) - pronation_deg(t - h)) / (2.0 * h);
            assert!((d - pronation_rate_deg_s(t)).abs() < 1e-5);
        }
        // Noise: the same orientations, rates off by about the noise.
        let noisy = simulate(&cfg.clone().with_gyro(1.0)).unwrap();
        assert_eq!(
            noisy.trial.imus[1].orientation,
            sim.trial.imus[1].orientation
        );
        let g = noisy.trial.imus[0].gyro.as_ref().unwrap();
        let sd = (g.iter().map(|w| w.norm_squared()).sum::<f64>() / (3 * g.len()) as f64).sqrt();
        assert!((sd.to_degrees() - 1.0).abs() < 0.05, "{}", sd.to_degrees());
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
