//! What the engine's integration tests share: a correction with the shipped
//! limit table and settings, the median of a sample, and the geodesic error of
//! a joint against the truth.

use acm_workbench::acm::{Correction, RunControl, Variant};
use acm_workbench::correct::correct_trial;
use acm_workbench::limits::{LimitTable, Settings};
use acm_workbench::model::Model;
use acm_workbench::rotation::{angle_between_deg, Quat};
use acm_workbench::trial::Trial;

/// `variant` on `trial` with `model`, the limit table `table` and the default
/// settings.
pub fn run_with_table(
    model: &Model,
    trial: &Trial,
    table: &LimitTable,
    variant: Variant,
) -> Correction {
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

/// `variant` on `trial` with `model`, the default limit table and settings.
pub fn run_on(model: &Model, trial: &Trial, variant: Variant) -> Correction {
    run_with_table(model, trial, &LimitTable::default_table(), variant)
}

/// [`run_on`] with `infant13`, the model of the simulated trials.
pub fn run(trial: &Trial, variant: Variant) -> Correction {
    run_on(&Model::infant13(), trial, variant)
}

/// The median (mean of the middle two for an even count).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// RMS over samples of the angle between `joint`'s rotation (distal segment
/// in the proximal one) in `trial` and in `truth`, degrees.
pub fn geodesic_error_deg(model: &Model, joint: &str, trial: &Trial, truth: &Trial) -> f64 {
    let j = model.joint(joint).unwrap();
    let rot = |t: &Trial| -> Vec<Quat> {
        let p = &t.imu(&j.proximal).unwrap().orientation;
        let d = &t.imu(&j.distal).unwrap().orientation;
        p.iter().zip(d).map(|(p, d)| p.inverse() * d).collect()
    };
    let (got, want) = (rot(trial), rot(truth));
    let sum: f64 = (got.iter().zip(&want))
        .map(|(g, w)| angle_between_deg(g, w).powi(2))
        .sum();
    (sum / got.len() as f64).sqrt()
}
