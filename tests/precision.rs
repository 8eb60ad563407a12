//! Outputs keep the precision of their input (issue 19 item 4): a trial
//! whose quaternions have six decimals is written back with six decimals,
//! the text of what the correction leaves unchanged comes back as it was
//! read, and `--precision full` writes today's shortest round-trip digits.
//! Each test writes the input file, runs `acmw correct` and reads the
//! files it wrote.
//!
//! The bound on the joint angles: a unit quaternion `q` rounded to six
//! decimals, `q6`, is off by at most 0.5e-6 per component, so
//! `|q6 - q| <= 1e-6`; the angle `a` between `q6` and `q` as 4-vectors has
//! `sin a <= |q6 - q| / |q| = 1e-6`, and renormalising when reading does not
//! change it, so the two rotations differ by `2a <= 2e-6` rad = 1.15e-4
//! degrees. A joint rotation `p^-1 d` combines two such IMUs: it moves by at
//! most [`JOINT_BOUND_DEG`] = 2.3e-4 degrees, and each of its Z-Y-X angles
//! by at most that over `|cos(y)|` (first order; the rows of the map from a
//! small rotation to the Z-Y-X angle changes have norms `1/|cos y|`, 1 and
//! `1/|cos y|`).

mod common;

use acm_workbench::model::Model;
use acm_workbench::rotation::{angle_deg, euler_zyx_deg, Quat};
use acm_workbench::simulate::{simulate_with, SimConfig};
use acm_workbench::trial::precision::{decimals_of, quaternion_round_trips, AngleNumbers};
use acm_workbench::trial::{read_trial, Trial};
use common::acmw_ok;
use std::path::Path;

/// Most a joint rotation moves between a six-decimal output and a full one, degrees.
const JOINT_BOUND_DEG: f64 = 2.3e-4;

/// A 12 s, 50 Hz simulated infant trial (13 IMUs).
fn simulated() -> Trial {
    let model = Model::infant13();
    let mut cfg = SimConfig::full_body(19);
    cfg.duration_s = 12.0;
    simulate_with(&cfg, &model).unwrap().trial
}

/// The text of `k` millionths with six decimals, trailing zeros trimmed.
fn millionths(k: i64, padded: bool) -> String {
    let text = format!("{:.6}", k as f64 / 1e6);
    if padded {
        return text;
    }
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// `q` (with `w >= 0`) at six decimals, rounded up or down per component so
/// that the text round-trips ([`quaternion_round_trips`]): of the sixteen
/// roundings, the first that does, nearest to unit norm first.
fn six_decimals(q: &Quat, padded: bool) -> [String; 4] {
    let c = [q.w, q.i, q.j, q.k];
    let mut options: Vec<([i64; 4], f64)> = (0..16)
        .map(|bits| {
            let k: [i64; 4] = std::array::from_fn(|i| {
                let scaled = c[i] * 1e6;
                (if bits & (1 << i) == 0 {
                    scaled.floor()
                } else {
                    scaled.ceil()
                }) as i64
            });
            let norm = k.iter().map(|&v| (v as f64 * 1e-6).powi(2)).sum::<f64>();
            (k, (norm.sqrt() - 1.0).abs())
        })
        .collect();
    options.sort_by(|a, b| a.1.total_cmp(&b.1));
    let k = options
        .iter()
        .map(|(k, _)| *k)
        .find(|k| {
            let parsed = k.map(|v| millionths(v, false).parse::<f64>().unwrap());
            quaternion_round_trips(parsed, 6)
        })
        .expect("a rounding that round-trips");
    k.map(|v| millionths(v, padded))
}

/// The trial as a canonical CSV with six-decimal quaternions that round-trip.
fn six_decimal_csv(trial: &Trial, padded: bool) -> String {
    let mut out = String::from("time");
    for s in &trial.imus {
        for p in ["qw", "qx", "qy", "qz"] {
            out.push_str(&format!(",{}_{p}", s.name));
        }
    }
    out.push('\n');
    for (i, t) in trial.time_s.iter().enumerate() {
        out.push_str(&t.to_string());
        for s in &trial.imus {
            let q = acm_workbench::rotation::canonical(&s.orientation[i]);
            for c in six_decimals(&q, padded) {
                out.push(',');
                out.push_str(&c);
            }
        }
        out.push('\n');
    }
    out
}

/// `text` with every third data row's quaternions negated (`w < 0`; the
/// same rotations).
fn negate_some_rows(text: &str) -> String {
    let mut out = String::new();
    for (n, line) in text.lines().enumerate() {
        if n == 0 || n % 3 != 0 {
            out.push_str(line);
        } else {
            let cells: Vec<String> = line
                .split(',')
                .enumerate()
                .map(|(k, c)| match (k, c.strip_prefix('-')) {
                    (0, _) => c.to_string(),
                    (_, Some(positive)) => positive.to_string(),
                    (_, None) => format!("-{c}"),
                })
                .collect();
            out.push_str(&cells.join(","));
        }
        out.push('\n');
    }
    out
}

/// Runs `acmw correct input --variant V -o output` with short windows and `extra`.
fn correct(dir: &Path, input: &str, variant: &str, output: &str, extra: &[&str]) -> String {
    let mut args = vec![
        "correct",
        input,
        "--variant",
        variant,
        "-o",
        output,
        "--window",
        "4",
        "--hop",
        "2",
        "-q",
    ];
    args.extend(extra);
    acmw_ok(dir, &args);
    std::fs::read_to_string(dir.join(output)).unwrap()
}

#[test]
fn an_uncorrected_six_decimal_trial_is_written_back_as_its_own_text() {
    let dir = tempfile::tempdir().unwrap();
    let trial = simulated();
    for padded in [false, true] {
        let input = six_decimal_csv(&trial, padded);
        std::fs::write(dir.path().join("in.csv"), &input).unwrap();
        let read = read_trial(&dir.path().join("in.csv"), &Model::infant13()).unwrap();
        let d = read.orientation_decimals.unwrap();
        assert_eq!((d.numbers, d.most), (AngleNumbers::Quaternion, 6));
        assert_eq!(d.padded(), padded);
        let out = correct(dir.path(), "in.csv", "none", "none.csv", &[]);
        assert!(out == input, "padded {padded}: the text changed");
        // At full precision the same trial takes more room.
        let full = correct(
            dir.path(),
            "in.csv",
            "none",
            "full.csv",
            &["--precision", "full"],
        );
        assert!(
            full.len() > input.len() * 3 / 2,
            "{} vs {}",
            full.len(),
            input.len()
        );
    }
}

#[test]
fn rows_read_with_w_below_zero_come_back_with_their_signs_flipped() {
    let dir = tempfile::tempdir().unwrap();
    let input = six_decimal_csv(&simulated(), false);
    let flipped = negate_some_rows(&input);
    assert_ne!(flipped, input);
    std::fs::write(dir.path().join("in.csv"), &flipped).unwrap();
    let out = correct(dir.path(), "in.csv", "none", "none.csv", &[]);
    // The writer puts w >= 0: every row as it was before its signs flipped
    // (no w of the trial is exactly 0, whose sign the writer keeps).
    assert!(
        out == input,
        "the negated rows did not come back as written"
    );
}

#[test]
fn a_corrected_six_decimal_trial_keeps_six_decimals_and_its_base_imu_text() {
    let dir = tempfile::tempdir().unwrap();
    let model = Model::infant13();
    let input = six_decimal_csv(&simulated(), false);
    std::fs::write(dir.path().join("in.csv"), &input).unwrap();
    let six = correct(dir.path(), "in.csv", "drift-centroid", "six.csv", &[]);
    let full = correct(
        dir.path(),
        "in.csv",
        "drift-centroid",
        "full.csv",
        &["--precision", "full"],
    );
    assert_ne!(six, full);
    // The base IMU is not corrected: its columns are the input's text.
    let base_columns = |text: &str| -> Vec<String> {
        let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
        let first = header
            .iter()
            .position(|h| *h == format!("{}_qw", model.base))
            .unwrap();
        text.lines()
            .skip(1)
            .map(|l| {
                l.split(',')
                    .skip(first)
                    .take(4)
                    .collect::<Vec<_>>()
                    .join(",")
            })
            .collect()
    };
    assert_eq!(base_columns(&six), base_columns(&input));
    // Every orientation number has at most six decimals; at full precision most have more.
    let numbers = |text: &str| -> Vec<u8> {
        text.lines()
            .skip(1)
            .flat_map(|l| l.split(',').skip(1).map(decimals_of).collect::<Vec<_>>())
            .collect()
    };
    assert!(numbers(&six).iter().all(|&d| d <= 6));
    assert!(numbers(&full).iter().filter(|&&d| d > 6).count() > numbers(&full).len() / 2);
    // The corrected joint angles read back from both agree to the bound.
    let read = |name: &str| read_trial(&dir.path().join(name), &model).unwrap();
    let (six, full) = (read("six.csv"), read("full.csv"));
    let mut worst = 0.0f64;
    for joint in &model.joints {
        let rel = |t: &Trial, i: usize| {
            let p = t.imu(&joint.proximal).unwrap().orientation[i];
            let d = t.imu(&joint.distal).unwrap().orientation[i];
            p.inverse() * d
        };
        for i in 0..six.len() {
            let (a, b) = (rel(&six, i), rel(&full, i));
            let moved = angle_deg(&(a.inverse() * b));
            worst = worst.max(moved);
            assert!(moved <= JOINT_BOUND_DEG, "{}: {moved} deg", joint.name);
            let (ea, eb) = (euler_zyx_deg(&a), euler_zyx_deg(&b));
            let cos_y = eb[1].to_radians().cos().abs();
            for k in 0..3 {
                let diff = (ea[k] - eb[k] + 180.0).rem_euclid(360.0) - 180.0;
                assert!(
                    diff.abs() <= JOINT_BOUND_DEG / cos_y * 1.01,
                    "{} angle {k}: {diff} deg (cos y {cos_y})",
                    joint.name
                );
            }
        }
    }
    assert!(worst > 0.0, "six and full decimals read back alike");
    // The sidecars record what was asked for and what was written.
    let sidecar = |name: &str| -> serde_json::Value {
        let text = std::fs::read_to_string(dir.path().join(format!("{name}.acmw.json"))).unwrap();
        serde_json::from_str(&text).unwrap()
    };
    let (s6, sf) = (sidecar("six.csv"), sidecar("full.csv"));
    assert_eq!(s6["output_precision"]["decimals"], 6);
    assert_eq!(s6["output_precision"]["padded"], false);
    assert!(s6["settings"].get("precision").is_none());
    assert!(sf.get("output_precision").is_none());
    assert_eq!(sf["settings"]["precision"], "full");
}

#[test]
fn precision_n_and_from_sidecar_reproduce_the_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let input = six_decimal_csv(&simulated(), false);
    std::fs::write(dir.path().join("in.csv"), &input).unwrap();
    let three = correct(
        dir.path(),
        "in.csv",
        "drift-centroid",
        "three.csv",
        &["--precision", "3"],
    );
    assert!(three
        .lines()
        .skip(1)
        .flat_map(|l| l.split(',').skip(1).map(decimals_of).collect::<Vec<_>>())
        .all(|d| d <= 3));
    // Same input and settings, same bytes: again, and from its sidecar.
    let again = correct(
        dir.path(),
        "in.csv",
        "drift-centroid",
        "again.csv",
        &["--precision", "3"],
    );
    assert!(again == three);
    acmw_ok(
        dir.path(),
        &[
            "correct",
            "in.csv",
            "--from-sidecar",
            "three.csv.acmw.json",
            "-o",
            "replay.csv",
            "-q",
        ],
    );
    assert!(std::fs::read_to_string(dir.path().join("replay.csv")).unwrap() == three);
    // The same precision from the lab's settings file, the flag overriding it.
    let limits = dir.path().join("joint_limits");
    std::fs::create_dir(&limits).unwrap();
    let settings =
        acm_workbench::limits::BUILTIN_SETTINGS.replace("precision = \"auto\"", "precision = 3");
    assert!(settings.contains("precision = 3"));
    std::fs::write(limits.join("settings.toml"), settings).unwrap();
    let from_settings = correct(dir.path(), "in.csv", "drift-centroid", "set.csv", &[]);
    assert!(from_settings == three);
    let sidecar = std::fs::read_to_string(dir.path().join("set.csv.acmw.json")).unwrap();
    assert!(sidecar.contains("\"precision\": \"3\""), "{sidecar}");
    let overridden = correct(
        dir.path(),
        "in.csv",
        "drift-centroid",
        "full.csv",
        &["--precision", "full"],
    );
    assert!(overridden != three);
    assert!(overridden
        .lines()
        .skip(1)
        .flat_map(|l| l.split(',').skip(1).map(decimals_of).collect::<Vec<_>>())
        .any(|d| d > 6));
    let bad = common::acmw(dir.path(), &["correct", "in.csv", "--precision", "18"]);
    assert!(!bad.status.success());
    let message = String::from_utf8_lossy(&bad.stderr);
    assert!(message.contains("0..=17"), "{message}");
}

/// The figures the README quotes: size and write time of a 5-minute
/// 13-IMU trial (50 Hz) at six decimals against full precision. Run with
/// `cargo test --test precision -- --ignored --nocapture` (one run; times
/// vary with the machine).
#[test]
#[ignore]
fn size_and_write_time_of_a_five_minute_trial() {
    use acm_workbench::trial::precision::Precision;
    use acm_workbench::trial::{write_trial_hashed, TrialFormat};
    use std::time::Instant;
    let dir = tempfile::tempdir().unwrap();
    let model = Model::infant13();
    let sim = simulate_with(&SimConfig::full_body(5), &model)
        .unwrap()
        .trial;
    let six = dir.path().join("six.csv");
    write_trial_hashed(&sim, &six, TrialFormat::QuatCsv, Precision::Decimals(6)).unwrap();
    let trial = read_trial(&six, &model).unwrap();
    assert_eq!(trial.orientation_decimals.map(|d| d.most), Some(6));
    let mut sizes = Vec::new();
    for (name, precision) in [("auto.csv", Precision::Auto), ("full.csv", Precision::Full)] {
        let path = dir.path().join(name);
        let start = Instant::now();
        write_trial_hashed(&trial, &path, TrialFormat::QuatCsv, precision).unwrap();
        let elapsed = start.elapsed();
        let size = std::fs::metadata(&path).unwrap().len();
        println!(
            "{} samples x {} IMUs, {precision}: {size} bytes in {:.1} ms",
            trial.len(),
            trial.imus.len(),
            elapsed.as_secs_f64() * 1e3
        );
        sizes.push(size);
    }
    assert!(sizes[0] < sizes[1]);
}
