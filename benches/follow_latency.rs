//! `acmw follow` on the drifting sample trial (`sample_trials/full_body_drift.csv.gz`,
//! 13 IMUs, 300 s at 50 Hz, heading drift on two IMUs):
//!
//! 1. latency: a writer appends the trial's rows in real time (one write per
//!    row, 50 Hz) while `acmw follow` streams to a pipe; for each row, the
//!    time from its write returning to its corrected row being read from the
//!    pipe (median, 99th percentile, max). `FOLLOW_LATENCY_S` seconds of the
//!    trial (default 60), `FOLLOW_VARIANT` (default drift-centroid);
//! 2. what extrapolation costs: per variant, the RMS difference between the
//!    live joint angles (each row corrected on arrival with the newest
//!    solution, extrapolated) and the final offline correction's, per joint.
//!    Computed in process with the follower of the library, each solve
//!    awaited after the row that asked for it was corrected (the solver
//!    keeping up, as it does at real time: a 300-s solve takes well under the
//!    10-s warm-up interval), so the figures do not depend on this machine.
//!
//! Run: `cargo bench --bench follow_latency` (or `bash benches/follow_latency.sh`).

use acm_workbench::acm::{RunControl, Variant};
use acm_workbench::correct::pipeline::{self, Preparation, Setup};
use acm_workbench::follow::{Extrapolation, Follower, FollowerConfig};
use acm_workbench::limits::{LimitTable, Settings};
use acm_workbench::metrics::joint_angles;
use acm_workbench::model::Model;
use acm_workbench::rotation::wrap180;
use acm_workbench::trial::{read_trial, trial_to_string, Trial, TrialFormat};
use std::collections::HashMap;
use std::io::{BufRead, BufReader, Write};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn sample() -> Trial {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("sample_trials/full_body_drift.csv.gz");
    read_trial(&path, &Model::infant13()).expect("the sample trial")
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    let i = ((sorted.len() - 1) as f64 * p).round() as usize;
    sorted[i]
}

fn latency(trial: &Trial, seconds: f64, variant: &str) {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("live.csv");
    let text = trial_to_string(trial, TrialFormat::QuatCsv);
    let mut lines = text.split_inclusive('\n');
    let header = lines.next().unwrap();
    let t0 = trial.time_s[0];
    let rows: Vec<&str> = lines
        .zip(&trial.time_s)
        .take_while(|(_, &t)| t - t0 <= seconds)
        .map(|(l, _)| l)
        .collect();
    let index: HashMap<String, usize> = rows
        .iter()
        .enumerate()
        .map(|(i, l)| (l.split(',').next().unwrap().to_string(), i))
        .collect();
    let mut file = std::fs::File::create(&input).unwrap();
    file.write_all(header.as_bytes()).unwrap();
    file.flush().unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_acmw"))
        .current_dir(dir.path())
        .args([
            "follow",
            "live.csv",
            "--idle-exit",
            "1",
            "--variant",
            variant,
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stdout = child.stdout.take().unwrap();
    let n = rows.len();
    let reader = std::thread::spawn(move || {
        let mut seen = vec![None; n];
        for line in BufReader::new(stdout).lines() {
            let line = line.unwrap();
            let at = Instant::now();
            if let Some(&i) = index.get(line.split(',').next().unwrap()) {
                seen[i] = Some(at);
            }
        }
        seen
    });
    // Give the follower time to start and read the header.
    std::thread::sleep(Duration::from_millis(500));
    let dt = trial.median_dt();
    let start = Instant::now();
    let mut written = Vec::with_capacity(n);
    for (i, row) in rows.iter().enumerate() {
        let due = start + Duration::from_secs_f64(i as f64 * dt);
        if let Some(wait) = due.checked_duration_since(Instant::now()) {
            std::thread::sleep(wait);
        }
        file.write_all(row.as_bytes()).unwrap();
        file.flush().unwrap();
        written.push(Instant::now());
    }
    let seen = reader.join().unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut ms: Vec<f64> = seen
        .iter()
        .zip(&written)
        .map(|(s, w)| {
            let s = s.expect("every row was streamed");
            s.saturating_duration_since(*w).as_secs_f64() * 1e3
        })
        .collect();
    ms.sort_by(f64::total_cmp);
    println!(
        "latency, {variant}, {n} rows at {:.0} Hz: median {:.2} ms, p99 {:.2} ms, max {:.2} ms",
        1.0 / dt,
        percentile(&ms, 0.5),
        percentile(&ms, 0.99),
        ms[ms.len() - 1]
    );
    let solves = String::from_utf8_lossy(&out.stderr)
        .lines()
        .filter(|l| l.starts_with("solved"))
        .count();
    println!("  {solves} background solves during the run");
}

/// The live rows of `trial` as `acmw follow` corrects them, each solve
/// awaited after the row that asked for it.
fn live(trial: &Trial, config: FollowerConfig) -> Trial {
    let text = trial_to_string(trial, TrialFormat::QuatCsv);
    let mut f = Follower::new("sample.csv", config);
    let mut parts: Vec<Trial> = Vec::new();
    for (i, line) in text.split_inclusive('\n').enumerate() {
        let range = f.push(line, i as u64 + 1).unwrap();
        if !range.is_empty() {
            parts.push(f.corrected(range).unwrap());
        }
        while f.solving() {
            f.wait_solved(Duration::from_secs(60));
        }
    }
    let mut all = parts.remove(0);
    for p in parts {
        all.time_s.extend(p.time_s);
        for (a, b) in all.imus.iter_mut().zip(p.imus) {
            a.orientation.extend(b.orientation);
        }
    }
    all
}

fn rms_table(trial: &Trial) {
    let model = Model::infant13();
    let limits = LimitTable::default_table();
    let settings = Settings::default();
    let setup = Setup {
        model: &model,
        limits: &limits,
        limits_source: "<built-in>",
        settings: &settings,
    };
    println!(
        "\nRMS difference live - final joint angles, degrees (all three axes; window {} s, hop {} s, warm-up solves every 10 s)",
        settings.window_s, settings.hop_s
    );
    let joints: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    println!(
        "{:<30}  mean >{:.0}s  worst joint       {}",
        "variant (extrapolation)",
        settings.window_s,
        joints.join(" ")
    );
    let variants = [
        (Variant::Basic, Extrapolation::Hold),
        (Variant::Drift, Extrapolation::Hold),
        (Variant::DriftCentroid, Extrapolation::Hold),
        (Variant::DriftHeading, Extrapolation::Hold),
        (Variant::DriftHeading, Extrapolation::HeadingRate),
        (Variant::DriftHeadingCentroid, Extrapolation::Hold),
        (Variant::DriftHeadingCentroid, Extrapolation::HeadingRate),
        (Variant::Rivest, Extrapolation::Hold),
        (Variant::Mueller, Extrapolation::Hold),
        (Variant::Hinge, Extrapolation::Hold),
    ];
    for (variant, how) in variants {
        let prepared = pipeline::prepare(trial.clone(), setup, &Preparation::default()).unwrap();
        let fin =
            pipeline::correct(&prepared.trial, setup, variant, &RunControl::default()).unwrap();
        let live = live(
            trial,
            FollowerConfig {
                model: model.clone(),
                limits: limits.clone(),
                limits_source: "<built-in>".into(),
                settings,
                variant,
                extrapolation: how,
                warmup_s: 10.0,
                until_s: None,
                calibration: None,
                pose: None,
            },
        );
        // Samples from the first window's end on (what is left once warmed up).
        let t0 = trial.time_s[0];
        let warm = trial
            .time_s
            .partition_point(|&t| t - t0 < settings.window_s);
        let mut per_joint = Vec::new();
        let mut after = Vec::new();
        for j in &model.joints {
            let (Some(a), Some(b)) = (joint_angles(&live, j), joint_angles(&fin.corrected, j))
            else {
                continue;
            };
            let rms = |from: usize| {
                let sum: f64 = a[from..]
                    .iter()
                    .zip(&b[from..])
                    .map(|(x, y)| (0..3).map(|k| wrap180(x[k] - y[k]).powi(2)).sum::<f64>())
                    .sum();
                (sum / (3 * (a.len() - from)) as f64).sqrt()
            };
            per_joint.push((j.name.clone(), rms(0)));
            after.push(rms(warm));
        }
        let mean = per_joint.iter().map(|p| p.1).sum::<f64>() / per_joint.len() as f64;
        let mean_after = after.iter().sum::<f64>() / after.len() as f64;
        let worst = per_joint.iter().max_by(|a, b| a.1.total_cmp(&b.1)).unwrap();
        let label = format!("{} ({})", variant, acm_workbench::names::Named::name(how));
        let cells: Vec<String> = per_joint.iter().map(|p| format!("{:.2}", p.1)).collect();
        println!(
            "{label:<30} {mean:5.2} {mean_after:5.2}  {:<10} {:5.2}  {}",
            worst.0,
            worst.1,
            cells.join(" ")
        );
    }
}

fn main() {
    // `cargo bench` passes `--bench`; a filter argument is ignored.
    let trial = sample();
    let seconds: f64 = std::env::var("FOLLOW_LATENCY_S")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(60.0);
    let variant = std::env::var("FOLLOW_VARIANT").unwrap_or_else(|_| "drift-centroid".into());
    if seconds > 0.0 {
        latency(&trial, seconds, &variant);
    }
    rms_table(&trial);
}
