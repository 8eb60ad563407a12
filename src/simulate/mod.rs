//! Simulated trials with a known truth: misalignment, heading drift and noise
//! applied to clean segment orientations, so the ACM can be judged against what
//! it should find.
//!
//! Frames and units:
//! - `G_R_segment(t)`: orientation of a body segment (sensor frame of a perfectly
//!   aligned, drift-free IMU) in the global frame G; G's +Z is vertical.
//! - Misalignment `M` is fixed in the sensor frame: `G_R_imu = G_R_segment * M`.
//! - Heading drift is a rotation about global +Z by `h(t)` degrees, 0 before its
//!   start, then growing at a constant rate (deg/s):
//!   `G_R_imu_measured(t) = Rz(h(t)) * G_R_segment(t) * M * N(t)`,
//!   where `N(t)` is per-sample noise, a small random rotation in the sensor frame
//!   whose rotation angle has the RMS [`SimConfig::noise_deg`].
//! - Sensor slippage (the strap turning slowly on the limb) is a rotation
//!   `S(t)` about a fixed sensor-frame axis by `s(t)` degrees, 0 before its
//!   start, then growing at a constant rate: `... * M * S(t) * N(t)`. It is the
//!   error the source's windowed sensor-frame correction models; heading drift
//!   is the one the `drift-heading` variants model.
//! - The base IMU is assumed correct: never misaligned nor drifting (it gets
//!   noise like every sensor).
//! - Joint angles are Z-Y-X Euler angles of `G_R_prox^T * G_R_dist`, degrees;
//!   segments chain as `G_R_dist = G_R_prox * R_joint(angles)` in model order.
//! - Times are seconds from 0, sample `i` at `i / rate_hz`.
//! - Gyroscopes (optional, [`SimConfig::gyro`]): the angular rate of each
//!   sensor's orientation without the noise `N(t)`, `Rz(h(t)) G_R_segment(t) M S(t)`,
//!   in the sensor frame, rad/s, plus white noise ([`gyro`]).

use crate::limits::LimitTable;
use crate::model::Model;
use crate::rotation::{self, Quat};
use crate::trial::{ImuSeries, Trial};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal, UnitSphere};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::f64::consts::TAU;
use truth::{Truth, TruthMeta};

mod elbow;
pub mod gyro;
mod motion;
pub mod swing;
#[cfg(test)]
mod tests;
pub mod truth;

/// The body model every simulation uses.
pub const MODEL: &str = "infant13";
/// Knee test (thesis 4.1): lowest knee flexion, degrees.
pub const KNEE_FLEXION_MIN_DEG: f64 = 15.0;
/// Knee test: highest knee flexion, degrees.
pub const KNEE_FLEXION_MAX_DEG: f64 = 75.0;
/// Knee test: flexion cycles per minute.
pub const KNEE_CYCLES_PER_MIN: f64 = 5.0;
/// Knee test: the proximal and distal IMU (joint `l_knee` of `infant13`).
pub const KNEE_IMUS: [&str; 2] = ["l_thigh", "l_calf"];
/// Default random misalignment angles, degrees.
pub const RANDOM_MISALIGNMENT_DEG: [f64; 2] = [5.0, 30.0];
/// Names accepted by [`preset`].
pub const PRESETS: [&str; 6] = [
    "knee_calf_z15",
    "full_body_clean",
    "full_body_drift",
    "elbow_20",
    "full_body_swing",
    "full_body_crawl",
];
pub use elbow::{
    elbow_joint, flexion_deg as elbow_flexion_deg, forearm_rate as elbow_forearm_rate,
    pronation_deg as elbow_pronation_deg, ELBOW_IMUS,
};
pub use gyro::GyroSim;

/// What to simulate, for how long, and which errors to put into the sensors.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SimConfig {
    /// The movement and the set of IMUs.
    pub kind: SimKind,
    /// Trial length, seconds (`round(duration_s * rate_hz)` samples).
    pub duration_s: f64,
    /// Sampling rate, Hz.
    pub rate_hz: f64,
    /// Seed of every random choice: same config, same trial, bit for bit.
    pub seed: u64,
    /// RMS rotation angle of the per-sample orientation noise, degrees (0 = none).
    pub noise_deg: f64,
    /// Sensor-to-segment misalignment of the non-base IMUs (for [`SimKind::Knee`]
    /// applied after the kind's own: `M = M_knee * M_this`).
    pub misalignment: Misalignment,
    /// Heading drifts, at most one per IMU, never on the base.
    #[serde(default)]
    pub drifts: Vec<HeadingDrift>,
    /// Sensor slippages, at most one per IMU, never on the base.
    #[serde(default)]
    pub slips: Vec<SensorSlip>,
    /// Gyroscope readings of every IMU beside its orientations (`None`: none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gyro: Option<GyroSim>,
}

/// The simulated movement.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum SimKind {
    /// Thesis section 4.1: IMUs `l_thigh` and `l_calf` only (joint `l_knee`).
    /// The thigh is static at identity; the calf flexes about Y sinusoidally
    /// between 15 and 75 degrees at 5 cycles per minute (X = Z = 0), starting at 15.
    /// One IMU may be misaligned about its X or Z axis by `angle_deg`.
    Knee {
        misaligned_imu: KneeImu,
        axis: KneeAxis,
        angle_deg: f64,
    },
    /// The 13 IMUs of `infant13`: a moving base and smooth joint angles, mostly
    /// inside Table 3-2, around the Table 3-3 centroids (or the middle of the range).
    FullBody,
    /// The Mueller et al. (2017) elbow test: IMUs `l_upper_arm` and `l_forearm`
    /// only (joint `l_elbow`). The upper arm is static at identity; the forearm
    /// flexes (X, 20-130 deg) and pronates/supinates (Z, +-28 deg) at once
    /// (`simulate::elbow`). Each IMU is misaligned by `angle_deg` about a
    /// random axis perpendicular to its hinge axis (upper arm Z, forearm X).
    Elbow { angle_deg: f64 },
    /// The 13 IMUs of `infant13`, every joint axis one sinusoid over a known
    /// range (see [`swing`]): clean trials whose limits and centroids are known.
    Swing,
    /// As [`SimKind::FullBody`] (same seed, same motion elsewhere), on hands
    /// and knees: hip flexion (table Y) 62-98 deg and knee flexion 85-125 deg,
    /// sums of three sinusoids, mostly beyond 90 deg (the other Z-Y-X triplet:
    /// docs/method.md section 2.5).
    Crawl,
}

/// Which IMU of the knee test is misaligned.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum KneeImu {
    None,
    Thigh,
    Calf,
}

/// The sensor axis of the knee test's misalignment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum KneeAxis {
    X,
    Z,
}

/// How the non-base IMUs are misaligned.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "mode", rename_all = "snake_case")]
pub enum Misalignment {
    /// Every sensor sits exactly on its segment.
    None,
    /// Every non-base IMU: a uniformly random axis and an angle uniform in
    /// `[min_deg, max_deg]`, drawn from the seed.
    Random { min_deg: f64, max_deg: f64 },
    /// The listed IMUs only.
    Fixed { imus: Vec<ImuMisalignment> },
}

/// A chosen misalignment of one IMU.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ImuMisalignment {
    pub imu: String,
    /// Rotation vector of `M` in the sensor frame, degrees (axis times angle).
    pub rotvec_deg: [f64; 3],
}

/// Heading drift of one IMU: `h(t) = 0` before `start_s`, then
/// `rate_deg_s * (t - start_s)` degrees about the global vertical +Z.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HeadingDrift {
    pub imu: String,
    /// When the drift starts, seconds from the first sample.
    pub start_s: f64,
    /// Drift rate, degrees per second (sign = direction about +Z).
    pub rate_deg_s: f64,
}

impl HeadingDrift {
    /// The heading error `h(t)` at time `t_s`, degrees.
    pub fn heading_deg(&self, t_s: f64) -> f64 {
        if t_s <= self.start_s {
            0.0
        } else {
            self.rate_deg_s * (t_s - self.start_s)
        }
    }

    /// `Rz(h(t))`.
    pub fn rotation_at(&self, t_s: f64) -> Quat {
        rotation::quat_axis_angle_deg([0.0, 0.0, 1.0], self.heading_deg(t_s))
    }
}

/// Slippage of one IMU on its segment: a rotation about the sensor-frame axis
/// `axis` by `s(t) = 0` before `start_s`, then `rate_deg_s * (t - start_s)`
/// degrees, applied after the misalignment (`G_R_imu = G_R_seg * M * S(t)`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SensorSlip {
    pub imu: String,
    /// When the slippage starts, seconds from the first sample.
    pub start_s: f64,
    /// Slippage rate, degrees per second.
    pub rate_deg_s: f64,
    /// Rotation axis in the sensor frame (any length but zero).
    pub axis: [f64; 3],
}

impl SensorSlip {
    /// `S(t)`.
    pub fn rotation_at(&self, t_s: f64) -> Quat {
        let angle = if t_s <= self.start_s {
            0.0
        } else {
            self.rate_deg_s * (t_s - self.start_s)
        };
        rotation::quat_axis_angle_deg(self.axis, angle)
    }
}

/// A simulated trial: what the sensors report, and the truth behind it.
#[derive(Debug, Clone, PartialEq)]
pub struct Simulated {
    /// Measured orientations (misaligned, drifting, noisy).
    pub trial: Trial,
    /// Clean segment orientations plus the errors that were applied.
    pub truth: Truth,
}

/// A configuration that cannot be simulated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("cannot simulate: {0}")]
pub struct SimError(pub String);

impl SimConfig {
    /// The knee test (5 min at 50 Hz, no noise, seed 0) with one misaligned IMU.
    pub fn knee(misaligned_imu: KneeImu, axis: KneeAxis, angle_deg: f64) -> SimConfig {
        SimConfig {
            kind: SimKind::Knee {
                misaligned_imu,
                axis,
                angle_deg,
            },
            duration_s: 300.0,
            rate_hz: 50.0,
            seed: 0,
            noise_deg: 0.0,
            misalignment: Misalignment::None,
            drifts: vec![],
            slips: vec![],
            gyro: None,
        }
    }

    /// The 13-IMU body (5 min at 50 Hz), random 5-30 degree misalignment on every
    /// non-base IMU, 0.3 degree noise, no drift.
    pub fn full_body(seed: u64) -> SimConfig {
        SimConfig {
            kind: SimKind::FullBody,
            duration_s: 300.0,
            rate_hz: 50.0,
            seed,
            noise_deg: 0.3,
            misalignment: Misalignment::Random {
                min_deg: RANDOM_MISALIGNMENT_DEG[0],
                max_deg: RANDOM_MISALIGNMENT_DEG[1],
            },
            drifts: vec![],
            slips: vec![],
            gyro: None,
        }
    }

    /// The elbow test (5 min at 50 Hz, 0.5 degree noise) with both IMUs
    /// misaligned by `angle_deg`.
    pub fn elbow(seed: u64, angle_deg: f64) -> SimConfig {
        SimConfig {
            kind: SimKind::Elbow { angle_deg },
            duration_s: 300.0,
            rate_hz: 50.0,
            seed,
            noise_deg: 0.5,
            misalignment: Misalignment::None,
            drifts: vec![],
            slips: vec![],
            gyro: None,
        }
    }

    /// The same configuration with gyroscopes whose white noise has the
    /// standard deviation `noise_deg_s` per axis (deg/s).
    pub fn with_gyro(mut self, noise_deg_s: f64) -> SimConfig {
        self.gyro = Some(GyroSim { noise_deg_s });
        self
    }

    /// Number of samples: `round(duration_s * rate_hz)`.
    pub fn samples(&self) -> usize {
        (self.duration_s * self.rate_hz).round().max(0.0) as usize
    }

    /// The IMUs this configuration simulates, in model order.
    pub fn imus(&self, model: &Model) -> Vec<String> {
        match self.kind {
            SimKind::Knee { .. } => KNEE_IMUS.iter().map(|s| s.to_string()).collect(),
            SimKind::FullBody | SimKind::Swing | SimKind::Crawl => model.imus.clone(),
            SimKind::Elbow { .. } => elbow::elbow_joint(model)
                .map(|j| vec![j.proximal.clone(), j.distal.clone()])
                .unwrap_or_default(),
        }
    }

    /// Checks the numbers and the IMU names against the model.
    pub fn validate(&self, model: &Model) -> Result<(), SimError> {
        let err = |m: String| Err(SimError(m));
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0) {
            return err(format!(
                "rate must be a positive number of Hz, found {}",
                self.rate_hz
            ));
        }
        if !self.duration_s.is_finite() || self.samples() < 2 {
            return err(format!(
                "duration {} s at {} Hz gives fewer than 2 samples",
                self.duration_s, self.rate_hz
            ));
        }
        if !(self.noise_deg.is_finite() && self.noise_deg >= 0.0) {
            return err(format!(
                "noise must be >= 0 degrees, found {}",
                self.noise_deg
            ));
        }
        if let Some(g) = &self.gyro {
            if !(g.noise_deg_s.is_finite() && g.noise_deg_s >= 0.0) {
                return err(format!(
                    "gyroscope noise must be >= 0 deg/s, found {}",
                    g.noise_deg_s
                ));
            }
        }
        if let SimKind::Knee { angle_deg, .. } | SimKind::Elbow { angle_deg } = self.kind {
            if !angle_deg.is_finite() {
                return err(format!(
                    "misalignment angle must be finite, found {angle_deg}"
                ));
            }
        }
        if matches!(self.kind, SimKind::Elbow { .. }) && elbow::elbow_joint(model).is_none() {
            return err(format!(
                "the elbow test needs a joint of kind 'elbow'; model '{}' has none",
                model.name
            ));
        }
        let imus = self.imus(model);
        let check_imu = |imu: &str, what: &str| -> Result<(), SimError> {
            if !imus.iter().any(|i| i == imu) {
                return Err(SimError(format!(
                    "{what}: IMU '{imu}' is not simulated (IMUs: {})",
                    imus.join(", ")
                )));
            }
            if imu == model.base {
                return Err(SimError(format!(
                    "{what}: '{imu}' is the base IMU, which is assumed correct"
                )));
            }
            Ok(())
        };
        match &self.misalignment {
            Misalignment::None => {}
            Misalignment::Random { min_deg, max_deg } => {
                if !(min_deg.is_finite()
                    && max_deg.is_finite()
                    && 0.0 <= *min_deg
                    && min_deg <= max_deg
                    && *max_deg <= 180.0)
                {
                    return err(format!(
                        "random misalignment needs 0 <= min <= max <= 180 degrees, found {min_deg}..{max_deg}"
                    ));
                }
            }
            Misalignment::Fixed { imus: list } => {
                for (k, m) in list.iter().enumerate() {
                    check_imu(&m.imu, "misalignment")?;
                    if list[..k].iter().any(|o| o.imu == m.imu) {
                        return err(format!("misalignment: IMU '{}' is listed twice", m.imu));
                    }
                    if m.rotvec_deg.iter().any(|v| !v.is_finite()) {
                        return err(format!("misalignment of '{}' is not finite", m.imu));
                    }
                }
            }
        }
        for (k, d) in self.drifts.iter().enumerate() {
            check_imu(&d.imu, "drift")?;
            if self.drifts[..k].iter().any(|o| o.imu == d.imu) {
                return err(format!("drift: IMU '{}' is listed twice", d.imu));
            }
            if !(d.start_s.is_finite() && d.rate_deg_s.is_finite()) {
                return err(format!("drift of '{}' is not finite", d.imu));
            }
        }
        for (k, d) in self.slips.iter().enumerate() {
            check_imu(&d.imu, "slippage")?;
            if self.slips[..k].iter().any(|o| o.imu == d.imu) {
                return err(format!("slippage: IMU '{}' is listed twice", d.imu));
            }
            let finite = d.start_s.is_finite()
                && d.rate_deg_s.is_finite()
                && d.axis.iter().all(|a| a.is_finite());
            if !finite || d.axis.iter().all(|&a| a == 0.0) {
                return err(format!(
                    "slippage of '{}' needs finite numbers and a non-zero axis",
                    d.imu
                ));
            }
        }
        Ok(())
    }
}

/// A named configuration: `knee_calf_z15` (knee test, calf 15 degrees about Z,
/// 5 min, 50 Hz, no noise), `full_body_clean` (13 IMUs, 90 s, 50 Hz, seed 1,
/// random 5-30 degree misalignment, 0.3 degree noise, no drift), `full_body_drift`
/// (as clean but 300 s, seed 2, heading drift on `l_calf` from 60 s at 0.05 deg/s
/// and on `r_upper_arm` from 30 s at 0.08 deg/s), `elbow_20` (elbow test, both
/// IMUs 20 degrees off their hinge axes, 5 min, 50 Hz, seed 3, 0.5 degree noise),
/// `full_body_swing` (13 IMUs, [`SimKind::Swing`], 60 s, 50 Hz, seed 1, no
/// misalignment, 0.3 degree noise), `full_body_crawl` (13 IMUs,
/// [`SimKind::Crawl`]: hips and knees flexed mostly beyond 90 deg, 60 s, 50 Hz,
/// seed 1, no misalignment, 0.3 degree noise).
pub fn preset(name: &str) -> Option<SimConfig> {
    match name {
        "knee_calf_z15" => Some(SimConfig::knee(KneeImu::Calf, KneeAxis::Z, 15.0)),
        "elbow_20" => Some(SimConfig::elbow(3, 20.0)),
        "full_body_clean" => Some(SimConfig {
            duration_s: 90.0,
            ..SimConfig::full_body(1)
        }),
        "full_body_drift" => Some(SimConfig {
            drifts: vec![
                HeadingDrift {
                    imu: "l_calf".into(),
                    start_s: 60.0,
                    rate_deg_s: 0.05,
                },
                HeadingDrift {
                    imu: "r_upper_arm".into(),
                    start_s: 30.0,
                    rate_deg_s: 0.08,
                },
            ],
            ..SimConfig::full_body(2)
        }),
        "full_body_swing" => Some(SimConfig {
            kind: SimKind::Swing,
            duration_s: 60.0,
            misalignment: Misalignment::None,
            ..SimConfig::full_body(1)
        }),
        "full_body_crawl" => Some(SimConfig {
            kind: SimKind::Crawl,
            duration_s: 60.0,
            misalignment: Misalignment::None,
            ..SimConfig::full_body(1)
        }),
        _ => None,
    }
}

/// Independent random streams, so that e.g. adding noise leaves the motion and
/// the misalignments of a seed unchanged.
#[derive(Clone, Copy)]
enum Stream {
    Motion = 1,
    Misalignment = 2,
    Noise = 3,
    ElbowMisalignment = 4,
    GyroNoise = 5,
}

fn rng(seed: u64, stream: Stream) -> ChaCha8Rng {
    let mut r = ChaCha8Rng::seed_from_u64(seed);
    r.set_stream(stream as u64);
    r
}

/// Runs a simulation (model `infant13`, limits Table 3-2).
pub fn simulate(config: &SimConfig) -> Result<Simulated, SimError> {
    let model = Model::builtin(MODEL).map_err(|e| SimError(e.to_string()))?;
    simulate_with(config, &model)
}

/// Runs a simulation of `model`'s IMUs (limits Table 3-2). The knee and
/// elbow kinds simulate their own two or three IMUs, whatever the model.
pub fn simulate_with(config: &SimConfig, model: &Model) -> Result<Simulated, SimError> {
    let model = model.clone();
    config.validate(&model)?;
    let n = config.samples();
    let time_s: Vec<f64> = (0..n).map(|i| i as f64 / config.rate_hz).collect();

    // Clean segment orientations, in model IMU order.
    let segments = segments_at(config, &model, &time_s);

    let misalignments = misalignments(config, &model, &segments);
    let gyros = config
        .gyro
        .map(|g| sensor_gyros(config, &model, &time_s, &misalignments, g));
    let mut noise_rng = rng(config.seed, Stream::Noise);
    let sigma_rad = config.noise_deg.to_radians() / 3f64.sqrt();
    let noise = Normal::new(0.0, sigma_rad).map_err(|e| SimError(e.to_string()))?;

    let mut measured = Vec::with_capacity(segments.len());
    for (name, seg) in &segments {
        let m = misalignments[name];
        let drift = config.drifts.iter().find(|d| &d.imu == name);
        let slip = config.slips.iter().find(|d| &d.imu == name);
        let orientation = seg
            .iter()
            .zip(&time_s)
            .map(|(s, &t)| {
                let mut q = clean_sensor(s, &m, drift, slip, t);
                if config.noise_deg > 0.0 {
                    let v = Vector3::new(
                        noise.sample(&mut noise_rng),
                        noise.sample(&mut noise_rng),
                        noise.sample(&mut noise_rng),
                    );
                    q *= rotation::quat_from_rotvec(&v);
                }
                q
            })
            .collect();
        let gyro = gyros.as_ref().map(|g| g[name].clone());
        measured.push(ImuSeries::new(name.clone(), orientation).with_gyro(gyro));
    }

    let label = kind_label(&config.kind);
    let trial = Trial {
        name: label.clone(),
        time_s: time_s.clone(),
        imus: measured,
        warnings: vec![],
        orientation_decimals: None,
    };
    let truth = Truth {
        segments: Trial {
            name: format!("{label}.truth"),
            time_s,
            imus: segments
                .into_iter()
                .map(|(name, orientation)| ImuSeries::new(name, orientation))
                .collect(),
            warnings: vec![],
            orientation_decimals: None,
        },
        meta: TruthMeta {
            model: model.name.clone(),
            config: config.clone(),
            misalignments: misalignments
                .iter()
                .map(|(k, q)| (k.clone(), rotation::wxyz(&rotation::canonical(q))))
                .collect(),
            drifts: config.drifts.clone(),
        },
    };
    Ok(Simulated { trial, truth })
}

/// Clean segment orientations of every simulated IMU at `time_s`, in model
/// IMU order (the motion depends on the seed, not on the times asked for).
fn segments_at(config: &SimConfig, model: &Model, time_s: &[f64]) -> Vec<(String, Vec<Quat>)> {
    match config.kind {
        SimKind::Knee { .. } => knee_segments(time_s),
        SimKind::FullBody => full_body_segments(model, config.seed, time_s, false),
        SimKind::Crawl => full_body_segments(model, config.seed, time_s, true),
        SimKind::Elbow { .. } => match elbow::elbow_joint(model) {
            Some(joint) => elbow::segments(joint, time_s),
            None => vec![],
        },
        SimKind::Swing => swing::segments(model, config.seed, time_s),
    }
}

/// The sensor's orientation without noise: `Rz(h(t)) G_R_segment M S(t)`.
fn clean_sensor(
    segment: &Quat,
    m: &Quat,
    drift: Option<&HeadingDrift>,
    slip: Option<&SensorSlip>,
    t: f64,
) -> Quat {
    let mut q = segment * m;
    if let Some(d) = slip {
        q *= d.rotation_at(t);
    }
    if let Some(d) = drift {
        q = d.rotation_at(t) * q;
    }
    q
}

/// Gyroscope readings per IMU (rad/s, sensor frame): the body rate of the
/// clean sensor orientation by a central difference over `t -+ gyro::STEP_S`,
/// plus white noise from its own random stream (adding gyros changes nothing
/// else of a seed's trial).
fn sensor_gyros(
    config: &SimConfig,
    model: &Model,
    time_s: &[f64],
    misalignments: &BTreeMap<String, Quat>,
    g: GyroSim,
) -> BTreeMap<String, Vec<Vector3<f64>>> {
    let shifted = |h: f64| -> Vec<f64> { time_s.iter().map(|t| t + h).collect() };
    let (t_minus, t_plus) = (shifted(-gyro::STEP_S), shifted(gyro::STEP_S));
    let span: Vec<f64> = t_plus.iter().zip(&t_minus).map(|(p, m)| p - m).collect();
    let minus = segments_at(config, model, &t_minus);
    let plus = segments_at(config, model, &t_plus);
    let mut noise_rng = rng(config.seed, Stream::GyroNoise);
    let mut out = BTreeMap::new();
    for ((name, seg_m), (_, seg_p)) in minus.iter().zip(&plus) {
        let m = misalignments[name];
        let drift = config.drifts.iter().find(|d| &d.imu == name);
        let slip = config.slips.iter().find(|d| &d.imu == name);
        let sensor = |seg: &[Quat], ts: &[f64]| -> Vec<Quat> {
            seg.iter()
                .zip(ts)
                .map(|(s, &t)| clean_sensor(s, &m, drift, slip, t))
                .collect()
        };
        let mut rates = gyro::body_rates(&sensor(seg_m, &t_minus), &sensor(seg_p, &t_plus), &span);
        gyro::add_noise(&mut rates, g.noise_deg_s, &mut noise_rng);
        out.insert(name.clone(), rates);
    }
    out
}

fn kind_label(kind: &SimKind) -> String {
    match kind {
        SimKind::Knee { .. } => "simulated-knee".into(),
        SimKind::FullBody => "simulated-full-body".into(),
        SimKind::Elbow { .. } => "simulated-elbow".into(),
        SimKind::Swing => "simulated-swing".into(),
        SimKind::Crawl => "simulated-crawl".into(),
    }
}

/// Thesis 4.1: thigh static at identity, calf = thigh * Ry(flexion(t)).
fn knee_segments(time_s: &[f64]) -> Vec<(String, Vec<Quat>)> {
    let mid = 0.5 * (KNEE_FLEXION_MIN_DEG + KNEE_FLEXION_MAX_DEG);
    let amp = 0.5 * (KNEE_FLEXION_MAX_DEG - KNEE_FLEXION_MIN_DEG);
    let omega = TAU * KNEE_CYCLES_PER_MIN / 60.0;
    let thigh = vec![Quat::identity(); time_s.len()];
    let calf = time_s
        .iter()
        .map(|&t| rotation::quat_from_euler_zyx_deg([0.0, mid - amp * (omega * t).cos(), 0.0]))
        .collect();
    vec![
        (KNEE_IMUS[0].to_string(), thigh),
        (KNEE_IMUS[1].to_string(), calf),
    ]
}

/// Base motion plus every joint's angles, chained in model joint order; with
/// `crawl`, hips and knees flexed deep ([`SimKind::Crawl`], drawn after the
/// rest so the other joints move as in [`SimKind::FullBody`]).
fn full_body_segments(
    model: &Model,
    seed: u64,
    time_s: &[f64],
    crawl: bool,
) -> Vec<(String, Vec<Quat>)> {
    let table = LimitTable::default_table();
    let mut r = rng(seed, Stream::Motion);
    let base = motion::BaseMotion::random(&mut r);
    let mut joints: Vec<motion::JointMotion> = model
        .joints
        .iter()
        .map(|j| motion::joint_motion(&mut r, &table, j))
        .collect();
    if crawl {
        joints = model
            .joints
            .iter()
            .zip(joints)
            .map(|(j, m)| motion::crawl_motion(&mut r, j, m))
            .collect();
    }
    chain_segments(model, &base, time_s, |k, t| joints[k].angles_at(t))
}

/// Segment orientations of every IMU of `model`: the base from `base`, each
/// joint's distal segment as its proximal one times the joint rotation of
/// `angles(joint index, t)` (degrees, the table's convention: [`crate::model::Joint::rotation`]).
fn chain_segments(
    model: &Model,
    base: &motion::BaseMotion,
    time_s: &[f64],
    angles: impl Fn(usize, f64) -> [f64; 3],
) -> Vec<(String, Vec<Quat>)> {
    let mut by_imu: BTreeMap<&str, Vec<Quat>> = BTreeMap::new();
    by_imu.insert(
        &model.base,
        time_s.iter().map(|&t| base.orientation_at(t)).collect(),
    );
    for (k, j) in model.joints.iter().enumerate() {
        let prox = &by_imu[j.proximal.as_str()];
        let dist = prox
            .iter()
            .zip(time_s)
            .map(|(p, &t)| p * j.rotation(angles(k, t)))
            .collect();
        by_imu.insert(&j.distal, dist);
    }
    model
        .imus
        .iter()
        .filter_map(|name| by_imu.remove(name.as_str()).map(|q| (name.clone(), q)))
        .collect()
}

/// `M` per simulated IMU (identity where none), drawn or taken from the config.
fn misalignments(
    config: &SimConfig,
    model: &Model,
    segments: &[(String, Vec<Quat>)],
) -> BTreeMap<String, Quat> {
    let mut out: BTreeMap<String, Quat> = segments
        .iter()
        .map(|(n, _)| (n.clone(), Quat::identity()))
        .collect();
    if let SimKind::Knee {
        misaligned_imu,
        axis,
        angle_deg,
    } = config.kind
    {
        let imu = match misaligned_imu {
            KneeImu::None => None,
            KneeImu::Thigh => Some(KNEE_IMUS[0]),
            KneeImu::Calf => Some(KNEE_IMUS[1]),
        };
        let axis = match axis {
            KneeAxis::X => [1.0, 0.0, 0.0],
            KneeAxis::Z => [0.0, 0.0, 1.0],
        };
        if let Some(imu) = imu {
            out.insert(imu.into(), rotation::quat_axis_angle_deg(axis, angle_deg));
        }
    }
    if let SimKind::Elbow { angle_deg } = config.kind {
        if let Some(joint) = elbow::elbow_joint(model) {
            out.extend(elbow::misalignments(joint, config.seed, angle_deg));
        }
    }
    match &config.misalignment {
        Misalignment::None => {}
        Misalignment::Random { min_deg, max_deg } => {
            let mut r = rng(config.seed, Stream::Misalignment);
            for (name, _) in segments {
                if *name == model.base {
                    continue;
                }
                let axis: [f64; 3] = UnitSphere.sample(&mut r);
                let angle = r.random_range(*min_deg..=*max_deg);
                let m = out[name] * rotation::quat_axis_angle_deg(axis, angle);
                out.insert(name.clone(), m);
            }
        }
        Misalignment::Fixed { imus } => {
            for f in imus {
                let v = Vector3::from(f.rotvec_deg).map(f64::to_radians);
                let m = out[&f.imu] * rotation::quat_from_rotvec(&v);
                out.insert(f.imu.clone(), m);
            }
        }
    }
    out
}

/// The trial with every quaternion component rounded to `decimals` decimals,
/// as a sensor with that output resolution writes it. The components are kept
/// as rounded (their norm is 1 within about `10^-decimals`); readers renormalise.
pub fn round_orientations(trial: &Trial, decimals: u32) -> Trial {
    let scale = 10f64.powi(decimals as i32);
    let round = |v: f64| (v * scale).round() / scale;
    let mut out = trial.clone();
    for imu in &mut out.imus {
        for q in &mut imu.orientation {
            let c = crate::rotation::canonical(q);
            *q = Quat::new_unchecked(nalgebra::Quaternion::new(
                round(c.w),
                round(c.i),
                round(c.j),
                round(c.k),
            ));
        }
    }
    out
}
