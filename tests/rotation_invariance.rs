//! A whole trial turned about the global vertical changes no joint rotation
//! (`(R G_P)^T (R G_D) = G_P^T G_D`), so the corrected joint angles must not
//! change either: checked for three angles and the windowed variants, to
//! 1e-4 deg on every sample of every joint of the 5-minute drifting trial,
//! in the angles the user gets (the table's convention).

use acm_workbench::acm::{Correction, RunControl, Variant};
use acm_workbench::correct::correct_trial;
use acm_workbench::limits::{LimitTable, Settings};
use acm_workbench::model::Model;
use acm_workbench::rotation::{quat_axis_angle_deg, wrap180};
use acm_workbench::simulate::{preset, simulate};
use acm_workbench::trial::Trial;

fn corrected_angles(run: &Correction, model: &Model) -> Vec<Vec<[f64; 3]>> {
    run.joints
        .iter()
        .map(|jr| {
            let j = model.joint(&jr.joint).unwrap();
            let p = &run.corrected.imu(&j.proximal).unwrap().orientation;
            let d = &run.corrected.imu(&j.distal).unwrap().orientation;
            p.iter()
                .zip(d)
                .map(|(p, d)| j.table_angles(&(p.inverse() * d)))
                .collect()
        })
        .collect()
}

#[test]
fn turning_the_trial_about_the_vertical_changes_no_corrected_angle() {
    let model = Model::infant13();
    let table = LimitTable::default_table();
    let settings = Settings::default();
    let trial = simulate(&preset("full_body_drift").unwrap()).unwrap().trial;
    let run = |t: &Trial, v: Variant| {
        correct_trial(t, &model, &table, &settings, v, &RunControl::default()).unwrap()
    };
    for variant in [Variant::Drift, Variant::DriftCentroid] {
        let base = corrected_angles(&run(&trial, variant), &model);
        for angle in [30.0, 137.0, -101.0] {
            let turn = quat_axis_angle_deg([0.0, 0.0, 1.0], angle);
            let mut turned = trial.clone();
            for imu in &mut turned.imus {
                for q in &mut imu.orientation {
                    *q = turn * *q;
                }
            }
            let again = corrected_angles(&run(&turned, variant), &model);
            let mut worst: f64 = 0.0;
            for (a, b) in base.iter().zip(&again) {
                for (x, y) in a.iter().zip(b) {
                    for k in 0..3 {
                        worst = worst.max(wrap180(x[k] - y[k]).abs());
                    }
                }
            }
            eprintln!("{variant} turned {angle} deg: largest change {worst:e} deg");
            assert!(worst < 1e-4, "{variant} turned {angle} deg: {worst} deg");
        }
    }
}
