//! A variant is registered in one place. With the `demo-variant` feature,
//! `src/variant.rs` (and no other source file) adds `basic-centroid`, `basic`
//! with the centroid term; it must then reach the command line, the report,
//! the sidecar and the workbench's screens with no other change.
//!
//! Run with `cargo test --features demo-variant --test variant_registry`
//! (`.ci/run` does).
#![cfg(feature = "demo-variant")]

mod common;

use common::{acmw_ok, ok};
use std::path::{Path, PathBuf};

const NAME: &str = "basic-centroid";

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every file under `dir` (recursively) whose text mentions `needle`.
fn files_mentioning(dir: &Path, needle: &str) -> Vec<PathBuf> {
    let mut found = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            found.extend(files_mentioning(&path, needle));
        } else if std::fs::read_to_string(&path).is_ok_and(|t| t.contains(needle)) {
            found.push(path);
        }
    }
    found
}

#[test]
fn the_variant_is_registered_in_one_source_file() {
    let src = repo().join("src");
    let mut files = files_mentioning(&src, "demo-variant");
    files.extend(files_mentioning(&src, NAME));
    files.sort();
    files.dedup();
    assert_eq!(files, [src.join("variant.rs")]);
}

#[test]
fn the_command_line_offers_it() {
    let help = ok(&acmw_ok(&repo(), &["correct", "--help"]));
    assert!(help.contains(NAME), "{help}");
}

#[test]
fn correct_writes_it_and_its_sidecar_names_it() {
    let dir = tempfile::tempdir().unwrap();
    let input = repo().join("sample_trials/full_body_clean.csv.gz");
    let run = |variant: &str| {
        let out = dir.path().join(format!("{variant}.csv"));
        acmw_ok(
            &repo(),
            &[
                "correct",
                input.to_str().unwrap(),
                "--variant",
                variant,
                "-o",
                out.to_str().unwrap(),
            ],
        );
        out
    };
    let demo = run(NAME);
    let basic = run("basic");
    let sidecar = std::fs::read_to_string(demo.with_extension("csv.acmw.json")).unwrap();
    let json: serde_json::Value = serde_json::from_str(&sidecar).unwrap();
    assert_eq!(json["variant"], NAME, "{sidecar}");
    // The centroid term is on: the written trial differs from `basic`'s.
    assert_ne!(
        std::fs::read(&demo).unwrap(),
        std::fs::read(&basic).unwrap()
    );
}

#[test]
fn the_report_runs_it_beside_the_others() {
    let out = acmw_ok(
        &repo(),
        &["report", "sample_trials/full_body_clean.csv.gz", "--json"],
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let names: Vec<&str> = json["variants"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v["variant"].as_str().unwrap())
        .collect();
    assert!(
        names.contains(&NAME) && names.contains(&"basic"),
        "{names:?}"
    );
    let text = ok(&acmw_ok(
        &repo(),
        &["report", "sample_trials/full_body_clean.csv.gz"],
    ));
    assert!(text.contains(NAME), "{text}");
}

#[test]
fn the_workbench_shows_its_labels() {
    let compare = ok(&acmw_ok(
        &repo(),
        &["render", "compare", "--size", "200x40", "--variant", NAME],
    ));
    assert!(compare.contains(NAME), "{compare}");
    let trials = ok(&acmw_ok(&repo(), &["render", "trials", "--size", "200x40"]));
    assert!(trials.contains("b+c"), "{trials}");
}
