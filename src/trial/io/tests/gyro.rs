//! Gyroscope columns `<imu>_gx,<imu>_gy,<imu>_gz` (rad/s, sensor frame) in the
//! CSV formats: round trips, where they may stand, and located errors.

use super::super::*;
use super::{check, infant, random_trial};
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const Q: TrialFormat = TrialFormat::QuatCsv;
const E: TrialFormat = TrialFormat::EulerCsv;

/// `random_trial` with random rates (up to 10 rad/s a component) on the IMUs
/// at `with` (indices).
fn gyro_trial(names: &[&str], with: &[usize], n: usize, seed: u64) -> Trial {
    let mut t = random_trial(names, n, seed);
    let mut rng = ChaCha8Rng::seed_from_u64(seed + 100);
    for &k in with {
        let g = (0..n)
            .map(|_| Vector3::from_fn(|_, _| rng.random_range(-10.0..10.0)))
            .collect();
        t.imus[k].gyro = Some(g);
    }
    t
}

fn gyros(t: &Trial) -> Vec<Option<Vec<Vector3<f64>>>> {
    t.imus.iter().map(|s| s.gyro.clone()).collect()
}

#[test]
fn gyro_columns_round_trip_exactly_in_both_csv_formats_and_gzip() {
    let dir = tempfile::tempdir().unwrap();
    let trial = gyro_trial(&["base", "l_thigh", "head"], &[0, 2], 120, 4);
    for (file, format) in [("g.csv", Q), ("g.csv.gz", Q), ("e.csv", E)] {
        let path = dir.path().join(file);
        write_trial(&trial, &path, format).unwrap();
        let back = read_trial(&path, &infant()).unwrap();
        assert!(back.warnings.is_empty(), "{:?}", back.warnings);
        // Shortest round-trip decimals: the rates come back bit for bit.
        assert_eq!(gyros(&back), gyros(&trial), "{file}");
        assert_eq!(back.time_s, trial.time_s);
        let head = read_trial_header(&path, &infant()).unwrap();
        assert_eq!(head.imus, ["base", "l_thigh", "head"]);
        assert_eq!(detect_format(&path).unwrap().0, format);
    }
    // .sto has no place for them: written without, read back without.
    let text = trial_to_string(&trial, TrialFormat::Sto);
    let back = read_trial_from_str(&text, "g.sto", TrialFormat::Sto, &infant()).unwrap();
    assert!(!back.has_gyros());
}

#[test]
fn gyro_columns_are_written_after_each_imus_orientation() {
    let mut trial = gyro_trial(&["base", "head"], &[1], 2, 1);
    trial.imus[1].gyro = Some(vec![Vector3::new(0.5, -1.25, 3.0), Vector3::zeros()]);
    let csv = trial_to_string(&trial, Q);
    let mut lines = csv.lines();
    assert_eq!(
        lines.next().unwrap(),
        "time,base_qw,base_qx,base_qy,base_qz,head_qw,head_qx,head_qy,head_qz,head_gx,head_gy,head_gz"
    );
    assert!(lines.next().unwrap().ends_with(",0.5,-1.25,3"), "{csv}");
    let euler = trial_to_string(&trial, E);
    assert!(euler.starts_with("time,base_roll,base_pitch,base_yaw,head_roll,head_pitch,head_yaw,head_gx,head_gy,head_gz\n"));
}

#[test]
fn gyro_columns_may_stand_anywhere_in_any_case_and_through_aliases() {
    // Before the orientation, in upper case, one IMU without.
    let text = "time,BASE_GZ,base_gx,base_gy,base_qw,base_qx,base_qy,base_qz,head_qw,head_qx,head_qy,head_qz\n\
                0,3,1,2,1,0,0,0,1,0,0,0\n\
                0.01,-3,-1,-2,1,0,0,0,1,0,0,0\n";
    let t = read_trial_from_str(text, "a.csv", Q, &infant()).unwrap();
    assert_eq!(
        t.imu("base").unwrap().gyro.as_deref(),
        Some(&[Vector3::new(1.0, 2.0, 3.0), Vector3::new(-1.0, -2.0, -3.0)][..])
    );
    assert!(t.imu("head").unwrap().gyro.is_none());
    // An IMU not in the model keeps its gyros under the name found.
    let text = "time,gadget_qw,gadget_qx,gadget_qy,gadget_qz,gadget_gx,gadget_gy,gadget_gz\n0,1,0,0,0,1,2,3\n";
    let t = read_trial_from_str(text, "a.csv", Q, &infant()).unwrap();
    assert_eq!(
        t.imus[0].gyro.as_ref().unwrap()[0],
        Vector3::new(1.0, 2.0, 3.0)
    );
    assert_eq!(t.warnings.len(), 1, "{:?}", t.warnings);
}

#[test]
fn gyro_columns_malformed() {
    let q = "base_qw,base_qx,base_qy,base_qz";
    check(
        &format!("time,{q},base_gx,base_gy\n0,1,0,0,0,1,2\n"),
        Q,
        1,
        6,
        "incomplete gyroscope columns for 'base': missing 'base_gz'; expected all three of base_gx,base_gy,base_gz (rad/s, sensor frame) or none",
    );
    check(
        &format!("time,{q},base_gz\n0,1,0,0,0,1\n"),
        Q,
        1,
        6,
        "missing 'base_gx' and 'base_gy'",
    );
    check(
        &format!("time,{q},base_gx,base_gy,base_gz,base_gx\n"),
        Q,
        1,
        9,
        "repeated gyroscope column 'base_gx' (already column 6 'base_gx')",
    );
    check(
        &format!("time,{q},head_gx,head_gy,head_gz\n"),
        Q,
        1,
        6,
        "gyroscope column 'head_gx' names IMU 'head', which has no orientation columns",
    );
    check(
        "time,base_gx,base_gy,base_gz\n",
        Q,
        1,
        2,
        "no orientation columns: expected <imu>_qw,<imu>_qx,<imu>_qy,<imu>_qz for each IMU",
    );
    // A gyro column inside an IMU's orientation columns breaks the group.
    check(
        "time,base_qw,base_gx,base_qx,base_qy,base_qz,base_gy,base_gz\n",
        Q,
        1,
        3,
        "expected column 'base_qx' after 'base_qw'",
    );
    let h = format!("time,{q},base_gx,base_gy,base_gz\n");
    check(
        &format!("{h}0,1,0,0,0,1,x,3\n"),
        Q,
        2,
        7,
        "expected a number for base_gy, found 'x'",
    );
    check(
        &format!("{h}0,1,0,0,0,1,2,\n"),
        Q,
        2,
        8,
        "expected a number for base_gz, found an empty cell",
    );
    check(
        &format!("{h}0,1,0,0,0,1,2,3\n0.01,1,0,0,0,inf,2,3\n"),
        Q,
        3,
        6,
        "expected a finite number for base_gx, found 'inf'",
    );
    check(
        &format!("{h}0,1,0,0,0,1,2\n"),
        Q,
        2,
        8,
        "too few fields: expected 8 comma-separated fields, found 7",
    );
    check(
        "time,base_roll,base_pitch,base_yaw,base_gx,base_gy\n",
        E,
        1,
        5,
        "incomplete gyroscope columns",
    );
}

#[test]
fn gyro_readings_of_the_wrong_length_are_not_written() {
    let dir = tempfile::tempdir().unwrap();
    let mut t = gyro_trial(&["base"], &[0], 5, 2);
    t.imus[0].gyro.as_mut().unwrap().pop();
    let e = write_trial(&t, &dir.path().join("w.csv"), Q).unwrap_err();
    assert!(
        e.message
            .contains("has 4 gyroscope readings, expected one per time (5)"),
        "{e}"
    );
}

#[test]
fn selecting_samples_keeps_gyros_aligned() {
    let t = gyro_trial(&["base", "head"], &[0], 10, 9);
    let idx = [0, 3, 4, 9];
    let s = t.select(&idx, "s");
    let g = s.imus[0].gyro.as_ref().unwrap();
    for (j, &i) in idx.iter().enumerate() {
        assert_eq!(g[j], t.imus[0].gyro.as_ref().unwrap()[i]);
        assert_eq!(s.imus[1].orientation[j], t.imus[1].orientation[i]);
        assert_eq!(s.time_s[j], t.time_s[i]);
    }
    assert!(s.imus[1].gyro.is_none());
}
