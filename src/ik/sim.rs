//! Simulated trials for inverse kinematics: motion that has exactly the
//! model's degrees of freedom and stays inside its hard limits, so that the
//! true joint coordinates are known.
//!
//! Each coordinate moves as a centre plus three sinusoids (periods 1-8 s,
//! random phases) whose amplitudes add up to its reach: `reach` times the
//! half-range of a coordinate limited on both sides, [`FREE_AMPLITUDE_DEG`]
//! around the default pose otherwise. The base turns through all headings and
//! tilts by up to [`BASE_TILT_DEG`]. IMUs are `G_R_imu = S_segment * M * N(t)`
//! with an optional fixed misalignment `M` (never on the base) and per-sample
//! noise `N(t)`, as in `crate::simulate`.

use super::skeleton::Skeleton;
use super::solver::{forward, Pose};
use crate::model::Model;
use crate::rotation::{quat_from_euler_zyx_deg, quat_from_rotvec, Quat};
use crate::trial::{ImuSeries, Trial};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal, UnitSphere};
use std::f64::consts::TAU;

/// Amplitude of coordinates without hard limits (both sides), degrees: keeps
/// a three-axis joint's Y angle far from the Z-Y-X singularity.
pub const FREE_AMPLITUDE_DEG: f64 = 25.0;
/// Largest tilt of the base about X and Y, degrees.
pub const BASE_TILT_DEG: f64 = 20.0;

/// What to simulate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IkSimConfig {
    pub duration_s: f64,
    pub rate_hz: f64,
    pub seed: u64,
    /// Fraction of a limited coordinate's half-range its motion reaches (1:
    /// it touches both limits).
    pub reach: f64,
    /// Misalignment angle of each non-base IMU, uniform in `[min, max]`
    /// degrees about a random axis; `[0, 0]` for none.
    pub misalignment_deg: [f64; 2],
    /// RMS angle of the per-sample noise rotation, degrees.
    pub noise_deg: f64,
}

impl IkSimConfig {
    /// `duration_s` at 50 Hz, seed 0, motion to 90% of the limits, exact sensors.
    pub fn clean(duration_s: f64) -> IkSimConfig {
        IkSimConfig {
            duration_s,
            rate_hz: 50.0,
            seed: 0,
            reach: 0.9,
            misalignment_deg: [0.0, 0.0],
            noise_deg: 0.0,
        }
    }
}

/// A simulated trial and its truth.
#[derive(Debug, Clone, PartialEq)]
pub struct IkSim {
    /// What the IMUs report.
    pub trial: Trial,
    /// True segment orientations (segment to global), named by IMU.
    pub segments: Trial,
    /// True coordinates per frame, degrees, in the skeleton's order.
    pub coordinates_deg: Vec<Vec<f64>>,
    /// True base orientation per frame.
    pub base: Vec<Quat>,
}

/// A centre plus a sum of sinusoids, degrees.
struct Signal {
    centre: f64,
    waves: Vec<(f64, f64, f64)>,
}

impl Signal {
    fn random(rng: &mut ChaCha8Rng, centre: f64, amplitude: f64) -> Signal {
        let raw: Vec<(f64, f64, f64)> = (0..3)
            .map(|_| {
                let weight: f64 = rng.random_range(0.5..=1.0);
                let period = rng.random_range(1.0f64.ln()..=8.0f64.ln()).exp();
                (weight, TAU / period, rng.random_range(0.0..TAU))
            })
            .collect();
        let total: f64 = raw.iter().map(|w| w.0).sum();
        Signal {
            centre,
            waves: raw
                .into_iter()
                .map(|(w, om, ph)| (amplitude * w / total, om, ph))
                .collect(),
        }
    }

    fn at(&self, t: f64) -> f64 {
        self.centre
            + self
                .waves
                .iter()
                .map(|(a, om, ph)| a * (om * t + ph).sin())
                .sum::<f64>()
    }
}

/// Simulates every IMU of `model` (a full tree) with `config`.
pub fn simulate(model: &Model, config: &IkSimConfig) -> IkSim {
    let sk = Skeleton::new(model, |_| true).expect("every IMU is simulated");
    let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
    let signals: Vec<Signal> = sk
        .coordinates
        .iter()
        .map(|c| {
            if c.lower.is_finite() && c.upper.is_finite() {
                let (lo, hi) = (c.lower.to_degrees(), c.upper.to_degrees());
                Signal::random(&mut rng, (lo + hi) / 2.0, config.reach * (hi - lo) / 2.0)
            } else {
                Signal::random(&mut rng, c.default.to_degrees(), FREE_AMPLITUDE_DEG)
            }
        })
        .collect();
    let base: Vec<Signal> = (0..3)
        .map(|k| {
            let amp = if k == 2 { 180.0 } else { BASE_TILT_DEG };
            Signal::random(&mut rng, 0.0, amp)
        })
        .collect();
    let misalign: Vec<Quat> = sk
        .segments
        .iter()
        .enumerate()
        .map(|(k, _)| {
            let [lo, hi] = config.misalignment_deg;
            if k == 0 || hi <= 0.0 {
                return Quat::identity();
            }
            let axis: [f64; 3] = UnitSphere.sample(&mut rng);
            let angle = rng.random_range(lo..=hi).to_radians();
            quat_from_rotvec(&(Vector3::from(axis) * angle))
        })
        .collect();
    let noise = Normal::new(0.0, config.noise_deg.to_radians() / 3f64.sqrt().max(1e-300))
        .expect("finite noise");
    let n = (config.duration_s * config.rate_hz).round() as usize;
    let time_s: Vec<f64> = (0..n).map(|i| i as f64 / config.rate_hz).collect();
    let segs = sk.segments.len();
    let mut truth = vec![Vec::with_capacity(n); segs];
    let mut measured = vec![Vec::with_capacity(n); segs];
    let mut coordinates_deg = Vec::with_capacity(n);
    let mut base_q = Vec::with_capacity(n);
    let mut orient = vec![Quat::identity(); segs];
    let mut axes = vec![Vector3::zeros(); sk.coordinates.len()];
    for &t in &time_s {
        let q_deg: Vec<f64> = signals.iter().map(|s| s.at(t)).collect();
        let pose = Pose {
            base: quat_from_euler_zyx_deg([base[0].at(t), base[1].at(t), base[2].at(t)]),
            q: q_deg.iter().map(|v| v.to_radians()).collect(),
        };
        forward(&sk, &pose, &mut orient, &mut axes);
        for k in 0..segs {
            truth[k].push(orient[k]);
            let mut m = orient[k] * misalign[k];
            if config.noise_deg > 0.0 {
                let v = Vector3::new(
                    noise.sample(&mut rng),
                    noise.sample(&mut rng),
                    noise.sample(&mut rng),
                );
                m *= quat_from_rotvec(&v);
            }
            measured[k].push(m);
        }
        coordinates_deg.push(q_deg);
        base_q.push(pose.base);
    }
    let trial = |name: &str, series: Vec<Vec<Quat>>| Trial {
        name: name.to_string(),
        time_s: time_s.clone(),
        imus: sk
            .segments
            .iter()
            .zip(series)
            .map(|(s, orientation)| ImuSeries::new(s.imu.clone(), orientation))
            .collect(),
        warnings: vec![],
        orientation_decimals: None,
    };
    IkSim {
        trial: trial("ik_sim", measured),
        segments: trial("ik_sim.truth", truth),
        coordinates_deg,
        base: base_q,
    }
}
