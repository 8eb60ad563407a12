//! `acmw batch` through the binary, on simulated trials the tests write:
//! a malformed trial is recorded and the batch goes on; a batch killed half
//! way finishes on a re-run without redoing done trials; outputs are the
//! same for any number of workers and any sharding.

mod common;

use acm_workbench::batch::journal;
use acm_workbench::batch::manifest::{Manifest, Status};
use acm_workbench::simulate::{simulate, HeadingDrift, SimConfig};
use acm_workbench::trial::{write_trial, TrialFormat};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant, SystemTime};

/// Writes `n` simulated full-body trials of `duration_s` seconds into
/// `dir/trials` (seeds 100, 101, ...; every third with heading drift).
fn write_trials(dir: &Path, n: u64, duration_s: f64) -> PathBuf {
    let trials = dir.join("trials");
    std::fs::create_dir_all(&trials).unwrap();
    for k in 0..n {
        let mut cfg = SimConfig::full_body(100 + k);
        cfg.duration_s = duration_s;
        if k % 3 == 0 {
            cfg.drifts = vec![HeadingDrift {
                imu: "l_calf".into(),
                start_s: 10.0,
                rate_deg_s: 0.1,
            }];
        }
        let sim = simulate(&cfg).unwrap();
        let path = trials.join(format!("trial{k:03}.csv"));
        write_trial(&sim.trial, &path, TrialFormat::QuatCsv).unwrap();
    }
    trials
}

/// Copies the trial files of `from` into `to`.
fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let e = e.unwrap();
        std::fs::copy(e.path(), to.join(e.file_name())).unwrap();
    }
}

fn manifest(out: &Path) -> Manifest {
    Manifest::load(&out.join("manifest.json")).unwrap()
}

/// The outputs in `out` (corrected trials and sidecars; not the manifests,
/// backups or lock files), by name.
fn outputs(out: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(out)
        .unwrap()
        .map(|e| e.unwrap())
        .map(|e| (e.file_name().to_string_lossy().into_owned(), e.path()))
        .filter(|(n, _)| !n.starts_with('.') && !n.starts_with("manifest.") && !n.ends_with(".bak"))
        .map(|(n, p)| (n, std::fs::read(p).unwrap()))
        .collect()
}

/// The manifest's rows without their wall times.
fn rows_without_time(m: &Manifest) -> Vec<acm_workbench::batch::manifest::Row> {
    m.rows
        .iter()
        .cloned()
        .map(|mut r| {
            r.wall_s = 0.0;
            r
        })
        .collect()
}

#[test]
fn a_malformed_trial_is_recorded_and_the_batch_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let trials = write_trials(dir.path(), 3, 120.0);
    // A number that is not one on line 4, and a file that is no trial at all.
    let good = std::fs::read_to_string(trials.join("trial000.csv")).unwrap();
    let mut lines: Vec<String> = good.lines().map(String::from).collect();
    let header_line = lines.iter().position(|l| l.starts_with("time")).unwrap();
    let bad_line = header_line + 3;
    lines[bad_line] = lines[bad_line].replacen(',', ",x1.5q,", 1);
    std::fs::write(trials.join("bad_number.csv"), lines.join("\n")).unwrap();
    std::fs::write(trials.join("empty.csv"), "").unwrap();
    let out = common::acmw(
        dir.path(),
        &["batch", "trials", "--out", "out", "--jobs", "2", "--quiet"],
    );
    assert_eq!(out.status.code(), Some(1), "a failed trial fails the run");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("5 trials: 3 outputs ok, 2 failed"),
        "{stderr}"
    );
    let m = manifest(&dir.path().join("out"));
    assert_eq!(m.rows.len(), 5);
    let by_trial: BTreeMap<&str, _> = m.rows.iter().map(|r| (r.trial.as_str(), r)).collect();
    let bad = by_trial["trials/bad_number.csv"];
    assert_eq!(bad.status, Status::Failed);
    let err = bad.error.as_deref().unwrap();
    assert!(
        err.contains(&format!("bad_number.csv:{}:", bad_line + 1)),
        "the error locates the bad line: {err}"
    );
    assert_eq!(by_trial["trials/empty.csv"].status, Status::Failed);
    for k in 0..3 {
        let r = by_trial[format!("trials/trial{k:03}.csv").as_str()];
        assert_eq!(r.status, Status::Ok, "{:?}", r.error);
        // The output is on disk as the manifest records it, with its sidecar.
        let bytes = std::fs::read(dir.path().join(&r.output)).unwrap();
        assert_eq!(acm_workbench::input::sha256_hex(&bytes), r.output_sha256);
        assert!(dir.path().join(&r.sidecar).is_file());
        // The correction removed excursion.
        assert!(r.excursion_after_deg.unwrap() < r.excursion_before_deg.unwrap());
        assert_eq!(r.joints.len(), 12);
    }
    // The CSV manifest holds the same rows.
    let csv = std::fs::read_to_string(dir.path().join("out/manifest.csv")).unwrap();
    let mut reader = csv::Reader::from_reader(csv.as_bytes());
    let statuses: Vec<String> = reader
        .records()
        .map(|r| r.unwrap().get(2).unwrap().to_string())
        .collect();
    assert_eq!(statuses, ["failed", "failed", "ok", "ok", "ok"]);
}

#[test]
fn a_batch_killed_half_way_finishes_without_redoing_done_trials() {
    let dir = tempfile::tempdir().unwrap();
    let n = 10;
    write_trials(dir.path(), n, 120.0);
    let out = dir.path().join("out");
    let mut child = Command::new(env!("CARGO_BIN_EXE_acmw"))
        .current_dir(dir.path())
        .args(["batch", "trials", "--out", "out", "--jobs", "1", "--quiet"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Kill it once three trials are recorded.
    let start = Instant::now();
    let stalled = loop {
        let rows = journal::recorded(&out.join("manifest.json")).map_or(0, |r| r.len());
        if rows >= 3 || start.elapsed() > Duration::from_secs(300) {
            break rows < 3;
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let _ = child.kill();
    child.wait().unwrap();
    assert!(!stalled, "batch stalled");
    // What the killed run recorded: its manifest (rewritten now and then)
    // and the journal of the trials finished since.
    let done_before = journal::recorded(&out.join("manifest.json")).unwrap();
    let done = done_before.len();
    assert!(
        done < n as usize,
        "killed before the end ({done} of {n} done)"
    );
    assert!(done_before.iter().all(|r| r.status == Status::Ok));
    let mtimes: Vec<(PathBuf, SystemTime)> = done_before
        .iter()
        .flat_map(|r| [dir.path().join(&r.output), dir.path().join(&r.sidecar)])
        .map(|p| {
            let t = std::fs::metadata(&p).unwrap().modified().unwrap();
            (p, t)
        })
        .collect();
    // Files' times have a coarse resolution on some file systems.
    std::thread::sleep(Duration::from_millis(1100));
    let rerun = common::acmw_ok(
        dir.path(),
        &["batch", "trials", "--out", "out", "--jobs", "2"],
    );
    let stderr = String::from_utf8_lossy(&rerun.stderr);
    assert_eq!(
        stderr.matches(": done earlier").count(),
        done,
        "the done trials are skipped: {stderr}"
    );
    let after = manifest(&out);
    assert_eq!(after.rows.len(), n as usize);
    assert!(after.rows.iter().all(|r| r.status == Status::Ok));
    for (p, t) in &mtimes {
        let now = std::fs::metadata(p).unwrap().modified().unwrap();
        assert_eq!(now, *t, "{} was written again", p.display());
        assert!(
            !acm_workbench::save::backup_path(p).exists(),
            "{} was replaced",
            p.display()
        );
    }
    // The rows of the done trials are those of the first run, untouched.
    for r in &done_before {
        assert!(after.rows.contains(r));
    }
    // A trial whose input changed is done again; the others are not.
    let first = &after.rows[0];
    let path = dir.path().join(&first.trial);
    let mut text = std::fs::read_to_string(&path).unwrap();
    text.insert_str(0, "# edited\n");
    std::fs::write(&path, text).unwrap();
    let third = common::acmw_ok(
        dir.path(),
        &["batch", "trials", "--out", "out", "--jobs", "2"],
    );
    let stderr = String::from_utf8_lossy(&third.stderr);
    assert_eq!(
        stderr.matches(": done earlier").count(),
        n as usize - 1,
        "{stderr}"
    );
    assert!(stderr.contains(&format!("{}: ok", first.trial)), "{stderr}");
    // So is every trial after a change of settings.
    let fourth = common::acmw_ok(
        dir.path(),
        &[
            "batch",
            "trials",
            "--out",
            "out",
            "--jobs",
            "2",
            "--lambda1",
            "0.06",
        ],
    );
    let stderr = String::from_utf8_lossy(&fourth.stderr);
    assert_eq!(stderr.matches(": done earlier").count(), 0, "{stderr}");
}

#[test]
fn outputs_do_not_depend_on_the_number_of_workers() {
    let dir = tempfile::tempdir().unwrap();
    let trials = write_trials(&dir.path().join("a"), 4, 120.0);
    copy_dir(&trials, &dir.path().join("b/trials"));
    let args = |jobs: &'static str| {
        [
            "batch",
            "trials",
            "--out",
            "out",
            "--jobs",
            jobs,
            "--quiet",
            "--variant",
            "drift-centroid",
            "--variant",
            "drift-heading",
        ]
    };
    common::acmw_ok(&dir.path().join("a"), &args("1"));
    common::acmw_ok(&dir.path().join("b"), &args("2"));
    let (a, b) = (dir.path().join("a/out"), dir.path().join("b/out"));
    let outs = outputs(&a);
    assert_eq!(outs.len(), 4 * 2 * 2, "{:?}", outs.keys());
    assert!(outs == outputs(&b), "outputs differ between --jobs 1 and 2");
    assert_eq!(
        rows_without_time(&manifest(&a)),
        rows_without_time(&manifest(&b))
    );
}

#[test]
fn four_shards_run_at_once_and_merged_equal_one_unsharded_run() {
    let dir = tempfile::tempdir().unwrap();
    let trials = write_trials(&dir.path().join("a"), 8, 120.0);
    copy_dir(&trials, &dir.path().join("b/trials"));
    let a = dir.path().join("a");
    // The four shards run at once: start them all, then wait.
    let children: Vec<_> = (1..=4)
        .map(|k| {
            Command::new(env!("CARGO_BIN_EXE_acmw"))
                .current_dir(&a)
                .args(["batch", "trials", "--out", "out2", "--jobs", "1", "--quiet"])
                .args(["--shard", &format!("{k}/4")])
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    let mut per_shard = Vec::new();
    for c in children {
        let out = c.wait_with_output().unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        per_shard.push(String::from_utf8_lossy(&out.stderr).into_owned());
    }
    common::acmw_ok(&a, &["batch", "--merge", "--out", "out2"]);
    common::acmw_ok(
        &dir.path().join("b"),
        &["batch", "trials", "--out", "out2", "--jobs", "2", "--quiet"],
    );
    let (sharded, whole) = (a.join("out2"), dir.path().join("b/out2"));
    // Every trial was done by exactly one shard.
    let counts: Vec<usize> = (1..=4)
        .map(|k| {
            Manifest::load(&sharded.join(format!("manifest.shard-{k}-of-4.json")))
                .unwrap()
                .rows
                .len()
        })
        .collect();
    assert_eq!(counts.iter().sum::<usize>(), 8, "{counts:?} {per_shard:?}");
    let outs = outputs(&sharded);
    assert_eq!(outs.len(), 16);
    assert!(outs == outputs(&whole), "sharded outputs differ");
    let merged = manifest(&sharded);
    assert_eq!(merged.shard, None);
    assert_eq!(
        rows_without_time(&merged),
        rows_without_time(&manifest(&whole))
    );
    // The CSV of the merged manifest is that of the whole run but for times.
    let csv = |p: &Path| -> Vec<Vec<String>> {
        let text = std::fs::read_to_string(p.join("manifest.csv")).unwrap();
        csv::Reader::from_reader(text.as_bytes())
            .records()
            .map(|r| {
                let r = r.unwrap();
                r.iter().take(r.len() - 1).map(String::from).collect()
            })
            .collect()
    };
    assert_eq!(csv(&sharded), csv(&whole));
    // A missing shard is named when merging.
    std::fs::remove_file(sharded.join("manifest.shard-3-of-4.json")).unwrap();
    let out = common::acmw(&a, &["batch", "--merge", "--out", "out2"]);
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("missing for 3/4"), "{stderr}");
}

#[test]
fn outputs_keep_the_inputs_decimals_and_precision_full_redoes_them() {
    use acm_workbench::trial::precision::{decimals_of, Precision};
    use acm_workbench::trial::write_trial_hashed;
    let dir = tempfile::tempdir().unwrap();
    let trials = dir.path().join("trials");
    std::fs::create_dir_all(&trials).unwrap();
    for k in 0..2 {
        let mut cfg = SimConfig::full_body(200 + k);
        cfg.duration_s = 40.0;
        let sim = simulate(&cfg).unwrap();
        let path = trials.join(format!("six{k}.csv"));
        write_trial_hashed(
            &sim.trial,
            &path,
            TrialFormat::QuatCsv,
            Precision::Decimals(6),
        )
        .unwrap();
    }
    let most_decimals = |out: &Path| -> Vec<u8> {
        let m = manifest(out);
        m.rows
            .iter()
            .map(|r| {
                let text = std::fs::read_to_string(dir.path().join(&r.output)).unwrap();
                let cells = text.lines().skip(1).flat_map(|l| l.split(',').skip(1));
                cells.map(decimals_of).max().unwrap()
            })
            .collect()
    };
    let batch = |extra: &[&str]| {
        let mut args = vec![
            "batch", "trials", "--out", "out", "--window", "20", "--hop", "10", "--quiet",
        ];
        args.extend(extra);
        common::acmw_ok(dir.path(), &args);
    };
    let out = dir.path().join("out");
    batch(&[]);
    assert_eq!(most_decimals(&out), [6, 6]);
    let auto_hash = manifest(&out).rows[0].settings_sha256.clone();
    // Another precision is another output: the trials are done again.
    batch(&["--precision", "full"]);
    assert!(most_decimals(&out).iter().all(|&d| d > 6));
    assert_ne!(manifest(&out).rows[0].settings_sha256, auto_hash);
}
