//! Swing-twist joint limits (docs/method.md section 5.1; README "Swing-twist
//! limits"): the shipped table, the loader's errors, the cost against the
//! direct formula and its gradient against finite differences, the knee test
//! near the Euler singularity, and the sample trials against the Euler table.
//!
//! Figures (printed, quoted in the README): the knee's geodesic error after
//! `basic` with the Euler and the swing-twist table per thigh misalignment,
//! and per sample trial and joint the RMS and largest angle between the
//! joints corrected with either table.

mod common;

use acm_workbench::acm::cost::WindowCost;
use acm_workbench::acm::{Correction, RunControl, Variant};
use acm_workbench::correct::correct_trial;
use acm_workbench::limits::swing_twist::{SwingTwistLimits, HEADER};
use acm_workbench::limits::{JointLimits, LimitTable, Settings, BUILTIN_TABLES};
use acm_workbench::model::Model;
use acm_workbench::rotation::{angle_between_deg, angle_deg, quat_axis_angle_deg, wxyz, Quat};
use acm_workbench::simulate::{simulate, KneeAxis, KneeImu, SimConfig};
use acm_workbench::trial::{read_trial, Trial};
use common::engine::geodesic_error_deg;
use nalgebra::Vector3;
use std::path::Path;

fn swing_table() -> LimitTable {
    let (name, text) = BUILTIN_TABLES
        .iter()
        .find(|(n, _)| *n == "swing_twist.csv")
        .expect("shipped");
    LimitTable::parse(text, name).unwrap()
}

fn correct(trial: &Trial, model: &Model, table: &LimitTable, variant: Variant) -> Correction {
    correct_trial(
        trial,
        model,
        table,
        &Settings::default(),
        variant,
        &RunControl::default(),
    )
    .unwrap()
}

/// The shipped table file on disk is the built-in one, reads back as
/// swing-twist, and its Euler boxes are Table 3-2's ranges, centroids and
/// weights: the derivation its comments state.
#[test]
fn the_shipped_table_is_table_3_2_in_swing_twist_form() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("joint_limits");
    let t = LimitTable::load(&dir.join("swing_twist.csv")).unwrap();
    assert_eq!(t, swing_table());
    assert_eq!(t.model_name(), "swing-twist");
    let euler = LimitTable::default_table();
    assert_eq!(euler.model_name(), "euler-zyx");
    let model = Model::builtin("full_body16").unwrap();
    t.check_covers(&model, "swing_twist.csv").unwrap();
    for j in &model.joints {
        let s = t.joint_limits(&j.name, &j.kind, true).unwrap();
        let e = euler.joint_limits(&j.name, &j.kind, true).unwrap();
        assert_eq!(s.range_deg, e.range_deg, "{}", j.name);
        assert_eq!(s.centroid_deg, e.centroid_deg, "{}", j.name);
        assert_eq!(s.lambda2, e.lambda2, "{}", j.name);
        let st = s.swing_twist.expect("swing-twist limits");
        let twist_row = euler.row(&j.name, &j.kind, st.twist_axis).unwrap();
        assert!(
            twist_row.movement.contains("rotation") || twist_row.movement.contains("pronation"),
            "{}: twist about {}",
            j.name,
            st.twist_axis
        );
    }
    // Saved and read back: the same table and hash.
    let again = LimitTable::parse(&t.to_csv(), "again.csv").unwrap();
    assert_eq!(again, t);
    assert_eq!(again.hash(), t.hash());
    assert!(t.to_csv().lines().any(|l| l == HEADER.join(",")));
}

fn parse_err(rows: &str) -> acm_workbench::limits::LimitsError {
    let text = format!("# comment\n{}\n{rows}", HEADER.join(","));
    LimitTable::parse(&text, "st.csv").unwrap_err()
}

#[test]
fn malformed_rows_are_located_errors() {
    let ok = "knee,X,m,65,0,65,5,,-5,5,,,,,,0";
    LimitTable::parse(&format!("{}\n{ok}\n", HEADER.join(",")), "st.csv").unwrap();
    let cases: [(&str, u64, usize, &str); 10] = [
        (
            "knee,W,m,65,0,65,5,,-5,5,,,,,,0",
            3,
            2,
            "twist axis X, Y or Z",
        ),
        (
            "knee,X,m,abc,0,65,5,,-5,5,,,,,,0",
            3,
            4,
            "swing_1_centre_deg",
        ),
        (
            "knee,X,m,65,0,0,5,,-5,5,,,,,,0",
            3,
            6,
            "swing_1_half_deg > 0",
        ),
        (
            "knee,X,m,65,0,65,5,9,-5,5,,,,,,0",
            3,
            8,
            "at most the smaller half-angle",
        ),
        (
            "knee,X,m,65,0,65,5,,5,-5,,,,,,0",
            3,
            10,
            "twist_upper_deg > twist_lower_deg",
        ),
        (
            "knee,X,m,65,0,65,5,,-5,5,-3,,,,,0",
            3,
            12,
            "edge_twist_upper_deg",
        ),
        (
            "knee,X,m,65,0,65,5,,-5,5,,,1,,,0",
            3,
            14,
            "all three centroid angles",
        ),
        ("knee,X,m,65,0,65,5,,-5,5,,,,,,-1", 3, 16, "lambda2"),
        ("knee,X,m,65,0,65,5,,-5,5,,,,,", 3, 16, "fields"),
        (
            "knee,X,m,65,0,65,5,,-5,200,,,,,,0",
            3,
            10,
            "within -180..180",
        ),
    ];
    for (row, line, column, what) in cases {
        let e = parse_err(&format!("{row}\n"));
        assert_eq!((e.line, e.column), (line, column), "{row}: {e}");
        assert!(e.message.contains(what), "{row}: {e}");
        assert!(
            e.to_string()
                .starts_with(&format!("st.csv:{line}:{column}:")),
            "{e}"
        );
    }
    let e = parse_err(&format!("{ok}\n{ok}\n"));
    assert_eq!((e.line, e.column), (4, 1), "{e}");
    assert!(e.message.contains("appears twice (first on line 3)"), "{e}");
    // A header that starts as the swing-twist one but differs: its column.
    let e = LimitTable::parse(
        "joint,twist_axis,movement,swing_1_centre_deg,oops\n",
        "h.csv",
    )
    .unwrap_err();
    assert_eq!((e.line, e.column), (1, 5), "{e}");
    assert!(e.message.contains("swing-twist header"), "{e}");
    // A joint missing from the table, against a model.
    let t = LimitTable::parse(&format!("{}\n{ok}\n", HEADER.join(",")), "st.csv").unwrap();
    let e = t.check_covers(&Model::infant13(), "st.csv").unwrap_err();
    assert!(e.message.contains("no row for joint"), "{e}");
}

/// The swing-twist coordinates computed independently (nalgebra's
/// quaternions: twist = the projection of the quaternion on the axis), and
/// the excursion from them with a dense search for the ellipse's nearest
/// point.
fn direct_excursion(l: &SwingTwistLimits, q: &Quat) -> f64 {
    let t = l.twist_axis;
    let mut e = Vector3::zeros();
    e[t] = 1.0;
    let v = q.imag();
    let twist = Quat::from_quaternion(nalgebra::Quaternion::from_parts(q.w, v.dot(&e) * e));
    // The twist about Z in the proximal frame (R = T S), else the distal (R = S T).
    let swing = if t == 2 {
        twist.inverse() * q
    } else {
        q * twist.inverse()
    };
    let sv = swing.scaled_axis().map(f64::to_degrees);
    let tw = twist.scaled_axis().map(f64::to_degrees)[t];
    let others: Vec<usize> = (0..3).filter(|k| *k != t).collect();
    let p = [
        sv[others[0]] - l.centre_deg[0],
        sv[others[1]] - l.centre_deg[1],
    ];
    let [a, b] = l.half_deg;
    let u = ((p[0] / a).powi(2) + (p[1] / b).powi(2)).sqrt();
    let swing_e = if let Some(r) = l.corner_deg {
        // The rounded box: the distance from the box shrunk by r, less r.
        let near = [p[0].clamp(r - a, a - r), p[1].clamp(r - b, b - r)];
        (((p[0] - near[0]).powi(2) + (p[1] - near[1]).powi(2)).sqrt() - r).max(0.0)
    } else if u <= 1.0 {
        0.0
    } else {
        // Dense search, then refined around the best.
        let dist = |th: f64| ((a * th.cos() - p[0]).powi(2) + (b * th.sin() - p[1]).powi(2)).sqrt();
        let n = 20_000;
        let step = std::f64::consts::TAU / n as f64;
        let k = (0..n)
            .min_by(|i, j| dist(*i as f64 * step).total_cmp(&dist(*j as f64 * step)))
            .unwrap();
        let (mut lo, mut hi) = ((k as f64 - 1.0) * step, (k as f64 + 1.0) * step);
        for _ in 0..200 {
            let m1 = lo + (hi - lo) / 3.0;
            let m2 = hi - (hi - lo) / 3.0;
            if dist(m1) < dist(m2) {
                hi = m2;
            } else {
                lo = m1;
            }
        }
        dist(0.5 * (lo + hi))
    };
    let f = u.min(1.0);
    let lo = l.twist_deg[0] + (l.edge_twist_deg[0] - l.twist_deg[0]) * f;
    let hi = l.twist_deg[1] + (l.edge_twist_deg[1] - l.twist_deg[1]) * f;
    let twist_e = if tw > hi {
        tw - hi
    } else if tw < lo {
        lo - tw
    } else {
        0.0
    };
    swing_e + twist_e
}

fn random_quats(seed: u64, n: usize, max_deg: f64) -> Vec<Quat> {
    // A small deterministic generator (no test-only dependency needed).
    let mut s = seed;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    (0..n)
        .map(|_| {
            let axis = [next(), next(), next()];
            quat_axis_angle_deg(axis, (next() + 1.0) * 0.5 * max_deg)
        })
        .collect()
}

fn test_limits() -> Vec<JointLimits> {
    let table = swing_table();
    let model = Model::builtin("full_body16").unwrap();
    let mut out = Vec::new();
    for name in ["l_knee", "r_elbow", "r_hip", "l_shoulder", "l_ankle"] {
        let j = model.joint(name).unwrap();
        out.push(
            table
                .joint_limits(&j.name, &j.kind, true)
                .unwrap()
                .in_table_axes(j),
        );
    }
    // A twist range that narrows towards the edge, a cone and an offset centre.
    let mut knee = out[0];
    knee.swing_twist = Some(SwingTwistLimits {
        twist_axis: 1,
        centre_deg: [20.0, -10.0],
        half_deg: [40.0, 40.0],
        corner_deg: None,
        twist_deg: [-30.0, 50.0],
        edge_twist_deg: [-5.0, 10.0],
    });
    knee.axes = None;
    out.push(knee);
    out
}

/// `WindowCost` with swing-twist limits against the direct formula: mean
/// excursion plus centroid term over the samples plus `lambda1 angle(C)`.
#[test]
fn the_cost_is_the_direct_formula() {
    let model = Model::builtin("full_body16").unwrap();
    for (k, lim) in test_limits().into_iter().enumerate() {
        let measured = random_quats(11 + k as u64, 300, 150.0);
        let cost = WindowCost::new(&measured, &lim, 0.05);
        let st = lim.swing_twist.unwrap();
        let centroid = lim
            .centroid_deg
            .filter(|_| lim.lambda2 > 0.0)
            .map(acm_workbench::rotation::quat_from_euler_zyx_deg);
        let mut outside = 0;
        for c in random_quats(100 + k as u64, 15, 60.0) {
            let want: f64 = measured
                .iter()
                .map(|m| {
                    let rt = lim.to_axes(&(m * c));
                    let e = direct_excursion(&st, &rt);
                    outside += usize::from(e > 0.0);
                    e + centroid.map_or(0.0, |qc| {
                        let (a, b) = (rt.into_inner(), qc.into_inner());
                        lim.lambda2 * (a - b).norm().min((a + b).norm())
                    })
                })
                .sum::<f64>()
                / measured.len() as f64
                + 0.05 * angle_deg(&c);
            let got = cost.eval(&c);
            assert!((got - want).abs() < 1e-6, "{k}: {got} vs {want}");
        }
        let _ = &model;
        assert!(outside > 500, "{k}: only {outside} samples outside");
    }
}

/// The gradient of the cost's data part against central finite differences,
/// skipping a direction whose one-sided differences disagree (a sample's kink
/// within the step).
#[test]
fn the_gradient_is_the_finite_difference() {
    let mut kinks = 0;
    let mut checked = 0;
    for (k, lim) in test_limits().into_iter().enumerate() {
        let measured = random_quats(21 + k as u64, 200, 120.0);
        let cost = WindowCost::new(&measured, &lim, 0.05);
        for c in random_quats(200 + k as u64, 12, 60.0) {
            let (f, g) = cost.data_grad(&c);
            assert!((f + 0.05 * angle_deg(&c) - cost.eval(&c)).abs() < 1e-12);
            let h = 1e-7;
            for a in 0..3 {
                let mut v = Vector3::zeros();
                v[a] = h;
                let up = (cost.data_grad(&(c * Quat::from_scaled_axis(v))).0 - f) / h;
                let down = (f - cost.data_grad(&(c * Quat::from_scaled_axis(-v))).0) / h;
                let tol = 1e-4 * (1.0 + g[a].abs());
                if (up - down).abs() > tol {
                    kinks += 1;
                    continue;
                }
                checked += 1;
                let fd = 0.5 * (up + down);
                assert!((fd - g[a]).abs() < tol, "{k} axis {a}: {fd} vs {}", g[a]);
            }
        }
    }
    assert!(
        kinks < 10 && checked > 200,
        "{kinks} kinks, {checked} checked"
    );
}

const ANGLES_DEG: [f64; 6] = [5.0, 10.0, 15.0, 20.0, 25.0, 30.0];

/// The knee test (thigh static, calf flexing 15-75 deg; the thigh IMU
/// misaligned about X or Z): `basic` and `hinge` with either table, the
/// knee's geodesic error against the truth.
#[test]
fn the_knee_test_has_no_singularity_residuals() {
    let model = Model::infant13();
    let euler = LimitTable::default_table();
    let st = swing_table();
    let mut rows = Vec::new();
    for axis in [KneeAxis::X, KneeAxis::Z] {
        for angle in ANGLES_DEG {
            let sim = simulate(&SimConfig::knee(KneeImu::Thigh, axis, angle)).unwrap();
            let err = |t: &LimitTable, v: Variant| {
                let c = correct(&sim.trial, &model, t, v);
                geodesic_error_deg(&model, "l_knee", &c.corrected, &sim.truth.segments)
            };
            let none = geodesic_error_deg(&model, "l_knee", &sim.trial, &sim.truth.segments);
            let (e, s) = (err(&euler, Variant::Basic), err(&st, Variant::Basic));
            let (he, hs) = (err(&euler, Variant::Hinge), err(&st, Variant::Hinge));
            eprintln!(
                "thigh {axis:?} {angle:>4}: knee error basic Euler {e:5.2}, swing-twist {s:5.2}; hinge Euler {he:5.2}, swing-twist {hs:5.2}; uncorrected {none:5.2} deg"
            );
            rows.push((axis, angle, e, s, none, hs));
        }
    }
    for (axis, angle, e, s, none, hs) in rows {
        // A misaligned proximal IMU is beyond any correction of the distal
        // one: `basic` leaves much of it whatever the table (never worse than
        // leaving the trial alone); `hinge` undoes it with either table.
        assert!(
            s <= none + 0.5,
            "{axis:?} {angle}: {s} vs uncorrected {none} (Euler {e})"
        );
        assert!(hs <= 3.0, "{axis:?} {angle}: hinge with swing-twist {hs}");
    }
}

/// On the sample trials with truth, the corrections with the swing-twist
/// table against those with the Euler table, per joint: the RMS angle between
/// the corrected joint rotations, and each one's error against the truth.
/// Away from the Euler singularity (|Y| < 60 deg in every sample of both
/// results) the joints twisting about X agree within 1-2 deg.
#[test]
fn sample_trials_agree_with_the_euler_table_away_from_the_singularity() {
    let model = Model::infant13();
    let euler = LimitTable::default_table();
    let st = swing_table();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("sample_trials");
    let mut compared = 0;
    let mut worst_far = Vec::new();
    for name in [
        "knee_calf_z15.csv.gz",
        "full_body_clean.csv.gz",
        "full_body_drift.csv.gz",
        "elbow_20.csv.gz",
    ] {
        let path = dir.join(name);
        let trial = read_trial(&path, &model).unwrap();
        let truth = acm_workbench::simulate::truth::load_truth_beside(&path, &model)
            .unwrap()
            .unwrap();
        for variant in [Variant::Basic, Variant::DriftCentroid] {
            let a = correct(&trial, &model, &euler, variant);
            let b = correct(&trial, &model, &st, variant);
            for jr in &a.joints {
                let j = model.joint(&jr.joint).unwrap();
                let rot = |t: &Trial| -> Vec<Quat> {
                    let p = &t.imu(&j.proximal).unwrap().orientation;
                    let d = &t.imu(&j.distal).unwrap().orientation;
                    p.iter().zip(d).map(|(p, d)| p.inverse() * d).collect()
                };
                let (ra, rb) = (rot(&a.corrected), rot(&b.corrected));
                let diffs: Vec<f64> = ra
                    .iter()
                    .zip(&rb)
                    .map(|(x, y)| angle_between_deg(x, y))
                    .collect();
                let rms = (diffs.iter().map(|d| d * d).sum::<f64>() / diffs.len() as f64).sqrt();
                let worst = diffs.iter().copied().fold(0.0, f64::max);
                let pitch = ra
                    .iter()
                    .chain(&rb)
                    .map(|r| j.table_angles(r)[1].abs())
                    .fold(0.0, f64::max);
                let near = pitch >= 60.0;
                let truth_err = |t: &Trial| geodesic_error_deg(&model, &j.name, t, &truth.segments);
                eprintln!(
                    "{name} {variant} {}: swing-twist vs Euler RMS {rms:5.2}, max {worst:5.2} deg (max |Y| {pitch:5.1}{}); error vs truth Euler {:5.2}, swing-twist {:5.2}",
                    j.name,
                    if near { ", near the singularity" } else { "" },
                    truth_err(&a.corrected),
                    truth_err(&b.corrected)
                );
                if !near {
                    compared += 1;
                    worst_far.push((format!("{name} {variant} {}", j.name), rms));
                }
            }
        }
    }
    assert!(compared >= 20, "{compared}");
    let mut by_kind: std::collections::BTreeMap<String, f64> = Default::default();
    for (what, rms) in &worst_far {
        let joint = what.rsplit(' ').next().unwrap();
        let kind = model.joint(joint).unwrap().kind.clone();
        let e = by_kind.entry(kind).or_insert(0.0);
        *e = e.max(*rms);
    }
    eprintln!("largest RMS difference away from the singularity, per kind: {by_kind:?}");
    // Where the twist axis is the Z-Y-X sequence's last (X: back, hips,
    // ankles, neck), the two tables agree: within 1 deg on back and hips,
    // 2 deg on neck and ankles (measured 0.71, 0.32, 1.88, 1.81). Shoulders
    // (twist about Y, the middle axis) and elbows (flexion to 160 deg with
    // pronation) read differently in the two models at large combined
    // movements and are printed only (measured up to 13 and 27 deg).
    for (kind, bound) in [("back", 1.0), ("hip", 1.0), ("neck", 2.0), ("ankle", 2.0)] {
        let got = by_kind[kind];
        assert!(got <= bound, "{kind}: {got} > {bound}");
    }
}

/// The heading variants (and `auto`, which tries them) refuse a swing-twist
/// table: every joint skipped with the reason; the command line says so as an
/// error.
#[test]
fn heading_variants_refuse_swing_twist_tables() {
    let model = Model::infant13();
    let sim = simulate(&SimConfig::knee(KneeImu::Thigh, KneeAxis::X, 10.0)).unwrap();
    let c = correct(&sim.trial, &model, &swing_table(), Variant::DriftHeading);
    assert!(c.joints.is_empty());
    assert!(!c.skipped.is_empty());
    for s in &c.skipped {
        assert!(s.reason.contains("Euler limit tables only"), "{}", s.reason);
    }
    let b = correct(&sim.trial, &model, &swing_table(), Variant::Drift);
    assert!(!b.joints.is_empty());
}

#[test]
fn wxyz_of_the_cost_samples_is_sign_invariant() {
    // The excursion of q and -q is the same (the table's rotation, not its
    // quaternion's sign).
    let l = swing_table()
        .joint_limits("l_knee", "knee", false)
        .unwrap()
        .swing_twist
        .unwrap();
    for q in random_quats(5, 200, 179.0) {
        let w = wxyz(&q);
        assert_eq!(l.excursion(w), l.excursion(w.map(|c| -c)));
    }
}

/// The command line with a swing-twist table: `correct` refuses a heading
/// variant with a located error (exit 3), corrects with `drift` and records
/// the model in the sidecar, which `--from-sidecar` reproduces byte for byte;
/// `report` names the model; `plot globe` draws the region's edge.
#[test]
fn the_command_line_selects_and_records_a_swing_twist_table() {
    use std::process::Command;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let table = root.join("joint_limits/swing_twist.csv");
    let trial = root.join("sample_trials/elbow_20.csv.gz");
    let dir = tempfile::tempdir().unwrap();
    let acmw = || {
        let mut c = Command::new(env!("CARGO_BIN_EXE_acmw"));
        c.current_dir(dir.path());
        c
    };
    let out = acmw()
        .args([
            "correct",
            "--quiet",
            "--variant",
            "drift-heading",
            "--limits",
        ])
        .arg(&table)
        .arg(&trial)
        .arg("-o")
        .arg(dir.path().join("h.csv"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(3), "{err}");
    assert!(
        err.contains("swing_twist.csv") && err.contains("takes Euler limit tables only"),
        "{err}"
    );
    let first = dir.path().join("d.csv");
    let out = acmw()
        .args(["correct", "--quiet", "--variant", "drift", "--limits"])
        .arg(&table)
        .arg(&trial)
        .arg("-o")
        .arg(&first)
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let sidecar = dir.path().join("d.csv.acmw.json");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&sidecar).unwrap()).unwrap();
    assert_eq!(json["limits"]["model"], "swing-twist");
    let again = dir.path().join("again.csv");
    let out = acmw()
        .args(["correct", "--quiet", "--from-sidecar"])
        .arg(&sidecar)
        .arg(&trial)
        .arg("-o")
        .arg(&again)
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        std::fs::read(&first).unwrap(),
        std::fs::read(&again).unwrap()
    );
    let out = acmw()
        .args(["report", "--variant", "basic", "--limits"])
        .arg(&table)
        .arg(&trial)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("swing_twist.csv (swing-twist)"), "{text}");
    let svg = dir.path().join("g.svg");
    let out = acmw()
        .args(["plot", "globe", "--joint", "l_elbow", "--limits"])
        .arg(&table)
        .arg(&trial)
        .arg("-o")
        .arg(&svg)
        .output()
        .unwrap();
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains("#D06000"), "the region's edge");
}
