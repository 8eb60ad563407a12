//! Real recordings as labs have them, in files this test makes in the same
//! shapes as the public examples: Xsens MT Manager exports (one per sensor, with
//! matrix, quaternion or Euler columns, packet counters that start apart and
//! wrap), an OpenSense mapping XML, and a qmt-style wide CSV.
//! Every read is compared with the orientations written (1e-9 per quaternion
//! component, up to sign: the files carry Rust's shortest round-trip decimals, so
//! only the matrix-to-quaternion conversion rounds) or with a located error.

use acm_workbench::model::Model;
use acm_workbench::rotation::{euler_zyx_deg, quat_from_euler_zyx_deg, Quat};
use acm_workbench::trial::mapping::sensor_to_opensim;
use acm_workbench::trial::{detect_format, detect_model, is_trial_path, read_trial, TrialFormat};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::fmt::Write as _;
use std::path::Path;

#[derive(Clone, Copy)]
enum Columns {
    Matrix,
    Quaternion,
    Euler,
}

/// Random orientations, pitch within +-80 deg (Euler columns stay regular).
fn orientations(n: usize, seed: u64) -> Vec<Quat> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            quat_from_euler_zyx_deg([
                rng.random_range(-179.0..179.0),
                rng.random_range(-80.0..80.0),
                rng.random_range(-179.0..179.0),
            ])
        })
        .collect()
}

/// An MT Manager export: comments, the real files' header columns, and one
/// row per (raw 16-bit) packet counter.
fn export(counters: &[u64], qs: &[Quat], columns: Columns) -> String {
    let mut out = String::from(
        "// Start Time: Unknown\n// Update Rate: 100.0Hz\n// Filter Profile: human (46.1)\n// Option Flags: AHS Disabled ICC Disabled \n// Firmware Version: 4.0.2\n",
    );
    out.push_str("PacketCounter\tSampleTimeFine\tYear\tAcc_X\tAcc_Y\tAcc_Z");
    match columns {
        Columns::Matrix => {
            for j in 1..=3 {
                for i in 1..=3 {
                    let _ = write!(out, "\tMat[{i}][{j}]");
                }
            }
        }
        Columns::Quaternion => out.push_str("\tQuat_q0\tQuat_q1\tQuat_q2\tQuat_q3"),
        Columns::Euler => out.push_str("\tRoll\tPitch\tYaw"),
    }
    out.push('\n');
    for (c, q) in counters.iter().zip(qs) {
        let _ = write!(out, "{:05}\t\t\t0.1\t4.8\t-8.5", c % 65536);
        match columns {
            Columns::Matrix => {
                let m = q.to_rotation_matrix().into_inner();
                for j in 0..3 {
                    for i in 0..3 {
                        let _ = write!(out, "\t{}", m[(i, j)]);
                    }
                }
            }
            Columns::Quaternion => {
                let _ = write!(out, "\t{}\t{}\t{}\t{}", q.w, q.i, q.j, q.k);
            }
            Columns::Euler => {
                let [r, p, y] = euler_zyx_deg(q);
                let _ = write!(out, "\t{r}\t{p}\t{y}");
            }
        }
        out.push('\n');
    }
    out
}

fn mapping_xml(prefix: &str, sensors: &[(&str, &str)], rotation: Option<&str>) -> String {
    let mut out = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\" ?>\n<OpenSimDocument Version=\"40000\">\n\t<XsensDataReaderSettings>\n\t\t<trial_prefix>{prefix}</trial_prefix>\n\t\t<ExperimentalSensors>\n"
    );
    for (serial, name) in sensors {
        let _ = write!(
            out,
            "\t\t\t<ExperimentalSensor name=\"_{serial}\">\n\t\t\t\t<name_in_model>{name}</name_in_model>\n\t\t\t</ExperimentalSensor>\n"
        );
    }
    out.push_str("\t\t</ExperimentalSensors>\n\t</XsensDataReaderSettings>\n");
    if let Some(r) = rotation {
        let _ = writeln!(
            out,
            "\t<sensor_to_opensim_rotations>{r}</sensor_to_opensim_rotations>"
        );
    }
    out.push_str("</OpenSimDocument>\n");
    out
}

fn assert_quat_eq(a: &Quat, b: &Quat, what: &str) {
    let (a, b) = (a.into_inner(), b.into_inner());
    let d = (a - b).norm().min((a + b).norm());
    assert!(d < 1e-9, "{what}: {a:?} vs {b:?} ({d:e})");
}

/// One sensor: its serial, model name, column kind, raw counters and orientations.
struct Sensor {
    serial: &'static str,
    name: &'static str,
    columns: Columns,
    counters: Vec<u64>,
    qs: Vec<Quat>,
}

/// Three sensors of one recording whose counters cross the 16-bit wrap: they
/// start apart (65530, 65528, 65533), end apart, and the tibia misses packets
/// 65540..65542 (unwrapped), i.e. raw 4..6.
fn sensors() -> Vec<Sensor> {
    let make = |serial, name, columns, first: u64, last: u64, skip: &[u64], seed| {
        let counters: Vec<u64> = (first..=last).filter(|c| !skip.contains(c)).collect();
        let qs = orientations(counters.len(), seed);
        Sensor {
            serial,
            name,
            columns,
            counters,
            qs,
        }
    };
    vec![
        make(
            "00B42279",
            "pelvis_imu",
            Columns::Matrix,
            65530,
            65560,
            &[],
            1,
        ),
        make(
            "00B4227C",
            "femur_r_imu",
            Columns::Quaternion,
            65528,
            65570,
            &[],
            2,
        ),
        make(
            "00B4227D",
            "tibia_r_imu",
            Columns::Euler,
            65533,
            65565,
            &[65540, 65541, 65542],
            3,
        ),
    ]
}

fn write_recording(dir: &Path, sub: &str, sensors: &[Sensor], rotation: Option<&str>) {
    let data = dir.join(sub);
    std::fs::create_dir_all(&data).unwrap();
    for s in sensors {
        let f = data.join(format!("MT_TEST-001_{}.txt", s.serial));
        std::fs::write(f, export(&s.counters, &s.qs, s.columns)).unwrap();
    }
    let pairs: Vec<(&str, &str)> = sensors.iter().map(|s| (s.serial, s.name)).collect();
    std::fs::write(
        dir.join("myIMUMappings.xml"),
        mapping_xml("MT_TEST-001", &pairs, rotation),
    )
    .unwrap();
}

#[test]
fn xsens_exports_align_on_wrapped_counters_through_the_mapping() {
    let dir = tempfile::tempdir().unwrap();
    let sensors = sensors();
    let rx = -std::f64::consts::FRAC_PI_2;
    write_recording(
        dir.path(),
        "IMUData",
        &sensors,
        Some(&format!("{rx} 0 0.25")),
    );
    let xml = dir.path().join("myIMUMappings.xml");
    assert!(is_trial_path(&xml) && is_trial_path(&dir.path().join("IMUData")));
    assert_eq!(detect_format(&xml).unwrap(), (TrialFormat::Xsens, false));
    let model = detect_model(&xml);
    assert_eq!(model.name, "opensense_lower");
    let trial = read_trial(&xml, &model).unwrap();
    // Every sensor has 65533..=65560 except the tibia's 65540..=65542.
    let kept: Vec<u64> = (65533..=65560)
        .filter(|c| !(65540..=65542).contains(c))
        .collect();
    let times: Vec<f64> = kept.iter().map(|c| (c - 65533) as f64 / 100.0).collect();
    assert_eq!(trial.time_s, times);
    let r = sensor_to_opensim([rx, 0.0, 0.25]);
    for s in &sensors {
        let series = trial.imu(s.name).unwrap();
        for (k, c) in kept.iter().enumerate() {
            let i = s.counters.iter().position(|x| x == c).unwrap();
            assert_quat_eq(
                &series.orientation[k],
                &(r * s.qs[i]),
                &format!("{} packet {c}", s.name),
            );
        }
    }
    let w = trial.warnings.join("\n");
    assert!(
        w.contains("start at packet 65528..65533 and end at packet 65560..65570")
            && w.contains("kept packets 65533..65560 (25 samples)"),
        "{w}"
    );
    assert!(w.contains("3 packets missing (3 from packet 65540)"), "{w}");
    // The missing packets are a gap in time (4 intervals > 3), 0.07 s to 0.11 s.
    let gaps = acm_workbench::trial::timing::timing(&trial.time_s).gaps;
    assert_eq!(gaps.len(), 1, "{gaps:?}");
    assert_eq!(gaps[0].index, 7);
    assert!((gaps[0].from_s - 0.06).abs() < 1e-12 && (gaps[0].to_s - 0.10).abs() < 1e-12);
    assert_eq!(trial.warnings.len(), 2, "{w}");

    // The folder reads the same through the mapping in its parent.
    let folder = read_trial(&dir.path().join("IMUData"), &model).unwrap();
    assert_eq!(folder.time_s, trial.time_s);
    assert_eq!(folder.imus, trial.imus);
}

#[test]
fn folder_without_mapping_is_an_error_that_shows_the_mapping_to_write() {
    let dir = tempfile::tempdir().unwrap();
    let sensors = sensors();
    write_recording(dir.path(), "data", &sensors, None);
    std::fs::remove_file(dir.path().join("myIMUMappings.xml")).unwrap();
    let folder = dir.path().join("data");
    let model = Model::builtin("opensense_lower").unwrap();
    let e = read_trial(&folder, &model).unwrap_err();
    for serial in ["00B42279", "00B4227C", "00B4227D"] {
        assert!(e.message.contains(serial), "{e}");
        assert!(
            e.message
                .contains(&format!("<ExperimentalSensor name=\"_{serial}\">")),
            "{e}"
        );
    }
    assert!(
        e.message
            .contains("<trial_prefix>MT_TEST-001</trial_prefix>")
            && e.message.contains("pelvis_imu"),
        "{e}"
    );
    // The command line says so with exit code 3 (malformed input).
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_acmw"))
        .args(["report", "-q"])
        .arg(&folder)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{stderr}");
    assert!(
        stderr.contains("00B4227D") && stderr.contains("myIMUMappings.xml"),
        "{stderr}"
    );
    // Writing the XML the message shows (names filled in) makes the folder a trial.
    let xml_start = e.message.find("<?xml").unwrap();
    let mut xml = e.message[xml_start..].to_string();
    for s in &sensors {
        xml = xml.replacen(
            "<name_in_model>?</name_in_model>",
            &format!("<name_in_model>{}</name_in_model>", s.name),
            1,
        );
    }
    std::fs::write(folder.join("myIMUMappings.xml"), xml).unwrap();
    let trial = read_trial(&folder, &model).unwrap();
    let names: Vec<&str> = trial.imus.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["pelvis_imu", "femur_r_imu", "tibia_r_imu"]);
    // A model that knows the serials (aliases) reads the folder without a mapping.
    std::fs::remove_file(folder.join("myIMUMappings.xml")).unwrap();
    let aliased = Model::from_toml(
        "name = \"lab\"\nbase = \"pelvis\"\nimus = [\"pelvis\", \"thigh\"]\n[[joint]]\nname = \"r_hip\"\nkind = \"hip\"\nproximal = \"pelvis\"\ndistal = \"thigh\"\n[aliases]\n00B42279 = \"pelvis\"\n00B4227C = \"thigh\"\n",
        "lab.toml",
    )
    .unwrap();
    let trial = read_trial(&folder, &aliased).unwrap();
    let names: Vec<&str> = trial.imus.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["pelvis", "thigh", "00B4227D"]);
    // No rotation without a mapping: the Xsens frame as exported.
    let i = sensors[0]
        .counters
        .iter()
        .position(|&c| c == 65533)
        .unwrap();
    assert_quat_eq(&trial.imus[0].orientation[0], &sensors[0].qs[i], "pelvis");
}

/// The export's text with another separator (and, for semicolons, decimal commas).
fn with_delimiter(text: &str, sep: char) -> String {
    text.lines()
        .map(|l| {
            if l.starts_with("//") {
                l.to_string()
            } else if sep == ';' {
                l.replace('.', ",").replace('\t', ";")
            } else {
                l.replace('\t', &sep.to_string())
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The export with its columns in reverse order, older header spellings
/// (`Counter`, `q0..q3`) and no `SampleTimeFine`/`Year` columns.
fn reordered(text: &str) -> String {
    let rows: Vec<Vec<&str>> = text
        .lines()
        .filter(|l| !l.starts_with("//"))
        .map(|l| l.split('\t').collect())
        .collect();
    let keep: Vec<usize> = (0..rows[0].len())
        .filter(|&k| !["SampleTimeFine", "Year"].contains(&rows[0][k]))
        .rev()
        .collect();
    let mut out: Vec<String> = text
        .lines()
        .filter(|l| l.starts_with("//"))
        .map(str::to_string)
        .collect();
    for (n, row) in rows.iter().enumerate() {
        let cells: Vec<String> = keep
            .iter()
            .map(|&k| {
                let c = row[k];
                if n > 0 {
                    return c.to_string();
                }
                match c {
                    "PacketCounter" => "Counter".to_string(),
                    c if c.starts_with("Quat_") => c.trim_start_matches("Quat_").to_string(),
                    c => c.to_string(),
                }
            })
            .collect();
        out.push(cells.join("\t"));
    }
    out.join("\n")
}

/// A rewrite of an export's text.
type Rewrite = fn(&str) -> String;

#[test]
fn exports_read_alike_in_any_delimiter_column_order_and_spelling() {
    let dir = tempfile::tempdir().unwrap();
    let sensors = sensors();
    write_recording(dir.path(), "IMUData", &sensors, None);
    let model = Model::builtin("opensense_lower").unwrap();
    let xml = dir.path().join("myIMUMappings.xml");
    let tab = read_trial(&xml, &model).unwrap();
    let data = dir.path().join("IMUData");
    let originals: Vec<(std::path::PathBuf, String)> = sensors
        .iter()
        .map(|s| {
            let f = data.join(format!("MT_TEST-001_{}.txt", s.serial));
            let t = std::fs::read_to_string(&f).unwrap();
            (f, t)
        })
        .collect();
    let variants: [(&str, Rewrite); 3] = [
        ("comma", |t| with_delimiter(t, ',')),
        ("semicolon", |t| with_delimiter(t, ';')),
        ("reordered", reordered),
    ];
    for (what, rewrite) in variants {
        for (f, t) in &originals {
            std::fs::write(f, rewrite(t)).unwrap();
        }
        let other = read_trial(&xml, &model).unwrap_or_else(|e| panic!("{what}: {e}"));
        assert_eq!(other.time_s, tab.time_s, "{what}");
        assert_eq!(other.imus, tab.imus, "{what}: bit for bit");
        assert_eq!(other.warnings, tab.warnings, "{what}");
    }
    // Saved as .csv (comma-separated) under the mapping's names: found and read alike.
    for (f, t) in &originals {
        std::fs::remove_file(f).unwrap();
        std::fs::write(f.with_extension("csv"), with_delimiter(t, ',')).unwrap();
    }
    let csv = read_trial(&xml, &model).unwrap();
    assert_eq!(
        (csv.time_s.clone(), csv.imus.clone()),
        (tab.time_s.clone(), tab.imus.clone())
    );
    for (f, t) in &originals {
        std::fs::remove_file(f.with_extension("csv")).unwrap();
        std::fs::write(f, t).unwrap();
    }
    // A semicolon export says where a bad cell is, naming the separator.
    let (f, t) = &originals[0];
    let bad = with_delimiter(t, ';').replacen("\n00000;", "\n00000", 1);
    std::fs::write(f, bad).unwrap();
    let e = read_trial(&xml, &model).unwrap_err();
    assert!(e.message.contains("semicolon-separated"), "{e}");
}

#[test]
fn a_single_export_is_a_trial_of_one_imu() {
    let dir = tempfile::tempdir().unwrap();
    let sensors = sensors();
    write_recording(dir.path(), "IMUData", &sensors, None);
    let model = Model::builtin("opensense_lower").unwrap();
    let file = dir.path().join("IMUData/MT_TEST-001_00B4227C.txt");
    assert!(is_trial_path(&file));
    assert_eq!(detect_format(&file).unwrap(), (TrialFormat::Xsens, false));
    // Named by the mapping in the folder above, all its own packets kept.
    let one = read_trial(&file, &model).unwrap();
    assert_eq!(one.imus.len(), 1);
    assert_eq!(one.imus[0].name, "femur_r_imu");
    assert_eq!(one.len(), sensors[1].counters.len());
    for (q, want) in one.imus[0].orientation.iter().zip(&sensors[1].qs) {
        assert_quat_eq(q, want, "femur");
    }
    // Without a mapping: by its serial, with a warning, and no error.
    std::fs::remove_file(dir.path().join("myIMUMappings.xml")).unwrap();
    let one = read_trial(&file, &model).unwrap();
    assert_eq!(one.imus[0].name, "00B4227C");
    // Saved as .csv by the lab: read as an export, not a canonical CSV.
    let csv = dir.path().join("femur.csv");
    std::fs::write(
        &csv,
        with_delimiter(&std::fs::read_to_string(&file).unwrap(), ','),
    )
    .unwrap();
    assert_eq!(detect_format(&csv).unwrap(), (TrialFormat::Xsens, false));
    let from_csv = read_trial(&csv, &model).unwrap();
    assert_eq!(from_csv.imus[0].orientation, one.imus[0].orientation);
    assert_eq!(from_csv.imus[0].name, "femur");
}

#[test]
fn rate_comes_from_sample_time_fine_without_an_update_rate_comment() {
    let dir = tempfile::tempdir().unwrap();
    let qs = orientations(20, 9);
    let mut text = String::from("// MT Manager version: 2022.2.0\nPacketCounter,SampleTimeFine,Quat_q0,Quat_q1,Quat_q2,Quat_q3\n");
    for (k, q) in qs.iter().enumerate() {
        // 60 Hz: 166.67 ticks of 100 us per packet, printed as whole ticks.
        let ticks = (1_000_000.0 + k as f64 * 10_000.0 / 60.0).round();
        let _ = writeln!(text, "{},{ticks},{},{},{},{}", 100 + k, q.w, q.i, q.j, q.k);
    }
    let file = dir.path().join("MT_1_00B4AAAA.txt");
    std::fs::write(&file, &text).unwrap();
    let model = Model::builtin("opensense_lower").unwrap();
    let trial = read_trial(&file, &model).unwrap();
    // The median of 166/167 ticks per packet.
    let rate = trial.rate_hz();
    assert!(
        (rate - 10_000.0 / 167.0).abs() < 1e-9 || (rate - 10_000.0 / 166.0).abs() < 1e-9,
        "{rate}"
    );
    // Neither a comment nor sample times: a located error.
    let bare: String = text
        .replace(",SampleTimeFine", "")
        .lines()
        .map(|l| {
            if l.starts_with("//") || l.starts_with("Packet") {
                return format!("{l}\n");
            }
            let mut c: Vec<&str> = l.split(',').collect();
            c.remove(1);
            format!("{}\n", c.join(","))
        })
        .collect();
    std::fs::write(&file, bare).unwrap();
    let e = read_trial(&file, &model).unwrap_err();
    assert!(
        e.message.contains("no update rate") && e.message.contains("SampleTimeFine"),
        "{e}"
    );
}

#[test]
fn comment_lines_above_a_csv_header_are_skipped() {
    let dir = tempfile::tempdir().unwrap();
    let model = Model::builtin("opensense_lower").unwrap();
    let quat = dir.path().join("q.csv");
    std::fs::write(
        &quat,
        "# exported by the lab\n# subject 3\ntime,pelvis_imu_qw,pelvis_imu_qx,pelvis_imu_qy,pelvis_imu_qz\n0,1,0,0,0\n0.01,1,0,0,0\n",
    )
    .unwrap();
    assert_eq!(detect_format(&quat).unwrap(), (TrialFormat::QuatCsv, false));
    let t = read_trial(&quat, &model).unwrap();
    assert_eq!((t.len(), t.imus[0].name.as_str()), (2, "pelvis_imu"));
    let euler = dir.path().join("e.csv");
    std::fs::write(
        &euler,
        "#degrees\n\ntime,pelvis_imu_roll,pelvis_imu_pitch,pelvis_imu_yaw\n0,0,0,90\n0.01,0,0,90\n",
    )
    .unwrap();
    assert_eq!(
        detect_format(&euler).unwrap(),
        (TrialFormat::EulerCsv, false)
    );
    let t = read_trial(&euler, &model).unwrap();
    let [_, _, yaw] = euler_zyx_deg(&t.imus[0].orientation[1]);
    assert!((yaw - 90.0).abs() < 1e-9);
    // A bad row after comments is located on its own line.
    std::fs::write(
        &euler,
        "#a\n#b\ntime,pelvis_imu_roll,pelvis_imu_pitch,pelvis_imu_yaw\n0,0,x,90\n",
    )
    .unwrap();
    let e = read_trial(&euler, &model).unwrap_err();
    assert_eq!((e.line, e.column), (4, 3), "{e}");
}

#[test]
fn xsens_errors_name_file_line_and_column() {
    let dir = tempfile::tempdir().unwrap();
    let sensors = sensors();
    write_recording(dir.path(), "IMUData", &sensors, None);
    let model = Model::builtin("opensense_lower").unwrap();
    let xml = dir.path().join("myIMUMappings.xml");
    // A bad cell: the quaternion's x of the femur's 3rd sample (line 6 + 3 = 9, column 8).
    let femur = dir.path().join("IMUData/MT_TEST-001_00B4227C.txt");
    let text = std::fs::read_to_string(&femur).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut cells: Vec<&str> = lines[8].split('\t').collect();
    cells[7] = "0.5x";
    lines[8] = cells.join("\t");
    std::fs::write(&femur, lines.join("\n")).unwrap();
    let e = read_trial(&xml, &model).unwrap_err();
    assert_eq!(e.file, femur.display().to_string());
    assert_eq!((e.line, e.column), (9, 8), "{e}");
    assert!(e.message.contains("Quat_q1"), "{e}");
    // A mapping naming a sensor without an export: the sensor's line in the XML.
    let pairs = [("00B42279", "pelvis_imu"), ("00B4FFFF", "torso_imu")];
    std::fs::write(&xml, mapping_xml("MT_TEST-001", &pairs, None)).unwrap();
    let e = read_trial(&xml, &model).unwrap_err();
    assert_eq!((e.file.as_str(), e.line), (xml.to_str().unwrap(), 9), "{e}");
    assert!(e.message.contains("MT_TEST-001_00B4FFFF.txt"), "{e}");
}

#[test]
fn wide_csv_with_time_s_reads_with_the_16_segment_model() {
    let dir = tempfile::tempdir().unwrap();
    let segments = [
        "foot_left",
        "lower_leg_left",
        "upper_leg_left",
        "foot_right",
        "lower_leg_right",
        "upper_leg_right",
        "hip",
        "lower_back",
        "upper_back",
        "head",
        "hand_left",
        "forearm_left",
        "upper_arm_left",
        "hand_right",
        "forearm_right",
        "upper_arm_right",
    ];
    let n = 20;
    let qs: Vec<Vec<Quat>> = (0..segments.len())
        .map(|k| orientations(n, 10 + k as u64))
        .collect();
    let mut text = String::from("time_s");
    for s in segments {
        let _ = write!(text, ",{s}_qw,{s}_qx,{s}_qy,{s}_qz");
    }
    text.push('\n');
    for i in 0..n {
        let _ = write!(text, "{:.2}", i as f64 * 0.01);
        for q in &qs {
            let q = q[i];
            let _ = write!(text, ",{},{},{},{}", q.w, q.i, q.j, q.k);
        }
        text.push('\n');
    }
    let path = dir.path().join("full_body_quat_wxyz_100Hz.csv");
    std::fs::write(&path, text).unwrap();
    let model = detect_model(&path);
    assert_eq!(model.name, "full_body16");
    let trial = read_trial(&path, &model).unwrap();
    assert!(trial.warnings.is_empty(), "{:?}", trial.warnings);
    assert_eq!(trial.imus.len(), 16);
    assert_quat_eq(
        &trial.imu("l_hand").unwrap().orientation[7],
        &qs[10][7],
        "hand_left",
    );
    assert_quat_eq(
        &trial.imu("pelvis").unwrap().orientation[3],
        &qs[6][3],
        "hip",
    );
    // Every joint of the model, wrists and both back joints included, is covered
    // by the shipped default table.
    let table = acm_workbench::limits::LimitTable::default_table();
    table.check_covers(&model, "table_3_2.csv").unwrap();
    let names: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
    assert!(names.contains(&"l_wrist") && names.contains(&"lumbar") && names.contains(&"thoracic"));
}

/// `text` (an [`export`] of `counters`) with MT Manager's `Gyr_X Gyr_Y Gyr_Z`
/// after `Acc_Z`: per packet `(counter / 1000, id, -counter / 1000)` rad/s
/// (unwrapped counter), so every reading says which packet it came from.
fn with_gyros(text: &str, counters: &[u64], id: f64) -> String {
    let mut rows = counters.iter();
    let mut out = String::new();
    for line in text.lines() {
        if line.starts_with("//") {
            out.push_str(line);
        } else if line.starts_with("PacketCounter") {
            out.push_str(&line.replace("Acc_Z", "Acc_Z\tGyr_X\tGyr_Y\tGyr_Z"));
        } else {
            let c = *rows.next().unwrap() as f64 / 1000.0;
            let mut cells: Vec<String> = line.split('\t').map(str::to_string).collect();
            cells.insert(6, format!("{c}\t{id}\t{}", -c));
            out.push_str(&cells.join("\t"));
        }
        out.push('\n');
    }
    out
}

#[test]
fn xsens_gyroscope_columns_stay_aligned_with_the_orientations() {
    let dir = tempfile::tempdir().unwrap();
    let sensors = sensors();
    write_recording(dir.path(), "IMUData", &sensors, None);
    // Pelvis and tibia (which misses packets) get gyros, the femur none.
    for (s, id) in [(&sensors[0], 1.0), (&sensors[2], 3.0)] {
        let f = dir
            .path()
            .join(format!("IMUData/MT_TEST-001_{}.txt", s.serial));
        let text = std::fs::read_to_string(&f).unwrap();
        std::fs::write(&f, with_gyros(&text, &s.counters, id)).unwrap();
    }
    let model = Model::builtin("opensense_lower").unwrap();
    let trial = read_trial(&dir.path().join("myIMUMappings.xml"), &model).unwrap();
    let kept: Vec<u64> = (65533..=65560)
        .filter(|c| !(65540..=65542).contains(c))
        .collect();
    assert_eq!(trial.len(), kept.len());
    assert!(trial.imu("femur_r_imu").unwrap().gyro.is_none());
    for (s, id) in [(&sensors[0], 1.0), (&sensors[2], 3.0)] {
        let series = trial.imu(s.name).unwrap();
        let g = series.gyro.as_ref().expect("gyros read");
        assert_eq!(g.len(), kept.len());
        for (k, c) in kept.iter().enumerate() {
            // The reading of packet c sits beside the orientation of packet c.
            let want = *c as f64 / 1000.0;
            assert_eq!(
                (g[k].x, g[k].y, g[k].z),
                (want, id, -want),
                "{} {c}",
                s.name
            );
            let i = s.counters.iter().position(|x| x == c).unwrap();
            assert_quat_eq(&series.orientation[k], &s.qs[i], s.name);
        }
    }
    // Two of the three columns: an error at the header's first gyro column.
    let f = dir.path().join("IMUData/MT_TEST-001_00B42279.txt");
    let text = std::fs::read_to_string(&f).unwrap();
    std::fs::write(&f, text.replace("\tGyr_Z", "\tGyr_Q")).unwrap();
    let e = read_trial(&dir.path().join("myIMUMappings.xml"), &model).unwrap_err();
    assert_eq!(
        (e.file.as_str(), e.line, e.column),
        (f.to_str().unwrap(), 6, 7),
        "{e}"
    );
    assert!(
        e.message
            .contains("missing Gyr_Z; expected all of Gyr_X, Gyr_Y, Gyr_Z (rad/s, sensor frame)"),
        "{e}"
    );
    // A bad reading names its line and column.
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let mut cells: Vec<String> = lines[9].split('\t').map(str::to_string).collect();
    cells[7] = "fast".into();
    lines[9] = cells.join("\t");
    std::fs::write(&f, lines.join("\n")).unwrap();
    let e = read_trial(&dir.path().join("myIMUMappings.xml"), &model).unwrap_err();
    assert_eq!((e.line, e.column), (10, 8), "{e}");
    assert!(e.message.contains("Gyr_Y, found 'fast'"), "{e}");
}

#[test]
fn xsens_exports_at_six_decimals_are_corrected_into_a_six_decimal_sto() {
    use acm_workbench::trial::precision::{decimals_of, AngleNumbers};
    let dir = tempfile::tempdir().unwrap();
    let mut sensors = sensors();
    for s in &mut sensors {
        s.columns = Columns::Quaternion;
    }
    write_recording(dir.path(), "IMUData", &sensors, None);
    // MT Manager writes `%.6f`: six decimals, trailing zeros kept.
    for s in &sensors {
        let f = dir
            .path()
            .join(format!("IMUData/MT_TEST-001_{}.txt", s.serial));
        let text = std::fs::read_to_string(&f).unwrap();
        let six: Vec<String> = text
            .lines()
            .map(|l| match l.split('\t').collect::<Vec<_>>() {
                cells if cells.len() == 10 && !l.starts_with("Packet") => {
                    let mut out: Vec<String> = cells[..6].iter().map(|c| c.to_string()).collect();
                    out.extend(
                        cells[6..]
                            .iter()
                            .map(|c| format!("{:.6}", c.parse::<f64>().unwrap())),
                    );
                    out.join("\t")
                }
                _ => l.to_string(),
            })
            .collect();
        std::fs::write(&f, six.join("\n") + "\n").unwrap();
    }
    let xml = dir.path().join("myIMUMappings.xml");
    let model = detect_model(&xml);
    let trial = read_trial(&xml, &model).unwrap();
    let d = trial.orientation_decimals.unwrap();
    assert_eq!(
        (d.numbers, d.most, d.padded()),
        (AngleNumbers::Quaternion, 6, true)
    );
    let out = dir.path().join("out.sto");
    let run = std::process::Command::new(env!("CARGO_BIN_EXE_acmw"))
        .arg("correct")
        .arg(&xml)
        .args(["--variant", "none", "-q", "-o"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let text = std::fs::read_to_string(&out).unwrap();
    let rows = text.lines().skip_while(|l| !l.starts_with("time")).skip(1);
    let numbers: Vec<u8> = rows
        .flat_map(|l| {
            l.split('\t')
                .skip(1)
                .flat_map(|c| c.split(','))
                .map(decimals_of)
                .collect::<Vec<_>>()
        })
        .collect();
    assert_eq!(numbers.len(), trial.len() * 3 * 4);
    assert!(
        numbers.iter().all(|&d| d == 6),
        "every number padded to six decimals"
    );
}
