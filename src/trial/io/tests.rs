//! Tests of trial reading and writing: round trips, malformed input, names.

mod gyro;
mod precision;

use super::*;
use crate::rotation::{angle_between_deg, quat_from_euler_zyx_deg, quat_from_wxyz, Quat};
use crate::trial::ImuSeries;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::PathBuf;

pub(super) fn infant() -> Model {
    Model::infant13()
}

pub(super) fn opensim() -> Model {
    Model::builtin("opensim").unwrap()
}

/// A trial of `names` with random orientations, pitch kept within +-80 degrees
/// (away from the Euler singularity) and slightly irregular times.
pub(super) fn random_trial(names: &[&str], n: usize, seed: u64) -> Trial {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut t = rng.random_range(-5.0..5.0);
    let time_s: Vec<f64> = (0..n)
        .map(|_| {
            t += 0.01 + rng.random_range(0.0..0.001);
            t
        })
        .collect();
    let imus = names
        .iter()
        .map(|name| {
            let orientation = (0..n)
                .map(|_| {
                    let q = quat_from_euler_zyx_deg([
                        rng.random_range(-179.9..179.9),
                        rng.random_range(-80.0..80.0),
                        rng.random_range(-179.9..179.9),
                    ]);
                    // Half of them with negative w, to exercise sign handling.
                    if rng.random_bool(0.5) {
                        Quat::new_unchecked(-q.into_inner())
                    } else {
                        q
                    }
                })
                .collect();
            ImuSeries::new(*name, orientation)
        })
        .collect();
    Trial {
        name: "random".into(),
        time_s,
        imus,
        warnings: vec![],
        orientation_decimals: None,
    }
}

/// Same times exactly; same rotations to `tol` (as rotations, up to sign).
fn assert_same(a: &Trial, b: &Trial, tol_deg: f64) {
    assert_eq!(a.time_s, b.time_s);
    assert_eq!(a.imus.len(), b.imus.len());
    for (sa, sb) in a.imus.iter().zip(&b.imus) {
        assert_eq!(sa.name, sb.name);
        assert_eq!(sa.orientation.len(), sb.orientation.len());
        for (qa, qb) in sa.orientation.iter().zip(&sb.orientation) {
            let dot = qa.into_inner().dot(&qb.into_inner()).abs();
            assert!((1.0 - dot).abs() < 1e-9, "{qa:?} vs {qb:?}");
            assert!(angle_between_deg(qa, qb) < tol_deg, "{qa:?} vs {qb:?}");
        }
    }
}

const NAMES: [&str; 4] = ["base", "l_thigh", "l_calf", "head"];

fn round_trip_file(file: &str, format: TrialFormat, model: &Model, names: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(file);
    let trial = random_trial(names, 200, 7);
    write_trial(&trial, &path, format).unwrap();
    let back = read_trial(&path, model).unwrap();
    assert_eq!(back.name, file);
    assert!(back.warnings.is_empty(), "{:?}", back.warnings);
    assert_same(&trial, &back, 1e-9);
    let (f, gz) = detect_format(&path).unwrap();
    assert_eq!(
        (f, gz),
        (format, file.to_ascii_lowercase().ends_with(".gz"))
    );
    let head = read_trial_header(&path, model).unwrap();
    assert_eq!(head.format, format);
    assert_eq!(head.imus, names);
    assert!(head.unknown_imus.is_empty());
}

#[test]
fn trial_round_trip_quat_csv() {
    round_trip_file("walk.csv", TrialFormat::QuatCsv, &infant(), &NAMES);
}

#[test]
fn trial_round_trip_euler_csv() {
    round_trip_file("um6.csv", TrialFormat::EulerCsv, &infant(), &NAMES);
}

#[test]
fn trial_round_trip_sto() {
    let names = ["pelvis_imu", "torso_imu", "tibia_r_imu"];
    round_trip_file("opensense.sto", TrialFormat::Sto, &opensim(), &names);
}

#[test]
fn trial_round_trip_gzip() {
    round_trip_file("walk.csv.gz", TrialFormat::QuatCsv, &infant(), &NAMES);
    round_trip_file("um6.CSV.GZ", TrialFormat::EulerCsv, &infant(), &NAMES);
    let names = ["pelvis_imu", "femur_l_imu"];
    round_trip_file("o.sto.gz", TrialFormat::Sto, &opensim(), &names);
}

#[test]
fn trial_round_trip_through_strings() {
    let trial = random_trial(&NAMES, 50, 11);
    for format in [
        TrialFormat::QuatCsv,
        TrialFormat::EulerCsv,
        TrialFormat::Sto,
    ] {
        let text = trial_to_string(&trial, format);
        let back = read_trial_from_str(&text, "dir/x.txt", format, &infant()).unwrap();
        assert_eq!(back.name, "x.txt");
        assert_same(&trial, &back, 1e-9);
    }
}

#[test]
fn trial_written_shapes() {
    let mut trial = random_trial(&["base", "head"], 3, 3);
    trial.time_s = vec![0.0, 0.01, 0.02];
    let csv = trial_to_string(&trial, TrialFormat::QuatCsv);
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "time,base_qw,base_qx,base_qy,base_qz,head_qw,head_qx,head_qy,head_qz"
    );
    for l in lines {
        let f: Vec<f64> = l.split(',').map(|c| c.parse().unwrap()).collect();
        assert_eq!(f.len(), 9);
        assert!(f[1] >= 0.0 && f[5] >= 0.0, "w >= 0: {l}");
    }
    let eul = trial_to_string(&trial, TrialFormat::EulerCsv);
    assert!(eul.starts_with("time,base_roll,base_pitch,base_yaw,head_roll,head_pitch,head_yaw\n"));
    let sto = trial_to_string(&trial, TrialFormat::Sto);
    assert!(
        sto.starts_with(
            "\nDataRate=100.000000\nDataType=Quaternion\nversion=3\nOpenSimVersion=4.1\nendheader\ntime\tbase\thead\n0\t"
        ),
        "{sto}"
    );
    let row = sto.lines().nth(7).unwrap();
    assert_eq!(row.split('\t').count(), 3);
    assert_eq!(row.split('\t').nth(1).unwrap().split(',').count(), 4);
}

#[test]
fn trial_euler_matches_um6_convention() {
    let text = "time,base_roll,base_pitch,base_yaw\n0,10,20,30\n0.02,0,0,90\n";
    let t = read_trial_from_str(text, "um6.csv", TrialFormat::EulerCsv, &infant()).unwrap();
    let q = t.imus[0].orientation[0];
    let want = quat_from_euler_zyx_deg([10.0, 20.0, 30.0]);
    assert!(angle_between_deg(&q, &want) < 1e-9);
    // yaw 90 deg: a rotation about the global Z axis
    let z90 = crate::rotation::quat_axis_angle_deg([0.0, 0.0, 1.0], 90.0);
    assert!(angle_between_deg(&t.imus[0].orientation[1], &z90) < 1e-9);
}

#[test]
fn trial_reads_opensense_shaped_sto() {
    // The shape OpenSense writes: blank first line, header, tab-separated labels,
    // one `w,x,y,z` cell per IMU.
    let text =
        "\nDataRate=100.000000\nDataType=Quaternion\nversion=3\nOpenSimVersion=4.1\nendheader\n\
time\ttorso_imu\tpelvis_imu\n\
417\t0.5,0.5,-0.5,0.5\t1,0,0,0\n\
417.01\t0.5,0.5,-0.5,0.5\t0,1,0,0\n";
    let t = read_trial_from_str(text, "a/b/swing.sto", TrialFormat::Sto, &opensim()).unwrap();
    assert_eq!(t.name, "swing.sto");
    assert_eq!(t.time_s, [417.0, 417.01]);
    assert_eq!(t.imus[0].name, "torso_imu");
    assert_eq!(t.imus[1].name, "pelvis_imu");
    let q = quat_from_wxyz([0.0, 1.0, 0.0, 0.0]);
    assert!(angle_between_deg(&t.imus[1].orientation[1], &q) < 1e-12);
    // CRLF line endings and a name line before the header are accepted too.
    let crlf = text.replace('\n', "\r\n").replacen("\r\n", "swing\r\n", 1);
    let t2 = read_trial_from_str(&crlf, "swing.sto", TrialFormat::Sto, &opensim()).unwrap();
    assert_eq!(t2.imus, t.imus);
}

#[test]
fn trial_alias_mapping_and_unknown_imu() {
    let text = "time,L_Calf_qw,L_Calf_qx,L_Calf_qy,L_Calf_qz,pelvis_qw,pelvis_qx,pelvis_qy,pelvis_qz,tail_qw,tail_qx,tail_qy,tail_qz\n\
0,1,0,0,0,1,0,0,0,1,0,0,0\n";
    let t = read_trial_from_str(text, "walk.csv", TrialFormat::QuatCsv, &infant()).unwrap();
    let names: Vec<&str> = t.imus.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["l_calf", "base", "tail"]);
    assert_eq!(t.warnings.len(), 1, "{:?}", t.warnings);
    let w = &t.warnings[0];
    assert!(
        w.contains("'tail'") && w.contains("column 10") && w.contains("not in model infant13"),
        "{w}"
    );
    // The same through the header-only reader.
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("walk.csv");
    std::fs::write(&p, text).unwrap();
    let h = read_trial_header(&p, &infant()).unwrap();
    assert_eq!(h.imus, ["l_calf", "base"]);
    assert_eq!(h.unknown_imus, ["tail"]);
    assert_eq!((h.format, h.gzip), (TrialFormat::QuatCsv, false));
    // .sto aliases of the OpenSim model
    let sto = "endheader\ntime\tpelvis\tTibia_R\n0\t1,0,0,0\t1,0,0,0\n";
    let t = read_trial_from_str(sto, "o.sto", TrialFormat::Sto, &opensim()).unwrap();
    assert_eq!(t.imus[0].name, "pelvis_imu");
    assert_eq!(t.imus[1].name, "tibia_r_imu");
}

#[test]
fn trial_renormalisation_warning() {
    let text = "time,head_qw,head_qx,head_qy,head_qz,base_qw,base_qx,base_qy,base_qz\n\
0,1.005,0,0,0,1,0,0,0\n\
1,0.996,0,0,0,1,0,0,0\n\
2,1.009,0,0,0,0.70710678,0.70710678,0,0\n\
3,1,0,0,0,1,0,0,0\n";
    let t = read_trial_from_str(text, "walk.csv", TrialFormat::QuatCsv, &infant()).unwrap();
    assert_eq!(t.warnings.len(), 1, "{:?}", t.warnings);
    let w = &t.warnings[0];
    assert!(
        w.starts_with("head:")
            && w.contains("renormalised 3 of 4")
            && w.contains("worst norm 1.009 on line 4"),
        "{w}"
    );
    for q in &t.imus[0].orientation {
        assert!((q.into_inner().norm() - 1.0).abs() < 1e-15);
    }
}

#[test]
fn trial_missing_imus_and_blank_lines_are_fine() {
    let text = "\n\ntime,base_qw,base_qx,base_qy,base_qz\n0,1,0,0,0\n\n0.01, 1 ,0,0,0\n\n";
    let t = read_trial_from_str(text, "walk.csv", TrialFormat::QuatCsv, &infant()).unwrap();
    assert_eq!(t.len(), 2);
    assert_eq!(t.imus.len(), 1);
    assert!(t.warnings.is_empty());
}

#[test]
fn trial_file_names() {
    for yes in ["a.csv", "dir/B.CSV", "x.sto", "x.csv.gz", "x.sto.gz"] {
        assert!(is_trial_file(Path::new(yes)), "{yes}");
    }
    for no in [
        "a.truth.csv",
        "a.truth.csv.gz",
        "a.truth.sto",
        "a.json",
        "a.csv.json",
        "a.csv.bak",
        "a.gz",
        ".csv",
        "a.txt",
        "dir/",
        "",
    ] {
        assert!(!is_trial_file(Path::new(no)), "{no}");
    }
    let e = detect_format(Path::new("x.dat")).unwrap_err();
    assert!(e.message.contains("Xsens MT Manager export"), "{e}");
    // A .txt names an Xsens export.
    assert_eq!(
        detect_format(Path::new("x.txt")).unwrap(),
        (TrialFormat::Xsens, false)
    );
}

#[test]
fn trial_write_keeps_backup_and_checks_names() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("w.csv");
    let t = random_trial(&["base"], 5, 1);
    write_trial(&t, &p, TrialFormat::QuatCsv).unwrap();
    write_trial(&t, &p, TrialFormat::EulerCsv).unwrap();
    assert!(crate::save::backup_path(&p).exists());
    assert_eq!(detect_format(&p).unwrap(), (TrialFormat::EulerCsv, false));
    let e = write_trial(&t, &dir.path().join("w.sto"), TrialFormat::QuatCsv).unwrap_err();
    assert!(e.message.contains("expected a name ending in .csv"), "{e}");
    let mut bad = t.clone();
    bad.imus[0].orientation.pop();
    let e = write_trial(&bad, &p, TrialFormat::QuatCsv).unwrap_err();
    assert!(e.message.contains("has 4 samples"), "{e}");
}

// ---------------------------------------------------------------------------
// Malformed input: each case names the exact line, column and a key phrase.

const Q: TrialFormat = TrialFormat::QuatCsv;
const E: TrialFormat = TrialFormat::EulerCsv;
const S: TrialFormat = TrialFormat::Sto;
const HDR: &str = "time,base_qw,base_qx,base_qy,base_qz\n";
const STO_HDR: &str =
    "\nDataRate=100\nDataType=Quaternion\nendheader\ntime\tpelvis_imu\ttorso_imu\n";

pub(super) fn check(text: &str, format: TrialFormat, line: u64, column: usize, phrase: &str) {
    let model = if format == S { opensim() } else { infant() };
    let origin = if format == S { "run.sto" } else { "walk.csv" };
    let e = read_trial_from_str(text, origin, format, &model)
        .expect_err(&format!("should fail: {text:?}"));
    assert_eq!(e.file, origin);
    assert_eq!(
        (e.line, e.column),
        (line, column),
        "wrong place for {text:?}: {e}"
    );
    assert!(e.message.contains(phrase), "{e} lacks {phrase:?}");
    let shown = e.to_string();
    assert!(
        shown.starts_with(&format!("{origin}:{line}:{column}: ")),
        "{shown}"
    );
}

#[test]
fn trial_malformed_headers() {
    check("", Q, 1, 1, "empty file");
    check("\n  \n", Q, 1, 1, "empty file");
    check(
        "t,base_qw,base_qx,base_qy,base_qz\n0,1,0,0,0\n",
        Q,
        1,
        1,
        "expected the first column to be 'time', found 't'",
    );
    check("time\n0\n", Q, 1, 2, "no IMU columns");
    check("time,foo\n0,1\n", Q, 1, 2, "expected a column '<imu>_qw'");
    check(
        "time,base_qw,base_qy,base_qx,base_qz\n",
        Q,
        1,
        3,
        "expected column 'base_qx' after 'base_qw'",
    );
    check(
        "time,base_qw,base_qx\n",
        Q,
        1,
        4,
        "found the end of the header line",
    );
    check(
        "time,base_qw,base_qx,base_qy,head_qz\n",
        Q,
        1,
        5,
        "expected column 'base_qz'",
    );
    check(
        "time,l_calf_qw,l_calf_qx,l_calf_qy,l_calf_qz,L_Calf_qw,L_Calf_qx,L_Calf_qy,L_Calf_qz\n",
        Q,
        1,
        6,
        "repeated IMU: 'L_Calf' is 'l_calf', already in column 2",
    );
    check(
        "time,base_roll,base_yaw,base_pitch\n",
        E,
        1,
        3,
        "expected column 'base_pitch'",
    );
    check(HDR, E, 1, 2, "expected a column '<imu>_roll'");
}

#[test]
fn trial_malformed_rows() {
    let h = HDR;
    check(
        &format!("{h}0,1,0,0\n"),
        Q,
        2,
        5,
        "too few fields: expected 5 comma-separated fields, found 4",
    );
    check(
        &format!("{h}0,1,0,0,0\n0.1,1,0,0,0,0\n"),
        Q,
        3,
        6,
        "too many fields: expected 5 comma-separated fields, found 6",
    );
    check(
        &format!("{h}0,1,0,0,0\n0.1,1,abc,0,0\n"),
        Q,
        3,
        3,
        "expected a number for base_qx, found 'abc'",
    );
    check(
        &format!("{h}0,1,,0,0\n"),
        Q,
        2,
        3,
        "expected a number for base_qx, found an empty cell",
    );
    check(
        &format!("{h}0,1,0,NaN,0\n"),
        Q,
        2,
        4,
        "expected a finite number for base_qy, found 'NaN'",
    );
    check(
        &format!("{h}0,1,0,0,-inf\n"),
        Q,
        2,
        5,
        "expected a finite number for base_qz, found '-inf'",
    );
    check(
        &format!("{h}x,1,0,0,0\n"),
        Q,
        2,
        1,
        "expected a number for time, found 'x'",
    );
    check(
        &format!("{h}0,1,0,0,0\n0.01,1,0,0,0\n0.01,1,0,0,0\n"),
        Q,
        4,
        1,
        "repeated time 0.01 (also on line 3)",
    );
    check(
        &format!("{h}0,1,0,0,0\n0.01,1,0,0,0\n\n0.005,1,0,0,0\n"),
        Q,
        5,
        1,
        "time 0.005 is before the previous time 0.01 (line 3)",
    );
    check(
        &format!("{h}0,1.5,0,0,0\n"),
        Q,
        2,
        2,
        "expected a unit quaternion for base (norm within 0.01 of 1), found norm 1.5",
    );
    check(
        &format!("{h}0,1,0,0,0\n1,0,0,0,0\n"),
        Q,
        3,
        2,
        "found the zero quaternion",
    );
    check(&format!("{h}0,0.98,0,0,0\n"), Q, 2, 2, "found norm 0.98");
    check(
        h,
        Q,
        2,
        1,
        "no samples: expected data rows after the header on line 1",
    );
    check(
        "time,base_roll,base_pitch,base_yaw\n0,1,2\n",
        E,
        2,
        4,
        "expected 4 comma-separated fields, found 3",
    );
    check(
        "time,base_roll,base_pitch,base_yaw\n0,1,x,3\n",
        E,
        2,
        3,
        "expected a number for base_pitch, found 'x'",
    );
    check(
        "time,base_roll,base_pitch,base_yaw\n0,1,inf,3\n",
        E,
        2,
        3,
        "expected a finite number for base_pitch",
    );
}

#[test]
fn trial_malformed_sto() {
    check(
        "time\tpelvis_imu\n0\t1,0,0,0\n",
        S,
        1,
        1,
        "missing 'endheader'",
    );
    check("", S, 1, 1, "empty file");
    check(
        "DataType=Vec3\nendheader\ntime\tpelvis_imu\n",
        S,
        1,
        1,
        "expected DataType=Quaternion",
    );
    check(
        "DataRate=100\nendheader\n\n",
        S,
        4,
        1,
        "expected the column labels",
    );
    check(
        "endheader\nframe\tpelvis_imu\n",
        S,
        2,
        1,
        "expected the first column to be 'time', found 'frame'",
    );
    check("endheader\ntime\n0\n", S, 2, 2, "no IMU columns");
    check(
        "endheader\ntime,pelvis_imu,torso_imu\n",
        S,
        2,
        1,
        "expected the first column to be 'time'",
    );
    check(
        "endheader\ntime\tpelvis_imu\t\n",
        S,
        2,
        3,
        "found an empty label",
    );
    check(
        "endheader\ntime\tpelvis_imu\tpelvis\n",
        S,
        2,
        3,
        "repeated IMU: 'pelvis' is 'pelvis_imu', already in column 2",
    );
    let h = STO_HDR;
    check(
        &format!("{h}0\t1,0,0,0\n"),
        S,
        6,
        3,
        "too few fields: expected 3 tab-separated fields, found 2",
    );
    check(
        &format!("{h}0\t1,0,0,0\t1,0,0,0\t1,0,0,0\n"),
        S,
        6,
        4,
        "too many fields",
    );
    check(
        &format!("{h}0\t1,0,0,0\t1,0,0\n"),
        S,
        6,
        3,
        "expected 4 comma-separated numbers w,x,y,z for torso_imu, found 3",
    );
    check(&format!("{h}0\t1,0,0,0\t1 0 0 0\n"), S, 6, 3, "found 1");
    check(
        &format!("{h}0\t1,0,abc,0\t1,0,0,0\n"),
        S,
        6,
        2,
        "expected a number for pelvis_imu y, found 'abc'",
    );
    check(
        &format!("{h}0\t1,0,0,0\t1,0,0,nan\n"),
        S,
        6,
        3,
        "expected a finite number for torso_imu z",
    );
    check(
        &format!("{h}0\t1,0,0,0\t2,0,0,0\n"),
        S,
        6,
        3,
        "expected a unit quaternion for torso_imu",
    );
    check(
        &format!("{h}1\t1,0,0,0\t1,0,0,0\n0.5\t1,0,0,0\t1,0,0,0\n"),
        S,
        7,
        1,
        "time 0.5 is before the previous time 1 (line 6)",
    );
    check(h, S, 6, 1, "no samples");
}

#[test]
fn trial_binary_garbage_never_panics() {
    let mut rng = ChaCha8Rng::seed_from_u64(99);
    let good_csv = trial_to_string(&random_trial(&["base", "head"], 5, 2), Q);
    let good_sto = trial_to_string(&random_trial(&["pelvis_imu"], 5, 2), S);
    for round in 0..3000 {
        let base = if round % 2 == 0 { &good_csv } else { &good_sto };
        let mut bytes = base.as_bytes().to_vec();
        match round % 3 {
            0 => {
                for _ in 0..rng.random_range(1..6) {
                    let i = rng.random_range(0..bytes.len());
                    bytes[i] = rng.random();
                }
            }
            1 => bytes.truncate(rng.random_range(0..bytes.len())),
            _ => {
                let n = rng.random_range(0..200);
                bytes = (0..n).map(|_| rng.random()).collect();
            }
        }
        let text = String::from_utf8_lossy(&bytes);
        for format in [Q, E, S] {
            let _ = read_trial_from_str(&text, "g", format, &infant());
        }
    }
}

// ---------------------------------------------------------------------------
// Whole files through read_trial: bytes that are not text, not gzip, not there.

fn temp_file(dir: &tempfile::TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    let p = dir.path().join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn trial_bad_files() {
    let dir = tempfile::tempdir().unwrap();
    let m = infant();

    let p = temp_file(&dir, "empty.csv", b"");
    let e = read_trial(&p, &m).unwrap_err();
    assert_eq!((e.line, e.column), (1, 1), "{e}");
    assert!(e.message.contains("empty file"), "{e}");
    assert!(e.file.ends_with("empty.csv"));
    assert!(detect_format(&p)
        .unwrap_err()
        .message
        .contains("empty file"));
    assert!(read_trial_header(&p, &m)
        .unwrap_err()
        .message
        .contains("empty file"));

    let p = temp_file(&dir, "notgz.csv.gz", HDR.as_bytes());
    let e = read_trial(&p, &m).unwrap_err();
    assert!(e.message.contains("invalid gzip data"), "{e}");
    assert!(read_trial_header(&p, &m)
        .unwrap_err()
        .message
        .contains("invalid gzip"));

    // A gzip stream cut short.
    let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    enc.write_all(format!("{HDR}0,1,0,0,0\n").repeat(50).as_bytes())
        .unwrap();
    let gz = enc.finish().unwrap();
    let p = temp_file(&dir, "cut.csv.gz", &gz[..gz.len() / 2]);
    assert!(read_trial(&p, &m)
        .unwrap_err()
        .message
        .contains("invalid gzip data"));

    // Gzip data under a plain name.
    let p = temp_file(&dir, "packed.csv", &gz);
    let e = read_trial(&p, &m).unwrap_err();
    assert!(e.message.contains("found gzip-compressed data"), "{e}");

    let mut bytes = format!("{HDR}0,1,0,0,0\n0.1,1,").into_bytes();
    bytes.extend_from_slice(&[0xff, 0xfe]);
    bytes.extend_from_slice(b",0,0\n");
    let p = temp_file(&dir, "latin.csv", &bytes);
    let e = read_trial(&p, &m).unwrap_err();
    assert_eq!((e.line, e.column), (3, 3), "{e}");
    assert!(
        e.message
            .contains("expected UTF-8 text, found invalid byte 0xff"),
        "{e}"
    );

    let p = temp_file(&dir, "garbage.sto", &[0u8, 159, 146, 150, 7, 1, 2]);
    let e = read_trial(&p, &opensim()).unwrap_err();
    assert!(e.message.contains("UTF-8"), "{e}");
    let p = temp_file(&dir, "garbage2.sto", b"\x00\x01\x02binary\x7f");
    let e = read_trial(&p, &opensim()).unwrap_err();
    assert!(e.message.contains("missing 'endheader'"), "{e}");

    let e = read_trial(&dir.path().join("absent.csv"), &m).unwrap_err();
    assert!(e.message.contains("cannot read"), "{e}");
    let e = read_trial(&temp_file(&dir, "x.dat", HDR.as_bytes()), &m).unwrap_err();
    assert!(e.message.contains("unknown trial file type"), "{e}");
    // A .txt is read as an Xsens export, and says what it lacks.
    let e = read_trial(&temp_file(&dir, "x.txt", HDR.as_bytes()), &m).unwrap_err();
    assert!(e.message.contains("'PacketCounter' column"), "{e}");
}

#[test]
fn trial_header_only_reads_header() {
    let dir = tempfile::tempdir().unwrap();
    // Rows after the header are broken; the header reader does not look at them.
    let text = format!("{STO_HDR}0\tbroken\n");
    let p = temp_file(&dir, "h.sto", text.as_bytes());
    let h = read_trial_header(&p, &opensim()).unwrap();
    assert_eq!(h.imus, ["pelvis_imu", "torso_imu"]);
    assert_eq!((h.format, h.gzip), (TrialFormat::Sto, false));
    assert!(read_trial(&p, &opensim()).is_err());
    // Header errors are reported as read_trial reports them.
    let p = temp_file(&dir, "bad.csv", b"time,base_qw,base_qx\n");
    let e = read_trial_header(&p, &infant()).unwrap_err();
    assert_eq!((e.line, e.column), (1, 4), "{e}");
    let p = temp_file(&dir, "e.csv", b"time,l_calf_roll,l_calf_pitch,l_calf_yaw\n");
    let h = read_trial_header(&p, &infant()).unwrap();
    assert_eq!(
        (h.format, h.imus),
        (TrialFormat::EulerCsv, vec!["l_calf".to_string()])
    );
}

#[test]
fn trial_large_csv_reads_back() {
    // 5 minutes at 50 Hz, 13 IMUs: 15,000 rows x 53 columns (speed: benches/).
    let names = infant().imus;
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let trial = random_trial(&names, 15_000, 5);
    let text = trial_to_string(&trial, Q);
    assert!(text.len() > 7_000_000, "{}", text.len());
    let back = read_trial_from_str(&text, "big.csv", Q, &infant()).unwrap();
    assert_eq!(back.len(), 15_000);
    assert_eq!(back.time_s, trial.time_s);
}

/// A text of 20,000 rows of four IMUs (about 2 MB, read in parallel parts)
/// with its rows as lines: `lines[0]` is the header.
fn large_text() -> (Trial, Vec<String>) {
    let trial = random_trial(&NAMES, 20_000, 9);
    let text = trial_to_string(&trial, Q);
    assert!(text.len() > 2 * (1 << 20), "{}", text.len());
    (trial, text.lines().map(str::to_string).collect())
}

fn joined(lines: &[String]) -> String {
    let mut t = lines.join("\n");
    t.push('\n');
    t
}

#[test]
fn trial_large_text_reads_in_parts_as_in_one_pass() {
    let (trial, mut lines) = large_text();
    // Off unit norm on rows in different parts: the worst, seen twice, is
    // reported on its first line (file lines are row + 1).
    for (row, w) in [(3_000, "1.003"), (17_000, "1.008"), (18_500, "1.008")] {
        let mut cells: Vec<String> = lines[row].split(',').map(str::to_string).collect();
        cells[1] = w.to_string();
        for c in &mut cells[2..5] {
            *c = "0".to_string();
        }
        lines[row] = cells.join(",");
    }
    // Blank lines and CRLF endings anywhere are as in one pass.
    lines[9_000].push('\r');
    lines.insert(12_000, String::new());
    let text = joined(&lines);
    let back = read_trial_from_str(&text, "big.csv", Q, &infant()).unwrap();
    assert_eq!(back.len(), 20_000);
    assert_eq!(back.time_s, trial.time_s);
    assert_eq!(back.orientation_decimals, None);
    assert_eq!(back.warnings.len(), 1, "{:?}", back.warnings);
    let w = &back.warnings[0];
    assert!(
        w.starts_with("base:")
            && w.contains("renormalised 3 of 20000")
            // 17,001, moved down by the blank line
            && w.contains("worst norm 1.008 on line 17002"),
        "{w}"
    );
    let q = &back.imus[0].orientation;
    assert_eq!(
        q[16_999].into_inner(),
        nalgebra::Quaternion::new(1.0, 0.0, 0.0, 0.0)
    );
    // Rows with fixed decimals: the decimals of every part.
    let fixed = trial_to_string_at(&back, Q, Precision::Decimals(6));
    let again = read_trial_from_str(&fixed, "big.csv", Q, &infant()).unwrap();
    let d = again.orientation_decimals.expect("decimals read");
    assert_eq!((d.fewest, d.most), (0, 6));
}

#[test]
fn trial_large_text_errors_are_the_first_in_the_file() {
    let (_, lines) = large_text();
    let bad = |edits: &[(usize, &str)]| {
        let mut l = lines.clone();
        for &(row, cell) in edits {
            let mut cells: Vec<&str> = l[row].split(',').collect();
            cells[2] = cell;
            l[row] = cells.join(",");
        }
        let e = read_trial_from_str(&joined(&l), "big.csv", Q, &infant()).unwrap_err();
        (e.line, e.column, e.message)
    };
    let (line, column, message) = bad(&[(19_000, "x")]);
    assert_eq!((line, column), (19_001, 3), "{message}");
    assert!(
        message.contains("expected a number for base_qx, found 'x'"),
        "{message}"
    );
    // Of two bad rows in different parts, the earlier is reported.
    let (line, _, message) = bad(&[(19_000, "x"), (2_500, "nan")]);
    assert_eq!(line, 2_501, "{message}");
    assert!(message.contains("expected a finite number"), "{message}");
    // A time repeated on the first row of a part, across the cut.
    let body = joined(&lines[1..]);
    let cut = super::parse::PART_BYTES
        + body.as_bytes()[super::parse::PART_BYTES..]
            .iter()
            .position(|&b| b == b'\n')
            .unwrap()
        + 1;
    let row = body[..cut].lines().count() + 1;
    let mut l = lines.clone();
    let prev_time = l[row - 1].split(',').next().unwrap().to_string();
    let rest: Vec<&str> = l[row].split(',').skip(1).collect();
    l[row] = format!("{prev_time},{}", rest.join(","));
    let e = read_trial_from_str(&joined(&l), "big.csv", Q, &infant()).unwrap_err();
    assert_eq!((e.line, e.column), (row as u64 + 1, 1), "{e}");
    assert!(
        e.message
            .contains(&format!("repeated time {prev_time} (also on line {row})")),
        "{e}"
    );
}
