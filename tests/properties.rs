//! Property tests (proptest) of every writer and reader.
//!
//! Round trips: what the program writes reads back equal to what was
//! written: trials (quaternion CSV, Euler CSV, `.sto`, each plain and gzip)
//! from disk, limit tables with odd joint names, settings TOML, models (TOML
//! and the sidecar's JSON) and calibration files. Tolerances: times, table
//! and settings values, models and calibrations are exact (shortest
//! round-trip decimal printing); quaternion CSV and `.sto` orientations within
//! 1e-9 degrees; Euler CSV orientations within 1e-6 degrees (written as
//! degrees, turned back into quaternions).
//!
//! Hostile bytes: random bytes and random damage to valid files, fed to each
//! reader, end in a value or an error that names the file and a line (no
//! panic, which proptest would report with its shrunk input).
//!
//! Case counts stay small so that `cargo test` runs each property in a few
//! seconds; `PROPTEST_CASES` raises them for a longer search.

use acm_workbench::calibration::protocol::Protocol;
use acm_workbench::calibration::{AxisResult, Calibration, SegmentResult, SkippedSegment};
use acm_workbench::limits::{LimitRow, LimitTable, SettingsFile};
use acm_workbench::model::Model;
use acm_workbench::rotation::{angle_between_deg, quat_from_euler_zyx_deg};
use acm_workbench::trial::mapping::parse_mapping;
use acm_workbench::trial::precision::Precision;
use acm_workbench::trial::xsens::parse_export;
use acm_workbench::trial::{
    read_trial, read_trial_from_str, write_trial, ImuSeries, Trial, TrialFormat,
};
use acm_workbench::vertical::Vertical;
use nalgebra::Vector3;
use proptest::prelude::*;
use std::path::Path;

fn config(cases: u32) -> ProptestConfig {
    ProptestConfig {
        cases: std::env::var("PROPTEST_CASES")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(cases),
        // Shrinking a failure may take long; the first counterexample is
        // printed either way.
        max_shrink_iters: 200,
        ..ProptestConfig::default()
    }
}

// ---------------------------------------------------------------- trials

/// Z-Y-X Euler angles, degrees, away from gimbal lock (the Euler CSV's own
/// limit: pitch +-90 has no unique roll and yaw).
fn euler() -> impl Strategy<Value = [f64; 3]> {
    (-180.0..180.0f64, -89.0..89.0f64, -180.0..180.0f64).prop_map(|(a, b, c)| [a, b, c])
}

/// Gyro readings, rad/s: ordinary values and extremes of magnitude.
fn gyro_value() -> impl Strategy<Value = f64> {
    prop_oneof![
        -40.0..40.0f64,
        Just(0.0),
        Just(-0.0),
        Just(1e-300),
        Just(-1e300),
        Just(f64::MIN_POSITIVE),
    ]
}

prop_compose! {
    /// A trial of 1 to 3 IMUs of the infant model, 2 to 40 samples with
    /// irregular steps from 0.1 ms to 10 s starting anywhere in +-1e4 s,
    /// with or without gyros.
    fn trial()(
        n in 2usize..40,
        k in 1usize..=3,
        gyros in any::<bool>(),
    )(
        start in -1e4..1e4f64,
        log_dt in -4.0..1.0f64,
        jitter in prop::collection::vec(0.5..1.5f64, n),
        angles in prop::collection::vec(euler(), n * k),
        g in prop::collection::vec(gyro_value(), if gyros { 3 * n * k } else { 0 }),
        k in Just(k),
        n in Just(n),
    ) -> Trial {
        let dt = 10f64.powf(log_dt);
        let mut t = start;
        let time_s = jitter.iter().map(|j| { t += dt * j; t }).collect();
        let imus = ["base", "upper_back", "head"][..k]
            .iter()
            .enumerate()
            .map(|(i, name)| {
                let q = angles[i * n..(i + 1) * n].iter().map(|a| quat_from_euler_zyx_deg(*a)).collect();
                let gyro = (!g.is_empty()).then(|| {
                    (0..n).map(|s| {
                        let at = 3 * (i * n + s);
                        Vector3::new(g[at], g[at + 1], g[at + 2])
                    }).collect()
                });
                ImuSeries::new(*name, q).with_gyro(gyro)
            })
            .collect();
        Trial { name: "p".into(), time_s, imus, warnings: vec![], orientation_decimals: None }
    }
}

proptest! {
    #![proptest_config(config(24))]

    #[test]
    fn written_trials_read_back(trial in trial()) {
        let dir = tempfile::tempdir().unwrap();
        let model = Model::infant13();
        for (format, name, tol_deg) in [
            (TrialFormat::QuatCsv, "t.csv", 1e-9),
            (TrialFormat::QuatCsv, "t.csv.gz", 1e-9),
            (TrialFormat::EulerCsv, "e.csv", 1e-6),
            (TrialFormat::EulerCsv, "e.csv.gz", 1e-6),
            (TrialFormat::Sto, "s.sto", 1e-9),
            (TrialFormat::Sto, "s.sto.gz", 1e-9),
        ] {
            let path = dir.path().join(name);
            write_trial(&trial, &path, format).unwrap();
            let back = read_trial(&path, &model).map_err(|e| TestCaseError::fail(format!("{name}: {e}")))?;
            prop_assert_eq!(&back.time_s, &trial.time_s, "{}", name);
            prop_assert_eq!(back.imus.len(), trial.imus.len());
            for (a, b) in trial.imus.iter().zip(&back.imus) {
                prop_assert_eq!(&a.name, &b.name);
                for (p, q) in a.orientation.iter().zip(&b.orientation) {
                    let d = angle_between_deg(p, q);
                    prop_assert!(d < tol_deg, "{}: {} deg apart", name, d);
                }
                // `.sto` holds orientations only.
                if format != TrialFormat::Sto {
                    prop_assert_eq!(&a.gyro, &b.gyro, "{}", name);
                }
            }
        }
    }
}

// ----------------------------------------------------------- limit tables

/// A name as the table reader gives it: trimmed, not empty, holding
/// separators, quotes, comment signs, tabs, line breaks and non-ASCII.
fn name() -> impl Strategy<Value = String> {
    "[a-z#,\"\t\r\n üé_/()-]{0,8}[a-zé0-9]"
        .prop_map(|s| s.trim_start().to_string())
        .prop_filter("not empty", |s| !s.is_empty())
}

fn degrees() -> impl Strategy<Value = f64> {
    prop_oneof![
        -180.0..=180.0f64,
        Just(-180.0),
        Just(180.0),
        Just(0.0),
        Just(1e-300),
        Just(-0.1 + 0.2),
    ]
}

prop_compose! {
    /// The three rows of one joint: limits, an optional centroid on all
    /// three axes or none, one lambda2.
    fn joint_rows()(
        joint in name(),
        movements in prop::collection::vec(prop_oneof![Just(String::new()), name()], 3),
        ranges in prop::collection::vec((degrees(), degrees()).prop_filter("lower < upper", |(a, b)| a != b), 3),
        centroid in prop::option::of(prop::collection::vec(degrees(), 3)),
        lambda2 in prop_oneof![Just(0.0), 0.0..1e6f64, Just(1e300)],
    ) -> Vec<LimitRow> {
        (0..3).map(|axis| {
            let (a, b) = ranges[axis];
            LimitRow {
                joint: joint.clone(),
                axis,
                movement: movements[axis].clone(),
                lower_deg: a.min(b),
                upper_deg: a.max(b),
                centroid_deg: centroid.as_ref().map(|c| c[axis]),
                lambda2,
            }
        }).collect()
    }
}

prop_compose! {
    fn table()(
        joints in prop::collection::vec(joint_rows(), 1..6),
        preamble in prop::collection::vec("#[ -~]{0,20}", 0..3),
    ) -> LimitTable {
        // Joint names are unique: the first of each name is kept.
        let mut seen = std::collections::BTreeSet::new();
        let rows = joints
            .into_iter()
            .filter(|rows| seen.insert(rows[0].joint.clone()))
            .flatten()
            .collect();
        LimitTable {
            preamble,
            rows,
            swing_twist: None,
        }
    }
}

proptest! {
    #![proptest_config(config(64))]

    #[test]
    fn written_limit_tables_read_back(table in table()) {
        let text = table.to_csv();
        let back = LimitTable::parse(&text, "t.csv")
            .map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(&back, &table);
        prop_assert_eq!(back.hash(), table.hash());
        // And from disk, as the workbench saves it.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        std::fs::write(&path, &text).unwrap();
        prop_assert_eq!(LimitTable::load(&path).map_err(|e| TestCaseError::fail(e.to_string()))?, table);
    }
}

// --------------------------------------------------------------- settings

prop_compose! {
    fn settings()(
        table in "[ -~üé\t\u{1}\u{1b}\u{7f}\u{200b}]{1,12}",
        lambda1 in prop_oneof![Just(0.0), Just(1e6), 0.0..1e6f64, 0.0..1.0f64],
        window_s in prop_oneof![Just(1e7), Just(1e-6), 1e-3..1e7f64, 1.0..120.0f64],
        hop_fraction in prop_oneof![Just(1e-3), Just(1.0), 1e-3..=1.0f64],
        z_down in any::<bool>(),
        glitch_deg in prop_oneof![Just(180.0), Just(1e-9), 1e-9..=180.0f64],
        precision in prop_oneof![Just(Precision::Auto), Just(Precision::Full), (0u8..=17).prop_map(Precision::Decimals)],
    ) -> SettingsFile {
        SettingsFile {
            table,
            lambda1,
            window_s,
            // Within [window / 1000, window] however it rounds.
            hop_s: (window_s * hop_fraction).clamp(window_s / 1000.0, window_s),
            vertical: if z_down { Vertical::ZDown } else { Vertical::ZUp },
            glitch_deg,
            precision,
        }
    }
}

proptest! {
    #![proptest_config(config(128))]

    #[test]
    fn written_settings_read_back(s in settings()) {
        let text = s.to_toml();
        let back = SettingsFile::parse(&text, "settings.toml")
            .map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(back, s);
    }
}

// ----------------------------------------------------------------- models

prop_compose! {
    /// A built-in model with random aliases, weights, segment lengths and
    /// directions.
    fn model()(
        which in 0..acm_workbench::model::BUILTIN_MODELS.len(),
        picks in prop::collection::vec((any::<prop::sample::Index>(), name(), 1e-6..1e3f64, -1.0..1.0f64), 0..6),
    ) -> Model {
        let mut m = Model::builtin(acm_workbench::model::BUILTIN_MODELS[which].0).unwrap();
        for (i, alias, x, d) in picks {
            let imu = i.get(&m.imus).clone();
            m.aliases.insert(alias, imu.clone());
            m.imu_weight.insert(imu.clone(), x);
            m.segment_length_m.insert(imu.clone(), x / 10.0);
            m.segment_direction.insert(imu, [d, x, -0.0]);
        }
        m
    }
}

proptest! {
    #![proptest_config(config(32))]

    #[test]
    fn written_models_read_back(m in model()) {
        // As TOML (a lab's model file) ...
        let text = toml::to_string(&m).unwrap();
        let back = Model::from_toml(&text, "m.toml")
            .map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(&back, &m);
        // ... and as a sidecar records it (JSON), checked as `--from-sidecar` does.
        let json = serde_json::to_string_pretty(&m).unwrap();
        let back: Model = serde_json::from_str(&json).unwrap();
        prop_assert!(back.check("s.json").is_ok());
        prop_assert_eq!(back, m);
    }
}

// ----------------------------------------------------------- calibrations

fn real() -> impl Strategy<Value = f64> {
    prop_oneof![
        -1e3..1e3f64,
        Just(0.0),
        Just(-0.0),
        Just(1e300),
        Just(-5e-324),
        Just(0.1 + 0.2),
    ]
}

fn unit_q() -> impl Strategy<Value = [f64; 4]> {
    (euler()).prop_map(|a| {
        let q = quat_from_euler_zyx_deg(a);
        let s = if q.w < 0.0 { -1.0 } else { 1.0 };
        [s * q.w, s * q.i, s * q.j, s * q.k]
    })
}

prop_compose! {
    fn axis_result()(
        movement in name(),
        static_kind in any::<bool>(),
        axis in "[+-]?[xyz]",
        samples in 0usize..1_000_000,
        rho in 0.0..=1.0f64,
        estimate in (real(), real(), real()),
        r in (real(), real(), prop::option::of(real())),
    ) -> AxisResult {
        let kind: acm_workbench::calibration::protocol::MovementKind =
            serde_json::from_str(if static_kind { "\"static\"" } else { "\"functional\"" }).unwrap();
        AxisResult {
            movement,
            kind,
            axis,
            samples,
            rho,
            estimate: [estimate.0, estimate.1, estimate.2],
            residual_before_deg: r.0,
            residual_lm_deg: r.1,
            residual_triad_deg: r.2,
        }
    }
}

prop_compose! {
    fn segment()(
        imu in name(),
        q in unit_q(),
        iterations in 0usize..10_000,
        costs in (real(), real()),
        triad in prop::option::of((unit_q(), prop::collection::vec(name(), 2), real())),
        axes in prop::collection::vec(axis_result(), 0..4),
        missing in prop::collection::vec(name(), 0..3),
    ) -> SegmentResult {
        SegmentResult {
            imu,
            q,
            iterations,
            cost_start: costs.0,
            cost_end: costs.1,
            triad_q: triad.as_ref().map(|t| t.0),
            triad_movements: triad.as_ref().map(|t| t.1.clone()).unwrap_or_default(),
            lm_triad_deg: triad.map(|t| t.2),
            axes,
            missing,
        }
    }
}

prop_compose! {
    fn calibration()(
        recording in "[ -~é]{0,16}",
        samples in 0usize..1_000_000_000,
        duration_s in real(),
        rate_hz in real(),
        protocol in name(),
        movements in prop::collection::vec(name(), 0..5),
        segments in prop::collection::vec(segment(), 0..4),
        skipped in prop::collection::vec((name(), "[ -~\n]{0,30}"), 0..2),
        warnings in prop::collection::vec("[ -~\t\n'\"\\\\]{0,30}", 0..3),
    ) -> Calibration {
        Calibration {
            program: "acmw".into(),
            version: env!("CARGO_PKG_VERSION").into(),
            recording,
            samples,
            duration_s,
            rate_hz,
            protocol,
            protocol_sha256: "0".repeat(64),
            movements,
            segments,
            skipped: skipped.into_iter().map(|(imu, reason)| SkippedSegment { imu, reason }).collect(),
            warnings,
        }
    }
}

proptest! {
    #![proptest_config(config(64))]

    #[test]
    fn written_calibrations_read_back(c in calibration()) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("c.calibration.toml");
        c.save(&path).unwrap();
        let back = Calibration::load(&path)
            .map_err(|e| TestCaseError::fail(format!("{e}\n{}", c.to_toml())))?;
        prop_assert_eq!(back, c);
    }
}

// ---------------------------------------------------------- hostile bytes

/// Valid files of every format, to damage.
fn seeds() -> Vec<(&'static str, String)> {
    let mut quat = String::from("time,base_qw,base_qx,base_qy,base_qz\n");
    let mut euler = String::from("time,base_roll,base_pitch,base_yaw\n");
    let mut sto = String::from(
        "DataRate=100\nDataType=Quaternion\nversion=3\nendheader\ntime\tbase\tupper_back\n",
    );
    let mut export = String::from(
        "// Update Rate: 100.0Hz\n// Coordinate system: ENU\nPacketCounter\tSampleTimeFine\tQuat_q0\tQuat_q1\tQuat_q2\tQuat_q3\n",
    );
    for i in 0..8 {
        let t = i as f64 / 100.0;
        let q = quat_from_euler_zyx_deg([i as f64 * 10.0, 5.0, -3.0]);
        quat.push_str(&format!("{t},{},{},{},{}\n", q.w, q.i, q.j, q.k));
        euler.push_str(&format!("{t},{},5,-3\n", i * 10));
        sto.push_str(&format!("{t}\t{},{},{},{}\t1,0,0,0\n", q.w, q.i, q.j, q.k));
        export.push_str(&format!(
            "{:05}\t{}\t{}\t{}\t{}\t{}\n",
            (65530 + i) % 65536,
            100 * i,
            q.w,
            q.i,
            q.j,
            q.k
        ));
    }
    let mapping = "<?xml version=\"1.0\"?>\n<OpenSimDocument Version=\"40000\">\n<XsensDataReaderSettings>\n<trial_prefix>MT_01</trial_prefix>\n<ExperimentalSensors>\n<ExperimentalSensor name=\"_00B1\">\n<name_in_model>base</name_in_model>\n</ExperimentalSensor>\n</ExperimentalSensors>\n</XsensDataReaderSettings>\n</OpenSimDocument>\n";
    vec![
        ("t.csv", quat),
        ("e.csv", euler),
        ("t.sto", sto),
        ("MT_01_00B1.txt", export),
        ("m.xml", mapping.to_string()),
        (
            "l.csv",
            acm_workbench::limits::BUILTIN_TABLES[0].1.to_string(),
        ),
        (
            "settings.toml",
            acm_workbench::limits::BUILTIN_SETTINGS.to_string(),
        ),
        (
            "m.toml",
            acm_workbench::model::BUILTIN_MODELS[0].1.to_string(),
        ),
        ("p.toml", Protocol::default_protocol().text),
    ]
}

/// One damage to a text: a byte range replaced by other bytes.
#[derive(Debug, Clone)]
struct Edit {
    at: prop::sample::Index,
    len: usize,
    with: Vec<u8>,
}

fn edit() -> impl Strategy<Value = Edit> {
    let nasty = prop_oneof![
        prop::collection::vec(any::<u8>(), 0..6),
        prop::sample::select(vec![
            b"\n".to_vec(),
            b"\r\n".to_vec(),
            b"\"".to_vec(),
            b",".to_vec(),
            b"\t".to_vec(),
            b"#".to_vec(),
            b"[[".to_vec(),
            b"nan".to_vec(),
            b"inf".to_vec(),
            b"-0".to_vec(),
            b"1e308".to_vec(),
            b"1e-320".to_vec(),
            b"99999999999999999999".to_vec(),
            b"<!ENTITY a \"a\">".to_vec(),
            "\u{feff}".as_bytes().to_vec(),
            b"\xff\xfe".to_vec(),
            b"=".to_vec(),
            b"//".to_vec(),
            b"endheader".to_vec(),
        ]),
    ];
    (any::<prop::sample::Index>(), 0usize..12, nasty).prop_map(|(at, len, with)| Edit {
        at,
        len,
        with,
    })
}

fn damage(text: &str, edits: &[Edit]) -> Vec<u8> {
    let mut b = text.as_bytes().to_vec();
    for e in edits {
        let at = e.at.index(b.len() + 1);
        let end = (at + e.len).min(b.len());
        b.splice(at..end, e.with.iter().copied());
    }
    b
}

/// Feeds `bytes` to the reader of `name`'s format: `Err` with a description
/// when the reader's answer is neither a value nor an error naming the file
/// with a line (a panic fails the property by itself).
fn read_any(name: &str, bytes: &[u8], dir: &Path) -> Result<(), String> {
    let text = String::from_utf8_lossy(bytes);
    let model = Model::infant13();
    let located = |shown: String, file: &str, line: u64| {
        if shown.starts_with(&format!("{file}:")) && line >= 1 {
            Ok(())
        } else {
            Err(format!("not located: {shown}"))
        }
    };
    match name {
        "t.csv" | "e.csv" | "t.sto" => {
            let format = match name {
                "t.csv" => TrialFormat::QuatCsv,
                "e.csv" => TrialFormat::EulerCsv,
                _ => TrialFormat::Sto,
            };
            if let Err(e) = read_trial_from_str(&text, name, format, &model) {
                located(e.to_string(), name, e.line)?;
            }
            // From disk too, raw and gzip (invalid UTF-8 located there).
            for file in [name.to_string(), format!("{name}.gz")] {
                let path = dir.join(&file);
                let raw = if file.ends_with(".gz") {
                    let mut z =
                        flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
                    std::io::Write::write_all(&mut z, bytes).unwrap();
                    z.finish().unwrap()
                } else {
                    bytes.to_vec()
                };
                std::fs::write(&path, raw).unwrap();
                if let Err(e) = read_trial(&path, &model) {
                    let shown = e.to_string();
                    let origin = path.display().to_string();
                    if !(shown.starts_with(&format!("{origin}:")) && e.line >= 1) {
                        return Err(format!("not located: {shown}"));
                    }
                }
            }
            Ok(())
        }
        "MT_01_00B1.txt" => match parse_export(&text, name) {
            Err(e) => located(e.to_string(), name, e.line),
            Ok(_) => Ok(()),
        },
        "m.xml" => match parse_mapping(&text, name) {
            Err(e) => located(e.to_string(), name, e.line),
            Ok(_) => Ok(()),
        },
        "l.csv" => match LimitTable::parse(&text, name) {
            Err(e) => located(e.to_string(), name, e.line),
            Ok(t) => {
                // What parses writes back to what parses to the same rows.
                let again = LimitTable::parse(&t.to_csv(), name).map_err(|e| e.to_string())?;
                (again.rows == t.rows)
                    .then_some(())
                    .ok_or_else(|| "table changed on its round trip".to_string())
            }
        },
        "settings.toml" => match SettingsFile::parse(&text, name) {
            Err(e) => located(e.to_string(), name, e.line),
            Ok(s) => {
                let again = SettingsFile::parse(&s.to_toml(), name).map_err(|e| e.to_string())?;
                (again == s)
                    .then_some(())
                    .ok_or_else(|| "settings changed on their round trip".to_string())
            }
        },
        "m.toml" => match Model::from_toml(&text, name) {
            Err(e) => located(e.to_string(), name, e.line),
            Ok(_) => Ok(()),
        },
        "p.toml" => match Protocol::from_toml(&text, name) {
            Err(e) => located(e.to_string(), name, e.line),
            Ok(_) => Ok(()),
        },
        other => unreachable!("{other}"),
    }
}

proptest! {
    #![proptest_config(config(512))]

    /// Valid files of every format with one to four random damages.
    #[test]
    fn damaged_files_give_values_or_located_errors(
        which in any::<prop::sample::Index>(),
        edits in prop::collection::vec(edit(), 1..5),
    ) {
        let seeds = seeds();
        let (name, text) = which.get(&seeds);
        let bytes = damage(text, &edits);
        let dir = tempfile::tempdir().unwrap();
        read_any(name, &bytes, dir.path()).map_err(|e| {
            TestCaseError::fail(format!("{name}: {e}\n{}", String::from_utf8_lossy(&bytes)))
        })?;
    }

    /// Random bytes, to every reader.
    #[test]
    fn random_bytes_give_values_or_located_errors(
        bytes in prop::collection::vec(any::<u8>(), 0..300),
    ) {
        let dir = tempfile::tempdir().unwrap();
        for (name, _) in seeds() {
            read_any(name, &bytes, dir.path())
                .map_err(|e| TestCaseError::fail(format!("{name}: {e}")))?;
        }
    }
}

#[test]
fn the_seeds_are_valid() {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in seeds() {
        read_any(name, text.as_bytes(), dir.path()).unwrap();
    }
    let model = Model::infant13();
    read_trial_from_str(&seeds()[0].1, "t.csv", TrialFormat::QuatCsv, &model).unwrap();
    parse_export(&seeds()[3].1, "x.txt").unwrap();
    parse_mapping(&seeds()[4].1, "m.xml").unwrap();
}

/// What the properties found, kept as fixed cases: a table name with a
/// control character (written with Rust's `\u{1b}` escape, not TOML's), a
/// 17-digit float that serde_json's default parser read one ulp off, and
/// invalid UTF-8 after `//` (read as an export, its error was not located).
#[test]
fn regressions_found_by_the_properties() {
    let s = SettingsFile {
        table: "\u{1b}t\u{7f}.csv".into(),
        ..SettingsFile::parse(acm_workbench::limits::BUILTIN_SETTINGS, "s").unwrap()
    };
    assert_eq!(SettingsFile::parse(&s.to_toml(), "s.toml").unwrap(), s);
    let mut m = Model::infant13();
    m.segment_direction
        .insert("base".into(), [0.44317299437524277, 1e-6, -0.0]);
    let back: Model = serde_json::from_str(&serde_json::to_string_pretty(&m).unwrap()).unwrap();
    assert_eq!(back, m);
    // Bytes that begin like an MT Manager export (`//`) and are not UTF-8:
    // the export reader's error is located too.
    let dir = tempfile::tempdir().unwrap();
    read_any("t.csv", b"//\x80", dir.path()).unwrap();
}
