//! The baselines through the command line: `correct --variant rivest|mueller`
//! writes the method's record into the sidecar, the sidecar reproduces the
//! output byte for byte (whatever the thread count), and `report` lists them.

mod common;

use common::acmw_ok as acmw;

#[test]
fn baselines_correct_reproduce_and_report() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    acmw(
        d,
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
    for (variant, kind, key) in [("rivest", "knee", "fits"), ("mueller", "elbow", "fit")] {
        acmw(d, &["correct", "t.csv", "--variant", variant, "--quiet"]);
        let first = d.join(format!("corrected/t.{variant}.csv"));
        let sidecar = d.join(format!("corrected/t.{variant}.csv.acmw.json"));
        let json: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&sidecar).unwrap()).unwrap();
        assert_eq!(json["variant"], variant);
        let joints = json["joints"].as_array().unwrap();
        assert_eq!(joints.len(), 12);
        for j in joints {
            let name = j["joint"].as_str().unwrap();
            if name.ends_with(kind) {
                assert_eq!(j["baseline"]["method"], variant, "{name}");
                assert!(!j["baseline"][key].is_null(), "{name}");
                if variant == "mueller" {
                    // No gyroscope columns in this trial.
                    assert_eq!(j["baseline"]["rates"], "orientations", "{name}");
                }
            } else {
                assert!(j.get("baseline").is_none(), "{name} has a baseline");
            }
        }
        acmw(
            d,
            &[
                "correct",
                "t.csv",
                "--from-sidecar",
                sidecar.to_str().unwrap(),
                "--threads",
                "1",
                "-o",
                "again.csv",
                "--quiet",
            ],
        );
        assert_eq!(
            std::fs::read(&first).unwrap(),
            std::fs::read(d.join("again.csv")).unwrap(),
            "{variant}"
        );
    }
    let out = acmw(
        d,
        &[
            "report",
            "t.csv",
            "--variant",
            "rivest",
            "--variant",
            "mueller",
            "--quiet",
        ],
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("rivest") && text.contains("mueller"),
        "{text}"
    );
}

/// An elbow simulated with gyroscope columns: Mueller takes its rates from them
/// and says so in the sidecar; the sidecar reproduces the output byte for byte,
/// and so does one written before the `rates` field existed.
#[test]
fn mueller_with_gyro_columns_records_and_reproduces() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    acmw(
        d,
        &[
            "simulate",
            "elbow",
            "--duration",
            "60",
            "--gyro",
            "--gyro-noise",
            "1",
            "-o",
            "e.csv",
        ],
    );
    acmw(d, &["correct", "e.csv", "--variant", "mueller", "--quiet"]);
    let first = d.join("corrected/e.mueller.csv");
    let sidecar = d.join("corrected/e.mueller.csv.acmw.json");
    let text = std::fs::read_to_string(&sidecar).unwrap();
    let json: serde_json::Value = serde_json::from_str(&text).unwrap();
    let elbow = json["joints"]
        .as_array()
        .unwrap()
        .iter()
        .find(|j| j["joint"] == "l_elbow")
        .unwrap();
    assert_eq!(elbow["baseline"]["rates"], "gyroscopes");
    assert!(!elbow["baseline"]["fit"].is_null());
    // The corrected trial keeps gyroscope columns (in the corrected frames).
    let out = std::fs::read_to_string(&first).unwrap();
    assert!(
        out.lines().next().unwrap().contains("l_forearm_gx"),
        "{}",
        &out[..200]
    );
    let mut old: serde_json::Value = serde_json::from_str(&text).unwrap();
    for j in old["joints"].as_array_mut().unwrap() {
        if let Some(b) = j.get_mut("baseline").and_then(|b| b.as_object_mut()) {
            b.remove("rates");
        }
    }
    let old_path = d.join("old.json");
    std::fs::write(&old_path, serde_json::to_string_pretty(&old).unwrap()).unwrap();
    for (sc, out) in [(&sidecar, "again.csv"), (&old_path, "again_old.csv")] {
        acmw(
            d,
            &[
                "correct",
                "e.csv",
                "--from-sidecar",
                sc.to_str().unwrap(),
                "-o",
                out,
                "--quiet",
            ],
        );
        assert_eq!(
            std::fs::read(&first).unwrap(),
            std::fs::read(d.join(out)).unwrap(),
            "{out}"
        );
    }
}
