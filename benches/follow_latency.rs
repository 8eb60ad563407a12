//! `acmw follow` on the drifting sample trial (`sample_trials/full_body_drift.csv.gz`,
//! 13 IMUs, 300 s at 50 Hz, heading drift on two IMUs):
//!
//! 1. latency: a writer appends the trial's rows in real time (one write per
//!    row, 50 Hz) while `acmw follow` streams to a pipe; for each row, the
//!    time from its write returning to its corrected row being read from the
//!    pipe (median, 99th percentile, max). `FOLLOW_LATENCY_S` seconds of the
//!    trial (default 60), `FOLLOW_VARIANT` (default drift-centroid). Twice:
//!    into one CSV, and into a folder of 13 Xsens exports (each row written
//!    to every export in turn; the latency runs from the last export's
//!    write); `FOLLOW_INPUT=csv` or `exports` runs one;
//! 2. what extrapolation costs: per variant, the RMS difference between the
//!    live joint angles (each row corrected on arrival with the newest
//!    solution, extrapolated) and the final offline correction's, per joint.
//!    Computed in process with the follower of the library, each solve
//!    awaited after the row that asked for it was corrected (the solver
//!    keeping up, as it does at real time: a 300-s solve takes well under the
//!    10-s warm-up interval), so the figures do not depend on this machine.
//!
//! Run: `cargo bench --bench follow_latency` (or `bash benches/follow_latency.sh`);
//! `FOLLOW_RMS=0` skips part 2.

use acm_workbench::acm::{RunControl, Variant};
use acm_workbench::correct::pipeline::{self, Preparation, Setup};
use acm_workbench::follow::{Extrapolation, Follower, FollowerConfig};
use acm_workbench::limits::{LimitTable, Settings};
use acm_workbench::metrics::joint_angles;
use acm_workbench::model::Model;
use acm_workbench::rotation::wrap180;
use acm_workbench::trial::{read_trial, trial_to_string, Trial, TrialFormat};
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

/// What the writer appends to, as a lab's recorder would.
#[derive(Clone, Copy, PartialEq)]
enum Input {
    /// One canonical CSV, one write per row.
    Csv,
    /// A folder of MT Manager exports (tab-separated, one per IMU, with a
    /// mapping XML), each row written to every export in turn.
    Exports,
}

/// The files the writer appends to in `dir`: (path, header, one text per
/// row), and the argument `acmw follow` takes.
type Files = (Vec<(std::path::PathBuf, String, Vec<String>)>, String);

fn csv_files(dir: &Path, trial: &Trial, n: usize) -> Files {
    let text = trial_to_string(trial, TrialFormat::QuatCsv);
    let mut lines = text.split_inclusive('\n');
    let header = lines.next().unwrap().to_string();
    let rows = lines.take(n).map(str::to_string).collect();
    (
        vec![(dir.join("live.csv"), header, rows)],
        "live.csv".into(),
    )
}

fn export_files(dir: &Path, trial: &Trial, n: usize) -> Files {
    let folder = dir.join("session");
    std::fs::create_dir_all(&folder).unwrap();
    let serial = |name: &str| name.replace('_', "-");
    let sensors: String = (trial.imus.iter())
        .map(|s| {
            format!(
                "<ExperimentalSensor name=\"_{}\"><name_in_model>{}</name_in_model></ExperimentalSensor>",
                serial(&s.name),
                s.name
            )
        })
        .collect();
    std::fs::write(
        folder.join("myIMUMappings.xml"),
        format!("<?xml version=\"1.0\" encoding=\"UTF-8\" ?>\n<OpenSimDocument Version=\"40000\"><XsensDataReaderSettings><trial_prefix>session</trial_prefix><ExperimentalSensors>{sensors}</ExperimentalSensors></XsensDataReaderSettings></OpenSimDocument>\n"),
    )
    .unwrap();
    let rate = 1.0 / trial.median_dt();
    let files = (trial.imus.iter())
        .map(|s| {
            let header = format!(
                "// Update Rate: {rate:.1}Hz\nPacketCounter\tQuat_q0\tQuat_q1\tQuat_q2\tQuat_q3\n"
            );
            let rows = (s.orientation.iter().take(n).enumerate())
                .map(|(c, q)| format!("{:05}\t{}\t{}\t{}\t{}\n", c % 65_536, q.w, q.i, q.j, q.k))
                .collect();
            (
                folder.join(format!("session_{}.txt", serial(&s.name))),
                header,
                rows,
            )
        })
        .collect();
    (files, "session".into())
}

fn latency(trial: &Trial, seconds: f64, variant: &str, input: Input) {
    let dir = tempfile::tempdir().unwrap();
    let t0 = trial.time_s[0];
    let n = trial.time_s.partition_point(|&t| t - t0 <= seconds);
    let (files, arg) = match input {
        Input::Csv => csv_files(dir.path(), trial, n),
        Input::Exports => export_files(dir.path(), trial, n),
    };
    let mut handles: Vec<std::fs::File> = (files.iter())
        .map(|(path, header, _)| {
            let mut f = std::fs::File::create(path).unwrap();
            f.write_all(header.as_bytes()).unwrap();
            f.flush().unwrap();
            f
        })
        .collect();
    let mut child = Command::new(env!("CARGO_BIN_EXE_acmw"))
        .current_dir(dir.path())
        .args(["follow", &arg, "--idle-exit", "1", "--variant", variant])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let stdout = child.stdout.take().unwrap();
    // Rows are streamed in order, each once (nothing restarts here): the
    // k-th data line read is row k.
    let reader = std::thread::spawn(move || {
        let mut seen = Vec::with_capacity(n);
        for line in BufReader::new(stdout).lines() {
            let line = line.unwrap();
            if !line.starts_with("time") {
                seen.push(Instant::now());
            }
        }
        seen
    });
    // Give the follower time to start and read the headers.
    std::thread::sleep(Duration::from_millis(500));
    let dt = trial.median_dt();
    let start = Instant::now();
    let mut written = Vec::with_capacity(n);
    for i in 0..n {
        let due = start + Duration::from_secs_f64(i as f64 * dt);
        if let Some(wait) = due.checked_duration_since(Instant::now()) {
            std::thread::sleep(wait);
        }
        for (f, (_, _, rows)) in handles.iter_mut().zip(&files) {
            f.write_all(rows[i].as_bytes()).unwrap();
            f.flush().unwrap();
        }
        written.push(Instant::now());
    }
    let seen = reader.join().unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // An export folder's last row goes out when the final correction is
    // written (no later packet proves every sensor wrote past it).
    let m = seen.len().min(n);
    assert!(m + 1 >= n, "{m} of {n} rows were streamed");
    let mut ms: Vec<f64> = seen[..m]
        .iter()
        .zip(&written)
        .map(|(s, w)| s.saturating_duration_since(*w).as_secs_f64() * 1e3)
        .collect();
    ms.sort_by(f64::total_cmp);
    let what = match input {
        Input::Csv => "CSV".to_string(),
        Input::Exports => format!("{} Xsens exports", files.len()),
    };
    println!(
        "latency, {what}, {variant}, {m} rows at {:.0} Hz: median {:.2} ms, p99 {:.2} ms, max {:.2} ms",
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
    let inputs = match std::env::var("FOLLOW_INPUT").as_deref() {
        Ok("csv") => vec![Input::Csv],
        Ok("exports") => vec![Input::Exports],
        _ => vec![Input::Csv, Input::Exports],
    };
    if seconds > 0.0 {
        for input in inputs {
            latency(&trial, seconds, &variant, input);
        }
    }
    if std::env::var("FOLLOW_RMS").as_deref() != Ok("0") {
        rms_table(&trial);
    }
}
