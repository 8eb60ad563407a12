use super::*;
use crate::acm::{RunControl, Variant};
use crate::correct::correct_trial;
use crate::limits::{LimitTable, Settings};
use crate::metrics::joint_angles;
use crate::rotation::{angle_between_deg, quat_from_wxyz, wrap180};
use crate::simulate::{preset, simulate};
use rand::{Rng, SeedableRng};

fn short_trial() -> Trial {
    let mut cfg = preset("full_body_clean").unwrap();
    cfg.duration_s = 20.0;
    simulate(&cfg).unwrap().trial
}

/// The trial seen from a frame turned by `deg` about the vertical: every IMU
/// `Rz(deg) * G_R_imu`.
fn turned(trial: &Trial, deg: f64) -> Trial {
    let rz = quat_axis_angle_deg([0.0, 0.0, 1.0], deg);
    let mut t = trial.clone();
    for s in &mut t.imus {
        for q in &mut s.orientation {
            *q = rz * *q;
        }
    }
    t
}

fn cal(at: &str) -> PoseCalibration {
    PoseCalibration {
        at: at.parse().unwrap(),
        setup: PoseSetup::default(),
    }
}

/// Largest wrapped difference of any joint angle between two trials, degrees.
fn max_angle_difference(a: &Trial, b: &Trial, model: &Model) -> f64 {
    let mut worst = 0.0f64;
    for j in &model.joints {
        let (x, y) = (joint_angles(a, j).unwrap(), joint_angles(b, j).unwrap());
        for (p, q) in x.iter().zip(&y) {
            for k in 0..3 {
                worst = worst.max(wrap180(p[k] - q[k]).abs());
            }
        }
    }
    worst
}

#[test]
fn pose_time_parses_and_prints() {
    assert_eq!("1.5".parse::<PoseTime>(), Ok(PoseTime::At(1.5)));
    assert_eq!("0..2".parse::<PoseTime>(), Ok(PoseTime::Span(0.0, 2.0)));
    assert_eq!(PoseTime::Span(0.5, 2.0).to_string(), "0.5..2");
    for bad in ["", "x", "2..1", "-1", "1..inf", "1..2..3"] {
        assert!(bad.parse::<PoseTime>().is_err(), "{bad}");
    }
    let json = serde_json::to_string(&cal("0..1.5")).unwrap();
    assert_eq!(
        json,
        r#"{"at":"0..1.5","base_forward":"+x","forward":"+x"}"#
    );
    assert_eq!(
        serde_json::from_str::<PoseCalibration>(&json).unwrap(),
        cal("0..1.5")
    );
}

#[test]
fn mean_orientation_is_sign_invariant_and_central() {
    let a = quat_axis_angle_deg([0.0, 0.0, 1.0], 10.0);
    let b = quat_axis_angle_deg([0.0, 0.0, 1.0], -10.0);
    let b_neg = Quat::new_unchecked(-b.into_inner());
    let m = mean_orientation(&[a, b_neg]);
    assert!(angle_between_deg(&m, &Quat::identity()) < 1e-9);
    let c = quat_axis_angle_deg([1.0, 2.0, 0.5], 40.0);
    assert!(angle_between_deg(&mean_orientation(&[c, c, c]), &c) < 1e-9);
}

#[test]
fn heading_turns_the_base_forward_axis_onto_the_model_forward_axis() {
    // Base facing 30 deg left of +X, pitched 20 deg: psi = -30.
    let base =
        quat_axis_angle_deg([0.0, 0.0, 1.0], 30.0) * quat_axis_angle_deg([0.0, 1.0, 0.0], 20.0);
    let setup = PoseSetup::default();
    assert!((heading_deg(&base, &setup).unwrap() + 30.0).abs() < 1e-9);
    // Forward along the model's +Y instead: psi = 60.
    let setup_y = PoseSetup {
        forward: "+y".parse().unwrap(),
        ..setup
    };
    assert!((heading_deg(&base, &setup_y).unwrap() - 60.0).abs() < 1e-9);
    // The sensor's -Z as forward (OpenSense): a base whose -Z points along global +Y.
    let lying = quat_axis_angle_deg([1.0, 0.0, 0.0], 90.0);
    let setup_z = PoseSetup {
        base_forward: "-z".parse().unwrap(),
        ..setup
    };
    assert!((wrap180(heading_deg(&lying, &setup_z).unwrap()) + 90.0).abs() < 1e-9);
    // An upright base has no heading along its Z axis.
    let e = heading_deg(&Quat::identity(), &setup_z).unwrap_err();
    assert!(e.to_string().contains("vertical"), "{e}");
}

#[test]
fn calibrated_trial_shows_the_default_pose_at_the_calibration_time() {
    let trial = short_trial();
    let mut model = Model::infant13();
    model.joints[8].default_pose_deg = [0.0, 20.0, 0.0]; // l_knee slightly flexed
    let (out, rec) = calibrate(&trial, &model, &cal("3.0")).unwrap();
    assert_eq!(rec.samples, 1);
    assert_eq!(rec.offsets.len(), 13);
    let i = 150; // 3.0 s at 50 Hz
    let base = out.imu("base").unwrap().orientation[i];
    assert!(angle_between_deg(&base, &Quat::identity()) < 1e-9);
    for j in &model.joints {
        let a = joint_angles(&out, j).unwrap()[i];
        for k in 0..3 {
            assert!(
                (a[k] - j.default_pose_deg[k]).abs() < 1e-7,
                "{} {a:?}",
                j.name
            );
        }
    }
    // Offsets: G'_R_seg = H G_R_imu O^-1 at every sample.
    let h = quat_axis_angle_deg([0.0, 0.0, 1.0], rec.heading_deg);
    let o = quat_from_wxyz(rec.offsets[5].offset);
    let name = &rec.offsets[5].imu;
    let raw = trial.imu(name).unwrap().orientation[777];
    let got = out.imu(name).unwrap().orientation[777];
    assert!(angle_between_deg(&got, &(h * raw * o.inverse())) < 1e-9);
}

#[test]
fn span_calibration_averages_the_span() {
    let trial = short_trial();
    let model = Model::infant13();
    let (out, rec) = calibrate(&trial, &model, &cal("1..2")).unwrap();
    assert_eq!(rec.samples, 51);
    // The calibrated base averages to identity over the span.
    let span: Vec<Quat> = out.imu("base").unwrap().orientation[50..=100].to_vec();
    assert!(angle_between_deg(&mean_orientation(&span), &Quat::identity()) < 1e-9);
    // The base moves during the span, so no single sample is at identity.
    assert!(span
        .iter()
        .all(|q| angle_between_deg(q, &Quat::identity()) > 1e-3));
}

#[test]
fn heading_correction_makes_joint_angles_independent_of_facing() {
    let trial = short_trial();
    let model = Model::infant13();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(6);
    let table = LimitTable::default_table();
    let settings = Settings::default();
    for _ in 0..3 {
        let alpha = rng.random_range(-180.0..180.0);
        let rotated = turned(&trial, alpha);
        for at in ["2.5", "0..1.5"] {
            let (a, ra) = calibrate(&trial, &model, &cal(at)).unwrap();
            let (b, rb) = calibrate(&rotated, &model, &cal(at)).unwrap();
            assert!((wrap180(rb.heading_deg - ra.heading_deg + alpha)).abs() < 1e-9);
            // Calibrated joint angles agree (the quaternions differ by rounding only).
            let d = max_angle_difference(&a, &b, &model);
            assert!(d < 1e-6, "alpha {alpha}, at {at}: {d} deg");
            // So do the ACM-corrected ones.
            let run = |t: &Trial| {
                correct_trial(
                    t,
                    &model,
                    &table,
                    &settings,
                    Variant::Basic,
                    &RunControl::default(),
                )
                .unwrap()
                .corrected
            };
            let d = max_angle_difference(&run(&a), &run(&b), &model);
            assert!(d < 1e-6, "alpha {alpha}, at {at}, basic: {d} deg");
            // And the inverse-kinematics coordinates.
            let ik = |t: &Trial| {
                correct_trial(
                    t,
                    &model,
                    &table,
                    &settings,
                    Variant::Ik,
                    &RunControl::default(),
                )
                .unwrap()
                .ik
                .unwrap()
            };
            let (ia, ib) = (ik(&a), ik(&b));
            let d = ia
                .values_deg
                .iter()
                .zip(&ib.values_deg)
                .map(|(x, y)| wrap180(x - y).abs())
                .fold(0.0, f64::max);
            assert!(d < 1e-6, "alpha {alpha}, at {at}, ik: {d} deg");
        }
    }
    // Without the heading correction the offsets turn with the subject and the
    // joint angles change: the test above can fail.
    let (rotated, t0) = (turned(&trial, 70.0), 100);
    let no_heading = |t: &Trial| {
        let mut out = t.clone();
        for s in &mut out.imus {
            let o = s.orientation[t0];
            for q in &mut s.orientation {
                *q *= o.inverse();
            }
        }
        out
    };
    let d = max_angle_difference(&no_heading(&trial), &no_heading(&rotated), &model);
    assert!(d > 5.0, "{d}");
}

#[test]
fn bad_calibrations_are_explained() {
    let trial = short_trial();
    let model = Model::infant13();
    let err = |t: &Trial, at: &str| calibrate(t, &model, &cal(at)).unwrap_err().to_string();
    assert!(err(&trial, "25").contains("after the trial's end"));
    assert!(err(&trial, "30..40").contains("no sample between"));
    let mut no_base = trial.clone();
    no_base.imus.retain(|s| s.name != "base");
    assert!(err(&no_base, "1").contains("base IMU 'base'"));
    // The last sample (19.98 s) and just past it are fine.
    assert!(calibrate(&trial, &model, &cal("19.99")).is_ok());
    // An IMU the model does not know is only turned by the heading.
    let mut extra = trial.clone();
    let mut s = extra.imus[3].clone();
    s.name = "wrist_watch".into();
    extra.imus.push(s);
    let (out, rec) = calibrate(&extra, &model, &cal("1")).unwrap();
    assert_eq!(rec.offsets.len(), 13);
    let h = quat_axis_angle_deg([0.0, 0.0, 1.0], rec.heading_deg);
    let got = out.imu("wrist_watch").unwrap().orientation[9];
    let raw = extra.imu("wrist_watch").unwrap().orientation[9];
    assert!(angle_between_deg(&got, &(h * raw)) < 1e-9);
}

#[test]
fn a_record_applied_to_the_trial_again_gives_the_calibrated_trial() {
    // What `acmw follow` does with rows after the span: the record found on
    // the trial, applied to it, turns every sample as `calibrate` did.
    let model = Model::infant13();
    let trial = turned(&short_trial(), 40.0);
    let (calibrated, record) = calibrate(&trial, &model, &cal("1..2")).unwrap();
    assert!(record.heading_deg.abs() > 10.0, "{}", record.heading_deg);
    let mut again = trial.clone();
    record.apply(&mut again);
    let mut worst = 0.0f64;
    for (a, b) in again.imus.iter().zip(&calibrated.imus) {
        assert_eq!(a.name, b.name);
        for (p, q) in a.orientation.iter().zip(&b.orientation) {
            worst = worst.max(angle_between_deg(p, q));
        }
    }
    assert!(worst < 1e-9, "{worst} deg");
    // ... and not the trial as read.
    assert!(angle_between_deg(&trial.imus[0].orientation[0], &again.imus[0].orientation[0]) > 10.0);
}
