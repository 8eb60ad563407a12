//! Every variant writes what it reports: for every built-in model and every
//! variant, the corrected trial is written to disk, read back, and its joint
//! angles and section-6 figures (excursions, shifts, errors against the truth)
//! equal those of the report to 1e-6 deg. The trials are simulated for each
//! model (random misalignment, noise, a heading drift on one IMU, gyros), in
//! every output format the variant can be written in.

use acm_workbench::acm::{RunControl, Variant};
use acm_workbench::correct::correct_trial;
use acm_workbench::limits::{LimitTable, Settings};
use acm_workbench::metrics::{joint_angles, trial_figures};
use acm_workbench::model::{Model, BUILTIN_MODELS};
use acm_workbench::report::ReportInput;
use acm_workbench::simulate::{simulate_with, HeadingDrift, SimConfig, SimKind};
use acm_workbench::trial::{read_trial, write_trial, TrialFormat};

/// Degrees (and percent, for the share of samples outside the limits).
const TOLERANCE: f64 = 1e-6;

/// Every number of two JSON values, pairwise; their shapes must agree.
fn assert_close(a: &serde_json::Value, b: &serde_json::Value, tol: f64, path: &str) {
    use serde_json::Value;
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            assert!((x - y).abs() <= tol, "{path}: {x} vs {y}");
        }
        (Value::Array(x), Value::Array(y)) => {
            assert_eq!(x.len(), y.len(), "{path}");
            for (k, (x, y)) in x.iter().zip(y).enumerate() {
                assert_close(x, y, tol, &format!("{path}[{k}]"));
            }
        }
        (Value::Object(x), Value::Object(y)) => {
            assert_eq!(
                x.keys().collect::<Vec<_>>(),
                y.keys().collect::<Vec<_>>(),
                "{path}"
            );
            for (k, v) in x {
                assert_close(v, &y[k], tol, &format!("{path}.{k}"));
            }
        }
        _ => assert_eq!(a, b, "{path}"),
    }
}

fn config(model: &Model) -> SimConfig {
    let mut c = SimConfig::full_body(7).with_gyro(0.2);
    c.kind = SimKind::FullBody;
    c.duration_s = 45.0;
    c.rate_hz = 25.0;
    // One IMU below the base drifts in heading (the heading variants fit it).
    c.drifts = vec![HeadingDrift {
        imu: model.joints[0].distal.clone(),
        start_s: 5.0,
        rate_deg_s: 0.3,
    }];
    c
}

#[test]
fn every_variant_of_every_model_writes_what_it_reports() {
    let dir = tempfile::tempdir().unwrap();
    let limits = LimitTable::default_table();
    let settings = Settings {
        window_s: 20.0,
        hop_s: 10.0,
        ..Settings::default()
    };
    for (name, _) in BUILTIN_MODELS {
        let model = Model::builtin(name).unwrap();
        let sim = simulate_with(&config(&model), &model).unwrap();
        let (trial, truth) = (&sim.trial, &sim.truth.segments);
        let input = ReportInput {
            trial,
            model: &model,
            limits: &limits,
            limits_source: "test",
            settings: &settings,
            truth: Some(truth),
        };
        for variant in Variant::ALL {
            let what = format!("{name} {variant}");
            let c = correct_trial(
                trial,
                &model,
                &limits,
                &settings,
                variant,
                &RunControl::default(),
            )
            .unwrap();
            assert!(
                c.skipped.is_empty(),
                "{what}: nothing may be skipped: {:?}",
                c.skipped
            );
            let report = input.report(std::slice::from_ref(&c));
            let reported = serde_json::to_value(&report.variants[0].joints).unwrap();
            assert_eq!(
                report.variants[0].joints.len(),
                model.joints.len(),
                "{what}"
            );
            for (format, ext) in [
                (TrialFormat::QuatCsv, "csv"),
                (TrialFormat::EulerCsv, "csv"),
                (TrialFormat::Sto, "sto.gz"),
            ] {
                let what = format!("{what} as {format:?}");
                let path = dir.path().join(format!("{name}.{variant}.{ext}"));
                write_trial(&c.corrected, &path, format).unwrap();
                let back = read_trial(&path, &model).unwrap();
                assert_eq!(back.time_s, trial.time_s, "{what}");
                for joint in &model.joints {
                    let want = joint_angles(&c.corrected, joint).unwrap();
                    let got = joint_angles(&back, joint).unwrap();
                    let worst = want
                        .iter()
                        .zip(&got)
                        .flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k]).abs()))
                        .fold(0.0, f64::max);
                    assert!(worst <= TOLERANCE, "{what} {}: {worst} deg", joint.name);
                }
                let written = trial_figures(&back, Some(trial), Some(truth), &model, &limits);
                assert_close(
                    &reported,
                    &serde_json::to_value(&written).unwrap(),
                    TOLERANCE,
                    &what,
                );
                for joint in &model.joints {
                    let want = joint_angles(&c.corrected, joint).unwrap();
                    let got = joint_angles(&back, joint).unwrap();
                    let worst = want
                        .iter()
                        .zip(&got)
                        .flat_map(|(a, b)| (0..3).map(move |k| (a[k] - b[k]).abs()))
                        .fold(0.0, f64::max);
                    assert!(worst <= TOLERANCE, "{what} {}: {worst} deg", joint.name);
                }
            }
        }
    }
}

/// What the user gets: `acmw correct --variant rivest` after a pose
/// calibration writes a trial whose `acmw report` figures (read as it is)
/// are the ones `acmw report --variant rivest` gave for the input.
#[test]
fn rivest_written_by_the_command_line_reports_as_it_was_reported() {
    let dir = tempfile::tempdir().unwrap();
    let model = Model::builtin("opensense_lower").unwrap();
    let sim = simulate_with(&config(&model), &model).unwrap();
    let input = dir.path().join("walk.csv");
    write_trial(&sim.trial, &input, TrialFormat::QuatCsv).unwrap();
    let run = |args: &[&str]| {
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_acmw"))
            .current_dir(dir.path())
            .args(args)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap_or_default()
    };
    let common = [
        "--model",
        "opensense_lower",
        "--window",
        "20",
        "--hop",
        "10",
    ];
    let mut args = vec!["report", "walk.csv", "--json", "-q", "--variant", "rivest"];
    args.extend(common);
    args.extend(["--pose-calibration", "1.5"]);
    let reported = run(&args);
    let mut args = vec![
        "correct",
        "walk.csv",
        "-q",
        "--variant",
        "rivest",
        "-o",
        "out.csv",
    ];
    args.extend(common);
    args.extend(["--pose-calibration", "1.5"]);
    run(&args);
    let mut args = vec!["report", "out.csv", "--json", "-q", "--variant", "none"];
    args.extend(common);
    let written = run(&args);
    let excursions = |v: &serde_json::Value| -> serde_json::Value {
        v.as_array()
            .unwrap()
            .iter()
            .map(|j| j["excursion"].clone())
            .collect()
    };
    let want = excursions(&reported["variants"][0]["joints"]);
    assert_eq!(want.as_array().unwrap().len(), model.joints.len());
    assert_close(
        &want,
        &excursions(&written["uncorrected"]),
        TOLERANCE,
        "rivest",
    );
}
