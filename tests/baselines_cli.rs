//! The baselines through the command line: `correct --variant rivest|mueller`
//! writes the method's record into the sidecar, the sidecar reproduces the
//! output byte for byte (whatever the thread count), and `report` lists them.

use std::path::Path;
use std::process::{Command, Output};

fn acmw(dir: &Path, args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_acmw"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "acmw {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

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
