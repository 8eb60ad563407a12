//! Calibration against simulated recordings whose true rotations are known.

use super::simulate::{simulate, CalibSimConfig, Sloppiness};
use super::*;
use crate::rotation::{angle_between_deg, quat_axis_angle_deg};

fn run(config: &CalibSimConfig) -> (simulate::SimulatedCalibration, Calibration) {
    let p = Protocol::default_protocol();
    let sim = simulate(&p, config).unwrap();
    let cal = calibrate(&sim.recording, &p);
    (sim, cal)
}

/// Angle between the LM (and TRIAD) rotation and the truth, degrees.
fn errors(sim: &simulate::SimulatedCalibration, s: &SegmentResult) -> (f64, f64) {
    let t = sim.truth(&s.imu).unwrap();
    (
        angle_between_deg(&s.rotation(), &t),
        angle_between_deg(&s.triad_rotation().unwrap(), &t),
    )
}

#[test]
fn lm_recovers_the_rotation_within_2_deg() {
    // Ten recordings with uniformly random sensor orientations, sloppy
    // movements (20 deg RMS wobble, 1 deg bias) and noise. The bias moves every
    // axis estimate by about 1 deg, so 2 deg is the error the paper's kind of
    // data allows; the worst seen is printed.
    let mut worst: f64 = 0.0;
    let mut iters = vec![];
    for seed in 0..10 {
        let (sim, cal) = run(&CalibSimConfig {
            seed,
            ..CalibSimConfig::default()
        });
        assert!(cal.skipped.is_empty(), "{:?}", cal.skipped);
        assert_eq!(cal.segments.len(), 5);
        for s in &cal.segments {
            let (lm, _) = errors(&sim, s);
            assert!(lm < 2.0, "seed {seed} {}: LM off by {lm:.2} deg", s.imu);
            worst = worst.max(lm);
            iters.push(s.iterations);
            // The fit lowers the cost from the identity start.
            assert!(s.cost_end < s.cost_start);
        }
    }
    let mean = iters.iter().sum::<usize>() as f64 / iters.len() as f64;
    eprintln!(
        "LM error worst {worst:.2} deg; iterations mean {mean:.1}, range {}-{}",
        iters.iter().min().unwrap(),
        iters.iter().max().unwrap()
    );
    // The paper reports 6-9 iterations on average from the identity start;
    // uniformly random orientations are further away than real straps.
    assert!((3.0..=20.0).contains(&mean), "mean iterations {mean}");
}

#[test]
fn lm_beats_triad_with_a_noisy_second_axis() {
    // TRIAD takes the supine posture (primary) and the next movement with
    // another axis (secondary): TR for the thorax, FEB for the upper arm. Make
    // that movement sloppy: 30 deg wobble and a 6 deg bias of its mean axis. LM
    // uses every other movement too, weighted by rho, so the bias pulls it less.
    // It is a weighted compromise, not immune: on a few recordings the bias
    // happens to lie where TRIAD ignores it, so the test compares means over ten
    // recordings and requires LM to win most of them.
    for (imu, noisy) in [("upper_back", "TR"), ("l_upper_arm", "FEB")] {
        let mut config = CalibSimConfig::default();
        config.overrides.insert(
            noisy.into(),
            Sloppiness {
                wobble_deg: 30.0,
                bias_deg: 6.0,
            },
        );
        let (mut lm_sum, mut triad_sum, mut wins) = (0.0, 0.0, 0);
        for seed in 0..10 {
            config.seed = seed;
            let (sim, cal) = run(&config);
            let s = cal.segment(imu).unwrap();
            assert_eq!(s.triad_movements, ["supine", noisy]);
            let (lm, triad) = errors(&sim, s);
            lm_sum += lm;
            triad_sum += triad;
            wins += usize::from(lm < triad);
        }
        eprintln!(
            "{imu}, noisy {noisy}: mean error LM {:.2} deg, TRIAD {:.2} deg; LM better in {wins} of 10",
            lm_sum / 10.0,
            triad_sum / 10.0
        );
        assert!(lm_sum < 0.7 * triad_sum, "{imu}: {lm_sum} vs {triad_sum}");
        assert!(wins >= 6, "{imu}: LM better in {wins} of 10");
    }
}

#[test]
fn rho_near_one_for_postures_lower_for_sloppy_movements() {
    let (_, cal) = run(&CalibSimConfig::default());
    for s in &cal.segments {
        for a in &s.axes {
            match a.kind {
                // Table 1: 0.97-0.99 for the supine posture.
                MovementKind::Static => {
                    assert!(a.rho > 0.97, "{} {}: {}", s.imu, a.movement, a.rho)
                }
                // Table 1: 0.53-0.84 for the movements.
                MovementKind::Functional => {
                    assert!(
                        (0.5..0.9).contains(&a.rho),
                        "{} {}: {}",
                        s.imu,
                        a.movement,
                        a.rho
                    )
                }
            }
            assert!(a.residual_lm_deg <= 180.0 && a.rho >= 1.0 / 3.0);
        }
    }
    // The sloppier the movement, the lower rho. Without noise a clean movement
    // gives 1; with gyroscope noise the slow readings at each turn-around point
    // anywhere, which keeps even a clean movement's rho well below a posture's.
    let rho = |wobble: f64, noise: f64| {
        let c = CalibSimConfig {
            gyro_noise_deg_s: noise,
            moving: Sloppiness {
                wobble_deg: wobble,
                bias_deg: 0.0,
            },
            ..CalibSimConfig::default()
        };
        let (_, cal) = run(&c);
        cal.segment("upper_back").unwrap().axis("TR").unwrap().rho
    };
    assert!(rho(0.0, 0.0) > 0.999);
    let r: Vec<f64> = [0.0, 10.0, 20.0, 35.0]
        .iter()
        .map(|&w| rho(w, 1.0))
        .collect();
    eprintln!("TR rho for wobble 0/10/20/35 deg: {r:.3?}");
    assert!(r.windows(2).all(|w| w[1] < w[0]), "{r:?}");
}

#[test]
fn residuals_shrink_and_more_reliable_axes_fit_closer() {
    // Figure 5: residual angles fall from the identity start to the fit.
    let (_, cal) = run(&CalibSimConfig::default());
    for s in &cal.segments {
        let before: f64 = s.axes.iter().map(|a| a.residual_before_deg).sum();
        let after: f64 = s.axes.iter().map(|a| a.residual_lm_deg).sum();
        assert!(after < before, "{}: {before} -> {after}", s.imu);
        // The supine estimate (rho 0.98) ends closer than the sloppiest movement.
        let supine = s.axis("supine").unwrap();
        let worst = s
            .axes
            .iter()
            .max_by(|a, b| a.residual_lm_deg.total_cmp(&b.residual_lm_deg))
            .unwrap();
        assert!(supine.residual_lm_deg <= worst.residual_lm_deg);
    }
}

#[test]
fn missing_movements_and_imus_are_reported() {
    let p = Protocol::default_protocol();
    let mut sim = simulate(&p, &CalibSimConfig::default()).unwrap();
    // Drop the thorax rotation rows and the right forearm.
    let tr = sim.recording.labels.iter().position(|l| l == "TR").unwrap() as u32;
    for l in sim.recording.label_of.iter_mut() {
        if *l == Some(tr) {
            *l = None;
        }
    }
    sim.recording.imus.retain(|i| i.name != "r_forearm");
    let cal = calibrate(&sim.recording, &p);
    let thorax = cal.segment("upper_back").unwrap();
    assert_eq!(thorax.missing, ["TR"]);
    assert_eq!(thorax.triad_movements, ["supine", "TFE"]);
    assert_eq!(cal.skipped.len(), 1);
    assert_eq!(cal.skipped[0].imu, "r_forearm");
}

#[test]
fn calibration_file_round_trips_and_errors_are_located() {
    let (_, cal) = run(&CalibSimConfig::default());
    let text = cal.to_toml();
    let back = Calibration::from_toml(&text, "c.toml").unwrap();
    assert_eq!(back, cal);
    let bad = text.replacen("iterations = ", "iterations = \"x\" # ", 1);
    let e = Calibration::from_toml(&bad, "c.toml").unwrap_err();
    let line = bad
        .lines()
        .position(|l| l.starts_with("iterations"))
        .unwrap() as u64
        + 1;
    assert_eq!((e.file.as_str(), e.line), ("c.toml", line), "{e}");
    assert!(e.column > 0);
    // A q that is not a unit quaternion: at the second segment's `q` key.
    let mut twice = cal.clone();
    twice.segments[1].q = [2.0, 0.0, 0.0, 0.0];
    let text2 = twice.to_toml();
    let line = text2
        .lines()
        .enumerate()
        .filter(|(_, l)| l.starts_with("q = "))
        .nth(1)
        .unwrap()
        .0
        + 1;
    assert_eq!(
        Calibration::from_toml(&text2, "c.toml")
            .unwrap_err()
            .to_string(),
        format!(
            "c.toml:{line}:1: IMU '{}': q is not a unit quaternion (norm 2)",
            twice.segments[1].imu
        )
    );
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("c.calibration.toml");
    cal.save(&path).unwrap();
    cal.save(&path).unwrap();
    assert!(crate::save::backup_path(&path).exists());
    assert_eq!(Calibration::load(&path).unwrap(), cal);
    assert_eq!(
        default_output(Path::new("d/walk.calib.csv.gz")),
        Path::new("d/walk.calibration.toml")
    );
}

#[test]
fn applying_the_calibration_gives_the_segment_orientation() {
    // IMU = segment * M with M = R_SF^FF: applying R undoes M.
    let m = quat_axis_angle_deg([0.2, 1.0, -0.3], 35.0);
    let seg = vec![
        quat_axis_angle_deg([1.0, 0.0, 0.0], 10.0),
        quat_axis_angle_deg([0.0, 1.0, 1.0], 80.0),
    ];
    let mut trial = Trial {
        name: "t".into(),
        time_s: vec![0.0, 0.02],
        imus: vec![crate::trial::ImuSeries::new(
            "l_forearm",
            seg.iter().map(|s| s * m).collect(),
        )],
        warnings: vec![],
        orientation_decimals: None,
    };
    let applied = AppliedCalibration {
        file: "c.toml".into(),
        sha256: String::new(),
        text: String::new(),
        protocol: "ricci2014".into(),
        imus: vec![
            AppliedRotation {
                imu: "L_Forearm".into(),
                q: wxyz(&m),
            },
            AppliedRotation {
                imu: "head".into(),
                q: [1.0, 0.0, 0.0, 0.0],
            },
        ],
    };
    let w = applied.apply(&mut trial, &Model::infant13());
    assert_eq!(w.len(), 1, "{w:?}");
    for (got, want) in trial.imus[0].orientation.iter().zip(&seg) {
        assert!(angle_between_deg(got, want) < 1e-9);
    }
}

#[test]
fn same_config_same_recording() {
    let p = Protocol::default_protocol();
    let c = CalibSimConfig::default();
    let a = simulate(&p, &c).unwrap();
    let b = simulate(&p, &c).unwrap();
    assert_eq!(a.recording, b.recording);
    let mut bad = c.clone();
    bad.overrides.insert("nope".into(), c.moving);
    assert!(simulate(&p, &bad).is_err());
}
