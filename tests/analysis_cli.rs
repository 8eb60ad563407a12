//! `acmw suggest-limits`, `acmw centroids` and `acmw plot` from the command line.

mod common;

use common::{acmw, ok};
use std::path::Path;

/// Two clean swing trials, 30 s each, with `--truth-json-only` (one file each).
fn trials(dir: &Path) {
    for seed in ["1", "2"] {
        ok(&acmw(
            dir,
            &[
                "simulate",
                "preset",
                "full_body_swing",
                "--duration",
                "30",
                "--seed",
                seed,
                "--truth-json-only",
                "-o",
                &format!("s{seed}.csv"),
            ],
        ));
    }
}

#[test]
fn suggest_limits_prints_the_diff_and_never_writes_over_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    trials(d);
    // The current table is a file in ./joint_limits (as settings.toml names it).
    std::fs::create_dir(d.join("joint_limits")).unwrap();
    let original = acm_workbench::limits::LimitTable::default_table().to_csv();
    std::fs::write(d.join("joint_limits/table_3_2.csv"), &original).unwrap();
    let out = acmw(
        d,
        &[
            "suggest-limits",
            "s1.csv",
            "s2.csv",
            "--out",
            "joint_limits/./table_3_2.csv",
        ],
    );
    assert_eq!(out.status.code(), Some(1));
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("never written over it"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        std::fs::read_to_string(d.join("joint_limits/table_3_2.csv")).unwrap(),
        original
    );
    let text = ok(&acmw(
        d,
        &[
            "suggest-limits",
            "s1.csv",
            "s2.csv",
            "--out",
            "joint_limits/suggested.csv",
        ],
    ));
    assert!(text.contains("from 2 trial(s), 0-30 s"), "{text}");
    assert!(text.contains("130 -> 80"), "{text}");
    let t = acm_workbench::limits::LimitTable::load(&d.join("joint_limits/suggested.csv")).unwrap();
    assert_eq!(
        t.rows.len(),
        acm_workbench::limits::LimitTable::default_table()
            .rows
            .len()
    );
    // A dry run writes nothing; a bad span is a usage error.
    ok(&acmw(
        d,
        &["suggest-limits", "s1.csv", "--out", "x.csv", "--dry-run"],
    ));
    assert!(!d.join("x.csv").exists());
    let out = acmw(
        d,
        &["suggest-limits", "s1.csv", "--out", "x.csv", "--from", "40"],
    );
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    // A malformed trial names its file and exits 3.
    std::fs::write(d.join("bad.csv"), "time,base_qw\n0,x\n").unwrap();
    let out = acmw(d, &["suggest-limits", "bad.csv", "--out", "x.csv"]);
    assert_eq!(out.status.code(), Some(3));
    assert!(String::from_utf8_lossy(&out.stderr).contains("bad.csv:"));
}

#[test]
fn centroids_and_plots_are_written() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    trials(d);
    let text = ok(&acmw(
        d,
        &["centroids", "s1.csv", "s2.csv", "--out", "c.csv"],
    ));
    // Knee flexion swings over 13..80 deg: its centroid is 46.5.
    assert!(text.contains("\nknee,Y,46.5"), "{text}");
    assert_eq!(std::fs::read_to_string(d.join("c.csv")).unwrap(), text);
    let text = ok(&acmw(d, &["centroids", "s1.csv", "--by-joint"]));
    assert!(
        text.contains("\nl_knee,Y,46.5") && text.contains(",1500,1\n"),
        "{text}"
    );
    ok(&acmw(
        d,
        &[
            "plot",
            "histogram",
            "s1.csv",
            "s2.csv",
            "--joint",
            "hip",
            "-o",
            "h.svg",
        ],
    ));
    assert!(std::fs::read_to_string(d.join("h.svg"))
        .unwrap()
        .starts_with("<svg"));
    ok(&acmw(
        d,
        &[
            "plot",
            "traces",
            "s1.csv",
            "--joint",
            "l_knee",
            "--variant",
            "basic",
            "-o",
            "t.png",
            "--size",
            "400x300",
        ],
    ));
    assert_eq!(&std::fs::read(d.join("t.png")).unwrap()[1..4], b"PNG");
    let out = acmw(d, &["plot", "traces", "s1.csv", "-o", "t.pdf"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains(".svg or .png"));
    let out = acmw(
        d,
        &[
            "plot",
            "histogram",
            "s1.csv",
            "--joint",
            "nose",
            "-o",
            "n.svg",
        ],
    );
    assert!(String::from_utf8_lossy(&out.stderr).contains("no samples of 'nose'"));
}
