//! The `acmw` command line: correct, reproduce from a sidecar, report, errors.

mod common;

use common::acmw;
use std::path::Path;
use std::process::Command;

fn simulated(dir: &Path) {
    let out = acmw(
        dir,
        &[
            "simulate",
            "preset",
            "full_body_clean",
            "--duration",
            "70",
            "-o",
            "t.csv",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn correct_then_reproduce_from_the_sidecar() {
    let dir = tempfile::tempdir().unwrap();
    simulated(dir.path());
    let out = acmw(
        dir.path(),
        &["correct", "t.csv", "--variant", "drift", "--quiet"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let first = dir.path().join("corrected/t.drift.csv");
    let sidecar = dir.path().join("corrected/t.drift.csv.acmw.json");
    assert!(first.exists() && sidecar.exists());
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&sidecar).unwrap()).unwrap();
    assert_eq!(json["variant"], "drift");
    assert_eq!(json["joints"].as_array().unwrap().len(), 12);
    assert_eq!(json["joints"][0]["windows"].as_array().unwrap().len(), 2);
    assert_eq!(json["limits"]["sha256"].as_str().unwrap().len(), 64);
    let out = acmw(
        dir.path(),
        &[
            "correct",
            "t.csv",
            "--from-sidecar",
            "corrected/t.drift.csv.acmw.json",
            "--threads",
            "1",
            "-o",
            "again.csv",
            "--quiet",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        std::fs::read(&first).unwrap(),
        std::fs::read(dir.path().join("again.csv")).unwrap()
    );
}

#[test]
fn report_json_and_truth() {
    let dir = tempfile::tempdir().unwrap();
    simulated(dir.path());
    let out = acmw(
        dir.path(),
        &["report", "t.csv", "--variant", "basic", "--json", "--quiet"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(r["truth"], true);
    assert_eq!(r["variants"][0]["variant"], "basic");
    let before = r["uncorrected"][0]["excursion"]["joint_mean_excursion_deg"]
        .as_f64()
        .unwrap();
    let after = r["variants"][0]["joints"][0]["excursion"]["joint_mean_excursion_deg"]
        .as_f64()
        .unwrap();
    assert!(after <= before);
    assert!(r["variants"][0]["joints"][0]["truth"]["rms_error_deg"].is_array());
    let text = acmw(dir.path(), &["report", "t.csv", "--variant", "basic"]);
    let text = String::from_utf8(text.stdout).unwrap();
    assert!(text.contains("RMS error against truth"), "{text}");
    assert!(text.contains("l_knee"));
}

#[test]
fn malformed_input_names_file_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("bad.csv"),
        "time,l_calf_qw,l_calf_qx,l_calf_qy,l_calf_qz\n0,1,0,0,0\n0.02,1,0,x,0\n",
    )
    .unwrap();
    let out = acmw(dir.path(), &["correct", "bad.csv"]);
    assert_eq!(out.status.code(), Some(3));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.csv:3:4"), "{err}");
    std::fs::create_dir(dir.path().join("joint_limits")).unwrap();
    std::fs::write(
        dir.path().join("joint_limits/settings.toml"),
        "table = \"t.csv\"\nlambda1 = 0.05\nwindow_s = 60.0\nhop_s = 30.0\n",
    )
    .unwrap();
    std::fs::write(
        dir.path().join("joint_limits/t.csv"),
        "joint,axis,movement,lower_deg,upper_deg,centroid_deg,lambda2\nknee,Y,flexion,10,5,,0\n",
    )
    .unwrap();
    simulated(dir.path());
    let out = acmw(dir.path(), &["report", "t.csv"]);
    assert_eq!(out.status.code(), Some(3));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("t.csv:2:5") && err.contains("upper_deg > lower_deg"),
        "{err}"
    );
}

#[test]
fn output_into_a_closed_pipe_is_not_a_panic() {
    // `acmw report T --json | head -1`: the reader goes away before acmw writes.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut child = Command::new(env!("CARGO_BIN_EXE_acmw"))
        .current_dir(root)
        .args([
            "report",
            "sample_trials/knee_calf_z15.csv.gz",
            "--variant",
            "basic",
            "--json",
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(out.status.code(), Some(0), "{err}");
}

#[test]
fn render_reads_the_limits_folder_it_is_given() {
    // A lab keeps its tables elsewhere: `--limits-dir` names the folder; the
    // default is ./joint_limits, else the built-in tables.
    let dir = tempfile::tempdir().unwrap();
    simulated(dir.path());
    let lab = dir.path().join("lab_limits");
    std::fs::create_dir(&lab).unwrap();
    std::fs::write(
        lab.join("settings.toml"),
        "table = \"ours.csv\"\nlambda1 = 0.07\nwindow_s = 40.0\nhop_s = 20.0\n",
    )
    .unwrap();
    let table = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("joint_limits/table_3_2.csv"),
    )
    .unwrap();
    std::fs::write(lab.join("ours.csv"), table).unwrap();
    let render = |extra: &[&str]| {
        let mut args = vec!["render", "limits", "--dir", ".", "--size", "120x40"];
        args.extend_from_slice(extra);
        let out = acmw(dir.path(), &args);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    let theirs = render(&["--limits-dir", "lab_limits"]);
    assert!(theirs.contains("ours.csv"), "{theirs}");
    assert!(theirs.contains("0.07") && theirs.contains("40"), "{theirs}");
    let default = render(&[]);
    assert!(!default.contains("ours.csv"), "{default}");
    // A folder that does not hold what it should is an error, not a silent fallback.
    std::fs::write(
        lab.join("settings.toml"),
        "table = \"missing.csv\"\nlambda1 = 0.07\nwindow_s = 40.0\nhop_s = 20.0\n",
    )
    .unwrap();
    let out = acmw(
        dir.path(),
        &[
            "render",
            "limits",
            "--dir",
            ".",
            "--limits-dir",
            "lab_limits",
        ],
    );
    assert_eq!(out.status.code(), Some(3), "malformed input");
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("settings.toml:1:1") && err.contains("missing.csv"),
        "{err}"
    );
}

#[test]
fn writing_gyros_to_sto_warns_that_they_are_dropped() {
    let dir = tempfile::tempdir().unwrap();
    let out = acmw(
        dir.path(),
        &[
            "simulate",
            "elbow",
            "--gyro",
            "--duration",
            "20",
            "-o",
            "e.csv",
        ],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let run = |format: &str| {
        let o = format!("out.{}", if format == "sto" { "sto" } else { "csv" });
        let out = acmw(
            dir.path(),
            &["correct", "e.csv", "--format", format, "-o", &o, "--quiet"],
        );
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    assert!(run("sto").contains("gyroscope readings are not written"));
    assert!(!run("quat-csv").contains("gyroscope"));
}

#[test]
fn render_reads_every_trial_with_the_model_it_is_given() {
    // A lab's own model: the trials are read with it, not with the built-in
    // model that knows most of their IMUs.
    let dir = tempfile::tempdir().unwrap();
    simulated(dir.path());
    let ours =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("models/infant13.toml"))
            .unwrap()
            .replace("name = \"infant13\"", "name = \"our_suit\"");
    std::fs::write(dir.path().join("our_suit.toml"), ours).unwrap();
    let render = |extra: &[&str]| {
        let mut args = vec!["render", "trials", "--dir", ".", "--size", "120x40"];
        args.extend_from_slice(extra);
        acmw(dir.path(), &args)
    };
    let out = render(&["--model", "our_suit.toml"]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && text.contains("model our_suit"),
        "{text}"
    );
    let text = String::from_utf8(render(&[]).stdout).unwrap();
    assert!(text.contains("model infant13"), "{text}");
    // A malformed model is bad input, located.
    std::fs::write(dir.path().join("bad.toml"), "name = \"x\"\nbase = 3\n").unwrap();
    let out = render(&["--model", "bad.toml"]);
    assert_eq!(out.status.code(), Some(3));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.toml:"), "{err}");
}
