//! Saves killed at any instant: `acmw correct` over an existing output that
//! already has a `.bak`, killed with SIGKILL at each step of its save and at
//! 50 random instants, must always leave a readable output, a complete backup
//! of a previous version, and a sidecar that matches its trial or a reader
//! that says it does not. Temporaries of killed saves are cleaned by the next.
#![cfg(unix)]

use acm_workbench::correct::pipeline;
use acm_workbench::model::Model;
use acm_workbench::rotation::{quat_from_euler_zyx_deg, Quat};
use acm_workbench::sidecar::{sha256_hex, sidecar_path, Sidecar};
use acm_workbench::trial::read_trial;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::fmt::Write as _;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Instant;

/// A drifting two-IMU trial of the infant model, long enough that a run
/// takes a while to save.
fn trial_csv(n: usize) -> String {
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let mut out = String::from("time,base_qw,base_qx,base_qy,base_qz,upper_back_qw,upper_back_qx,upper_back_qy,upper_back_qz\n");
    for i in 0..n {
        let t = i as f64 / 100.0;
        let a = quat_from_euler_zyx_deg([10.0 * (t / 3.0).sin(), 5.0, 20.0]);
        let b: Quat = a * quat_from_euler_zyx_deg([
            rng.random_range(-5.0..5.0),
            40.0 * (t / 2.0).sin() + 0.2 * t,
            rng.random_range(-5.0..5.0) + 0.3 * t,
        ]);
        let _ = writeln!(
            out,
            "{t},{},{},{},{},{},{},{},{}",
            a.w, a.i, a.j, a.k, b.w, b.i, b.j, b.k
        );
    }
    out
}

fn correct(dir: &Path, lambda1: &str) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_acmw"));
    c.current_dir(dir)
        .args([
            "correct", "t.csv", "-o", "out.csv", "--quiet", "--model", "infant13",
        ])
        .args(["--lambda1", lambda1, "--window", "20", "--hop", "10"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped());
    c
}

fn run_ok(dir: &Path, lambda1: &str) {
    let out = correct(dir, lambda1).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// The folder's files before each killed run.
struct Before {
    v0: Vec<u8>,
    v1: Vec<u8>,
    sidecar1: Vec<u8>,
}

fn reset(dir: &Path, b: &Before) {
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        if name != "t.csv" {
            std::fs::remove_file(e.path()).unwrap();
        }
    }
    std::fs::write(dir.join("out.csv"), &b.v1).unwrap();
    std::fs::write(dir.join("out.csv.bak"), &b.v0).unwrap();
    std::fs::write(sidecar_path(&dir.join("out.csv")), &b.sidecar1).unwrap();
}

/// What a kill must leave; `v2` is the output of a complete run.
fn check(dir: &Path, b: &Before, v2: &[u8], what: &str) {
    let out = dir.join("out.csv");
    let now = std::fs::read(&out).unwrap_or_else(|e| panic!("{what}: no output: {e}"));
    let bak = std::fs::read(dir.join("out.csv.bak")).unwrap();
    let model = Model::infant13();
    // The pipeline's load warns of a sidecar that describes another version.
    let trial = pipeline::load(&out, &model)
        .unwrap_or_else(|e| panic!("{what}: output unreadable: {e}"))
        .trial;
    if now == v2 {
        assert_eq!(
            bak, b.v1,
            "{what}: new output without the previous version as backup"
        );
    } else {
        assert_eq!(
            now, b.v1,
            "{what}: output is neither the old nor the new version"
        );
        assert!(
            bak == b.v0 || bak == b.v1,
            "{what}: backup is no complete earlier version"
        );
    }
    let bak_path = dir.join("out.csv.bak.csv");
    std::fs::write(&bak_path, &bak).unwrap();
    read_trial(&bak_path, &model).unwrap_or_else(|e| panic!("{what}: backup unreadable: {e}"));
    std::fs::remove_file(&bak_path).unwrap();
    let sidecar = Sidecar::load(&sidecar_path(&out)).unwrap_or_else(|e| panic!("{what}: {e}"));
    let matches = sidecar.output_sha256.as_deref() == Some(sha256_hex(&now).as_str());
    let warned = trial
        .warnings
        .iter()
        .any(|w| w.contains("does not describe this file"));
    assert!(
        matches != warned,
        "{what}: sidecar matches: {matches}, reader warns: {warned}"
    );
}

fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect()
}

#[test]
fn kills_during_a_save_never_lose_a_version() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("t.csv"), trial_csv(6000)).unwrap();
    run_ok(d, "0.01");
    let v0 = std::fs::read(d.join("out.csv")).unwrap();
    run_ok(d, "0.05");
    let before = Before {
        v0,
        v1: std::fs::read(d.join("out.csv")).unwrap(),
        sidecar1: std::fs::read(sidecar_path(&d.join("out.csv"))).unwrap(),
    };
    assert_ne!(before.v0, before.v1, "lambda1 must change the output");
    // The complete run the kills interrupt, and how long it takes.
    reset(d, &before);
    let start = Instant::now();
    run_ok(d, "0.2");
    let full = start.elapsed();
    let v2 = std::fs::read(d.join("out.csv")).unwrap();
    assert_ne!(v2, before.v1);
    check(d, &before, &v2, "complete run");
    // Killed at each step of the save, until a run gets through all of them.
    let mut steps = 0;
    for step in 1.. {
        reset(d, &before);
        let status = correct(d, "0.2")
            .env(acm_workbench::save::KILL_AT_STEP_ENV, step.to_string())
            .status()
            .unwrap();
        check(d, &before, &v2, &format!("killed at save step {step}"));
        if status.success() {
            break;
        }
        use std::os::unix::process::ExitStatusExt;
        assert_eq!(status.signal(), Some(9), "step {step}: {status:?}");
        steps = step;
        assert!(step < 50, "the save never finished");
    }
    assert!(
        steps >= 6,
        "trial and sidecar each take three steps, found {steps}"
    );
    // Killed at random instants over the whole run (reading, solving, saving).
    let mut rng = ChaCha8Rng::seed_from_u64(50);
    let mut killed_late = 0;
    for k in 0..50 {
        reset(d, &before);
        let mut child = correct(d, "0.2").spawn().unwrap();
        let at = full.mul_f64(rng.random_range(0.3..1.1));
        std::thread::sleep(at);
        let _ = child.kill();
        let status = child.wait().unwrap();
        if status.success() {
            killed_late += 1;
        }
        check(d, &before, &v2, &format!("random kill {k} after {at:?}"));
    }
    assert!(killed_late < 50, "every run finished before its kill");
    // The next complete run removes what killed saves left behind.
    reset(d, &before);
    std::fs::write(d.join(".acmw-4000000000-left.tmp"), b"partial").unwrap();
    run_ok(d, "0.2");
    assert!(temporaries(d).is_empty(), "{:?}", temporaries(d));
}
