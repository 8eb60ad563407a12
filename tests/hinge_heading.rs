//! The `hinge-heading` variant: `hinge` on the trial with each IMU's heading
//! drift since its first window (as `drift-heading-centroid` estimates it)
//! removed first. What it
//! must keep: the headings it reports are the heading variant's, its joints
//! are `hinge`'s on the de-drifted trial, a limit edit redoes it whole, its
//! progress counts both passes, and a follower holding its last correction
//! continues the last sample exactly. The accuracy figures are in
//! `tests/elbow_hinge.rs`.

mod common;

use acm_workbench::acm::heading::remove_headings;
use acm_workbench::acm::{RunControl, Variant};
use acm_workbench::correct::{correct_trial, recorrect};
use acm_workbench::follow::{Extrapolation, Solution};
use acm_workbench::limits::{LimitTable, Settings};
use acm_workbench::model::Model;
use acm_workbench::rotation::angle_between_deg;
use acm_workbench::simulate::{simulate, HeadingDrift, SimConfig};
use acm_workbench::trial::Trial;
use common::engine::run;
use std::sync::Mutex;

/// A 13-IMU body of 90 s whose right upper arm drifts 0.15 deg/s from 10 s.
fn drifting_arm() -> Trial {
    let config = SimConfig {
        duration_s: 90.0,
        drifts: vec![HeadingDrift {
            imu: "r_upper_arm".into(),
            start_s: 10.0,
            rate_deg_s: 0.15,
        }],
        ..SimConfig::full_body(5)
    };
    simulate(&config).unwrap().trial
}

#[test]
fn it_is_hinge_on_the_trial_without_the_heading_variants_drift() {
    let trial = drifting_arm();
    let dhc = run(&trial, Variant::DriftHeadingCentroid);
    let hh = run(&trial, Variant::HingeHeading);
    assert_eq!(hh.variant, Variant::HingeHeading);
    // The drift since the first window: the heading fit's, less its first.
    assert_eq!(hh.headings.len(), dhc.headings.len());
    for (h, d) in hh.headings.iter().zip(&dhc.headings) {
        assert_eq!((&h.imu, h.correction), (&d.imu, d.correction));
        let first = d.windows[0].heading_deg;
        for (w, v) in h.windows.iter().zip(&d.windows) {
            assert_eq!(w.heading_deg, v.heading_deg - first);
            assert_eq!(w.rate_deg_s, v.rate_deg_s);
        }
    }
    // The drift rises by 4.5 deg between the two window centres (30 and 60
    // s); the fit reads the first window's as 0 and the second's as ~4.9.
    let arm = hh.heading("r_upper_arm").unwrap().max_abs_heading_deg();
    assert!(arm > 3.0, "{arm}");
    for h in hh.headings.iter().filter(|h| h.imu != "r_upper_arm") {
        assert!(h.max_abs_heading_deg() < 0.5 * arm, "{}", h.imu);
    }
    let hinge = run(&remove_headings(&trial, &hh.headings), Variant::Hinge);
    assert_eq!(hh.corrected.imus, hinge.corrected.imus);
    assert_eq!(hh.joints, hinge.joints);
}

#[test]
fn removing_headings_turns_each_fitted_imu_about_the_vertical_only() {
    let trial = drifting_arm();
    let dhc = run(&trial, Variant::DriftHeadingCentroid);
    let out = remove_headings(&trial, &dhc.headings);
    let arm = dhc.heading("r_upper_arm").unwrap();
    let last = arm.windows.last().unwrap().heading_deg;
    let (raw, new) = (
        &trial.imu("r_upper_arm").unwrap().orientation,
        &out.imu("r_upper_arm").unwrap().orientation,
    );
    let n = raw.len() - 1;
    // The last sample lies past the last centre: turned by exactly h_N.
    let turned = arm.vertical.heading_rotation(-last) * raw[n];
    assert!(angle_between_deg(&turned, &new[n]) < 1e-9);
    // The base has no heading fit and is untouched.
    let base = &Model::infant13().base;
    assert!(dhc.heading(base).is_none());
    assert_eq!(
        trial.imu(base).unwrap().orientation,
        out.imu(base).unwrap().orientation
    );
}

#[test]
fn a_limit_edit_redoes_it_whole_and_progress_counts_both_passes() {
    let trial = drifting_arm();
    let model = Model::infant13();
    let table = LimitTable::default_table();
    let seen = Mutex::new(Vec::new());
    let progress = |d: usize, n: usize| seen.lock().unwrap().push((d, n));
    let control = RunControl {
        cancel: None,
        progress: Some(&progress),
    };
    let settings = Settings::default();
    let first = correct_trial(
        &trial,
        &model,
        &table,
        &settings,
        Variant::HingeHeading,
        &control,
    )
    .unwrap();
    let seen = seen.into_inner().unwrap();
    let total = seen[0].1;
    assert!(seen.iter().all(|&(_, n)| n == total));
    let mut done: Vec<usize> = seen.iter().map(|&(d, _)| d).collect();
    done.sort_unstable();
    assert_eq!(done, (1..=total).collect::<Vec<_>>());
    // Redoing the elbow after an edit that changes nothing gives the same run.
    let again = recorrect(
        &trial,
        &model,
        &table,
        &settings,
        &first,
        &["r_elbow"],
        &RunControl::default(),
    )
    .unwrap();
    assert_eq!(again, first);
}

#[test]
fn a_follower_holding_the_last_correction_continues_the_last_sample() {
    let trial = drifting_arm();
    let c = run(&trial, Variant::HingeHeading);
    let hold = Solution::new(&trial, &c, Extrapolation::Hold);
    let n = trial.len();
    let out = hold.apply(&trial, n - 1..n, trial.time_s[0]);
    for imu in &c.corrected.imus {
        let got = out.imu(&imu.name).unwrap().orientation[0];
        let err = angle_between_deg(&got, &imu.orientation[n - 1]);
        assert!(err < 1e-9, "{}: {err} deg", imu.name);
    }
}
