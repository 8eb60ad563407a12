//! `acmw follow` through the binary: a writer appends a simulated drifting
//! trial in random fragments (cut anywhere, mid-number included) while the
//! follower reads it. The final correction must equal `acmw correct` of the
//! whole file byte for byte, the live stream must hold every row exactly
//! once with the uncorrected IMU's columns exactly as written (a row read
//! half-written would show a cut number), and a truncated file must be
//! noticed and followed from its new start.

use acm_workbench::rotation::{angle_between_deg, Quat};
use acm_workbench::simulate::{simulate, HeadingDrift, SimConfig};
use acm_workbench::trial::{read_trial, trial_to_string, Trial, TrialFormat};
use rand::{Rng, SeedableRng};
use std::io::Write;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn acmw() -> Command {
    Command::new(env!("CARGO_BIN_EXE_acmw"))
}

/// A drifting 13-IMU trial of `seconds` at 50 Hz.
fn drifting(seconds: f64, seed: u64) -> Trial {
    let config = SimConfig {
        duration_s: seconds,
        drifts: vec![
            HeadingDrift {
                imu: "l_calf".into(),
                start_s: 20.0,
                rate_deg_s: 0.1,
            },
            HeadingDrift {
                imu: "r_upper_arm".into(),
                start_s: 10.0,
                rate_deg_s: 0.15,
            },
        ],
        ..SimConfig::full_body(seed)
    };
    simulate(&config).unwrap().trial
}

/// Appends `text` to `path` in random fragments of 1..=4000 bytes, flushed
/// each, over about `seconds` of wall-clock time.
fn write_in_fragments(path: &Path, text: &[u8], seconds: f64, seed: u64) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut f = std::fs::OpenOptions::new()
        .append(true)
        .create(true)
        .open(path)
        .unwrap();
    let per_byte = seconds / text.len() as f64;
    let mut pos = 0;
    while pos < text.len() {
        let n = rng.random_range(1..=4000).min(text.len() - pos);
        f.write_all(&text[pos..pos + n]).unwrap();
        f.flush().unwrap();
        pos += n;
        std::thread::sleep(Duration::from_secs_f64(n as f64 * per_byte));
    }
}

fn follow(dir: &Path, input: &Path, extra: &[&str]) -> Child {
    acmw()
        .current_dir(dir)
        .arg("follow")
        .arg(input)
        .args([
            "-o",
            "stream.csv",
            "--corrected",
            "final.csv",
            "--sidecar",
            "final.json",
        ])
        .args([
            "--idle-exit",
            "2",
            "--window",
            "30",
            "--hop",
            "15",
            "--warmup",
            "5",
        ])
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn finish(child: Child) -> (String, String) {
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "acmw follow failed: {stderr}");
    (String::from_utf8_lossy(&out.stdout).into_owned(), stderr)
}

/// `acmw correct` of `input` with the settings the follower used.
fn correct(dir: &Path, input: &Path) -> (Vec<u8>, serde_json::Value) {
    correct_with(dir, input, &[])
}

/// `acmw correct` of `input` with the settings the follower used and `extra`.
fn correct_with(dir: &Path, input: &Path, extra: &[&str]) -> (Vec<u8>, serde_json::Value) {
    let out = acmw()
        .current_dir(dir)
        .arg("correct")
        .arg(input)
        .args(["-o", "offline.csv", "--sidecar", "offline.json", "-q"])
        .args(["--window", "30", "--hop", "15"])
        .args(extra)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    (
        std::fs::read(dir.join("offline.csv")).unwrap(),
        sidecar(&dir.join("offline.json")),
    )
}

/// A sidecar without the output's name (the one thing that differs).
fn sidecar(path: &Path) -> serde_json::Value {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    v.as_object_mut().unwrap().remove("output");
    v
}

fn model() -> acm_workbench::model::Model {
    acm_workbench::model::Model::infant13()
}

/// Every row once, in order, at the input's times; the uncorrected base IMU
/// exactly as written (canonical sign), so no row was read half-written.
fn check_stream(stream: &Path, input: &Trial, format: TrialFormat) {
    let live = read_trial(stream, &model()).unwrap();
    assert_eq!(live.time_s, input.time_s, "the stream has every row once");
    let base_in = &input.imus[0];
    let base_out = live.imu(&base_in.name).unwrap();
    assert_eq!(base_in.name, "base");
    // The stream's rows, as text, against the input's written the same way.
    let expect = trial_to_string(input, format);
    let got = std::fs::read_to_string(stream).unwrap();
    let column = |text: &str, k: usize| -> Vec<String> {
        text.lines()
            .map(|l| l.split(',').take(k).collect::<Vec<_>>().join(","))
            .collect()
    };
    let k = if format == TrialFormat::EulerCsv {
        4
    } else {
        5
    };
    assert_eq!(column(&got, k), column(&expect, k), "time and base columns");
    assert_eq!(base_out.orientation.len(), base_in.orientation.len());
}

#[test]
fn final_output_equals_correct_and_the_stream_has_every_row_whole() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("growing.csv");
    let trial = drifting(150.0, 5);
    let text = trial_to_string(&trial, TrialFormat::QuatCsv);
    let child = follow(dir.path(), &input, &[]);
    // 150 s of trial written in about 8 s (x19), cut anywhere.
    write_in_fragments(&input, text.as_bytes(), 8.0, 1);
    let (_, stderr) = finish(child);
    assert!(
        stderr.contains("solved 0-5.0 s") || stderr.contains("solved 0-"),
        "{stderr}"
    );
    let (offline, offline_sidecar) = correct(dir.path(), &input);
    let fin = std::fs::read(dir.path().join("final.csv")).unwrap();
    assert!(
        fin == offline,
        "the final correction differs from acmw correct"
    );
    assert_eq!(sidecar(&dir.path().join("final.json")), offline_sidecar);
    let written = read_trial(&input, &model()).unwrap();
    check_stream(
        &dir.path().join("stream.csv"),
        &written,
        TrialFormat::QuatCsv,
    );
    // The live rows were corrected: past the first solve they are not the raw ones.
    let live = read_trial(&dir.path().join("stream.csv"), &model()).unwrap();
    let calf = (live.imu("l_calf").unwrap(), written.imu("l_calf").unwrap());
    let last = live.len() - 1;
    assert!(
        acm_workbench::rotation::angle_between_deg(
            &calf.0.orientation[last],
            &calf.1.orientation[last]
        ) > 1.0,
        "the last live row was not corrected"
    );
}

#[test]
fn a_functional_calibration_is_applied_live_and_in_the_final_correction() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // A calibration made as a lab makes it: a simulated calibration
    // session, solved by `acmw calibrate`.
    for args in [
        &[
            "simulate",
            "calibration",
            "--seed",
            "3",
            "-o",
            "c.calib.csv",
        ][..],
        &["calibrate", "c.calib.csv", "--quiet"][..],
    ] {
        let out = acmw().current_dir(d).args(args).output().unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let cal = "c.calibration.toml";
    assert!(d.join(cal).exists());
    // The trial's calibrated IMUs are mounted as the session's truth says:
    // `G_R_sensor = G_R_segment * R` (what the calibration undoes).
    let truth: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("c.calib.truth.json")).unwrap())
            .unwrap();
    let aligned = drifting(75.0, 11);
    let mut trial = aligned.clone();
    let calibrated_imus = [
        "upper_back",
        "l_upper_arm",
        "r_upper_arm",
        "l_forearm",
        "r_forearm",
    ];
    for imu in calibrated_imus {
        let q: Vec<f64> = truth["rotations"][imu]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap())
            .collect();
        let r = Quat::new_normalize(nalgebra::Quaternion::new(q[0], q[1], q[2], q[3]));
        for o in &mut trial.imu_mut(imu).unwrap().orientation {
            *o *= r;
        }
    }
    let input = d.join("growing.csv");
    let text = trial_to_string(&trial, TrialFormat::QuatCsv);
    let child = follow(d, &input, &["--calibration", cal]);
    write_in_fragments(&input, text.as_bytes(), 4.0, 4);
    let (_, stderr) = finish(child);
    assert!(
        stderr.contains("calibration c.calibration.toml (5 IMUs) applied to every row first"),
        "{stderr}"
    );
    assert!(stderr.contains("solved 0-"), "{stderr}");
    // The final correction and its sidecar are `acmw correct --calibration`'s.
    let (offline, offline_sidecar) = correct_with(d, &input, &["--calibration", cal]);
    assert!(
        std::fs::read(d.join("final.csv")).unwrap() == offline,
        "the final correction differs from acmw correct --calibration"
    );
    let fin_sidecar = sidecar(&d.join("final.json"));
    assert_eq!(fin_sidecar["calibration"]["file"], cal);
    assert_eq!(fin_sidecar, offline_sidecar);
    // ... and not the uncalibrated correction.
    let (uncalibrated, _) = correct(d, &input);
    assert!(uncalibrated != offline);
    // Every row streamed once; the base IMU (not calibrated) as written.
    let written = read_trial(&input, &model()).unwrap();
    check_stream(&d.join("stream.csv"), &written, TrialFormat::QuatCsv);
    // The first batch goes out before any solve can answer: calibrated, not
    // corrected, so its first row is that of the calibrated trial `acmw
    // correct --variant none --calibration` writes, to the last digit.
    correct_with(d, &input, &["--calibration", cal, "--variant", "none"]);
    let first_row = |path: &Path| {
        std::fs::read_to_string(path)
            .unwrap()
            .lines()
            .nth(1)
            .unwrap()
            .to_string()
    };
    let calibrated = first_row(&d.join("offline.csv"));
    assert_eq!(first_row(&d.join("stream.csv")), calibrated);
    assert_ne!(
        first_row(&input),
        calibrated,
        "the calibration turned nothing"
    );
    // The calibration undoes the mounting: the live first row's calibrated
    // IMUs are within 3 deg of the aligned sensors (`acmw calibrate` finds
    // the rotations to under 2 deg on this session).
    let live = read_trial(&d.join("stream.csv"), &model()).unwrap();
    for imu in calibrated_imus {
        let err = angle_between_deg(
            &live.imu(imu).unwrap().orientation[0],
            &aligned.imu(imu).unwrap().orientation[0],
        );
        assert!(
            err < 3.0,
            "{imu}: calibrated {err} deg from the aligned sensor"
        );
    }
    // Past the first solve the calibrated IMUs are corrected too, in the
    // calibrated frame: the last live row is nearer the final correction's
    // last row than the calibrated input's.
    let fin = read_trial(&d.join("final.csv"), &model()).unwrap();
    let none = read_trial(&d.join("offline.csv"), &model()).unwrap();
    let last = live.len() - 1;
    let q = |t: &Trial| t.imu("r_upper_arm").unwrap().orientation[last];
    let (to_final, raw_to_final) = (
        angle_between_deg(&q(&live), &q(&fin)),
        angle_between_deg(&q(&none), &q(&fin)),
    );
    assert!(
        to_final < raw_to_final,
        "r_upper_arm: live {to_final} deg from the final, the calibrated input {raw_to_final}"
    );
}

#[test]
fn a_pose_calibration_waits_for_its_span_then_calibrates_the_rows_after() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let input = d.join("growing.csv");
    let trial = drifting(60.0, 12);
    let text = trial_to_string(&trial, TrialFormat::QuatCsv);
    // The header and the first 3 s of rows land well before the span 5..6 s.
    let cut = text.match_indices('\n').nth(150).unwrap().0 + 1;
    let pose = ["--pose-calibration", "5..6", "--base-forward", "+x"];
    let child = follow(d, &input, &pose);
    write_in_fragments(&input, &text.as_bytes()[..cut], 0.3, 5);
    std::thread::sleep(Duration::from_millis(1000));
    write_in_fragments(&input, &text.as_bytes()[cut..], 3.0, 6);
    let (_, stderr) = finish(child);
    assert!(
        stderr.contains(
            "rows go out as read (neither calibrated nor corrected) until a row after 6 s arrives"
        ),
        "{stderr}"
    );
    assert!(
        stderr.contains("pose calibration at 5..6 s (51 samples)"),
        "{stderr}"
    );
    assert!(!stderr.contains("could not solve"), "{stderr}");
    // The final correction and its sidecar are `acmw correct`'s with the same flags.
    let (offline, offline_sidecar) = correct_with(d, &input, &pose);
    assert!(
        std::fs::read(d.join("final.csv")).unwrap() == offline,
        "the final correction differs from acmw correct --pose-calibration"
    );
    let fin_sidecar = sidecar(&d.join("final.json"));
    assert!(fin_sidecar["pose_calibration"].is_object(), "{fin_sidecar}");
    assert_eq!(fin_sidecar, offline_sidecar);
    // Every row once; the first 3 s exactly as written (before the span).
    let written = read_trial(&input, &model()).unwrap();
    let live = read_trial(&d.join("stream.csv"), &model()).unwrap();
    assert_eq!(live.time_s, written.time_s);
    let stream = std::fs::read_to_string(d.join("stream.csv")).unwrap();
    let expect = trial_to_string(&written, TrialFormat::QuatCsv);
    let lines = |t: &str| t.lines().take(151).map(String::from).collect::<Vec<_>>();
    assert!(
        lines(&stream) == lines(&expect),
        "the rows before the pose span are not as written"
    );
    // The last row is calibrated: its base IMU (which the ACM leaves alone)
    // is the final correction's, heading and offset applied, not the raw one.
    let fin = read_trial(&d.join("final.csv"), &model()).unwrap();
    let last = live.len() - 1;
    let base = |t: &Trial| t.imu("base").unwrap().orientation[last];
    let to_final = angle_between_deg(&base(&live), &base(&fin));
    assert!(to_final < 1e-4, "live base {to_final} deg from the final");
    assert!(angle_between_deg(&base(&written), &base(&fin)) > 1.0);
}

#[test]
fn a_six_decimal_trial_is_followed_and_written_at_six_decimals() {
    use acm_workbench::trial::precision::{decimals_of, Precision};
    use acm_workbench::trial::trial_to_string_at;
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("growing.csv");
    let text = trial_to_string_at(
        &drifting(60.0, 8),
        TrialFormat::QuatCsv,
        Precision::Decimals(6),
    );
    let child = follow(dir.path(), &input, &[]);
    write_in_fragments(&input, text.as_bytes(), 3.0, 4);
    finish(child);
    // Live rows (raw before the first solve, corrected after) and the final
    // correction: six decimals at most, the final equal to acmw correct's.
    let orientation_decimals = |text: &str| -> Vec<u8> {
        text.lines()
            .skip(1)
            .flat_map(|l| l.split(',').skip(1).map(decimals_of).collect::<Vec<_>>())
            .collect()
    };
    let stream = std::fs::read_to_string(dir.path().join("stream.csv")).unwrap();
    let fin = std::fs::read_to_string(dir.path().join("final.csv")).unwrap();
    for written in [&stream, &fin] {
        let d = orientation_decimals(written);
        assert!(d.iter().all(|&d| d <= 6) && d.iter().filter(|&&d| d == 6).count() > d.len() / 2);
    }
    let (offline, offline_sidecar) = correct(dir.path(), &input);
    assert!(
        fin.as_bytes() == offline,
        "the final correction differs from acmw correct"
    );
    assert_eq!(sidecar(&dir.path().join("final.json")), offline_sidecar);
    assert_eq!(offline_sidecar["output_precision"]["decimals"], 6);
    let written = read_trial(&input, &model()).unwrap();
    check_stream(
        &dir.path().join("stream.csv"),
        &written,
        TrialFormat::QuatCsv,
    );
}

#[test]
fn truncation_is_noticed_and_an_euler_trial_followed_from_its_start() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("growing.csv");
    let first = trial_to_string(&drifting(40.0, 6), TrialFormat::QuatCsv);
    let second_trial = drifting(60.0, 7);
    let second = trial_to_string(&second_trial, TrialFormat::EulerCsv);
    let child = follow(dir.path(), &input, &["--format", "euler-csv"]);
    write_in_fragments(&input, &first.as_bytes()[..first.len() * 2 / 3], 2.0, 2);
    std::thread::sleep(Duration::from_millis(800));
    // The writer starts again: the file is truncated and a new trial written.
    std::fs::OpenOptions::new()
        .write(true)
        .open(&input)
        .unwrap()
        .set_len(0)
        .unwrap();
    std::thread::sleep(Duration::from_millis(500));
    write_in_fragments(&input, second.as_bytes(), 3.0, 3);
    let (_, stderr) = finish(child);
    assert!(
        // Truncated (or, should the follower look only once the new trial
        // outgrew the old, rewritten): either way it starts over.
        (stderr.contains("was truncated") || stderr.contains("was rewritten"))
            && stderr.contains("starting over"),
        "{stderr}"
    );
    let written = read_trial(&input, &model()).unwrap();
    let out = acmw()
        .current_dir(dir.path())
        .arg("correct")
        .arg(&input)
        .args([
            "-o",
            "offline.csv",
            "-q",
            "--window",
            "30",
            "--hop",
            "15",
            "--format",
            "euler-csv",
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    assert_eq!(
        std::fs::read(dir.path().join("final.csv")).unwrap(),
        std::fs::read(dir.path().join("offline.csv")).unwrap()
    );
    check_stream(
        &dir.path().join("stream.csv"),
        &written,
        TrialFormat::EulerCsv,
    );
}

#[test]
fn until_stops_at_the_trial_time_and_corrects_the_rows_read() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("growing.csv");
    let trial = drifting(50.0, 8);
    std::fs::write(&input, trial_to_string(&trial, TrialFormat::QuatCsv)).unwrap();
    let start = Instant::now();
    let (_, stderr) = finish(follow(dir.path(), &input, &["--until", "35"]));
    assert!(start.elapsed() < Duration::from_secs(60));
    assert!(stderr.contains("continues past --until"), "{stderr}");
    let fin = read_trial(&dir.path().join("final.csv"), &model()).unwrap();
    let want = trial
        .time_s
        .partition_point(|&t| t - trial.time_s[0] <= 35.0 + 1e-9);
    assert_eq!(fin.len(), want);
    let live = read_trial(&dir.path().join("stream.csv"), &model()).unwrap();
    assert_eq!(live.time_s, fin.time_s);
}

#[test]
fn a_malformed_row_is_located_and_exits_3() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("growing.csv");
    let trial = drifting(2.0, 9);
    let text = trial_to_string(&trial, TrialFormat::QuatCsv);
    let mut lines: Vec<&str> = text.lines().take(4).collect();
    lines.push("0.08,1,0,0");
    std::fs::write(&input, lines.join("\n") + "\n").unwrap();
    let out = follow(dir.path(), &input, &[]).wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(stderr.contains("growing.csv:5:"), "{stderr}");
}

#[cfg(unix)]
#[test]
fn a_termination_signal_ends_following_with_the_final_correction() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("growing.csv");
    let trial = drifting(40.0, 10);
    std::fs::write(&input, trial_to_string(&trial, TrialFormat::QuatCsv)).unwrap();
    let child = acmw()
        .current_dir(dir.path())
        .arg("follow")
        .arg(&input)
        .args([
            "-o",
            "stream.csv",
            "--corrected",
            "final.csv",
            "--window",
            "30",
            "--hop",
            "15",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Wait until every row was streamed, then stop it as Ctrl-C would.
    let stream = dir.path().join("stream.csv");
    let start = Instant::now();
    while std::fs::read_to_string(&stream).map_or(0, |s| s.lines().count()) < trial.len() + 1 {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "rows never streamed"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    // SAFETY: kill(2) on the child's pid, which has not been reaped.
    assert_eq!(unsafe { libc::kill(child.id() as i32, libc::SIGTERM) }, 0);
    let (_, stderr) = finish(child);
    assert!(
        stderr.contains("interrupted; writing the final correction"),
        "{stderr}"
    );
    let (offline, _) = correct(dir.path(), &input);
    assert!(std::fs::read(dir.path().join("final.csv")).unwrap() == offline);
}

/// The first raw packet counter of the exports: the recording crosses the
/// 16-bit wrap a few seconds in.
const FIRST_PACKET: u64 = 65_300;

/// `trial` as a folder of MT Manager exports (one per IMU, 50 Hz, the
/// mapping XML beside them naming each sensor's IMU, base first): the
/// sensors start up to two packets before the trial's first and end up to
/// one after its last (those packets hold the nearest sample), the third
/// misses three packets (a gap every sensor's trial then has), and the
/// counters wrap from 65535 to 0. Returns the export paths and texts; only
/// the mapping is written.
fn xsens_exports(folder: &Path, trial: &Trial) -> Vec<(std::path::PathBuf, String)> {
    use std::fmt::Write as _;
    std::fs::create_dir_all(folder).unwrap();
    let n = trial.len() as u64;
    let serial = |k: usize| format!("00B4{k:04X}");
    let mut xml = String::from(
        "<?xml version=\"1.0\" encoding=\"UTF-8\" ?>\n<OpenSimDocument Version=\"40000\">\n\t<XsensDataReaderSettings>\n\t\t<trial_prefix>MT_LIVE-000</trial_prefix>\n\t\t<ExperimentalSensors>\n",
    );
    for (k, s) in trial.imus.iter().enumerate() {
        let _ = write!(
            xml,
            "\t\t\t<ExperimentalSensor name=\"_{}\">\n\t\t\t\t<name_in_model>{}</name_in_model>\n\t\t\t</ExperimentalSensor>\n",
            serial(k),
            s.name
        );
    }
    xml.push_str("\t\t</ExperimentalSensors>\n\t</XsensDataReaderSettings>\n</OpenSimDocument>\n");
    std::fs::write(folder.join("myIMUMappings.xml"), xml).unwrap();
    let mut out = Vec::new();
    for (k, s) in trial.imus.iter().enumerate() {
        let mut text = String::from(
            "// Start Time: Unknown\n// Update Rate: 50.0Hz\n// Filter Profile: human (46.1)\n",
        );
        text.push_str("PacketCounter\tSampleTimeFine\tQuat_q0\tQuat_q1\tQuat_q2\tQuat_q3");
        if s.gyro.is_some() {
            text.push_str("\tGyr_X\tGyr_Y\tGyr_Z");
        }
        text.push('\n');
        let first = FIRST_PACKET - (k as u64 % 3);
        let last = FIRST_PACKET + n - 1 + (k as u64 % 2);
        for c in first..=last {
            if k == 2 && (FIRST_PACKET + 400..FIRST_PACKET + 403).contains(&c) {
                continue;
            }
            let i = (c.clamp(FIRST_PACKET, FIRST_PACKET + n - 1) - FIRST_PACKET) as usize;
            let q = s.orientation[i];
            let _ = write!(
                text,
                "{:05}\t{}\t{}\t{}\t{}\t{}",
                c % 65_536,
                c * 200,
                q.w,
                q.i,
                q.j,
                q.k
            );
            if let Some(g) = &s.gyro {
                let _ = write!(text, "\t{}\t{}\t{}", g[i].x, g[i].y, g[i].z);
            }
            text.push('\n');
        }
        out.push((folder.join(format!("MT_LIVE-000_{}.txt", serial(k))), text));
    }
    out
}

/// Appends `parts[k]` to `paths[k]`, all of them at once as MT Manager
/// writes them: each step a random export gets a random fragment of
/// 1..=3000 bytes (cut anywhere), flushed, over about `seconds`.
fn write_exports_in_fragments(
    paths: &[std::path::PathBuf],
    parts: &[&[u8]],
    seconds: f64,
    seed: u64,
) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    let mut files: Vec<std::fs::File> = paths
        .iter()
        .map(|p| {
            std::fs::OpenOptions::new()
                .append(true)
                .create(true)
                .open(p)
                .unwrap()
        })
        .collect();
    let total: usize = parts.iter().map(|p| p.len()).sum();
    let per_byte = seconds / total.max(1) as f64;
    let mut pos = vec![0usize; parts.len()];
    loop {
        let open: Vec<usize> = (0..parts.len())
            .filter(|&k| pos[k] < parts[k].len())
            .collect();
        if open.is_empty() {
            break;
        }
        let k = open[rng.random_range(0..open.len())];
        let n = rng.random_range(1..=3000).min(parts[k].len() - pos[k]);
        files[k].write_all(&parts[k][pos[k]..pos[k] + n]).unwrap();
        files[k].flush().unwrap();
        pos[k] += n;
        std::thread::sleep(Duration::from_secs_f64(n as f64 * per_byte));
    }
}

/// `acmw follow FOLDER` with the final correction in `final.sto`.
fn follow_exports(dir: &Path, folder: &Path) -> Child {
    acmw()
        .current_dir(dir)
        .arg("follow")
        .arg(folder)
        .args([
            "-o",
            "stream.csv",
            "--corrected",
            "final.sto",
            "--sidecar",
            "final.json",
        ])
        .args([
            "--idle-exit",
            "2",
            "--window",
            "30",
            "--hop",
            "15",
            "--warmup",
            "5",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

/// `acmw correct FOLDER` into `offline.sto`, with the follower's settings.
fn correct_exports(dir: &Path, folder: &Path) -> (Vec<u8>, serde_json::Value) {
    let out = acmw()
        .current_dir(dir)
        .arg("correct")
        .arg(folder)
        .args(["-o", "offline.sto", "--sidecar", "offline.json", "-q"])
        .args(["--window", "30", "--hop", "15"])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    (
        std::fs::read(dir.join("offline.sto")).unwrap(),
        sidecar(&dir.join("offline.json")),
    )
}

#[test]
fn an_xsens_export_folder_is_followed_and_its_final_correction_equals_correct() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("exports");
    let trial = drifting(120.0, 11);
    let exports = xsens_exports(&folder, &trial);
    let paths: Vec<_> = exports.iter().map(|(p, _)| p.clone()).collect();
    let parts: Vec<&[u8]> = exports.iter().map(|(_, t)| t.as_bytes()).collect();
    // The follower starts before MT Manager has created the exports.
    let child = follow_exports(dir.path(), &folder);
    std::thread::sleep(Duration::from_millis(300));
    // 120 s of 13 sensors written in about 8 s (x15), from another thread.
    std::thread::scope(|s| {
        s.spawn(|| write_exports_in_fragments(&paths, &parts, 8.0, 12));
    });
    let (_, stderr) = finish(child);
    assert!(stderr.contains("solved 0-5.0 s"), "{stderr}");
    assert!(!stderr.contains("starting over"), "{stderr}");
    let (offline, offline_sidecar) = correct_exports(dir.path(), &folder);
    let fin = std::fs::read(dir.path().join("final.sto")).unwrap();
    assert!(
        fin == offline,
        "the final correction differs from acmw correct"
    );
    assert_eq!(sidecar(&dir.path().join("final.json")), offline_sidecar);
    // The stream holds every aligned row once (the gap's packets left out
    // of every sensor), the base IMU as the whole-folder reader reads it.
    let written = read_trial(&folder, &model()).unwrap();
    assert_eq!(written.len(), trial.len() - 3);
    check_stream(
        &dir.path().join("stream.csv"),
        &written,
        TrialFormat::QuatCsv,
    );
    let live = read_trial(&dir.path().join("stream.csv"), &model()).unwrap();
    let calf = (live.imu("l_calf").unwrap(), written.imu("l_calf").unwrap());
    let last = live.len() - 1;
    assert!(
        acm_workbench::rotation::angle_between_deg(
            &calf.0.orientation[last],
            &calf.1.orientation[last]
        ) > 1.0,
        "the last live row was not corrected"
    );
}

#[test]
fn a_truncated_export_starts_the_folder_over() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("exports");
    let trial = drifting(40.0, 13);
    let exports = xsens_exports(&folder, &trial);
    let paths: Vec<_> = exports.iter().map(|(p, _)| p.clone()).collect();
    let half: Vec<&[u8]> = exports
        .iter()
        .map(|(_, t)| &t.as_bytes()[..t.len() / 2])
        .collect();
    let child = follow_exports(dir.path(), &folder);
    write_exports_in_fragments(&paths, &half, 1.5, 14);
    std::thread::sleep(Duration::from_millis(800));
    // MT Manager starts one export over: truncated, then written again.
    std::fs::OpenOptions::new()
        .write(true)
        .open(&paths[4])
        .unwrap()
        .set_len(0)
        .unwrap();
    std::thread::sleep(Duration::from_millis(500));
    let rest: Vec<&[u8]> = exports
        .iter()
        .enumerate()
        .map(|(k, (_, t))| {
            let b = t.as_bytes();
            if k == 4 {
                b
            } else {
                &b[b.len() / 2..]
            }
        })
        .collect();
    write_exports_in_fragments(&paths, &rest, 1.5, 15);
    let (_, stderr) = finish(child);
    assert!(
        stderr.contains("export MT_LIVE-000_00B40004.txt was truncated")
            && stderr.contains("starting over"),
        "{stderr}"
    );
    let (offline, _) = correct_exports(dir.path(), &folder);
    assert!(std::fs::read(dir.path().join("final.sto")).unwrap() == offline);
    let written = read_trial(&folder, &model()).unwrap();
    check_stream(
        &dir.path().join("stream.csv"),
        &written,
        TrialFormat::QuatCsv,
    );
}
