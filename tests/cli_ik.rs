//! `acmw correct/report --pose-calibration` and `--variant ik` end to end.

mod common;

use common::{acmw, ok};
use std::path::Path;

fn simulated(dir: &Path) {
    ok(&acmw(
        dir,
        &[
            "simulate",
            "preset",
            "full_body_clean",
            "--duration",
            "10",
            "-o",
            "t.csv",
        ],
    ));
}

#[test]
fn ik_with_pose_calibration_writes_coordinates_and_reproduces() {
    let dir = tempfile::tempdir().unwrap();
    simulated(dir.path());
    let stdout = ok(&acmw(
        dir.path(),
        &[
            "correct",
            "t.csv",
            "--variant",
            "ik",
            "--pose-calibration",
            "1..2",
            "--base-forward",
            "+x",
        ],
    ));
    assert!(
        stdout.contains("pose calibration at 1..2 s (51 samples)"),
        "{stdout}"
    );
    assert!(stdout.contains("ik, 30 coordinates"), "{stdout}");
    let coords = dir.path().join("corrected/t.ik.coordinates.csv");
    let text = std::fs::read_to_string(&coords).unwrap();
    assert_eq!(text.lines().count(), 501);
    assert!(text.starts_with("time,base_qw,base_qx,base_qy,base_qz,back_x,"));
    let sidecar = dir.path().join("corrected/t.ik.csv.acmw.json");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&sidecar).unwrap()).unwrap();
    assert_eq!(json["variant"], "ik");
    assert_eq!(json["pose_calibration"]["calibration"]["at"], "1..2");
    assert_eq!(
        json["pose_calibration"]["offsets"]
            .as_array()
            .unwrap()
            .len(),
        13
    );
    assert_eq!(json["ik"]["summary"]["frames"], 500);
    // The sidecar reproduces orientations and coordinates byte for byte.
    ok(&acmw(
        dir.path(),
        &[
            "correct",
            "t.csv",
            "--from-sidecar",
            "corrected/t.ik.csv.acmw.json",
            "-o",
            "again.csv",
            "--quiet",
        ],
    ));
    assert_eq!(
        std::fs::read(dir.path().join("corrected/t.ik.csv")).unwrap(),
        std::fs::read(dir.path().join("again.csv")).unwrap()
    );
    assert_eq!(
        text,
        std::fs::read_to_string(dir.path().join("again.coordinates.csv")).unwrap()
    );
}

#[test]
fn report_names_the_calibration_and_the_ik_figures() {
    let dir = tempfile::tempdir().unwrap();
    simulated(dir.path());
    let stdout = ok(&acmw(
        dir.path(),
        &[
            "report",
            "t.csv",
            "--variant",
            "basic",
            "--variant",
            "ik",
            "--pose-calibration",
            "0.5",
            "--quiet",
        ],
    ));
    assert!(
        stdout.contains("pose calibration at 0.5 s (1 samples)"),
        "{stdout}"
    );
    assert!(
        stdout.contains("Inverse kinematics (ik): 500 frames, 30 coordinates"),
        "{stdout}"
    );
}

#[test]
fn bad_pose_calibrations_are_usage_or_input_errors() {
    let dir = tempfile::tempdir().unwrap();
    simulated(dir.path());
    let out = acmw(
        dir.path(),
        &["correct", "t.csv", "--pose-calibration", "3..1"],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("start must be before"));
    let out = acmw(
        dir.path(),
        &["correct", "t.csv", "--pose-calibration", "50"],
    );
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("t.csv") && err.contains("after the trial's end"),
        "{err}"
    );
    let out = acmw(
        dir.path(),
        &[
            "correct",
            "t.csv",
            "--pose-calibration",
            "1",
            "--base-forward",
            "up",
        ],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("not an axis"));
}
