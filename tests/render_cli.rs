#![cfg(feature = "terminal")]
//! `acmw render SCREEN` prints exactly what the snapshot tests hold, and bare
//! `acmw` without a terminal says so and exits 4.

use acm_workbench::ui::headless::{write_demo_folder, SCREENS};
use std::path::Path;
use std::process::{Command, Stdio};

fn snapshot_text(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("src/ui/snapshots")
        .join(format!("acm_workbench__ui__tests__{name}.snap"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path:?}: {e}"));
    // After the front matter, each line is the row in quotes.
    let body = text.splitn(3, "---\n").nth(2).expect("snapshot body");
    body.lines()
        .map(|l| {
            let l = l.strip_prefix('"').unwrap_or(l);
            let l = l.strip_suffix('"').unwrap_or(l);
            format!("{l}\n")
        })
        .collect()
}

#[test]
fn render_prints_the_snapshots() {
    let tmp = tempfile::tempdir().unwrap();
    write_demo_folder(&tmp.path().join("trials")).unwrap();
    for screen in SCREENS {
        for size in ["80x24", "120x40"] {
            let out = Command::new(env!("CARGO_BIN_EXE_acmw"))
                .current_dir(tmp.path())
                .args(["render", screen, "--dir", "trials", "--trial", "knee.csv"])
                .args(["--size", size])
                .env_remove("NO_COLOR")
                .output()
                .unwrap();
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
            let text = String::from_utf8(out.stdout).unwrap();
            assert!(!text.contains('\x1b'), "no escape codes without --color");
            assert_eq!(
                text,
                snapshot_text(&format!("{screen}_{size}")),
                "{screen} {size}"
            );
        }
    }
    let out = Command::new(env!("CARGO_BIN_EXE_acmw"))
        .current_dir(tmp.path())
        .args(["render", "trials", "--dir", "trials", "--color"])
        .output()
        .unwrap();
    assert!(String::from_utf8(out.stdout).unwrap().contains("\x1b["));
}

#[test]
fn no_terminal_exits_4_without_escape_codes() {
    let out = Command::new(env!("CARGO_BIN_EXE_acmw"))
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(4));
    assert!(out.stdout.is_empty());
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("needs a terminal") && err.contains("acmw --help"),
        "{err}"
    );
    assert!(!err.contains('\x1b'));
}
