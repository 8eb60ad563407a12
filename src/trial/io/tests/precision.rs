//! The decimals of orientation numbers as each reader counts them, and what
//! the writers make of them.

use super::{infant, opensim};
use crate::trial::precision::{AngleNumbers, Decimals, Precision};
use crate::trial::xsens::parse_export;
use crate::trial::{read_trial_from_str, trial_to_string, trial_to_string_at, TrialFormat};

const Q: TrialFormat = TrialFormat::QuatCsv;
const E: TrialFormat = TrialFormat::EulerCsv;
const S: TrialFormat = TrialFormat::Sto;

fn decimals(numbers: AngleNumbers, most: u8, fewest: u8) -> Option<Decimals> {
    Some(Decimals {
        numbers,
        most,
        fewest,
    })
}

/// Rows of unit quaternions (to six places) whose text round-trips.
const QUAT_CSV: &str = "time,base_qw,base_qx,base_qy,base_qz\n0,0.984326,0.11327,-0.135163,0.001735\n0.02,0.5,0.5,0.5,0.5\n0.04,1,0,0,0\n";

#[test]
fn each_reader_counts_the_decimals_of_its_orientation_numbers() {
    let t = read_trial_from_str(QUAT_CSV, "a.csv", Q, &infant()).unwrap();
    assert_eq!(
        t.orientation_decimals,
        decimals(AngleNumbers::Quaternion, 6, 0)
    );
    // Gyroscope columns and times do not count; Euler angles count as degrees.
    let euler = "time,base_roll,base_pitch,base_yaw,base_gx,base_gy,base_gz\n0.000001,10.25,-3.5,120.125,0.1234567,0,0\n";
    let t = read_trial_from_str(euler, "e.csv", E, &infant()).unwrap();
    assert_eq!(
        t.orientation_decimals,
        decimals(AngleNumbers::EulerDeg, 3, 1)
    );
    let sto = "DataType=Quaternion\nendheader\ntime\tpelvis_imu\n0\t0.70710678,0.70710678,0.000000,0.000000\n";
    let t = read_trial_from_str(sto, "s.sto", S, &opensim()).unwrap();
    assert_eq!(
        t.orientation_decimals,
        decimals(AngleNumbers::Quaternion, 8, 6)
    );
    // Full precision anywhere: no record.
    let full = QUAT_CSV.replace("0.5,0.5", "0.5000000000000001,0.5");
    let t = read_trial_from_str(&full, "f.csv", Q, &infant()).unwrap();
    assert_eq!(t.orientation_decimals, None);
}

#[test]
fn xsens_exports_count_quaternion_and_euler_columns_not_matrices() {
    let quat = "// Update Rate: 100.0Hz\nPacketCounter\tQuat_q0\tQuat_q1\tQuat_q2\tQuat_q3\n1\t0.500000\t0.500000\t0.500000\t0.500000\n2\t1.000000\t0.000000\t0.000000\t0.000000\n";
    let e = parse_export(quat, "q.txt").unwrap();
    assert_eq!(e.decimals, decimals(AngleNumbers::Quaternion, 6, 6));
    let euler = "PacketCounter;Roll;Pitch;Yaw\n1;10,25;0,5;3\n";
    let e = parse_export(euler, "e.txt").unwrap();
    assert_eq!(e.decimals, decimals(AngleNumbers::EulerDeg, 2, 0));
    let matrix = "PacketCounter\tMat[1][1]\tMat[2][1]\tMat[3][1]\tMat[1][2]\tMat[2][2]\tMat[3][2]\tMat[1][3]\tMat[2][3]\tMat[3][3]\n1\t1\t0\t0\t0\t1\t0\t0\t0\t1\n";
    let e = parse_export(matrix, "m.txt").unwrap();
    assert_eq!(e.decimals, None);
}

#[test]
fn writers_give_back_the_text_read() {
    let t = read_trial_from_str(QUAT_CSV, "a.csv", Q, &infant()).unwrap();
    assert_eq!(trial_to_string(&t, Q), QUAT_CSV);
    // The same in .sto (w,x,y,z cells), and padded as read.
    let sto = "\nDataRate=50.000000\nDataType=Quaternion\nversion=3\nOpenSimVersion=4.1\nendheader\ntime\tpelvis_imu\n0\t0.500000,0.500000,0.500000,0.500000\n0.02\t1.000000,0.000000,0.000000,-0.000000\n";
    let t = read_trial_from_str(sto, "s.sto", S, &opensim()).unwrap();
    assert_eq!(trial_to_string(&t, S), sto);
    // Euler angles within the writer's ranges, away from pitch +-90.
    let euler = "time,base_roll,base_pitch,base_yaw\n0,10.25,-3.5,120.125\n0.02,-170,45.001,-0.5\n";
    let t = read_trial_from_str(euler, "e.csv", E, &infant()).unwrap();
    assert_eq!(trial_to_string(&t, E), euler);
    // Quaternions read, Euler angles written: full precision, and the reverse.
    assert!(trial_to_string(&t, Q).lines().nth(1).unwrap().len() > 40);
    let q = read_trial_from_str(QUAT_CSV, "a.csv", Q, &infant()).unwrap();
    assert!(trial_to_string(&q, E).lines().nth(1).unwrap().len() > 40);
    // Overrides: full writes the shortest round-trip digits, N rounds.
    let full = trial_to_string_at(&q, Q, Precision::Full);
    assert!(full.contains("0.984326") && full.lines().nth(1).unwrap().len() > 45);
    let two = trial_to_string_at(&q, Q, Precision::Decimals(2));
    assert_eq!(two.lines().nth(1), Some("0,0.98,0.11,-0.14,0"));
}

#[test]
fn files_with_fewer_decimals_than_a_sensor_gives_are_exact_values() {
    // Three decimals of quaternions: kept as read, written in full.
    let three = "time,base_qw,base_qx,base_qy,base_qz\n0,0.6,0.8,0,0\n0.02,0.707,0.707,0,0\n";
    let t = read_trial_from_str(three, "a.csv", Q, &infant()).unwrap();
    assert_eq!(
        t.orientation_decimals,
        decimals(AngleNumbers::Quaternion, 3, 0)
    );
    let text = trial_to_string(&t, Q);
    assert!(text.lines().nth(2).unwrap().len() > 30, "{text}");
}
