//! `acmw report --reference`: a simulated trial's true joint angles written as
//! an optical reference (CSV, OpenSim `.mot` through the model's coordinate
//! names and signs, C3D with Plug-in Gait angle points) score the same RMS as
//! `report` against the truth itself, and a lag imposed on the reference's
//! clock is found to one sample.

mod common;

use acm_workbench::metrics::joint_angles;
use acm_workbench::model::Model;
use acm_workbench::reference::{write_c3d, write_csv, write_mot};
use acm_workbench::simulate::{simulate_with, SimConfig};
use acm_workbench::trial::{write_trial, TrialFormat};
use common::{acmw, ok};
use std::collections::BTreeMap;
use std::path::Path;

/// Truth RMS and reference RMS agree to this, degrees (C3D stores 32-bit
/// floats: 7.6e-6 deg steps at 100 deg, whose effect on an RMS averages out).
const RMS_TOLERANCE: f64 = 1e-6;

/// True angles per joint of the simulated trial written beside it, plus the
/// trial and its truth files.
fn setup(dir: &Path) -> (Model, BTreeMap<String, Vec<[f64; 3]>>, Vec<f64>) {
    let model = Model::builtin("opensense_lower").unwrap();
    let mut config = SimConfig::full_body(3);
    config.duration_s = 30.0;
    config.rate_hz = 25.0;
    let sim = simulate_with(&config, &model).unwrap();
    let trial_path = dir.join("walk.csv");
    write_trial(&sim.trial, &trial_path, TrialFormat::QuatCsv).unwrap();
    sim.truth.save_beside(&trial_path).unwrap();
    let angles = model
        .joints
        .iter()
        .map(|j| {
            (
                j.name.clone(),
                joint_angles(&sim.truth.segments, j).unwrap(),
            )
        })
        .collect();
    (model, angles, sim.trial.time_s.clone())
}

/// The reference value of `[-]joint.axis` (undoing the mapping's sign).
fn value(angles: &BTreeMap<String, Vec<[f64; 3]>>, target: &str, i: usize) -> f64 {
    let (sign, t) = match target.strip_prefix('-') {
        Some(t) => (-1.0, t),
        None => (1.0, target),
    };
    let (joint, axis) = t.split_once('.').unwrap();
    let k = ["x", "y", "z"].iter().position(|a| *a == axis).unwrap();
    sign * angles[joint][i][k]
}

fn write_references(
    dir: &Path,
    model: &Model,
    angles: &BTreeMap<String, Vec<[f64; 3]>>,
    time: &[f64],
    shift_s: f64,
) {
    let n = time.len();
    let ref_time: Vec<f64> = time.iter().map(|t| t + shift_s).collect();
    // CSV: every joint axis, in the tool's convention.
    let mut columns = Vec::new();
    for (joint, a) in angles {
        for (k, axis) in ["x", "y", "z"].iter().enumerate() {
            columns.push((format!("{joint}_{axis}"), a.iter().map(|v| v[k]).collect()));
        }
    }
    write_csv(&dir.join("ref.csv"), &ref_time, &columns).unwrap();
    // .mot: the OpenSim coordinates the model maps, plus one it does not.
    let mut mot: Vec<(String, Vec<f64>)> = model
        .reference_coordinates
        .iter()
        .filter(|(k, _)| !k.contains('.'))
        .map(|(k, t)| (k.clone(), (0..n).map(|i| value(angles, t, i)).collect()))
        .collect();
    mot.push(("pelvis_tx".into(), vec![0.5; n]));
    write_mot(&dir.join("ref.mot"), &ref_time, &mot).unwrap();
    // C3D: Plug-in Gait points, unmapped components zero; the file starts at 0.
    let mut points: BTreeMap<String, [Vec<f64>; 3]> = BTreeMap::new();
    for (k, t) in model
        .reference_coordinates
        .iter()
        .filter(|(k, _)| k.contains('.'))
    {
        let (label, c) = k.split_once('.').unwrap();
        let c = ["x", "y", "z"].iter().position(|a| *a == c).unwrap();
        let p = points
            .entry(label.to_string())
            .or_insert_with(|| std::array::from_fn(|_| vec![0.0; n]));
        p[c] = (0..n).map(|i| value(angles, t, i)).collect();
    }
    // A C3D's time counts from its first frame: a later start is frames dropped.
    let skip = (shift_s * 25.0).round() as usize;
    let points: Vec<(String, [Vec<f64>; 3])> = points
        .into_iter()
        .map(|(l, p)| {
            let p = p.map(|v| {
                let mut v = v;
                // The reference clock started `shift_s` earlier: prepend frames.
                let mut pre = vec![v[0]; skip];
                pre.append(&mut v);
                pre
            });
            (l, p)
        })
        .collect();
    write_c3d(&dir.join("ref.c3d"), 25.0, &points).unwrap();
}

fn report_json(dir: &Path, args: &[&str]) -> serde_json::Value {
    let mut all = vec![
        "report",
        "walk.csv",
        "--json",
        "-q",
        "--variant",
        "basic",
        "--window",
        "20",
        "--hop",
        "10",
    ];
    all.extend(args);
    serde_json::from_str(&ok(&acmw(dir, &all))).unwrap()
}

#[test]
fn reference_files_score_as_the_truth_and_find_a_lag() {
    let dir = tempfile::tempdir().unwrap();
    let (model, angles, time) = setup(dir.path());
    write_references(dir.path(), &model, &angles, &time, 0.0);
    let plain = report_json(dir.path(), &[]);
    let truth_rms = |series: &serde_json::Value, joint: &str, k: usize| -> f64 {
        series
            .as_array()
            .unwrap()
            .iter()
            .find(|j| j["joint"] == joint)
            .unwrap()["truth"]["rms_error_deg"][k]
            .as_f64()
            .unwrap()
    };
    for file in ["ref.csv", "ref.mot", "ref.c3d"] {
        let r = report_json(dir.path(), &["--reference", file]);
        let reference = &r["reference"];
        assert_eq!(reference["lag_s"].as_f64().unwrap(), 0.0, "{file}");
        let expected_channels = match file {
            "ref.csv" => model.joints.len() * 3,
            _ => model
                .reference_coordinates
                .keys()
                .filter(|k| k.contains('.') == (file == "ref.c3d"))
                .count(),
        };
        let series = reference["variants"].as_array().unwrap();
        assert_eq!(series.len(), 2, "{file}: uncorrected and basic");
        for (s, figures) in series
            .iter()
            .zip([&plain["uncorrected"], &plain["variants"][0]["joints"]])
        {
            let axes = s["axes"].as_array().unwrap();
            assert_eq!(axes.len(), expected_channels, "{file}");
            for a in axes {
                let joint = a["joint"].as_str().unwrap();
                let k = ["x", "y", "z"]
                    .iter()
                    .position(|x| *x == a["axis"])
                    .unwrap();
                let want = truth_rms(figures, joint, k);
                let got = a["rms_deg"].as_f64().unwrap();
                assert!(
                    (got - want).abs() <= RMS_TOLERANCE,
                    "{file} {} {joint} {k}: {got} vs truth {want}",
                    s["variant"]
                );
                assert_eq!(
                    a["samples"].as_u64().unwrap() as usize,
                    time.len(),
                    "{file}"
                );
            }
        }
        if file == "ref.mot" {
            assert_eq!(reference["ignored"], serde_json::json!(["pelvis_tx"]));
        }
    }
    // The reference's clock runs 0.37 s ahead: found to one sample (0.04 s).
    let shifted = tempfile::tempdir().unwrap();
    let (model, angles, time) = setup(shifted.path());
    write_references(shifted.path(), &model, &angles, &time, 0.37);
    for file in ["ref.csv", "ref.mot", "ref.c3d"] {
        let r = report_json(shifted.path(), &["--reference", file, "--max-lag", "1"]);
        let lag = r["reference"]["lag_s"].as_f64().unwrap();
        // C3D frames were prepended (0.36 s), the text files' times shifted.
        let want = if file == "ref.c3d" { 0.36 } else { 0.37 };
        assert!((lag - want).abs() <= 0.04 + 1e-9, "{file}: lag {lag}");
        // Scored over a span, the lag still holds.
        let r = report_json(
            shifted.path(),
            &["--reference", file, "--from", "5", "--to", "20"],
        );
        let l = r["reference"]["lag_s"].as_f64().unwrap();
        assert!(
            (l - want).abs() <= 0.04 + 1e-9,
            "{file}: lag {l} over 5..20 s"
        );
        assert_eq!(r["reference"]["from_s"].as_f64().unwrap(), 5.0);
    }
    // Bad input: located errors, exit code 3.
    std::fs::write(
        shifted.path().join("bad.csv"),
        "time,r_knee_y\n0,1\n0.04,x\n",
    )
    .unwrap();
    let out = acmw(
        shifted.path(),
        &[
            "report",
            "walk.csv",
            "-q",
            "--variant",
            "basic",
            "--reference",
            "bad.csv",
        ],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(err.contains("bad.csv:3:2"), "{err}");
    // Damaged C3Ds: too short, and a parameter section the parser trips on.
    let mut trips = vec![0u8; 4096];
    trips[0] = 2;
    trips[1] = 0x50;
    trips[512 + 3] = 0x54;
    for (name, bytes) in [("short.c3d", vec![0u8; 700]), ("trips.c3d", trips)] {
        std::fs::write(shifted.path().join(name), bytes).unwrap();
        let args = [
            "report",
            "walk.csv",
            "-q",
            "--variant",
            "basic",
            "--reference",
            name,
        ];
        let out = acmw(shifted.path(), &args);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(3), "{err}");
        assert!(
            err.contains("invalid C3D") && !err.contains("panicked"),
            "{err}"
        );
    }
}
