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
use acm_workbench::acm::heading_cost::HeadingCost;
use acm_workbench::acm::parent_cost::ParentCost;
use acm_workbench::acm::Variant;
use acm_workbench::limits::swing_twist::{SwingTwistLimits, HEADER};
use acm_workbench::limits::{JointLimits, LimitTable, BUILTIN_TABLES};
use acm_workbench::model::Model;
use acm_workbench::rotation::{angle_between_deg, angle_deg, quat_axis_angle_deg, wxyz, Quat};
use acm_workbench::simulate::{preset, simulate, KneeAxis, KneeImu, SimConfig};
use acm_workbench::trial::{read_trial, Trial};
use acm_workbench::vertical::Vertical;
use common::engine::{geodesic_error_deg, median, run_with_table};
use nalgebra::Vector3;
use std::path::Path;

fn swing_table() -> LimitTable {
    let (name, text) = BUILTIN_TABLES
        .iter()
        .find(|(n, _)| *n == "swing_twist.csv")
        .expect("shipped");
    LimitTable::parse(text, name).unwrap()
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
        // The twist about X, the last axis of the Z-Y-X sequence, for every
        // joint (the table's comments say why).
        let st = s.swing_twist.expect("swing-twist limits");
        assert_eq!(st.twist_axis, 0, "{}", j.name);
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
    if l.zyx_box {
        return direct_zyx_excursion(l, q);
    }
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
    // The twist is an angle on the circle: 0 on the arc from lo to hi, else
    // the shorter way round to either end.
    let twist_e = if (tw - lo).rem_euclid(360.0) <= hi - lo {
        0.0
    } else {
        (tw - hi).rem_euclid(360.0).min((lo - tw).rem_euclid(360.0))
    };
    swing_e + twist_e
}

/// The excursion beyond an angle range on the circle: 0 on the arc from `lo`
/// to `hi`, else the shorter way round to either end.
fn arc_beyond(a: f64, lo: f64, hi: f64) -> f64 {
    if (a - lo).rem_euclid(360.0) <= hi - lo {
        0.0
    } else {
        (a - hi).rem_euclid(360.0).min((lo - a).rem_euclid(360.0))
    }
}

/// The Z-Y-X box region computed independently: nalgebra's Z-Y-X angles
/// (`R = Rz(yaw) Ry(pitch) Rx(roll)`), the twist about X as the quaternion's
/// projection on it; inside the caps |pitch| > 60 deg the roll gives way to
/// the twist and the yaw's excursion is weighed by `cos(pitch) / cos(60)`.
fn direct_zyx_excursion(l: &SwingTwistLimits, q: &Quat) -> f64 {
    let (roll, pitch, yaw) = q.euler_angles();
    let (roll, pitch, yaw) = (roll.to_degrees(), pitch.to_degrees(), yaw.to_degrees());
    let v = q.imag();
    let twist = Quat::from_quaternion(nalgebra::Quaternion::from_parts(
        q.w,
        Vector3::new(v.x, 0.0, 0.0),
    ));
    let twist = twist.scaled_axis().x.to_degrees();
    let weight = (pitch.to_radians().cos() / 60f64.to_radians().cos()).min(1.0);
    let (ylo, yhi) = (
        l.centre_deg[0] - l.half_deg[0],
        l.centre_deg[0] + l.half_deg[0],
    );
    let (zlo, zhi) = (
        l.centre_deg[1] - l.half_deg[1],
        l.centre_deg[1] + l.half_deg[1],
    );
    let reading = |roll: f64, pitch: f64, yaw: f64| {
        let roll = if weight < 1.0 {
            let shift = (twist - roll + 180.0).rem_euclid(360.0) - 180.0;
            twist - weight * shift
        } else {
            roll
        };
        let pitch_e = (pitch - yhi).max(ylo - pitch).max(0.0);
        arc_beyond(roll, l.twist_deg[0], l.twist_deg[1])
            + pitch_e
            + weight * arc_beyond(yaw, zlo, zhi)
    };
    let principal = reading(roll, pitch, yaw);
    if (ylo >= -90.0 && yhi <= 90.0) || principal == 0.0 {
        return principal;
    }
    let other_pitch = if pitch >= 0.0 {
        180.0 - pitch
    } else {
        -180.0 - pitch
    };
    principal.min(reading(roll + 180.0, other_pitch, yaw + 180.0))
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
        out.push(table.cost_limits(j, true).unwrap());
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
        zyx_box: false,
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
                let c = run_with_table(&model, &sim.trial, t, v);
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
/// results, at the joint and at every joint above it in the chain, whose
/// corrections its measured rotations take) every joint agrees within 1 deg:
/// the shipped table reads every joint but the knee as the Z-Y-X box
/// (`swing_corner_deg` `zyx`), which is the Euler box's excursion there.
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
            let a = run_with_table(&model, &trial, &euler, variant);
            let b = run_with_table(&model, &trial, &st, variant);
            // Per joint: the RMS and largest difference, and whether a
            // sample of either result comes within 30 deg of the pole.
            let mut rows = std::collections::BTreeMap::new();
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
                let truth_err = |t: &Trial| geodesic_error_deg(&model, &j.name, t, &truth.segments);
                let errs = (truth_err(&a.corrected), truth_err(&b.corrected));
                rows.insert(j.name.clone(), (rms, worst, pitch, errs));
            }
            for (joint, &(rms, worst, pitch, (ea, eb))) in &rows {
                // The joints whose corrections this joint's input takes.
                let mut near_above = None;
                let mut up = model.joint(joint).unwrap();
                while let Some(parent) = model.joint_of_distal(&up.proximal) {
                    if rows.get(&parent.name).is_some_and(|r| r.2 >= 60.0) {
                        near_above = Some(parent.name.clone());
                    }
                    up = parent;
                }
                let near = pitch >= 60.0 || near_above.is_some();
                eprintln!(
                    "{name} {variant} {joint}: swing-twist vs Euler RMS {rms:5.2}, max {worst:5.2} deg (max |Y| {pitch:5.1}{}); error vs truth Euler {ea:5.2}, swing-twist {eb:5.2}",
                    match (&near_above, pitch >= 60.0) {
                        (_, true) => ", near the singularity".to_string(),
                        (Some(p), false) => format!(", below {p} near the singularity"),
                        (None, false) => String::new(),
                    },
                );
                if !near {
                    compared += 1;
                    worst_far.push((joint.clone(), rms));
                }
            }
        }
    }
    assert!(compared >= 20, "{compared}");
    let mut by_kind: std::collections::BTreeMap<String, f64> = Default::default();
    for (joint, rms) in &worst_far {
        let kind = model.joint(joint).unwrap().kind.clone();
        let e = by_kind.entry(kind).or_insert(0.0);
        *e = e.max(*rms);
    }
    eprintln!("largest RMS difference away from the singularity, per kind: {by_kind:?}");
    // Measured: at most 1.2e-5 deg (the solver's stopping tolerance). The
    // ankles are never compared here: every knee above them nears Y = 90
    // (flexion 75-95 deg), and the knee's row is the rounded box, whose
    // corrections differ from the Euler box's there (the ankle's own cost is
    // the Euler one, the unit tests of `zyx_box` show).
    assert!(by_kind.len() >= 5, "{by_kind:?}");
    for (kind, got) in &by_kind {
        assert!(*got <= 1.0, "{kind}: {got} > 1 deg");
    }
}

/// The mean over `rotations` (segment frames) of the direct excursion plus
/// the centroid term, degrees: the per-sample part of the cost.
fn direct_mean(lim: &JointLimits, rotations: impl Iterator<Item = Quat>) -> (f64, usize) {
    let st = lim.swing_twist.unwrap();
    let centroid = lim
        .centroid_deg
        .filter(|_| lim.lambda2 > 0.0)
        .map(acm_workbench::rotation::quat_from_euler_zyx_deg);
    let (mut sum, mut n, mut outside) = (0.0, 0, 0);
    for r in rotations {
        let rt = lim.to_axes(&r);
        let e = direct_excursion(&st, &rt);
        outside += usize::from(e > 0.0);
        sum += e + centroid.map_or(0.0, |qc| {
            let (a, b) = (rt.into_inner(), qc.into_inner());
            lim.lambda2 * (a - b).norm().min((a + b).norm())
        });
        n += 1;
    }
    (sum / n as f64, outside)
}

/// The heading variants' costs with swing-twist limits against the direct
/// formula: the window cost as a function of the heading
/// (`P^T R_up(-h) D C`, plus `lambda1 (angle(C) + |h|)`) and the child
/// joint's cost as a function of the parent's correction (`C_p^T B`), for
/// both verticals.
#[test]
fn the_heading_and_parent_costs_are_the_direct_formula() {
    for (k, lim) in test_limits().into_iter().enumerate() {
        let k = k as u64;
        let parent = random_quats(31 + k, 200, 180.0);
        let child = random_quats(41 + k, 200, 180.0);
        let mut outside = 0;
        for (n, c) in random_quats(300 + k, 4, 40.0).into_iter().enumerate() {
            let vertical = [Vertical::ZUp, Vertical::ZDown][n % 2];
            let cost = HeadingCost::new(&parent, &child, &c, vertical.up(), &lim, 0.05, 1);
            for h in [-170.0, -33.0, 0.0, 4.5, 90.0] {
                let turn = vertical.heading_rotation(-h);
                let rotations = parent
                    .iter()
                    .zip(&child)
                    .map(|(p, d)| p.inverse() * turn * d * c);
                let (mean, out) = direct_mean(&lim, rotations);
                outside += out;
                let want = mean + 0.05 * (angle_deg(&c) + f64::abs(h));
                let got = cost.eval(h);
                assert!((got - want).abs() < 1e-6, "{k} h {h}: {got} vs {want}");
            }
        }
        assert!(outside > 1000, "{k}: only {outside} samples outside");
        let b = random_quats(51 + k, 200, 180.0);
        let cost = ParentCost::new(b.iter().copied(), &lim);
        for c in random_quats(400 + k, 10, 60.0) {
            let (want, _) = direct_mean(&lim, b.iter().map(|b| c.inverse() * b));
            let got = cost.eval(&c);
            assert!((got - want).abs() < 1e-6, "{k}: {got} vs {want}");
        }
    }
}

/// The heading cost's derivative in `h` and the parent cost's gradient in
/// `C_p` against central finite differences, skipping points whose
/// one-sided differences disagree (a sample's kink within the step).
#[test]
fn the_heading_and_parent_gradients_are_the_finite_differences() {
    let (mut kinks, mut checked) = (0, 0);
    for (k, lim) in test_limits().into_iter().enumerate() {
        let k = k as u64;
        let parent = random_quats(61 + k, 200, 180.0);
        let child = random_quats(71 + k, 200, 180.0);
        for c in random_quats(500 + k, 3, 40.0) {
            let cost = HeadingCost::new(&parent, &child, &c, [0.0, 0.0, 1.0], &lim, 0.05, 1);
            for h in [-170.0, -33.3, 4.5, 17.0, 90.2] {
                let (f, slope) = cost.eval_slope(h);
                assert_eq!(f, cost.eval(h));
                let step = 1e-6;
                let up = (cost.eval(h + step) - f) / step;
                let down = (f - cost.eval(h - step)) / step;
                let tol = 1e-4 * (1.0 + slope.abs());
                if (up - down).abs() > tol {
                    kinks += 1;
                    continue;
                }
                checked += 1;
                let fd = 0.5 * (up + down);
                assert!((fd - slope).abs() < tol, "{k} h {h}: {fd} vs {slope}");
            }
        }
        let b = random_quats(81 + k, 200, 150.0);
        let cost = ParentCost::new(b.iter().copied(), &lim);
        for c in random_quats(600 + k, 10, 60.0) {
            let (f, g) = cost.eval_grad(&c);
            assert_eq!(f, cost.eval(&c));
            let h = 1e-7;
            for a in 0..3 {
                let mut v = Vector3::zeros();
                v[a] = h;
                let up = (cost.eval(&(c * Quat::from_scaled_axis(v))) - f) / h;
                let down = (f - cost.eval(&(c * Quat::from_scaled_axis(-v)))) / h;
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
        kinks * 10 < checked && checked > 250,
        "{kinks} kinks, {checked} checked"
    );
}

/// The heading variants with the shipped swing-twist table on the simulated
/// drifting trial (`full_body_drift`: heading drift of two IMUs, every IMU
/// misaligned 5-30 deg, 0.3 deg noise): per joint the RMS geodesic error
/// against the truth with either table, printed. Over the joints touching a
/// drifting IMU the swing-twist table corrects about as well as the Euler
/// one (median within 1.5 deg), and every joint ends nearer the truth than
/// uncorrected.
#[test]
fn heading_variants_correct_a_drifting_trial_with_a_swing_twist_table() {
    let model = Model::infant13();
    let euler = LimitTable::default_table();
    let st = swing_table();
    let cfg = preset("full_body_drift").unwrap();
    let drifts = cfg.drifts.clone();
    let sim = simulate(&cfg).unwrap();
    for variant in [Variant::DriftHeading, Variant::DriftHeadingCentroid] {
        let a = run_with_table(&model, &sim.trial, &euler, variant);
        let b = run_with_table(&model, &sim.trial, &st, variant);
        assert!(b.skipped.is_empty(), "{:?}", b.skipped);
        assert_eq!(a.joints.len(), b.joints.len());
        let (mut touching_e, mut touching_s, mut others) = (Vec::new(), Vec::new(), Vec::new());
        for j in &model.joints {
            let err = |t: &Trial| geodesic_error_deg(&model, &j.name, t, &sim.truth.segments);
            let (none, e, s) = (err(&sim.trial), err(&a.corrected), err(&b.corrected));
            let touches = drifts
                .iter()
                .any(|d| d.imu == j.proximal || d.imu == j.distal);
            eprintln!(
                "{variant} {:<12} uncorrected {none:6.2}, Euler {e:6.2}, swing-twist {s:6.2} deg{}",
                j.name,
                if touches { "  (drifting IMU)" } else { "" }
            );
            assert!(s < none, "{variant} {}: {s} vs uncorrected {none}", j.name);
            if touches {
                touching_e.push(e);
                touching_s.push(s);
            } else {
                others.push((j.name.clone(), e, s));
            }
        }
        let (me, ms) = (median(touching_e), median(touching_s));
        let worst_other = others.iter().map(|o| o.2 - o.1).fold(f64::MIN, f64::max);
        eprintln!(
            "{variant}: median error on the joints touching a drifting IMU Euler {me:.2}, swing-twist {ms:.2} deg; other joints at most {worst_other:+.2} deg apart"
        );
        // Near the singularity (the knees) the two tables differ by up to 4
        // deg on this trial (as on the sample trials, README).
        assert!(ms <= me + 1.5, "{variant}: median {ms} vs Euler {me}");
    }
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

/// The command line with a swing-twist table: `correct` with `auto` (which
/// tries the heading variants) writes a trial that reads back, corrects with `drift` and records
/// the model in the sidecar, which `--from-sidecar` reproduces byte for byte;
/// `report` names the model; `plot globe` draws the region's edge.
#[test]
fn the_command_line_selects_and_records_a_swing_twist_table() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let table = root.join("joint_limits/swing_twist.csv");
    let trial = root.join("sample_trials/elbow_20.csv.gz");
    let (table, trial_arg) = (table.to_str().unwrap(), trial.to_str().unwrap());
    let dir = tempfile::tempdir().unwrap();
    let run_ok = |args: &[&str]| common::acmw_ok(dir.path(), args);
    // `auto` (which tries the heading variants) with the table: the file is
    // written and reads back, every joint corrected, the sidecar names the
    // model and each joint's choice.
    run_ok(&[
        "correct",
        "--quiet",
        "--variant",
        "auto",
        "--limits",
        table,
        trial_arg,
        "-o",
        "auto.csv",
    ]);
    let model = Model::infant13();
    let back = read_trial(&dir.path().join("auto.csv"), &model).unwrap();
    let raw = read_trial(&trial, &model).unwrap();
    assert_eq!(back.len(), raw.len());
    let auto_json: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(dir.path().join("auto.csv.acmw.json")).unwrap(),
    )
    .unwrap();
    assert_eq!(auto_json["limits"]["model"], "swing-twist");
    assert_eq!(auto_json["variant"], "auto");
    let joints = auto_json["joints"].as_array().expect("joints");
    assert!(!joints.is_empty());
    for j in joints {
        assert!(j["auto"]["chosen"].is_string(), "{j}");
    }
    run_ok(&[
        "correct",
        "--quiet",
        "--variant",
        "drift",
        "--limits",
        table,
        trial_arg,
        "-o",
        "d.csv",
    ]);
    let sidecar = dir.path().join("d.csv.acmw.json");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&sidecar).unwrap()).unwrap();
    assert_eq!(json["limits"]["model"], "swing-twist");
    // `auto` skipped no joint `drift` corrects.
    assert_eq!(auto_json["skipped"], json["skipped"]);
    run_ok(&[
        "correct",
        "--quiet",
        "--from-sidecar",
        sidecar.to_str().unwrap(),
        trial_arg,
        "-o",
        "again.csv",
    ]);
    assert_eq!(
        std::fs::read(dir.path().join("d.csv")).unwrap(),
        std::fs::read(dir.path().join("again.csv")).unwrap()
    );
    let out = common::acmw(
        dir.path(),
        &["report", "--variant", "basic", "--limits", table, trial_arg],
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("swing_twist.csv (swing-twist)"), "{text}");
    run_ok(&[
        "plot", "globe", "--joint", "l_elbow", "--limits", table, trial_arg, "-o", "g.svg",
    ]);
    let text = std::fs::read_to_string(dir.path().join("g.svg")).unwrap();
    assert!(text.contains("#D06000"), "the region's edge");
}

/// The figures the report, the sidecar and the workbench's trial screen show
/// count by the table's own model: with the swing-twist table a joint's mean
/// excursion is the cost's per-sample mean (`WindowCost` at the identity, no
/// centroid term), a sample is outside when its swing or twist is, and the
/// Euler table's figures are unchanged.
#[test]
fn figures_count_by_the_table_model() {
    use acm_workbench::metrics::{excursion_figures, joint_angles, trial_figures};
    let model = Model::infant13();
    let st = swing_table();
    let euler = LimitTable::default_table();
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("sample_trials/full_body_drift.csv.gz");
    let trial = read_trial(&path, &model).unwrap();
    let figures = trial_figures(&trial, None, None, &model, &st);
    let euler_figures = trial_figures(&trial, None, None, &model, &euler);
    assert_eq!(figures.len(), model.joints.len());
    let mut differ = 0;
    for (f, fe) in figures.iter().zip(&euler_figures) {
        let j = model.joint(&f.joint).unwrap();
        let lim = st.cost_limits(j, false).unwrap();
        let p = &trial.imu(&j.proximal).unwrap().orientation;
        let d = &trial.imu(&j.distal).unwrap().orientation;
        let rotations: Vec<Quat> = p.iter().zip(d).map(|(p, d)| p.inverse() * d).collect();
        let want = WindowCost::new(&rotations, &lim, 0.0).eval(&Quat::identity());
        let got = f.excursion.joint_mean_excursion_deg;
        assert!((got - want).abs() < 1e-9, "{}: {got} vs {want}", j.name);
        // Outside on any axis: the swing beyond its region or the twist
        // beyond its range, by the independent formula.
        let stl = lim.swing_twist.unwrap();
        let outside = rotations
            .iter()
            .filter(|r| direct_excursion(&stl, &lim.to_axes(r)) > 1e-9)
            .count();
        let pct = 100.0 * outside as f64 / rotations.len() as f64;
        assert!(
            (f.excursion.pct_outside_any - pct).abs() < 0.05,
            "{}: {} vs {pct}",
            j.name,
            f.excursion.pct_outside_any
        );
        // The per-axis figures: the twist's on the twist axis.
        let ang = joint_angles(&trial, j).unwrap();
        let e = excursion_figures(&ang, &euler.joint_limits(&j.name, &j.kind, false).unwrap());
        assert_eq!(e, fe.excursion, "{}", j.name);
        differ += usize::from(e != f.excursion);
        eprintln!(
            "{}: outside Euler {:.1}%, swing-twist {:.1}%; mean excursion {:.3} vs {:.3} deg",
            j.name,
            fe.excursion.pct_outside_any,
            f.excursion.pct_outside_any,
            fe.excursion.joint_mean_excursion_deg,
            got
        );
    }
    assert!(differ > 0);
}
