use super::output::{coordinates_csv, coordinates_path};
use super::sim::{simulate, IkSimConfig};
use super::*;
use crate::acm::Correction;
use crate::limits::{LimitTable, Settings};
use crate::metrics::joint_angles;
use crate::model::{Axis, HardLimits};
use crate::rotation::{angle_between_deg, quat_from_euler_zyx_deg, wrap180};
use crate::variant::Variant;
use std::path::Path;

/// The `ik` variant through the engine's dispatch.
fn correct_trial(
    trial: &Trial,
    model: &Model,
    settings: &Settings,
    control: &RunControl,
) -> Result<Correction, Cancelled> {
    let limits = LimitTable::default_table();
    crate::correct::correct_trial(trial, model, &limits, settings, Variant::Ik, control)
}

fn run(trial: &Trial, model: &Model) -> IkSolution {
    solve_trial(
        trial,
        model,
        &SolverOptions::default(),
        &RunControl::default(),
    )
    .unwrap()
    .expect("base present")
}

/// RMS over frames of the wrapped error of each coordinate, degrees.
fn rms_errors(run: &IkRun, truth: &[Vec<f64>]) -> Vec<f64> {
    (0..run.coordinates.len())
        .map(|c| {
            let sq: f64 = truth
                .iter()
                .enumerate()
                .map(|(i, t)| wrap180(run.frame(i)[c] - t[c]).powi(2))
                .sum();
            (sq / truth.len() as f64).sqrt()
        })
        .collect()
}

#[test]
fn recovers_reduced_dof_coordinates_from_exact_orientations() {
    let model = Model::infant13();
    let sim = simulate(&model, &IkSimConfig::clean(60.0));
    let sol = run(&sim.trial, &model);
    // 3 (back) + 3 (neck) + 2x3 (shoulders) + 2x2 (elbows) + 2x3 (hips)
    // + 2x1 (knees) + 2x3 (ankles).
    assert_eq!(sol.run.coordinates.len(), 30);
    let rms = rms_errors(&sol.run, &sim.coordinates_deg);
    let worst = rms.iter().copied().fold(0.0, f64::max);
    // The acceptance bar is 1 deg RMS; exact input and a 1e-8 rad step tolerance
    // leave only round-off, so hold the solver to far less.
    assert!(worst < 1e-4, "worst coordinate RMS error {worst} deg");
    eprintln!("noise-free IK: worst coordinate RMS error {worst:.2e} deg");
    let s = sol.run.summary();
    assert!(s.max_rms_error_deg < 1e-4, "{s:?}");
    eprintln!(
        "iterations per frame: mean {:.2}, max {}",
        s.mean_iterations, s.max_iterations
    );
    for (b, t) in sol.run.base.iter().zip(&sim.base) {
        assert!(angle_between_deg(b, t) < 1e-4);
    }
}

#[test]
fn noisy_orientations_give_small_coordinate_errors() {
    let model = Model::infant13();
    let cfg = IkSimConfig {
        noise_deg: 1.0,
        seed: 3,
        ..IkSimConfig::clean(60.0)
    };
    let sim = simulate(&model, &cfg);
    let sol = run(&sim.trial, &model);
    let rms = rms_errors(&sol.run, &sim.coordinates_deg);
    let worst = rms.iter().copied().fold(0.0, f64::max);
    let mean = rms.iter().sum::<f64>() / rms.len() as f64;
    eprintln!("1 deg noise: coordinate RMS error mean {mean:.3}, worst {worst:.3} deg");
    // Each IMU's noise is 1 deg RMS; a coordinate sees about the noise of the
    // two segments around it, partly averaged out by the other IMUs.
    assert!(worst < 1.5, "{rms:?}");
    // The fit is no worse than the noise itself.
    let s = sol.run.summary();
    assert!(s.mean_rms_error_deg < 1.0, "{s:?}");
}

#[test]
fn misaligned_sensors_never_push_coordinates_past_hard_limits() {
    let model = Model::infant13();
    let cfg = IkSimConfig {
        reach: 1.0,
        misalignment_deg: [10.0, 30.0],
        seed: 11,
        ..IkSimConfig::clean(60.0)
    };
    let sim = simulate(&model, &cfg);
    let sol = run(&sim.trial, &model);
    let mut limited = 0;
    for (c, co) in sol.run.coordinates.iter().enumerate() {
        if !co.limited() {
            continue;
        }
        limited += 1;
        let (lo, hi) = (co.lower.to_degrees(), co.upper.to_degrees());
        for v in sol.run.series(c) {
            assert!(
                v >= lo && v <= hi,
                "{} = {v} outside [{lo}, {hi}]",
                co.label()
            );
        }
    }
    assert_eq!(limited, 6); // 2 knees, 2 x 2 elbow axes
    let s = sol.run.summary();
    assert!(!s.pct_at_limit.is_empty(), "{s:?}");
    eprintln!("misaligned: frames at a limit {:?}", s.pct_at_limit);
    // The same trial without hard limits leaves them: the limits do the work.
    let mut free = model.clone();
    for j in &mut free.joints {
        j.hard_limits_deg = HardLimits::default();
    }
    let unlimited = run(&sim.trial, &free);
    let outside = sol.run.coordinates.iter().enumerate().any(|(c, co)| {
        co.limited()
            && unlimited
                .run
                .series(c)
                .iter()
                .any(|v| v.to_radians() < co.lower - 1e-6 || v.to_radians() > co.upper + 1e-6)
    });
    assert!(outside, "the unconstrained fit never left the limits");
}

#[test]
fn ik_variant_trial_shows_the_coordinates_as_joint_angles() {
    let model = Model::infant13();
    let sim = simulate(&model, &IkSimConfig::clean(5.0));
    let c = correct_trial(
        &sim.trial,
        &model,
        &Settings::default(),
        &RunControl::default(),
    )
    .unwrap();
    assert_eq!(c.variant, Variant::Ik);
    let ik = c.ik.as_ref().unwrap();
    let knee = model.joint("l_knee").unwrap();
    let angles = joint_angles(&c.corrected, knee).unwrap();
    let k = ik
        .coordinates
        .iter()
        .position(|co| co.label() == "l_knee_y")
        .unwrap();
    let mut beyond_90 = 0;
    for (i, a) in angles.iter().enumerate() {
        let y = ik.frame(i)[k];
        let hinge = crate::rotation::quat_axis_angle_deg([0.0, 1.0, 0.0], y);
        assert!(angle_between_deg(&quat_from_euler_zyx_deg(*a), &hinge) < 1e-7);
        // Past 90 deg of flexion too: the knee's limit box (Y 0..130) reads
        // the triplet with the flexion on Y.
        assert!(a[0].abs() < 1e-9 && a[2].abs() < 1e-9, "{a:?}");
        assert!((a[1] - y).abs() < 1e-9, "{a:?} vs {y}");
        beyond_90 += usize::from(y > 90.0);
    }
    assert!(beyond_90 > 0, "the simulated knee flexes beyond 90 deg");
    let elbow = model.joint("r_elbow").unwrap();
    let a = joint_angles(&c.corrected, elbow).unwrap();
    assert!(a.iter().all(|a| a[1].abs() < 1e-9));
    // Orientations equal the truth (exact input).
    for s in &c.corrected.imus {
        let t = &sim.segments.imu(&s.name).unwrap().orientation;
        assert!(s
            .orientation
            .iter()
            .zip(t)
            .all(|(a, b)| angle_between_deg(a, b) < 1e-4));
    }
}

#[test]
fn missing_imus_skip_their_joints_and_the_joints_below() {
    let model = Model::infant13();
    let mut trial = simulate(&model, &IkSimConfig::clean(2.0)).trial;
    trial.imus.retain(|s| s.name != "l_thigh");
    let c = correct_trial(&trial, &model, &Settings::default(), &RunControl::default()).unwrap();
    let skipped: Vec<&str> = c.skipped.iter().map(|s| s.joint.as_str()).collect();
    assert_eq!(skipped, ["l_hip", "l_knee", "l_ankle"]);
    assert!(c.skipped[1].reason.contains("proximal segment 'l_thigh'"));
    // Their IMUs are left as measured.
    assert!(c.corrected.imu("l_calf") == trial.imu("l_calf"));
    trial.imus.retain(|s| s.name != "base");
    let c = correct_trial(&trial, &model, &Settings::default(), &RunControl::default()).unwrap();
    assert!(c.ik.is_none());
    assert_eq!(c.skipped.len(), model.joints.len());
    assert!(c.corrected == trial);
}

#[test]
fn cancel_stops_and_progress_reaches_the_end() {
    let model = Model::infant13();
    let trial = simulate(&model, &IkSimConfig::clean(30.0)).trial;
    let cancel = std::sync::atomic::AtomicBool::new(true);
    let control = RunControl {
        cancel: Some(&cancel),
        progress: None,
    };
    assert!(matches!(
        correct_trial(&trial, &model, &Settings::default(), &control),
        Err(Cancelled)
    ));
    let last = std::sync::Mutex::new((0, 0));
    let report = |d: usize, t: usize| *last.lock().unwrap() = (d, t);
    let control = RunControl {
        cancel: None,
        progress: Some(&report),
    };
    correct_trial(&trial, &model, &Settings::default(), &control).unwrap();
    assert_eq!(*last.lock().unwrap(), (1500, 1500));
}

#[test]
fn coordinates_file_has_one_row_per_frame() {
    let model = Model::infant13();
    let sim = simulate(&model, &IkSimConfig::clean(1.0));
    let sol = run(&sim.trial, &model);
    let text = coordinates_csv(&sol.run);
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        header[..6],
        ["time", "base_qw", "base_qx", "base_qy", "base_qz", "back_x"]
    );
    assert!(header.contains(&"l_knee_y") && !header.contains(&"l_knee_x"));
    assert_eq!(header.last(), Some(&"iterations"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 50);
    let k = header.iter().position(|h| *h == "l_knee_y").unwrap();
    assert_eq!(rows[7][k], sol.run.frame(7)[k - 5]);
    assert_eq!(
        coordinates_path(Path::new("d/corrected/walk.ik.csv.gz")),
        Path::new("d/corrected/walk.ik.coordinates.csv")
    );
    assert_eq!(
        coordinates_path(Path::new("w.ik.sto")),
        Path::new("w.ik.coordinates.csv")
    );
    assert_eq!(sol.run.coordinates[k - 5].axis, Axis::Y);
}

/// The standing models' coordinates are their joints' table-convention angles
/// (Z-Y-X in the table's axes, docs/method.md section 2.5): noise-free IK
/// recovers them, and the joint angles of the solved trial are the
/// coordinates.
#[test]
fn standing_models_coordinates_are_their_table_angles() {
    for name in ["full_body16", "opensim"] {
        let model = Model::builtin(name).unwrap();
        let sim = simulate(&model, &IkSimConfig::clean(10.0));
        let sol = run(&sim.trial, &model);
        let rms = rms_errors(&sol.run, &sim.coordinates_deg);
        let worst = rms.iter().copied().fold(0.0, f64::max);
        assert!(
            worst < 1e-4,
            "{name}: worst coordinate RMS error {worst} deg"
        );
        let series = |imu: &str| {
            &sol.segments
                .iter()
                .find(|s| s.name == imu)
                .unwrap()
                .orientation
        };
        for (c, co) in sol.run.coordinates.iter().enumerate() {
            let joint = model.joint(&co.joint).unwrap();
            let (p, d) = (series(&joint.proximal), series(&joint.distal));
            for i in (0..p.len()).step_by(37) {
                let a = joint.angles(&p[i], &d[i])[co.axis.index()];
                let want = sol.run.frame(i)[c];
                if co.axis == Axis::Y && want.abs() > 89.0 {
                    // The middle angle reads at most 90 (opensim's hinge
                    // knee flexes further): the Z-Y-X convention's limit.
                    continue;
                }
                assert!(
                    wrap180(a - want).abs() < 1e-6,
                    "{name} {}: frame {i}: {a} vs {want}",
                    co.label()
                );
            }
        }
    }
}
