//! Refactoring guard: every variant on every sample trial writes the same
//! bytes as when `tests/output_hashes.txt` was made. Each run goes through
//! the real binary (`acmw correct`), and the SHA-256 of every file it writes
//! is compared: the angle file, the `ik` variant's coordinates, and the
//! sidecar with its volatile parts (program version, absolute paths) taken out.
//!
//! After a change that is meant to alter outputs, regenerate the list with
//! `ACMW_UPDATE_HASHES=1 cargo test --test output_hashes` and review the diff.

mod common;

use acm_workbench::acm::Variant;
use acm_workbench::sidecar::sha256_hex;
use common::acmw_ok;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The sample trials corrected (the calibration trial has its own test).
const TRIALS: [&str; 4] = [
    "knee_calf_z15.csv.gz",
    "elbow_20.csv.gz",
    "full_body_clean.csv.gz",
    "full_body_drift.csv.gz",
];

/// One run: a label, the trial and the extra arguments after `--variant`.
struct Run {
    label: String,
    trial: &'static str,
    variant: &'static str,
    /// Output file name (its extension picks gzip; `--format` follows).
    output: &'static str,
    format: Option<&'static str>,
    /// `--precision`, when given.
    precision: Option<&'static str>,
}

fn runs() -> Vec<Run> {
    let mut runs = Vec::new();
    for trial in TRIALS {
        for v in Variant::ALL {
            runs.push(Run {
                label: format!("{trial} {v}"),
                trial,
                variant: v.name(),
                output: "out.csv",
                format: None,
                precision: None,
            });
        }
    }
    // The other writers, on the short trial.
    for (variant, output, format) in [
        ("drift-centroid", "out.csv", "euler-csv"),
        ("drift-centroid", "out.sto.gz", "sto"),
        ("ik", "out.sto.gz", "sto"),
    ] {
        runs.push(Run {
            label: format!("knee_calf_z15.csv.gz {variant} {format}"),
            trial: "knee_calf_z15.csv.gz",
            variant,
            output,
            format: Some(format),
            precision: None,
        });
    }
    runs.extend(full_precision_runs());
    runs
}

/// The sample trials hold six decimals, which `auto` keeps: these runs
/// write them at `--precision full`, whose orientation files are to be the
/// bytes every run wrote before outputs kept the input's precision (the
/// sidecars differ by the `precision` setting they record).
fn full_precision_runs() -> Vec<Run> {
    let mut runs = Vec::new();
    let knee = "knee_calf_z15.csv.gz";
    let on_knee = Variant::ALL
        .iter()
        .map(|v| (knee, v.name(), "out.csv", None));
    let others = TRIALS[1..]
        .iter()
        .map(|&t| (t, "drift-centroid", "out.csv", None));
    let formats = [
        (knee, "drift-centroid", "out.csv", Some("euler-csv")),
        (knee, "drift-centroid", "out.sto.gz", Some("sto")),
    ];
    for (trial, variant, output, format) in on_knee.chain(others).chain(formats) {
        runs.push(Run {
            label: format!(
                "{trial} {variant}{} precision-full",
                format.map_or(String::new(), |f| format!(" {f}"))
            ),
            trial,
            variant,
            output,
            format,
            precision: Some("full"),
        });
    }
    runs
}

/// The sidecar's text without what changes from machine to machine: the
/// program version and the absolute paths of the input and output folders.
fn stable_sidecar(text: &str, out_dir: &Path, repo: &Path) -> String {
    let text = text
        .replace(&out_dir.display().to_string(), "<out>")
        .replace(&repo.display().to_string(), "<repo>");
    let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
    value.as_object_mut().unwrap().remove("version");
    serde_json::to_string_pretty(&value).unwrap()
}

/// SHA-256 of every file one run writes, by file name.
fn run_hashes(run: &Run, repo: &Path) -> BTreeMap<String, String> {
    let dir = tempfile::tempdir().unwrap();
    let cwd = dir.path().join("cwd");
    let out_dir = dir.path().join("out");
    std::fs::create_dir_all(&cwd).unwrap();
    std::fs::create_dir_all(&out_dir).unwrap();
    let input = repo.join("sample_trials").join(run.trial);
    let output = out_dir.join(run.output);
    let mut args = vec![
        "correct".to_string(),
        input.display().to_string(),
        "--variant".into(),
        run.variant.into(),
        "-o".into(),
        output.display().to_string(),
        "-q".into(),
    ];
    if let Some(f) = run.format {
        args.extend(["--format".into(), f.into()]);
    }
    if let Some(p) = run.precision {
        args.extend(["--precision".into(), p.into()]);
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    acmw_ok(&cwd, &args);
    let mut hashes = BTreeMap::new();
    for entry in std::fs::read_dir(&out_dir).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if name.starts_with('.') {
            continue; // lock files
        }
        let bytes = std::fs::read(&path).unwrap();
        let hash = if name.ends_with(".acmw.json") {
            let text = String::from_utf8(bytes).unwrap();
            sha256_hex(stable_sidecar(&text, &out_dir, repo).as_bytes())
        } else {
            sha256_hex(&bytes)
        };
        hashes.insert(name, hash);
    }
    hashes
}

fn hash_file(repo: &Path) -> PathBuf {
    repo.join("tests").join("output_hashes.txt")
}

/// `<trial> <variant> [format] | <file> <sha256>` lines.
fn all_hashes(repo: &Path) -> Vec<String> {
    let mut lines = Vec::new();
    for run in runs() {
        for (file, hash) in run_hashes(&run, repo) {
            lines.push(format!("{} | {file} {hash}", run.label));
        }
    }
    lines
}

#[test]
fn outputs_match_the_stored_hashes() {
    let repo = Path::new(env!("CARGO_MANIFEST_DIR"));
    let lines = all_hashes(repo);
    let path = hash_file(repo);
    if std::env::var_os("ACMW_UPDATE_HASHES").is_some() {
        std::fs::write(&path, lines.join("\n") + "\n").unwrap();
        return;
    }
    let stored = std::fs::read_to_string(&path).unwrap();
    let stored: Vec<&str> = stored.lines().collect();
    let differ: Vec<String> = lines
        .iter()
        .filter(|l| !stored.contains(&l.as_str()))
        .cloned()
        .collect();
    let missing: Vec<&&str> = stored
        .iter()
        .filter(|l| !lines.contains(&l.to_string()))
        .collect();
    assert!(
        differ.is_empty() && missing.is_empty(),
        "outputs changed:\n  now:\n    {}\n  stored:\n    {}",
        differ.join("\n    "),
        missing
            .iter()
            .map(|s| s.to_string())
            .collect::<Vec<_>>()
            .join("\n    ")
    );
}
