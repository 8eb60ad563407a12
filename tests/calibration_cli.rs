//! `acmw calibrate`, `acmw simulate calibration`, and trials corrected with a
//! calibration applied first (`--calibration`), against simulated truth.

mod common;

use common::{acmw, ok};
use std::path::Path;

/// The calibrated IMUs of the default protocol.
const IMUS: [&str; 5] = [
    "upper_back",
    "l_upper_arm",
    "r_upper_arm",
    "l_forearm",
    "r_forearm",
];

#[test]
fn calibrate_prints_tables_and_writes_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&acmw(
        d,
        &[
            "simulate",
            "calibration",
            "--seed",
            "4",
            "-o",
            "c.calib.csv.gz",
        ],
    ));
    assert!(d.join("c.calib.truth.json").exists());
    let text = ok(&acmw(d, &["calibrate", "c.calib.csv.gz"]));
    assert!(text.contains("Table 1"), "{text}");
    assert!(text.contains("Figure 5"), "{text}");
    assert!(text.contains("mean LM iterations"), "{text}");
    // Every IMU's LM error against the simulation's truth is under 2 deg.
    let rows: Vec<&str> = text
        .lines()
        .skip_while(|l| !l.starts_with("Rotation sensor"))
        .skip(2)
        .take(5)
        .collect();
    for (row, imu) in rows.iter().zip(IMUS) {
        let f: Vec<&str> = row.split_whitespace().collect();
        assert_eq!(f[0], imu, "{row}");
        let iterations: usize = f[1].parse().unwrap();
        assert!((1..50).contains(&iterations), "{row}");
        let lm_err: f64 = f[f.len() - 2].parse().unwrap();
        assert!(lm_err < 2.0, "{row}");
    }
    let cal = std::fs::read_to_string(d.join("c.calibration.toml")).unwrap();
    assert!(cal.contains("[[segment]]") && cal.contains("iterations"));
    // JSON output carries the same calibration.
    let json: serde_json::Value =
        serde_json::from_str(&ok(&acmw(d, &["calibrate", "c.calib.csv.gz", "--json"]))).unwrap();
    assert_eq!(json["segment"].as_array().unwrap().len(), 5);
    assert_eq!(json["protocol"], "ricci2014");
}

#[test]
fn bad_input_names_file_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("r.calib.csv"),
        "time,label,a_ax,a_ay,a_az,a_gx,a_gy,a_gz\n0,supine,0,0,9.8,0,0,0\n0.01,supine,0,oops,9.8,0,0,0\n",
    )
    .unwrap();
    let out = acmw(d, &["calibrate", "r.calib.csv"]);
    assert_eq!(out.status.code(), Some(3));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("r.calib.csv:3:4:"), "{err}");
    std::fs::write(d.join("p.toml"), "name = \"x\"\nsegments = [\"a\"\n").unwrap();
    let out = acmw(d, &["calibrate", "r.calib.csv", "--protocol", "p.toml"]);
    assert_eq!(out.status.code(), Some(3));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("p.toml:2:"), "{err}");
}

/// Rotation vector (degrees) of a `[w, x, y, z]` quaternion.
fn rotvec_deg(q: &serde_json::Value) -> [f64; 3] {
    let q: Vec<f64> = q
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    let (w, v) = (q[0], [q[1], q[2], q[3]]);
    let s = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    let angle = 2.0 * s.atan2(w);
    if s < 1e-12 {
        return [0.0; 3];
    }
    v.map(|c| c / s * angle.to_degrees())
}

#[test]
fn trial_corrected_with_the_calibration_applied_first() {
    // A full-body trial whose five calibrated IMUs sit on their segments
    // exactly as the calibration recording's truth says (IMU = segment * M with
    // M = R_SF^FF); applying the calibration must take them back to within the
    // calibration's error (under 2 deg).
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    ok(&acmw(
        d,
        &[
            "simulate",
            "calibration",
            "--seed",
            "1",
            "-o",
            "c.calib.csv",
        ],
    ));
    ok(&acmw(d, &["calibrate", "c.calib.csv", "--quiet"]));
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("c.calib.truth.json")).unwrap())
            .unwrap();
    let mut args: Vec<String> = ["simulate", "full-body", "--duration", "40", "-o", "t.csv"]
        .map(String::from)
        .to_vec();
    for imu in IMUS {
        let r = rotvec_deg(&truth["rotations"][imu]);
        args.push(format!("--misalign={imu}:{}:{}:{}", r[0], r[1], r[2]));
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    ok(&acmw(d, &args));
    let report = |extra: &[&str]| -> serde_json::Value {
        let mut a = vec!["report", "t.csv", "--variant", "basic", "--json", "--quiet"];
        a.extend_from_slice(extra);
        serde_json::from_str(&ok(&acmw(d, &a))).unwrap()
    };
    let raw = report(&[]);
    let cal = report(&["--calibration", "c.calibration.toml"]);
    // Distal IMU of these joints: the calibrated ones.
    for joint in ["back", "l_shoulder", "r_shoulder", "l_elbow", "r_elbow"] {
        let err = |r: &serde_json::Value| {
            r["uncorrected"]
                .as_array()
                .unwrap()
                .iter()
                .find(|j| j["joint"] == joint)
                .unwrap()["truth"]["mean_correction_error_deg"]
                .as_f64()
                .unwrap()
        };
        let (before, after) = (err(&raw), err(&cal));
        eprintln!(
            "{joint}: distal IMU off its segment by {before:.1} deg raw, {after:.2} deg calibrated"
        );
        assert!(after < 2.0, "{joint}: {after}");
        assert!(before > 5.0 * after, "{joint}: {before} vs {after}");
    }
    // `correct --calibration` records it in the sidecar, and the sidecar
    // reproduces the output byte for byte.
    ok(&acmw(
        d,
        &[
            "correct",
            "t.csv",
            "--variant",
            "basic",
            "--calibration",
            "c.calibration.toml",
            "--quiet",
        ],
    ));
    let sc_path = d.join("corrected/t.basic.csv.acmw.json");
    let sc: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&sc_path).unwrap()).unwrap();
    assert_eq!(sc["calibration"]["file"], "c.calibration.toml");
    assert_eq!(sc["calibration"]["imus"].as_array().unwrap().len(), 5);
    assert_eq!(sc["calibration"]["sha256"].as_str().unwrap().len(), 64);
    let first = std::fs::read(d.join("corrected/t.basic.csv")).unwrap();
    ok(&acmw(
        d,
        &[
            "correct",
            "t.csv",
            "--from-sidecar",
            "corrected/t.basic.csv.acmw.json",
            "-o",
            "again.csv",
            "--quiet",
        ],
    ));
    assert_eq!(std::fs::read(d.join("again.csv")).unwrap(), first);
}

#[test]
fn sample_recording_matches_its_truth_and_calibrates() {
    use acm_workbench::calibration::simulate::{load_truth_beside, simulate, CalibSimConfig};
    use acm_workbench::calibration::{calibrate, Protocol, Recording};
    use acm_workbench::rotation::angle_between_deg;
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("sample_trials/child_arms.calib.csv.gz");
    let rec = Recording::read(&path).unwrap();
    let truth = load_truth_beside(&path).unwrap().unwrap();
    // The file is the simulator's output (from the truth's configuration)
    // rounded to 3 decimals.
    let config: CalibSimConfig = serde_json::from_str(
        &std::fs::read_to_string(path.with_file_name("child_arms.calib.truth.json")).unwrap(),
    )
    .unwrap();
    let p = Protocol::default_protocol();
    let again = simulate(&p, &config).unwrap().recording;
    assert_eq!(again.len(), rec.len());
    for (a, b) in rec.imus.iter().zip(&again.imus) {
        for (x, y) in a.gyro.iter().zip(&b.gyro) {
            assert!((0..3).all(|k| (x[k] - y[k]).abs() <= 5e-4 + 1e-9));
        }
    }
    let cal = calibrate(&rec, &p);
    assert_eq!(cal.segments.len(), 5);
    for s in &cal.segments {
        let err = angle_between_deg(&s.rotation(), &truth[&s.imu]);
        assert!(err < 2.0, "{}: {err}", s.imu);
    }
}
