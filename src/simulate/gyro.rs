//! Simulated gyroscopes: the angular rate of each sensor's clean orientation
//! (misalignment, slippage and heading drift included, orientation noise not),
//! in the sensor frame, rad/s, plus optional white noise.
//!
//! The rate is the body rate `w` of `d/dt G_R_imu = G_R_imu [w]x`, taken from
//! the orientation at `t - h` and `t + h` (`h` = [`STEP_S`]) as
//! `log(G_R_imu(t-h)^-1 G_R_imu(t+h)) / 2h`: a central difference whose error
//! (order `h^2` times the rate's second derivative) is far below any sensor's.

use crate::rotation::Quat;
use nalgebra::Vector3;
use rand::Rng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};

/// Half the span of the central difference, seconds.
pub const STEP_S: f64 = 1e-5;

/// Gyroscope readings to simulate beside the orientations.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GyroSim {
    /// Standard deviation of the white noise added to each axis of each
    /// reading, degrees per second (0 = exact rates).
    pub noise_deg_s: f64,
}

/// Body rates (rad/s, sensor frame) from orientations at `t - h` (`minus`)
/// and `t + h` (`plus`), `span_s[i]` being the time between the two.
pub(super) fn body_rates(minus: &[Quat], plus: &[Quat], span_s: &[f64]) -> Vec<Vector3<f64>> {
    minus
        .iter()
        .zip(plus)
        .zip(span_s)
        .map(|((m, p), span)| (m.inverse() * p).scaled_axis() / *span)
        .collect()
}

/// Adds white noise of `noise_deg_s` per axis (standard deviation) to `rates`.
pub(super) fn add_noise(rates: &mut [Vector3<f64>], noise_deg_s: f64, rng: &mut impl Rng) {
    if noise_deg_s <= 0.0 {
        return;
    }
    let Ok(normal) = Normal::new(0.0, noise_deg_s.to_radians()) else {
        return;
    };
    for w in rates {
        *w += Vector3::from_fn(|_, _| normal.sample(rng));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::quat_axis_angle_deg;
    use rand::SeedableRng;

    #[test]
    fn rates_of_a_constant_turn_and_noise_spread() {
        // A turn at 30 deg/s about a fixed body axis: the rate is that axis times 30 deg/s.
        let axis = Vector3::new(1.0, -2.0, 0.5).normalize();
        let at = |t: f64| {
            quat_axis_angle_deg([0.3, 0.1, 0.9], 40.0) * quat_axis_angle_deg(axis.into(), 30.0 * t)
        };
        let ts = [0.0, 1.7, 12.0];
        let minus: Vec<Quat> = ts.iter().map(|&t| at(t - STEP_S)).collect();
        let plus: Vec<Quat> = ts.iter().map(|&t| at(t + STEP_S)).collect();
        let span: Vec<f64> = ts.iter().map(|&t| (t + STEP_S) - (t - STEP_S)).collect();
        for w in body_rates(&minus, &plus, &span) {
            assert!((w - axis * 30f64.to_radians()).norm() < 1e-9, "{w:?}");
        }
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let mut zero = vec![Vector3::zeros(); 20_000];
        add_noise(&mut zero, 2.0, &mut rng);
        let sd = (zero.iter().map(|w| w.x * w.x).sum::<f64>() / zero.len() as f64).sqrt();
        assert!((sd.to_degrees() - 2.0).abs() < 0.05, "{}", sd.to_degrees());
    }
}
