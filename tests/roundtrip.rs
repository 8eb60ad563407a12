//! Every writer's output reads back: seeded random trials (each format, with
//! and without gzip and gyros), limit tables with awkward names, and settings
//! files, written by the program's writers and read by its readers.

use acm_workbench::limits::{LimitRow, LimitTable, SettingsFile};
use acm_workbench::model::Model;
use acm_workbench::rotation::{angle_between_deg, quat_from_euler_zyx_deg};
use acm_workbench::trial::precision::Precision;
use acm_workbench::trial::{read_trial, write_trial, ImuSeries, Trial, TrialFormat};
use acm_workbench::vertical::Vertical;
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn random_trial(rng: &mut ChaCha8Rng) -> Trial {
    let n = rng.random_range(2..60);
    let dt = 10f64.powf(rng.random_range(-4.0..1.0));
    let mut t = rng.random_range(-1e4..1e4);
    let time_s: Vec<f64> = (0..n)
        .map(|_| {
            t += dt * rng.random_range(0.5..1.5);
            t
        })
        .collect();
    let names = ["base", "upper_back", "head"];
    let k = rng.random_range(1..=3);
    let gyros = rng.random_bool(0.5);
    let imus = names[..k]
        .iter()
        .map(|name| {
            let q = (0..n)
                .map(|_| {
                    quat_from_euler_zyx_deg([
                        rng.random_range(-180.0..180.0),
                        rng.random_range(-89.0..89.0),
                        rng.random_range(-180.0..180.0),
                    ])
                })
                .collect();
            let g = gyros.then(|| {
                (0..n)
                    .map(|_| Vector3::new(rng.random(), rng.random::<f64>() * -1e3, 1e-300))
                    .collect()
            });
            ImuSeries::new(*name, q).with_gyro(g)
        })
        .collect();
    Trial {
        name: "r".into(),
        time_s,
        imus,
        warnings: vec![],
        orientation_decimals: None,
    }
}

#[test]
fn written_trials_read_back() {
    let dir = tempfile::tempdir().unwrap();
    let model = Model::infant13();
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let formats = [
        (TrialFormat::QuatCsv, "t.csv", 1e-9),
        (TrialFormat::QuatCsv, "t.csv.gz", 1e-9),
        (TrialFormat::EulerCsv, "e.csv", 1e-6),
        (TrialFormat::Sto, "s.sto", 1e-9),
        (TrialFormat::Sto, "s.sto.gz", 1e-9),
    ];
    for case in 0..40 {
        let trial = random_trial(&mut rng);
        for (format, name, tol_deg) in formats {
            let path = dir.path().join(name);
            write_trial(&trial, &path, format).unwrap();
            let back =
                read_trial(&path, &model).unwrap_or_else(|e| panic!("case {case} {name}: {e}"));
            assert_eq!(back.time_s, trial.time_s, "case {case} {name}");
            for (a, b) in trial.imus.iter().zip(&back.imus) {
                assert_eq!(a.name, b.name);
                for (p, q) in a.orientation.iter().zip(&b.orientation) {
                    assert!(angle_between_deg(p, q) < tol_deg, "case {case} {name}");
                }
                if format != TrialFormat::Sto {
                    assert_eq!(a.gyro, b.gyro, "case {case} {name}");
                }
            }
        }
    }
}

#[test]
fn written_limit_tables_and_settings_read_back() {
    let mut rng = ChaCha8Rng::seed_from_u64(13);
    let awkward = [
        "knee",
        "a,b",
        "say \"hi\"",
        "#hash",
        "tab\there",
        "ünï",
        "x y",
    ];
    for case in 0..50 {
        let mut rows = Vec::new();
        for j in 0..rng.random_range(1..5) {
            let joint = format!("{}{j}", awkward[rng.random_range(0..awkward.len())]);
            let lambda2 = rng.random_range(0.0..50.0);
            let centroid = rng.random_bool(0.5);
            for axis in 0..3 {
                let lower: f64 = rng.random_range(-180.0..0.0);
                rows.push(LimitRow {
                    joint: joint.clone(),
                    axis,
                    movement: awkward[rng.random_range(0..awkward.len())].to_string(),
                    lower_deg: lower,
                    upper_deg: rng.random_range(lower..180.0),
                    centroid_deg: centroid.then(|| rng.random_range(-90.0..90.0)),
                    lambda2,
                });
            }
        }
        let table = LimitTable {
            preamble: vec!["# a comment".into()],
            rows,
            swing_twist: None,
        };
        let back = LimitTable::parse(&table.to_csv(), "t.csv")
            .unwrap_or_else(|e| panic!("case {case}: {e}\n{}", table.to_csv()));
        assert_eq!(back, table, "case {case}");
        assert_eq!(back.hash(), table.hash());
        let window_s = rng.random_range(0.1..1e4);
        let s = SettingsFile {
            table: awkward[rng.random_range(0..awkward.len())].to_string() + ".csv",
            lambda1: rng.random_range(0.0..1e3),
            window_s,
            hop_s: rng.random_range(window_s / 999.0..=window_s),
            vertical: if rng.random_bool(0.5) {
                Vertical::ZUp
            } else {
                Vertical::ZDown
            },
            glitch_deg: rng.random_range(0.01..180.0),
            precision: [Precision::Auto, Precision::Full, Precision::Decimals(6)]
                [rng.random_range(0..3)],
        };
        let back = SettingsFile::parse(&s.to_toml(), "s.toml")
            .unwrap_or_else(|e| panic!("case {case}: {e}"));
        assert_eq!(back, s, "case {case}");
    }
}
