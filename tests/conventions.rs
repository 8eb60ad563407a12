//! Joint angles come out in the limit table's convention after a pose
//! calibration, for every built-in model (docs/method.md section 2.5).
//!
//! The truth here is physical, not a set of Euler angles: a body holds its
//! model's calibration pose, then one joint moves by a known angle in a known
//! anatomical sense (the thigh swings forward, the shank folds back, the arm
//! rises forward, ...), each defined from the body's anatomical directions in
//! the pose (ventral, left, cranial: the standing pose of three models,
//! `infant13`'s prone one) and the segments' directions, never from the
//! model's own axes.
//! The IMUs sit on their segments at random orientations (the base with its
//! `pose.base_forward` axis forward, as pose calibration needs) and the subject
//! faces a random heading. After pose calibration the joint's angle on the
//! table's axis for that movement must equal the imposed angle, positive in
//! the sense the table counts positive (Table 3-3: flexion, external rotation,
//! abduction, plantar flexion, left rotation and left lateral bending of the
//! trunk), and the other two axes must stay 0.

use acm_workbench::acm::RunControl;
use acm_workbench::limits::{LimitTable, Settings};
use acm_workbench::metrics::joint_angles;
use acm_workbench::model::{Joint, Model, BUILTIN_MODELS};
use acm_workbench::pose::convention::check_conventions;
use acm_workbench::pose::{calibrate, PoseCalibration, PoseTime};
use acm_workbench::rotation::{quat_axis_angle_deg, Quat};
use acm_workbench::trial::{ImuSeries, Trial};
use nalgebra::{UnitQuaternion, Vector3};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeMap;

type V = Vector3<f64>;

/// A joint that moves: its name, the pose-frame axis and the angle (degrees) over time.
type Moving<'a> = (&'a str, V, &'a dyn Fn(f64) -> f64);

/// The calibration pose of a model: the body's anatomical directions in the
/// frame the calibration gives the segments (x forward after the heading
/// correction, z up).
struct PoseGeometry {
    /// The ventral side (where a standing subject faces).
    ventral: V,
    /// The subject's left.
    left: V,
    /// Towards the head (up when standing).
    cranial: V,
}

const STANDING: PoseGeometry = PoseGeometry {
    ventral: V::new(1.0, 0.0, 0.0),
    left: V::new(0.0, 1.0, 0.0),
    cranial: V::new(0.0, 0.0, 1.0),
};

/// One anatomical movement of one joint: the table axis it is counted on
/// (0 = X) and the axis (pose frame) the distal segment turns about by a
/// positive angle of it, from the definitions of the movements.
struct Movement {
    name: &'static str,
    table_axis: usize,
    axis: V,
}

/// Turning `from` towards `to` is a positive turn about `from x to`.
fn towards(from: V, to: V) -> V {
    from.cross(&to).normalize()
}

fn movement(name: &'static str, table_axis: usize, axis: V) -> Movement {
    Movement {
        name,
        table_axis,
        axis,
    }
}

/// The subject's lateral side at `joint` (its left for a left limb).
fn lateral(joint: &Joint, g: &PoseGeometry) -> V {
    if joint.name.starts_with("r_") {
        -g.left
    } else {
        g.left
    }
}

/// The movements of a trunk or leg joint, from the anatomical directions of
/// the pose `g` (the trunk and the legs lie along the cranial axis, the feet
/// point ventrally in the standing pose and caudally in the prone one, where
/// the foot keeps its angle to the shank); `None` for an arm.
fn trunk_and_leg_movements(joint: &Joint, g: &PoseGeometry) -> Option<Vec<Movement>> {
    let (ventral, dorsal, caudal) = (g.ventral, -g.ventral, -g.cranial);
    let lateral = lateral(joint, g);
    let m = movement;
    Some(match joint.kind.as_str() {
        "back" | "neck" | "lumbar" | "thoracic" => vec![
            m("left rotation", 0, towards(ventral, g.left)),
            m("flexion", 1, towards(g.cranial, ventral)),
            m("left lateral bending", 2, towards(g.cranial, g.left)),
        ],
        "hip" => vec![
            m("external rotation", 0, towards(ventral, lateral)),
            m("flexion", 1, towards(caudal, ventral)),
            m("abduction", 2, towards(caudal, lateral)),
        ],
        "knee" => vec![
            m("lateral rotation", 0, towards(ventral, lateral)),
            m("flexion", 1, towards(caudal, dorsal)),
            m("abduction", 2, towards(caudal, lateral)),
        ],
        "ankle" => vec![
            m("lateral rotation", 0, towards(ventral, lateral)),
            // The toes turn towards the sole: ventral to caudal (about the
            // same axis as caudal to dorsal).
            m("plantar flexion", 1, towards(ventral, caudal)),
            m("eversion", 2, towards(caudal, lateral)),
        ],
        _ => return None,
    })
}

/// The movements of a joint in the standing pose (arms hanging, palms towards
/// the thighs), by the joint's kind and side.
fn standing_movements(joint: &Joint) -> Vec<Movement> {
    let g = &STANDING;
    if let Some(mv) = trunk_and_leg_movements(joint, g) {
        return mv;
    }
    let (forward, down) = (g.ventral, -g.cranial);
    let lateral = lateral(joint, g);
    let medial = -lateral;
    let m = movement;
    match joint.kind.as_str() {
        "shoulder" => vec![
            m("flexion", 0, towards(down, forward)),
            m("external rotation", 1, towards(forward, lateral)),
            m("abduction", 2, towards(down, lateral)),
        ],
        "elbow" => vec![
            m("flexion", 0, towards(down, forward)),
            m("abduction", 1, towards(down, lateral)),
            m("pronation", 2, towards(forward, medial)),
        ],
        "wrist" => vec![
            // Palms towards the thighs: flexion turns the hand medially.
            m("flexion", 0, towards(down, medial)),
            m("ulnar deviation", 1, towards(down, -forward)),
            m("rotation", 2, towards(medial, -forward)),
        ],
        other => panic!("no movements for joint kind {other}"),
    }
}

/// `infant13`'s prone calibration pose (the source's Figure 2-3): face down
/// with the head forward along the floor, the back up, arms out to the sides
/// with palms and elbow creases on the floor, legs straight back, feet
/// pointed back (soles up). Pose calibration makes its segment frames: x
/// towards the head, y left, z up (dorsal).
const PRONE: PoseGeometry = PoseGeometry {
    ventral: V::new(0.0, 0.0, -1.0),
    left: V::new(0.0, 1.0, 0.0),
    cranial: V::new(1.0, 0.0, 0.0),
};

/// The movements of a joint of `infant13` from its prone pose: the trunk's
/// and the legs' as standing, turned face down; the arms', which point
/// laterally with their anterior side (the crease) on the floor and the thumb
/// towards the head, from the same anatomical definitions.
fn prone_movements(joint: &Joint) -> Vec<Movement> {
    let g = &PRONE;
    if let Some(mv) = trunk_and_leg_movements(joint, g) {
        return mv;
    }
    let lateral = lateral(joint, g);
    let m = movement;
    match joint.kind.as_str() {
        "shoulder" => vec![
            m("flexion", 0, towards(lateral, g.ventral)),
            m("external rotation", 1, towards(g.ventral, g.cranial)),
            m("abduction", 2, towards(lateral, g.cranial)),
        ],
        "elbow" => vec![
            m("flexion", 0, towards(lateral, g.ventral)),
            m("abduction", 1, towards(lateral, g.cranial)),
            m("pronation", 2, towards(g.cranial, g.ventral)),
        ],
        other => panic!("no prone movements for joint kind {other}"),
    }
}

/// The joint's angle over time, degrees: still for 1 s (the pose), then a
/// swing between 0 and `peak`.
fn swing(t: f64, peak: f64) -> f64 {
    if t < 1.0 {
        0.0
    } else {
        0.5 * peak * (1.0 - (2.0 * (t - 1.0)).cos())
    }
}

/// Sensor-to-segment mountings: random, except the base's `base_forward`
/// axis points forward (its turn about forward is random).
fn mountings(model: &Model, rng: &mut ChaCha8Rng) -> BTreeMap<String, Quat> {
    let mut random = || {
        let v = V::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        );
        (
            UnitQuaternion::from_scaled_axis(v * 2.0),
            rng.random_range(-180.0..180.0),
        )
    };
    model
        .imus
        .iter()
        .map(|imu| {
            let (m, roll) = random();
            let m = if *imu == model.base {
                let bf = V::from(model.pose.base_forward.vector());
                let onto_x = UnitQuaternion::rotation_between(&bf, &V::x())
                    .unwrap_or_else(|| quat_axis_angle_deg([0.0, 0.0, 1.0], 180.0));
                quat_axis_angle_deg([1.0, 0.0, 0.0], roll) * onto_x
            } else {
                m
            };
            (imu.clone(), m)
        })
        .collect()
}

/// A trial of `model` in which every joint of `moving` turns its distal
/// segment (and all below it) about `axis` (pose frame) by `angle(t)`;
/// sensors on their segments by `mount`, the subject facing `heading_deg`.
fn physical_trial(
    model: &Model,
    moving: &[Moving],
    mount: &BTreeMap<String, Quat>,
    heading_deg: f64,
) -> Trial {
    let turns: Vec<TurnFn> = moving
        .iter()
        .map(|&(_, axis, angle)| {
            let turn = move |t: f64| UnitQuaternion::from_scaled_axis(axis * angle(t).to_radians());
            Box::new(turn) as TurnFn
        })
        .collect();
    let turns: Vec<Turning> = moving
        .iter()
        .zip(&turns)
        .map(|((n, _, _), f)| (*n, f.as_ref()))
        .collect();
    turning_trial(model, &turns, mount, heading_deg)
}

/// A joint's rotation over time, boxed.
type TurnFn<'a> = Box<dyn Fn(f64) -> Quat + 'a>;

/// A joint that turns: its name and its rotation over time (pose frame, made
/// in the proximal segment).
type Turning<'a> = (&'a str, &'a dyn Fn(f64) -> Quat);

/// As [`physical_trial`], each joint of `turning` turning its distal segment
/// by any rotation over time.
fn turning_trial(
    model: &Model,
    turning: &[Turning],
    mount: &BTreeMap<String, Quat>,
    heading_deg: f64,
) -> Trial {
    let time_s: Vec<f64> = (0..400).map(|i| f64::from(i) / 50.0).collect();
    let heading = quat_axis_angle_deg([0.0, 0.0, 1.0], heading_deg);
    let mut seg: BTreeMap<&str, Vec<Quat>> = BTreeMap::new();
    seg.insert(&model.base, vec![Quat::identity(); time_s.len()]);
    for j in &model.joints {
        let parent = seg[j.proximal.as_str()].clone();
        let turn = turning.iter().find(|(n, _)| *n == j.name);
        let own: Vec<Quat> = parent
            .iter()
            .zip(&time_s)
            .map(|(p, &t)| match turn {
                // The turn in the pose frame, made in the proximal segment
                // (identity in the pose), carried by the parent.
                Some((_, rotation)) => p * rotation(t),
                None => *p,
            })
            .collect();
        seg.insert(&j.distal, own);
    }
    let imus = model
        .imus
        .iter()
        .map(|name| {
            let m = mount[name];
            let q = seg[name.as_str()].iter().map(|s| heading * s * m).collect();
            ImuSeries::new(name.clone(), q)
        })
        .collect();
    Trial {
        name: format!("{} physical", model.name),
        imus,
        time_s,
        warnings: vec![],
        orientation_decimals: None,
    }
}

fn calibrated(trial: &Trial, model: &Model) -> Trial {
    let cal = PoseCalibration {
        at: PoseTime::Span(0.0, 0.5),
        setup: model.pose,
    };
    calibrate(trial, model, &cal).unwrap().0
}

/// `joint` of `model` makes the movement `mv` alone, swinging to `peak` deg,
/// the subject facing `heading_deg`; after pose calibration the joint reads
/// it on `mv`'s table axis, positive, and 0 on the other two (to 1e-6 deg).
fn assert_movement_reads(
    model: &Model,
    mount: &BTreeMap<String, Quat>,
    joint: &Joint,
    mv: &Movement,
    peak: f64,
    heading_deg: f64,
) {
    let angle = |t: f64| swing(t, peak);
    let trial = physical_trial(model, &[(&joint.name, mv.axis, &angle)], mount, heading_deg);
    let cal = calibrated(&trial, model);
    let want = |t: f64| {
        let mut w = [0.0; 3];
        w[mv.table_axis] = angle(t);
        w
    };
    let what = format!("{} {} {peak}", model.name, mv.name);
    assert_reads(&cal, joint, &what, &want);
}

/// The standing models: every movement of every joint, alone, reads as
/// itself on its table axis, positive, the other axes 0.
#[test]
fn every_movement_of_every_standing_model_reads_positive_on_its_table_axis() {
    let mut rng = ChaCha8Rng::seed_from_u64(15);
    let mut checked = 0;
    for name in ["opensense_lower", "opensim", "full_body16"] {
        let model = Model::builtin(name).unwrap();
        let mount = mountings(&model, &mut rng);
        for joint in &model.joints {
            for mv in standing_movements(joint) {
                let heading = rng.random_range(-180.0..180.0);
                assert_movement_reads(&model, &mount, joint, &mv, 40.0, heading);
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 3 * (7 + 11 + 15));
}

/// `infant13` from its prone pose: every movement of every joint, alone,
/// reads as itself on its table axis, positive, the other axes 0; hip
/// flexion to 100 deg, knee flexion to 140 and elbow flexion to 150 too.
#[test]
fn every_movement_of_infant13_reads_positive_from_its_prone_pose() {
    let mut rng = ChaCha8Rng::seed_from_u64(18);
    let model = Model::builtin("infant13").unwrap();
    let mount = mountings(&model, &mut rng);
    let mut checked = 0;
    for joint in &model.joints {
        for (k, mv) in prone_movements(joint).iter().enumerate() {
            let large = match (joint.kind.as_str(), k) {
                ("hip", 1) => Some(100.0),
                ("knee", 1) => Some(140.0),
                ("elbow", 0) => Some(150.0),
                _ => None,
            };
            for peak in std::iter::once(40.0).chain(large) {
                let heading = rng.random_range(-180.0..180.0);
                assert_movement_reads(&model, &mount, joint, mv, peak, heading);
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 12 * 3 + 2 * 3);
}

/// Bounds on the flexion (table Y, deg) of the hips and knees of a
/// convention case: its peak above the first, its lowest above the second.
type FlexionBounds = (f64, f64);

/// `moving` (sensors by `mount`, the subject facing `heading_deg`) passes the
/// convention check after pose calibration, the hips' and knees' flexion
/// within `flexion`; the same with `mirrored` in place of its entry of that
/// joint gives exactly one warning, naming that joint's y as mirrored.
fn assert_silent_and_names_a_mirror(
    model: &Model,
    mount: &BTreeMap<String, Quat>,
    moving: &[Moving],
    heading_deg: f64,
    flexion: FlexionBounds,
    mirrored: Moving,
) {
    let table = LimitTable::default_table();
    let name = &model.name;
    let cal = calibrated(&physical_trial(model, moving, mount, heading_deg), model);
    let w = check_conventions(&cal, model, &table, true);
    assert!(w.is_empty(), "{name}: {w:?}");
    for j in ["l_hip", "r_hip", "l_knee", "r_knee"] {
        let a = joint_angles(&cal, model.joint(j).unwrap()).unwrap();
        let max = a.iter().map(|x| x[1]).fold(f64::MIN, f64::max);
        let min = a.iter().map(|x| x[1]).fold(f64::MAX, f64::min);
        assert!(
            max > flexion.0 && min > flexion.1,
            "{name} {j}: Y {min}..{max}"
        );
    }
    let mut copy = moving.to_vec();
    let k = copy
        .iter()
        .position(|m| m.0 == mirrored.0)
        .expect("a moving joint");
    copy[k] = mirrored;
    let cal = calibrated(&physical_trial(model, &copy, mount, heading_deg), model);
    let w = check_conventions(&cal, model, &table, true);
    let named = format!("{} y:", mirrored.0);
    assert!(
        w.len() == 1 && w[0].starts_with(&named) && w[0].contains("mirrored"),
        "{name}: {w:?}"
    );
}

/// A crawl of `infant13` from its prone pose: hips and knees flexing, the
/// shoulders and elbows working; the convention check is silent on it, hip
/// and knee flexion read positive, and a copy with one hip mirrored (moved
/// into extension) is named.
#[test]
fn infant13_crawl_passes_the_convention_check_and_a_mirrored_hip_is_named() {
    let mut rng = ChaCha8Rng::seed_from_u64(19);
    let model = Model::builtin("infant13").unwrap();
    let mount = mountings(&model, &mut rng);
    let hip = |t: f64| swing(t, 80.0);
    let knee = |t: f64| swing(t, 90.0);
    let shoulder = |t: f64| swing(t, 40.0);
    let elbow = |t: f64| swing(t, 70.0);
    let extended = |t: f64| -swing(t, 30.0);
    let axis = |j: &str, k: usize| prone_movements(model.joint(j).unwrap())[k].axis;
    let crawl: Vec<Moving> = vec![
        ("l_shoulder", axis("l_shoulder", 0), &shoulder),
        ("r_shoulder", axis("r_shoulder", 0), &shoulder),
        ("l_elbow", axis("l_elbow", 0), &elbow),
        ("r_elbow", axis("r_elbow", 0), &elbow),
        ("l_hip", axis("l_hip", 1), &hip),
        ("r_hip", axis("r_hip", 1), &hip),
        ("l_knee", axis("l_knee", 1), &knee),
        ("r_knee", axis("r_knee", 1), &knee),
    ];
    let mirrored = ("l_hip", axis("l_hip", 1), &extended as &dyn Fn(f64) -> f64);
    assert_silent_and_names_a_mirror(&model, &mount, &crawl, -40.0, (79.0, -1e-6), mirrored);
}

/// Asserts that `joint` of the calibrated `cal` reads `want(t)` (table
/// convention, degrees) at every sample to 1e-6 deg.
fn assert_reads(cal: &Trial, joint: &Joint, what: &str, want: &dyn Fn(f64) -> [f64; 3]) {
    let a = joint_angles(cal, joint).unwrap();
    for (i, (x, &t)) in a.iter().zip(&cal.time_s).enumerate() {
        let w = want(t);
        for k in 0..3 {
            assert!(
                (x[k] - w[k]).abs() < 1e-6,
                "{} {what}: sample {i}, axis {k}: {:.6} deg, want {:.6} (all {x:?}, want {w:?})",
                joint.name,
                x[k],
                w[k]
            );
        }
    }
}

/// Large movements read on their table axis too: elbow flexion to 150 deg,
/// shoulder flexion to 120 deg, hip flexion to 100 deg and knee flexion to
/// 140 deg (hip and knee flexion are the middle Z-Y-X angle in the table's
/// axes; beyond 90 deg the triplet the joint's limit box reads is shown,
/// docs/method.md section 2.5).
#[test]
fn large_movements_read_on_their_table_axis() {
    let mut rng = ChaCha8Rng::seed_from_u64(16);
    let mut checked = 0;
    for name in ["opensim", "full_body16", "opensense_lower"] {
        let model = Model::builtin(name).unwrap();
        let mount = mountings(&model, &mut rng);
        for (kind, table_axis, peak) in [
            ("elbow", 0, 150.0),
            ("shoulder", 0, 120.0),
            ("hip", 1, 100.0),
            ("knee", 1, 140.0),
        ] {
            for joint in model.joints.iter().filter(|j| j.kind == kind) {
                let mv = &standing_movements(joint)[table_axis];
                let heading = rng.random_range(-180.0..180.0);
                assert_movement_reads(&model, &mount, joint, mv, peak, heading);
                checked += 1;
            }
        }
    }
    // opensense_lower has no arms.
    assert_eq!(checked, 2 * 8 + 4);
}

/// Movements on all three axes at once read back the table-convention Z-Y-X
/// angles they were made of: the joint turns by
/// `R_Z(z) R_Y(y) R_X(x)` about the anatomical axes of its table's Z, Y and X
/// (from the movements' definitions, as above), e.g. elbow flexion 120 with
/// pronation 40, hip flexion 60 with abduction 20 and external rotation 15.
#[test]
fn combined_movements_read_back_their_table_angles() {
    let mut rng = ChaCha8Rng::seed_from_u64(17);
    let cases: [(&str, [f64; 3]); 9] = [
        ("elbow", [120.0, 0.0, 40.0]),
        ("elbow", [150.0, 5.0, -30.0]),
        ("hip", [15.0, 60.0, 20.0]),
        ("knee", [-10.0, 75.0, 5.0]),
        ("hip", [10.0, 100.0, 15.0]),
        ("knee", [-3.0, 125.0, 2.0]),
        ("shoulder", [100.0, 30.0, 40.0]),
        ("ankle", [10.0, 30.0, -10.0]),
        ("back", [20.0, 40.0, 15.0]),
    ];
    let mut checked = 0;
    for name in ["opensense_lower", "opensim", "full_body16"] {
        let model = Model::builtin(name).unwrap();
        let mount = mountings(&model, &mut rng);
        for (kind, peak) in cases {
            for joint in model.joints.iter().filter(|j| j.kind == kind) {
                let mv = standing_movements(joint);
                let at = move |t: f64| peak.map(|p| swing(t, p));
                let turn = |t: f64| {
                    let [x, y, z] = at(t);
                    let r = |k: usize, a: f64| {
                        UnitQuaternion::from_scaled_axis(mv[k].axis * a.to_radians())
                    };
                    r(2, z) * r(1, y) * r(0, x)
                };
                let heading = rng.random_range(-180.0..180.0);
                let trial = turning_trial(&model, &[(&joint.name, &turn)], &mount, heading);
                let cal = calibrated(&trial, &model);
                assert_reads(&cal, joint, &format!("{name} {peak:?}"), &at);
                checked += 1;
            }
        }
    }
    assert!(checked >= 20, "{checked}");
}

/// Gait on the standing models: hips and knees flexing (and the ankles
/// plantar flexing) as walking does; the convention check is silent on it and
/// names the joint of a mirrored copy.
#[test]
fn gait_passes_the_convention_check_and_a_mirrored_hip_is_named() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let hip = |t: f64| {
        if t < 1.0 {
            0.0
        } else {
            10.0 - 10.0 * (4.0 * (t - 1.0)).cos() + 5.0 * (4.0 * (t - 1.0)).sin()
        }
    };
    let knee = |t: f64| swing(t, 60.0);
    let ankle = |t: f64| swing(t, 15.0);
    let hyperextended = |t: f64| -hip(t);
    for name in ["opensense_lower", "opensim", "full_body16"] {
        let model = Model::builtin(name).unwrap();
        let mount = mountings(&model, &mut rng);
        let flexion = |j: &str| {
            let joint = model.joint(j).unwrap();
            let mv = standing_movements(joint);
            mv[1].axis
        };
        let gait: Vec<Moving> = vec![
            ("l_hip", flexion("l_hip"), &hip),
            ("r_hip", flexion("r_hip"), &hip),
            ("l_knee", flexion("l_knee"), &knee),
            ("r_knee", flexion("r_knee"), &knee),
            ("l_ankle", flexion("l_ankle"), &ankle),
            ("r_ankle", flexion("r_ankle"), &ankle),
        ];
        let mirrored = (
            "r_hip",
            flexion("r_hip"),
            &hyperextended as &dyn Fn(f64) -> f64,
        );
        assert_silent_and_names_a_mirror(&model, &mount, &gait, 70.0, (19.0, -1.2), mirrored);
    }
}

/// Every variant keeps the table's sense: on the calibrated gait of
/// `opensense_lower` with the thigh and shank sensors turned on their
/// segments after the pose (so the variants have something to correct), the
/// corrected hip and knee flexion follow the true flexion (correlation above
/// 0.9) and stay positive on average.
#[test]
fn every_variant_reports_flexion_positive() {
    use acm_workbench::acm::Variant;
    use acm_workbench::correct::correct_trial;
    let model = Model::builtin("opensense_lower").unwrap();
    let table = LimitTable::default_table();
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mount = mountings(&model, &mut rng);
    let hip = |t: f64| swing(t, 40.0) - 10.0;
    let knee = |t: f64| swing(t, 60.0);
    let flexion = |j: &str| standing_movements(model.joint(j).unwrap())[1].axis;
    let gait: Vec<Moving> = vec![
        ("l_hip", flexion("l_hip"), &hip),
        ("r_hip", flexion("r_hip"), &hip),
        ("l_knee", flexion("l_knee"), &knee),
        ("r_knee", flexion("r_knee"), &knee),
    ];
    let truth = calibrated(&physical_trial(&model, &gait, &mount, 20.0), &model);
    let mut trial = truth.clone();
    // A 10 deg slip of each thigh and shank sensor about its segment's long axis.
    for imu in ["femur_l_imu", "femur_r_imu", "tibia_l_imu", "tibia_r_imu"] {
        let s = quat_axis_angle_deg([0.0, 0.0, 1.0], 10.0);
        for q in &mut trial
            .imus
            .iter_mut()
            .find(|i| i.name == imu)
            .unwrap()
            .orientation
        {
            *q *= s;
        }
    }
    let settings = Settings {
        window_s: 4.0,
        hop_s: 2.0,
        ..Settings::default()
    };
    for variant in Variant::ALL {
        let c = correct_trial(
            &trial,
            &model,
            &table,
            &settings,
            variant,
            &RunControl::default(),
        )
        .unwrap();
        for j in ["l_hip", "r_hip", "l_knee", "r_knee"] {
            let joint = model.joint(j).unwrap();
            let got: Vec<f64> = joint_angles(&c.corrected, joint)
                .unwrap()
                .iter()
                .map(|a| a[1])
                .collect();
            let want: Vec<f64> = joint_angles(&truth, joint)
                .unwrap()
                .iter()
                .map(|a| a[1])
                .collect();
            let r = correlation(&got, &want);
            let mean = got.iter().sum::<f64>() / got.len() as f64;
            assert!(
                r > 0.9 && mean > 0.0,
                "{variant} {j}: r {r:.3}, mean {mean:.2}"
            );
        }
    }
}

fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
    cov / (va * vb).sqrt()
}

/// Every built-in model declares its joints' angle axes (none is left to
/// the default by accident), but `infant13`'s back and neck, whose table
/// axes are its prone segment axes.
#[test]
fn every_model_states_its_angle_axes() {
    for (name, text) in BUILTIN_MODELS {
        let model = Model::builtin(name).unwrap();
        let joints = text.matches("[[joint]]").count();
        let declared = text.matches("\nangle_axes = ").count();
        assert_eq!(model.joints.len(), joints);
        let want = if *name == "infant13" {
            joints - 2
        } else {
            joints
        };
        assert_eq!(declared, want, "{name}");
    }
}

/// The shared folder of public recordings, if this checkout sits beside it
/// (`ACMW_REAL_DATA` names it elsewhere).
fn real_data() -> Option<std::path::PathBuf> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    std::env::var_os("ACMW_REAL_DATA")
        .map(std::path::PathBuf::from)
        .into_iter()
        .chain([
            root.join("../shared/real_data"),
            root.join("../../shared/real_data"),
        ])
        .find(|p| p.join("opensense_example/myIMUMappings.xml").is_file())
}

/// The OpenSense example's walking trial (Xsens MTw, 100 Hz) after pose
/// calibration on its first second (standing): hips and knees flex positive,
/// and the convention check is silent. Skips when the recording is absent.
#[test]
fn opensense_walking_flexes_hips_and_knees_positive() {
    let Some(dir) = real_data() else {
        eprintln!("skipped: no shared real_data folder beside the checkout");
        return;
    };
    let model = Model::builtin("opensense_lower").unwrap();
    let path = dir.join("opensense_example/myIMUMappings.xml");
    let trial = acm_workbench::trial::read_trial(&path, &model).unwrap();
    let cal = PoseCalibration {
        at: PoseTime::Span(0.0, 1.0),
        setup: model.pose,
    };
    let cal = calibrate(&trial, &model, &cal).unwrap().0;
    let w = check_conventions(&cal, &model, &LimitTable::default_table(), true);
    assert!(w.is_empty(), "{w:?}");
    for j in ["l_hip", "r_hip", "l_knee", "r_knee", "l_ankle", "r_ankle"] {
        let y: Vec<f64> = joint_angles(&cal, model.joint(j).unwrap())
            .unwrap()
            .iter()
            .map(|a| a[1])
            .collect();
        let mean = y.iter().sum::<f64>() / y.len() as f64;
        let (min, max) = y
            .iter()
            .fold((f64::MAX, f64::MIN), |m, &v| (m.0.min(v), m.1.max(v)));
        eprintln!("{j} y: mean {mean:.1}, range {min:.1} .. {max:.1}");
        if j.ends_with("hip") || j.ends_with("knee") {
            // Walking flexes both by 20 deg and more, never as far the other way.
            assert!(
                mean > 0.0 && max > 20.0 && max > -2.0 * min,
                "{j}: {mean} {min}..{max}"
            );
        }
    }
}
