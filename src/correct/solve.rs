//! The solver of each variant kind, picked from the variant table's row: the
//! chain of `acm` (ACM, heading and baseline kinds), inverse kinematics
//! (`ik`), or no correction. The one place that knows all three solvers, so
//! that they need not know each other.

use crate::acm::{self, Correction};
use crate::ik::{self, IkSolution, SolverOptions};
use crate::limits::{LimitTable, Settings};
use crate::model::Model;
use crate::run::{Cancelled, RunControl, SkippedJoint};
use crate::trial::Trial;
use crate::variant::{Kind, Variant};
use std::sync::Arc;

/// Corrects every joint of `model` present in `trial` with `variant`.
pub fn correct_trial(
    trial: &Trial,
    model: &Model,
    limits: &LimitTable,
    settings: &Settings,
    variant: Variant,
    control: &RunControl,
) -> Result<Correction, Cancelled> {
    match variant.kind() {
        Kind::Ik => correct_ik(trial, model, settings, control),
        Kind::None => Ok(acm::uncorrected(trial, model, limits, settings)),
        Kind::Acm | Kind::Heading | Kind::Baseline => {
            acm::correct_chain(trial, model, limits, settings, variant, control)
        }
        Kind::Auto => {
            let none = Default::default();
            acm::auto_run::correct_auto(trial, model, limits, settings, &none, control)
        }
    }
}

/// Re-corrects the named joints and everything below them, reusing `previous`
/// for the rest (after a limit edit, say); see [`acm::recorrect_chain`].
/// `previous` must come from the same trial, model and variant.
pub fn recorrect(
    trial: &Trial,
    model: &Model,
    limits: &LimitTable,
    settings: &Settings,
    previous: &Correction,
    joints: &[&str],
    control: &RunControl,
) -> Result<Correction, Cancelled> {
    match previous.variant.kind() {
        // Inverse kinematics and no correction do not read the limit table
        // or the settings.
        Kind::Ik | Kind::None => Ok(previous.clone()),
        Kind::Acm | Kind::Heading | Kind::Baseline => {
            acm::recorrect_chain(trial, model, limits, settings, previous, joints, control)
        }
        // Its candidates include a heading-first one: all is redone,
        // keeping the user's overrides.
        Kind::Auto => {
            let forced = acm::auto_run::overrides(previous);
            acm::auto_run::correct_auto(trial, model, limits, settings, &forced, control)
        }
    }
}

/// The `ik` variant: the trial with every IMU of the tree replaced by the
/// segment orientation the solved coordinates imply. IMUs outside the tree
/// are left as they are.
fn correct_ik(
    trial: &Trial,
    model: &Model,
    settings: &Settings,
    control: &RunControl,
) -> Result<Correction, Cancelled> {
    let solved = ik::solve_trial(trial, model, &SolverOptions::default(), control)?;
    let mut corrected = trial.clone();
    let (ik, skipped) = match solved {
        Some(IkSolution { run, segments }) => {
            for s in segments {
                // Segment orientations, not sensor ones: the sensor-frame
                // gyros no longer describe them and are dropped.
                let imu = corrected.imu_mut(&s.name).expect("present");
                imu.orientation = s.orientation;
                imu.gyro = None;
            }
            let skipped = run.skipped.clone();
            (Some(Arc::new(run)), skipped)
        }
        None => (
            None,
            model
                .joints
                .iter()
                .map(|j| SkippedJoint {
                    joint: j.name.clone(),
                    reason: format!("the base IMU '{}' is not in the trial", model.base),
                })
                .collect(),
        ),
    };
    Ok(Correction {
        variant: Variant::Ik,
        settings: *settings,
        corrected,
        joints: vec![],
        skipped,
        headings: vec![],
        ik,
    })
}
