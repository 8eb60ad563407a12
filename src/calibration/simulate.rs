//! Simulated calibration recordings with a known sensor-to-functional-frame
//! rotation per IMU, imperfect mono-axial movements and sensor noise, so the
//! calibration can be judged against what it should find.
//!
//! Per movement of the protocol, in protocol order, separated by one second of
//! unlabelled rest:
//! * a still posture for `static_s` seconds: the accelerometer reads the specific
//!   force `g * a(t)` (FF) with `a(t)` the protocol's axis, turned by a fixed
//!   `bias_deg` and a slow sway (breathing) of RMS `sway_deg`;
//! * a functional movement of `reps` repetitions of period `period_s`: the
//!   angle goes `amplitude * sin(2 pi t / period)` (first phase positive) about
//!   an axis that is the protocol's turned by a fixed `bias_deg` and a smooth
//!   wobble of RMS `wobble_deg` (the imperfectly mono-axial movement).
//!
//! IMUs a movement does not calibrate are still (gravity along their FF +x,
//! gyroscope noise only); the accelerometer during movements reads gravity only
//! (the method does not use it). Readings are taken into the sensor frame with
//! the true rotation, `v_SF = R^T v_FF`, and get white noise: `gyro_noise_deg_s`
//! (deg/s) and `acc_noise` (m/s^2) per axis. Same configuration, same recording.

use super::protocol::{MovementKind, Protocol};
use super::recording::{ImuReadings, Recording};
use crate::rotation::{quat_from_wxyz, wxyz, Quat};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::f64::consts::TAU;

/// Standard gravity, m/s^2.
pub const GRAVITY: f64 = 9.81;

/// How sloppily a movement is performed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Sloppiness {
    /// RMS angle of the time-varying deviation of the axis, degrees.
    pub wobble_deg: f64,
    /// Fixed deviation of the movement's mean axis (random direction), degrees.
    pub bias_deg: f64,
}

/// What to simulate.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CalibSimConfig {
    /// Seed of every random choice.
    pub seed: u64,
    /// Sampling rate, Hz.
    pub rate_hz: f64,
    /// Length of a still posture, seconds.
    pub static_s: f64,
    /// Repetitions of a functional movement.
    pub reps: usize,
    /// Period of one repetition, seconds.
    pub period_s: f64,
    /// Peak angle of a repetition, degrees.
    pub amplitude_deg: f64,
    /// Gyroscope white noise per axis, deg/s (RMS).
    pub gyro_noise_deg_s: f64,
    /// Accelerometer white noise per axis, m/s^2 (RMS).
    pub acc_noise: f64,
    /// Still postures: sway (RMS, `wobble_deg`) and bias.
    pub still: Sloppiness,
    /// Functional movements: wobble and bias.
    pub moving: Sloppiness,
    /// Per movement label, a sloppiness overriding the above.
    #[serde(default)]
    pub overrides: BTreeMap<String, Sloppiness>,
    /// True rotation SF -> FF per IMU, `[w, x, y, z]`; IMUs of the protocol not
    /// listed get a uniformly random rotation drawn from the seed.
    #[serde(default)]
    pub rotations: BTreeMap<String, [f64; 4]>,
}

impl Default for CalibSimConfig {
    /// Values meant to resemble the paper's recordings (Table 1: rho about 0.98
    /// for the supine posture and 0.5-0.85 for the movements).
    fn default() -> Self {
        CalibSimConfig {
            seed: 0,
            rate_hz: 100.0,
            static_s: 5.0,
            reps: 10,
            period_s: 2.0,
            amplitude_deg: 40.0,
            gyro_noise_deg_s: 1.0,
            acc_noise: 0.1,
            still: Sloppiness {
                wobble_deg: 0.5,
                bias_deg: 1.0,
            },
            moving: Sloppiness {
                wobble_deg: 20.0,
                bias_deg: 1.0,
            },
            overrides: BTreeMap::new(),
            rotations: BTreeMap::new(),
        }
    }
}

/// A simulated recording and the true rotations it was made with.
#[derive(Debug, Clone)]
pub struct SimulatedCalibration {
    pub recording: Recording,
    /// True rotation SF -> FF per IMU (protocol order).
    pub truth: Vec<(String, Quat)>,
    /// The configuration with every rotation filled in.
    pub config: CalibSimConfig,
}

impl SimulatedCalibration {
    /// The true rotation of an IMU.
    pub fn truth(&self, imu: &str) -> Option<Quat> {
        self.truth.iter().find(|(n, _)| n == imu).map(|(_, q)| *q)
    }
}

/// Why a configuration cannot be simulated.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("calibration simulation: {0}")]
pub struct CalibSimError(pub String);

impl CalibSimConfig {
    fn validate(&self, protocol: &Protocol) -> Result<(), CalibSimError> {
        let pos = |v: f64, what: &str| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(CalibSimError(format!("{what} must be > 0, found {v}")))
            }
        };
        pos(self.rate_hz, "rate_hz")?;
        pos(self.static_s, "static_s")?;
        pos(self.period_s, "period_s")?;
        pos(self.amplitude_deg, "amplitude_deg")?;
        if self.reps == 0 {
            return Err(CalibSimError("reps must be at least 1".into()));
        }
        let slop = std::iter::once(&self.still)
            .chain(std::iter::once(&self.moving))
            .chain(self.overrides.values());
        for s in slop {
            if !(s.wobble_deg >= 0.0 && s.bias_deg >= 0.0) {
                return Err(CalibSimError("wobble and bias must be >= 0".into()));
            }
        }
        if !(self.gyro_noise_deg_s >= 0.0 && self.acc_noise >= 0.0) {
            return Err(CalibSimError("noise must be >= 0".into()));
        }
        for label in self.overrides.keys() {
            if protocol.movement(label).is_none() {
                return Err(CalibSimError(format!(
                    "override for '{label}', which is not a movement of protocol {}",
                    protocol.name
                )));
            }
        }
        Ok(())
    }
}

/// A smooth zero-mean signal: three sinusoids with periods 0.7-3 s, random
/// phases, scaled to the given RMS.
struct Smooth {
    waves: [(f64, f64, f64); 3],
}

impl Smooth {
    fn new(rng: &mut ChaCha8Rng, rms: f64) -> Smooth {
        let mut waves = [(0.0, 0.0, 0.0); 3];
        for w in &mut waves {
            *w = (
                rng.random_range(0.5..1.0),
                TAU / rng.random_range(0.7..3.0),
                rng.random_range(0.0..TAU),
            );
        }
        // RMS of a sum of sinusoids: sqrt(sum amp^2 / 2).
        let r = (waves.iter().map(|w| w.0 * w.0).sum::<f64>() / 2.0).sqrt();
        for w in &mut waves {
            w.0 *= rms / r;
        }
        Smooth { waves }
    }

    fn at(&self, t: f64) -> f64 {
        self.waves
            .iter()
            .map(|(a, om, ph)| a * (om * t + ph).sin())
            .sum()
    }
}

/// Two unit vectors completing `a` to an orthonormal basis.
fn perpendiculars(a: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let helper = if a.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let p1 = a.cross(&helper).normalize();
    (p1, a.cross(&p1))
}

/// The axis of one movement of one IMU over time: nominal axis, bias, wobble.
struct MovingAxis {
    biased: Vector3<f64>,
    p: (Vector3<f64>, Vector3<f64>),
    wobble: (Smooth, Smooth),
}

impl MovingAxis {
    fn new(rng: &mut ChaCha8Rng, axis: Vector3<f64>, s: Sloppiness) -> MovingAxis {
        let (p1, p2) = perpendiculars(&axis);
        let dir = rng.random_range(0.0..TAU);
        let bias_axis = p1 * dir.cos() + p2 * dir.sin();
        let bias = Quat::from_scaled_axis(bias_axis * s.bias_deg.to_radians());
        let biased = bias * axis;
        let rms = s.wobble_deg.to_radians() / std::f64::consts::SQRT_2;
        MovingAxis {
            p: perpendiculars(&biased),
            biased,
            wobble: (Smooth::new(rng, rms), Smooth::new(rng, rms)),
        }
    }

    fn at(&self, t: f64) -> Vector3<f64> {
        let w = self.p.0 * self.wobble.0.at(t) + self.p.1 * self.wobble.1.at(t);
        Quat::from_scaled_axis(w) * self.biased
    }
}

/// A uniformly random rotation.
fn random_rotation(rng: &mut ChaCha8Rng) -> Quat {
    let n = Normal::new(0.0, 1.0).expect("unit normal");
    let q = [n.sample(rng), n.sample(rng), n.sample(rng), n.sample(rng)];
    quat_from_wxyz(q)
}

/// Simulates a calibration recording of `protocol`.
pub fn simulate(
    protocol: &Protocol,
    config: &CalibSimConfig,
) -> Result<SimulatedCalibration, CalibSimError> {
    config.validate(protocol)?;
    let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
    let mut filled = config.clone();
    let truth: Vec<(String, Quat)> = protocol
        .segments
        .iter()
        .map(|imu| {
            let drawn = random_rotation(&mut rng);
            let q = config
                .rotations
                .get(imu)
                .map_or(drawn, |q| quat_from_wxyz(*q));
            filled.rotations.insert(imu.clone(), wxyz(&q));
            (imu.clone(), q)
        })
        .collect();
    let dt = 1.0 / config.rate_hz;
    let gyro_noise = Normal::new(0.0, config.gyro_noise_deg_s).expect("noise >= 0");
    let acc_noise = Normal::new(0.0, config.acc_noise).expect("noise >= 0");
    let mut rec = Recording {
        name: "simulated.calib.csv".into(),
        time_s: vec![],
        labels: vec![],
        label_of: vec![],
        imus: truth
            .iter()
            .map(|(n, _)| ImuReadings {
                name: n.clone(),
                acc: vec![],
                gyro: vec![],
            })
            .collect(),
    };
    let rest_rows = config.rate_hz.round() as usize;
    let push = |rec: &mut Recording,
                rng: &mut ChaCha8Rng,
                label: Option<u32>,
                ff: &[(Vector3<f64>, Vector3<f64>)]| {
        rec.time_s.push(rec.time_s.len() as f64 * dt);
        rec.label_of.push(label);
        for (k, (_, q)) in truth.iter().enumerate() {
            let inv = q.inverse();
            let (acc, gyro) = ff[k];
            let a = inv * acc;
            let g = inv * gyro;
            let imu = &mut rec.imus[k];
            imu.acc
                .push([0, 1, 2].map(|i| a[i] + acc_noise.sample(rng)));
            imu.gyro
                .push([0, 1, 2].map(|i| g[i] + gyro_noise.sample(rng)));
        }
    };
    let still = (Vector3::x() * GRAVITY, Vector3::zeros());
    for m in &protocol.movements {
        for _ in 0..rest_rows {
            let ff = vec![still; truth.len()];
            push(&mut rec, &mut rng, None, &ff);
        }
        rec.labels.push(m.label.clone());
        let label = Some((rec.labels.len() - 1) as u32);
        let slop = config
            .overrides
            .get(&m.label)
            .copied()
            .unwrap_or(match m.kind {
                MovementKind::Static => config.still,
                MovementKind::Functional => config.moving,
            });
        let axes: Vec<Option<MovingAxis>> = truth
            .iter()
            .map(|(imu, _)| {
                m.axes
                    .get(imu)
                    .map(|a| MovingAxis::new(&mut rng, a.vector(), slop))
            })
            .collect();
        let (rows, omega) = match m.kind {
            MovementKind::Static => ((config.static_s * config.rate_hz).round() as usize, 0.0),
            MovementKind::Functional => (
                (config.reps as f64 * config.period_s * config.rate_hz).round() as usize,
                TAU / config.period_s,
            ),
        };
        for i in 0..rows {
            let t = i as f64 * dt;
            let ff: Vec<(Vector3<f64>, Vector3<f64>)> = axes
                .iter()
                .map(|a| match (a, m.kind) {
                    (None, _) => still,
                    (Some(a), MovementKind::Static) => (a.at(t) * GRAVITY, Vector3::zeros()),
                    (Some(a), MovementKind::Functional) => {
                        let rate = config.amplitude_deg * omega * (omega * t).cos();
                        (Vector3::x() * GRAVITY, a.at(t) * rate)
                    }
                })
                .collect();
            push(&mut rec, &mut rng, label, &ff);
        }
    }
    Ok(SimulatedCalibration {
        recording: rec,
        truth,
        config: filled,
    })
}

/// The truth file of a simulated recording: `<stem>.truth.json` beside it
/// (`x.calib.csv.gz` -> `x.calib.truth.json`), holding the configuration with
/// every true rotation.
pub fn truth_path(recording: &std::path::Path) -> std::path::PathBuf {
    let stem = crate::file_names::stem_without(recording, &crate::file_names::CSV_SUFFIXES);
    recording.with_file_name(format!("{stem}.truth.json"))
}

/// The true rotations SF -> FF per IMU from the truth file beside a recording,
/// when there is one.
pub fn load_truth_beside(
    recording: &std::path::Path,
) -> Option<Result<BTreeMap<String, Quat>, super::CalibrationError>> {
    let path = truth_path(recording);
    if !path.exists() {
        return None;
    }
    let origin = path.display().to_string();
    Some((|| {
        let text = std::fs::read_to_string(&path)
            .map_err(|e| super::CalibrationError::file(&origin, format!("cannot read: {e}")))?;
        let c: CalibSimConfig = serde_json::from_str(&text).map_err(|e| {
            super::CalibrationError::at(
                &origin,
                e.line() as u64,
                e.column(),
                format!("not a calibration simulation truth: {e}"),
            )
        })?;
        Ok(c.rotations
            .iter()
            .map(|(k, q)| (k.clone(), quat_from_wxyz(*q)))
            .collect())
    })())
}
