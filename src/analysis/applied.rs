//! The applied correction over time (the `a` view): the rotation `C(t)` the
//! engine applied to a joint's distal IMU, `G_R_dist' = G_R_dist C(t)`, as its
//! angle and per-axis components, with the window centres it was slerped
//! between (docs/method.md section 7).
//!
//! Frames and units: `C(t)` is in the distal IMU's sensor frame; components are
//! the rotation vector (axis times angle) in that frame, degrees; times are
//! seconds from the trial's first sample.

use crate::acm::window::correction_series;
use crate::acm::JointResult;
use crate::rotation::{angle_deg, canonical, quat_from_wxyz, Quat};

/// A rotation as its angle and rotation-vector components, degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Components {
    /// Rotation angle, degrees, in [0, 180].
    pub angle_deg: f64,
    /// Rotation vector (unit axis times angle) along sensor X, Y, Z, degrees.
    pub axis_deg: [f64; 3],
}

/// The angle and components of `q` (taken with a non-negative scalar part).
pub fn components(q: &Quat) -> Components {
    let v = canonical(q).scaled_axis();
    Components {
        angle_deg: angle_deg(q),
        axis_deg: [v[0], v[1], v[2]].map(f64::to_degrees),
    }
}

/// The time-dependent correction of one joint, from its window solutions.
#[derive(Debug, Clone, PartialEq)]
pub struct AppliedCorrection {
    /// Window centres, seconds from the first sample.
    pub centres_s: Vec<f64>,
    /// The window corrections.
    pub qs: Vec<Quat>,
}

impl AppliedCorrection {
    /// The correction of a joint's result.
    pub fn of(result: &JointResult) -> AppliedCorrection {
        AppliedCorrection {
            centres_s: result.windows.iter().map(|w| w.centre_s).collect(),
            qs: result
                .windows
                .iter()
                .map(|w| quat_from_wxyz(w.correction))
                .collect(),
        }
    }

    /// `C` at ascending times (seconds from the first sample), as the engine
    /// applies it between window centres.
    pub fn at(&self, times_s: &[f64]) -> Vec<Quat> {
        if self.qs.is_empty() {
            return vec![Quat::identity(); times_s.len()];
        }
        // The series is measured from its first time: start it at 0.
        let mut t = Vec::with_capacity(times_s.len() + 1);
        t.push(0.0);
        t.extend_from_slice(times_s);
        let mut s = correction_series(&t, &self.centres_s, &self.qs);
        s.remove(0);
        s
    }

    /// Components over `[t0, t1]` at `points` evenly spaced times plus every
    /// window centre inside (where the slerp changes direction), ascending.
    /// Between those, `C(t)` moves along one great arc at constant speed, so
    /// these points draw it exactly at the chosen resolution.
    pub fn sampled(&self, t0: f64, t1: f64, points: usize) -> Vec<(f64, Components)> {
        let n = points.max(2);
        let mut times: Vec<f64> = (0..n)
            .map(|i| t0 + (t1 - t0) * i as f64 / (n - 1) as f64)
            .chain(
                self.centres_s
                    .iter()
                    .copied()
                    .filter(|c| *c > t0 && *c < t1),
            )
            .collect();
        times.sort_by(f64::total_cmp);
        times.dedup();
        let qs = self.at(&times);
        times.into_iter().zip(qs.iter().map(components)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::acm::{RunControl, Variant};
    use crate::correct::correct_trial;
    use crate::limits::{LimitTable, Settings};
    use crate::model::Model;
    use crate::rotation::{angle_between_deg, quat_axis_angle_deg};
    use crate::simulate::{simulate, SimConfig};

    #[test]
    fn components_of_known_rotations() {
        let c = components(&quat_axis_angle_deg([0.0, 0.0, 1.0], 15.0));
        assert!((c.angle_deg - 15.0).abs() < 1e-9);
        assert!((c.axis_deg[2] - 15.0).abs() < 1e-9 && c.axis_deg[0].abs() < 1e-12);
        let c = components(&quat_axis_angle_deg([1.0, -1.0, 0.0], 20.0));
        let k = 20.0 / 2f64.sqrt();
        assert!((c.axis_deg[0] - k).abs() < 1e-9 && (c.axis_deg[1] + k).abs() < 1e-9);
    }

    #[test]
    fn applied_equals_raw_to_corrected_rotation_per_sample() {
        // Three minutes with drift: several windows; the curve the view draws
        // is the rotation between raw and corrected distal IMU at every sample.
        let mut cfg = SimConfig::full_body(11);
        cfg.duration_s = 150.0;
        let sim = simulate(&cfg).unwrap();
        let model = Model::infant13();
        let c = correct_trial(
            &sim.trial,
            &model,
            &LimitTable::default_table(),
            &Settings::default(),
            Variant::Drift,
            &RunControl::default(),
        )
        .unwrap();
        let r = c.joint("l_knee").unwrap();
        let applied = AppliedCorrection::of(r);
        assert_eq!(applied.centres_s.len(), r.windows.len());
        assert!(r.windows.len() >= 4);
        let t0 = sim.trial.time_s[0];
        let times: Vec<f64> = sim.trial.time_s.iter().map(|t| t - t0).collect();
        let got = applied.at(&times);
        let raw = &sim.trial.imu(&r.distal).unwrap().orientation;
        let cor = &c.corrected.imu(&r.distal).unwrap().orientation;
        for i in (0..times.len()).step_by(97) {
            let want = raw[i].inverse() * cor[i];
            assert!(angle_between_deg(&got[i], &want) < 1e-6, "sample {i}");
        }
        // Sampled: window centres included, times ascending, angles match.
        let s = applied.sampled(0.0, times[times.len() - 1], 50);
        for c in &applied.centres_s {
            assert!(s.iter().any(|(t, _)| t == c));
        }
        assert!(s.windows(2).all(|w| w[0].0 < w[1].0));
        let mid = s[s.len() / 2];
        let direct = components(&applied.at(&[mid.0])[0]);
        assert_eq!(mid.1, direct);
    }
}
