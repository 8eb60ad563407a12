//! Behaviour of the simulator checked against its construction.

use super::*;
use crate::rotation::{angle_between_deg, euler_zyx_deg};

fn short_full_body(seed: u64, duration_s: f64) -> SimConfig {
    SimConfig {
        duration_s,
        ..SimConfig::full_body(seed)
    }
}

fn knee_angles(trial: &Trial) -> Vec<[f64; 3]> {
    let t = &trial.imu("l_thigh").unwrap().orientation;
    let c = &trial.imu("l_calf").unwrap().orientation;
    t.iter()
        .zip(c)
        .map(|(t, c)| euler_zyx_deg(&(t.inverse() * c)))
        .collect()
}

#[test]
fn simulate_knee_truth_flexes_15_to_75_only_about_y() {
    let sim = simulate(&preset("knee_calf_z15").unwrap()).unwrap();
    assert_eq!(sim.trial.len(), 15_000);
    assert_eq!(sim.trial.imus.len(), 2);
    assert!((sim.trial.rate_hz() - 50.0).abs() < 1e-9);
    let model = Model::infant13();
    let knee = model.joint("l_knee").unwrap();
    let a = sim.truth.true_joint_angles(knee);
    assert_eq!(a.len(), 15_000);
    let min = a.iter().map(|a| a[1]).fold(f64::MAX, f64::min);
    let max = a.iter().map(|a| a[1]).fold(f64::MIN, f64::max);
    assert!(
        (min - 15.0).abs() < 0.01 && (max - 75.0).abs() < 0.01,
        "{min} {max}"
    );
    assert!(a.iter().all(|a| a[0].abs() < 1e-9 && a[2].abs() < 1e-9));
    // 5 cycles per minute: back at 15 degrees after 12 s, at 75 after 6 s.
    assert!((a[600][1] - 15.0).abs() < 1e-9 && (a[300][1] - 75.0).abs() < 1e-9);
    // The thigh is static at identity.
    let thigh = &sim.truth.segments.imu("l_thigh").unwrap().orientation;
    assert!(thigh.iter().all(|q| rotation::angle_deg(q) < 1e-12));
}

#[test]
fn simulate_knee_calf_z15_shows_apparent_abduction_and_rotation() {
    // Thesis Figure 4-2: the calf IMU turned 15 deg about Z makes the measured knee
    // rotate and ab/adduct far outside the +-5 degree hinge band as it flexes.
    let sim = simulate(&preset("knee_calf_z15").unwrap()).unwrap();
    let a = knee_angles(&sim.trial);
    let max_x = a.iter().map(|a| a[0].abs()).fold(0.0, f64::max);
    let max_z = a.iter().map(|a| a[2].abs()).fold(0.0, f64::max);
    // Closed form for Ry(y) * Rz(15): x = atan2(sin y sin 15, cos y), z = atan2(sin 15, cos y cos 15).
    let (y, m) = (75f64.to_radians(), 15f64.to_radians());
    let want_x = (y.sin() * m.sin()).atan2(y.cos()).to_degrees();
    let want_z = m.sin().atan2(y.cos() * m.cos()).to_degrees();
    assert!((max_x - want_x).abs() < 1e-6 && (max_z - want_z).abs() < 1e-6);
    assert!(max_x > 40.0 && max_z > 40.0, "{max_x} {max_z}");
    let outside = a.iter().filter(|a| a[2].abs() > 5.0).count() as f64 / a.len() as f64;
    assert!(outside > 0.99, "{outside}");
    // The truth still knows the calf's misalignment and the thigh is aligned.
    let m = sim.truth.meta.misalignment("l_calf").unwrap();
    let want = rotation::quat_axis_angle_deg([0.0, 0.0, 1.0], 15.0);
    assert!(angle_between_deg(&m, &want) < 1e-12);
    assert!(rotation::angle_deg(&sim.truth.meta.misalignment("l_thigh").unwrap()) < 1e-12);
}

#[test]
fn simulate_knee_thigh_misalignment_about_x() {
    let cfg = SimConfig {
        duration_s: 20.0,
        ..SimConfig::knee(KneeImu::Thigh, KneeAxis::X, 20.0)
    };
    let sim = simulate(&cfg).unwrap();
    let thigh = &sim.trial.imu("l_thigh").unwrap().orientation;
    let want = rotation::quat_axis_angle_deg([1.0, 0.0, 0.0], 20.0);
    assert!(thigh.iter().all(|q| angle_between_deg(q, &want) < 1e-12));
    let calf_m = sim.truth.meta.misalignment("l_calf").unwrap();
    assert!(rotation::angle_deg(&calf_m) < 1e-12);
}

#[test]
fn simulate_same_seed_same_trial() {
    let cfg = short_full_body(7, 10.0);
    let a = simulate(&cfg).unwrap();
    let b = simulate(&cfg).unwrap();
    assert_eq!(a, b);
    let c = simulate(&short_full_body(8, 10.0)).unwrap();
    assert_ne!(a.trial, c.trial);
    // Noise has its own random stream: changing it leaves motion and misalignment alone.
    let quiet = simulate(&SimConfig {
        noise_deg: 0.0,
        ..cfg
    })
    .unwrap();
    assert_eq!(quiet.truth.segments, a.truth.segments);
    assert_eq!(quiet.truth.meta.misalignments, a.truth.meta.misalignments);
}

#[test]
fn simulate_full_body_measured_is_drift_segment_misalignment() {
    let cfg = SimConfig {
        noise_deg: 0.0,
        drifts: vec![HeadingDrift {
            imu: "l_calf".into(),
            start_s: 5.0,
            rate_deg_s: 0.5,
        }],
        slips: vec![SensorSlip {
            imu: "l_calf".into(),
            start_s: 2.0,
            rate_deg_s: 0.3,
            axis: [1.0, 2.0, 0.0],
        }],
        ..short_full_body(3, 20.0)
    };
    let sim = simulate(&cfg).unwrap();
    assert_eq!(sim.trial.imus.len(), 13);
    assert_eq!(sim.truth.segments.time_s, sim.trial.time_s);
    for seg in &sim.truth.segments.imus {
        let meas = &sim.trial.imu(&seg.name).unwrap().orientation;
        let m = sim.truth.meta.misalignment(&seg.name).unwrap();
        let drift = cfg.drifts.iter().find(|d| d.imu == seg.name);
        for ((s, q), &t) in seg.orientation.iter().zip(meas).zip(&sim.trial.time_s) {
            let h = drift.map_or(0.0, |d| d.heading_deg(t));
            let slip = match cfg.slips.iter().find(|d| d.imu == seg.name) {
                Some(_) if t <= 2.0 => Quat::identity(),
                Some(_) => rotation::quat_axis_angle_deg([1.0, 2.0, 0.0], 0.3 * (t - 2.0)),
                None => Quat::identity(),
            };
            let want = rotation::quat_axis_angle_deg([0.0, 0.0, 1.0], h) * s * m * slip;
            assert!(angle_between_deg(q, &want) < 1e-9, "{} at {t}", seg.name);
        }
    }
}

#[test]
fn simulate_random_misalignment_and_true_correction() {
    let sim = simulate(&SimConfig {
        noise_deg: 0.0,
        drifts: vec![HeadingDrift {
            imu: "r_foot".into(),
            start_s: 0.0,
            rate_deg_s: 1.0,
        }],
        ..short_full_body(4, 10.0)
    })
    .unwrap();
    let mut seen = 0;
    for imu in Model::infant13().imus {
        let m = sim.truth.meta.misalignment(&imu).unwrap();
        let angle = rotation::angle_deg(&m);
        if imu == "base" {
            assert!(angle < 1e-12);
        } else {
            assert!(
                (5.0 - 1e-9..=30.0 + 1e-9).contains(&angle),
                "{imu}: {angle}"
            );
        }
        let c = sim.truth.true_correction(&sim.trial, &imu);
        assert_eq!(c.len(), sim.trial.len());
        if imu == "r_foot" {
            // Drift makes the true correction change over time.
            assert!(angle_between_deg(&c[0], &c[c.len() - 1]) > 5.0);
            continue;
        }
        for c in &c {
            assert!(angle_between_deg(c, &m.inverse()) < 1e-9, "{imu}");
        }
        seen += 1;
    }
    assert_eq!(seen, 12);
    assert!(sim.truth.true_correction(&sim.trial, "tail").is_empty());
}

#[test]
fn simulate_full_body_true_angles_mostly_inside_table_3_2() {
    let model = Model::infant13();
    let table = LimitTable::default_table();
    for seed in 1..=5 {
        let sim = simulate(&SimConfig {
            noise_deg: 0.0,
            ..SimConfig::full_body(seed)
        })
        .unwrap();
        mostly_inside(&sim, &model, &table);
    }
}

fn mostly_inside(sim: &Simulated, model: &Model, table: &LimitTable) {
    let mut any_outside = false;
    for j in &model.joints {
        let lim = table.joint_limits(&j.name, &j.kind, true).unwrap();
        let a = sim.truth.true_joint_angles(j);
        assert_eq!(a.len(), 15_000);
        let outside = a
            .iter()
            .filter(|a| (0..3).any(|k| a[k] < lim.range_deg[k][0] || a[k] > lim.range_deg[k][1]))
            .count();
        let frac = outside as f64 / a.len() as f64;
        eprintln!(
            "seed {}: {}: {:.2}% outside",
            sim.truth.meta.config.seed,
            j.name,
            100.0 * frac
        );
        assert!(frac <= 0.10, "{}: {frac}", j.name);
        any_outside |= outside > 0;
        // Never far outside: a few degrees at most.
        for a in &a {
            for k in 0..3 {
                let [lo, hi] = lim.range_deg[k];
                assert!(a[k] > lo - 5.0 && a[k] < hi + 5.0, "{} {a:?}", j.name);
            }
        }
    }
    assert!(any_outside, "real motion leaves the limits now and then");
}

#[test]
fn simulate_heading_drift_rate_is_reproduced() {
    let sim = simulate(&preset("full_body_drift").unwrap()).unwrap();
    for d in &sim.truth.meta.drifts {
        let seg = &sim.truth.segments.imu(&d.imu).unwrap().orientation;
        let meas = &sim.trial.imu(&d.imu).unwrap().orientation;
        let m = sim.truth.meta.misalignment(&d.imu).unwrap();
        // The heading error: yaw of measured * (segment * M)^-1 (noise included).
        let (mut st, mut sh, mut stt, mut sth, mut n) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for ((s, q), &t) in seg.iter().zip(meas).zip(&sim.trial.time_s) {
            let h = euler_zyx_deg(&(q * (s * m).inverse()))[2];
            if t <= d.start_s {
                assert!(h.abs() < 3.0, "{} at {t}: {h}", d.imu);
                continue;
            }
            st += t;
            sh += h;
            stt += t * t;
            sth += t * h;
            n += 1.0;
        }
        let slope = (n * sth - st * sh) / (n * stt - st * st);
        assert!((slope - d.rate_deg_s).abs() < 0.002, "{}: {slope}", d.imu);
        let last = *sim.trial.time_s.last().unwrap();
        assert!((d.heading_deg(last) - d.rate_deg_s * (last - d.start_s)).abs() < 1e-12);
    }
    assert_eq!(sim.truth.meta.drifts.len(), 2);
}

#[test]
fn simulate_noise_has_the_requested_rms() {
    let sim = simulate(&SimConfig {
        noise_deg: 0.5,
        ..short_full_body(5, 60.0)
    })
    .unwrap();
    let (mut sum, mut n) = (0.0, 0.0);
    for seg in &sim.truth.segments.imus {
        let meas = &sim.trial.imu(&seg.name).unwrap().orientation;
        let m = sim.truth.meta.misalignment(&seg.name).unwrap();
        for (s, q) in seg.orientation.iter().zip(meas) {
            sum += angle_between_deg(&(s * m), q).powi(2);
            n += 1.0;
        }
    }
    let rms = (sum / n).sqrt();
    assert!((rms - 0.5).abs() < 0.01, "{rms}");
}

#[test]
fn simulate_presets_and_validation() {
    for name in PRESETS {
        let cfg = preset(name).unwrap();
        cfg.validate(&Model::infant13()).unwrap();
        let json = serde_json::to_string(&cfg).unwrap();
        assert_eq!(serde_json::from_str::<SimConfig>(&json).unwrap(), cfg);
    }
    assert!(preset("nope").is_none());
    let clean = preset("full_body_clean").unwrap();
    assert_eq!(
        (clean.duration_s, clean.seed, clean.noise_deg),
        (90.0, 1, 0.3)
    );
    let bad = |cfg: SimConfig, want: &str| {
        let e = simulate(&cfg).unwrap_err().to_string();
        assert!(e.contains(want), "{e}");
    };
    let drift_on = |imu: &str| HeadingDrift {
        imu: imu.into(),
        start_s: 0.0,
        rate_deg_s: 1.0,
    };
    bad(
        SimConfig {
            drifts: vec![drift_on("base")],
            ..short_full_body(1, 1.0)
        },
        "base IMU",
    );
    bad(
        SimConfig {
            drifts: vec![drift_on("r_foot")],
            ..SimConfig::knee(KneeImu::None, KneeAxis::X, 0.0)
        },
        "not simulated",
    );
    bad(
        SimConfig {
            drifts: vec![drift_on("r_foot"), drift_on("r_foot")],
            ..short_full_body(1, 1.0)
        },
        "twice",
    );
    bad(
        SimConfig {
            slips: vec![SensorSlip {
                imu: "l_foot".into(),
                start_s: 0.0,
                rate_deg_s: 0.1,
                axis: [0.0; 3],
            }],
            ..short_full_body(1, 1.0)
        },
        "non-zero axis",
    );
    bad(
        SimConfig {
            rate_hz: 0.0,
            ..short_full_body(1, 1.0)
        },
        "rate",
    );
    bad(short_full_body(1, 0.01), "fewer than 2 samples");
    bad(short_full_body(1, 1.0).with_gyro(-1.0), "gyroscope noise");
    bad(
        short_full_body(1, 1.0).with_gyro(f64::NAN),
        "gyroscope noise",
    );
    bad(
        SimConfig {
            misalignment: Misalignment::Random {
                min_deg: 30.0,
                max_deg: 5.0,
            },
            ..short_full_body(1, 1.0)
        },
        "min <= max",
    );
}

#[test]
fn simulate_fixed_misalignment_is_a_rotation_vector_in_degrees() {
    let sim = simulate(&SimConfig {
        misalignment: Misalignment::Fixed {
            imus: vec![ImuMisalignment {
                imu: "head".into(),
                rotvec_deg: [0.0, 20.0, 0.0],
            }],
        },
        ..short_full_body(1, 1.0)
    })
    .unwrap();
    let m = sim.truth.meta.misalignment("head").unwrap();
    let want = rotation::quat_axis_angle_deg([0.0, 1.0, 0.0], 20.0);
    assert!(angle_between_deg(&m, &want) < 1e-12);
    assert!(rotation::angle_deg(&sim.truth.meta.misalignment("l_foot").unwrap()) < 1e-12);
}

/// Full body at 500 Hz with heading drift and slippage: every IMU's gyro is
/// the rate at which its noise-free measured orientation turns, in its own
/// frame (central difference of neighbouring samples, good to about 0.1 deg/s
/// at this rate), and the drift's and slippage's own rates are in it.
#[test]
fn simulated_gyros_follow_the_measured_orientations_with_drift_and_slippage() {
    let cfg = SimConfig {
        noise_deg: 0.0,
        rate_hz: 500.0,
        drifts: vec![HeadingDrift {
            imu: "l_calf".into(),
            start_s: 1.0,
            rate_deg_s: 5.0,
        }],
        slips: vec![SensorSlip {
            imu: "l_calf".into(),
            start_s: 2.0,
            rate_deg_s: 8.0,
            axis: [1.0, 2.0, 0.0],
        }],
        ..short_full_body(3, 6.0)
    }
    .with_gyro(0.0);
    let sim = simulate(&cfg).unwrap();
    let t = &sim.trial.time_s;
    let mut worst = 0.0f64;
    let mut peak = 0.0f64;
    for imu in &sim.trial.imus {
        let g = imu.gyro.as_ref().expect("every IMU has gyros");
        let q = &imu.orientation;
        for i in 1..q.len() - 1 {
            if (t[i] - 1.0).abs() < 0.01 || (t[i] - 2.0).abs() < 0.01 {
                continue; // the drift and the slippage start with a kink
            }
            let fd = (q[i - 1].inverse() * q[i + 1]).scaled_axis() / (t[i + 1] - t[i - 1]);
            worst = worst.max((g[i] - fd).norm().to_degrees());
            peak = peak.max(g[i].norm().to_degrees());
        }
    }
    assert!(worst < 0.1, "gyro vs orientation: {worst} deg/s");
    assert!(peak > 30.0, "peak rate {peak} deg/s");
    // A heading drift adds its rate about the global vertical, seen in the
    // sensor frame: w = w_plain + G_R_plain^-1 (h' Z).
    let run = |drifts: Vec<HeadingDrift>| {
        simulate(&SimConfig {
            drifts,
            slips: vec![],
            ..cfg.clone()
        })
        .unwrap()
        .trial
    };
    let (drifting, plain) = (run(cfg.drifts.clone()), run(vec![]));
    let calf = |t: &Trial| t.imu("l_calf").unwrap().clone();
    let (a, b) = (calf(&drifting), calf(&plain));
    let (ga, gb) = (a.gyro.unwrap(), b.gyro.unwrap());
    for i in (600..3000).step_by(50) {
        let want = b.orientation[i].inverse() * Vector3::z() * 5f64.to_radians();
        assert!((ga[i] - gb[i] - want).norm() < 1e-7, "{i}");
    }
}
