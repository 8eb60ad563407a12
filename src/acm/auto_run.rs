//! The `auto` run: every candidate variant corrects the whole trial on its
//! own, then per joint, in chain order, [`super::auto::choose`] picks the
//! candidate whose joint rotation the result takes (docs/method.md section
//! 19).
//!
//! Taking a joint's rotation rather than its distal IMU's corrected
//! orientation keeps every joint's angles exactly those of the run it was
//! chosen from, whatever the joints above chose: the distal IMU becomes
//! `G_R_prox'(t) (G_R_prox,v(t))^-1 G_R_dist,v(t)`, the proximal IMU as
//! `auto` corrected it times the joint rotation of candidate `v`'s run. So a
//! `hinge` knee, whose thigh the hinge run turned onto the knee's axis,
//! keeps its hinge angles under a hip `drift-centroid` won (`hinge-heading`
//! is the hinge candidate).

use super::auto::{Candidate, JointCandidates, CANDIDATES};
use super::chain::{correct_chain, correct_deheaded_from};
use super::cost::WindowCost;
use super::window::layout;
use super::{Cancelled, Correction, ImuHeading, RunControl, WindowSolution};
use crate::limits::{LimitTable, Settings};
use crate::model::{Joint, Model};
use crate::rotation::Quat;
use crate::trial::Trial;
use crate::variant::Variant;
use std::collections::HashMap;

/// Corrects `trial` with `auto`; `forced` maps a joint name to the candidate
/// the user chose for it (an override kept from an earlier run).
pub fn correct_auto(
    trial: &Trial,
    model: &Model,
    limits: &LimitTable,
    settings: &Settings,
    forced: &HashMap<String, Variant>,
    control: &RunControl,
) -> Result<Correction, Cancelled> {
    let runs = candidate_runs(trial, model, limits, settings, control)?;
    let runs: Vec<(Variant, &Correction)> = runs.iter().map(|(v, c)| (*v, c)).collect();
    Ok(compose(trial, model, limits, settings, &runs, forced))
}

/// `auto` from corrections already made of the same trial with the same
/// model, limits and settings (every candidate but `none` among
/// `corrections`, whatever else is there): exactly [`correct_auto`]'s
/// result, without solving anything again. None when a candidate is missing.
pub fn compose_from(
    trial: &Trial,
    (model, limits, settings): (&Model, &LimitTable, &Settings),
    corrections: &[&Correction],
    forced: &HashMap<String, Variant>,
) -> Option<Correction> {
    let runs: Vec<(Variant, &Correction)> = (CANDIDATES.iter())
        .filter(|v| **v != Variant::None)
        .map(|&v| Some((v, *corrections.iter().find(|c| c.variant == v)?)))
        .collect::<Option<_>>()?;
    Some(compose(trial, model, limits, settings, &runs, forced))
}

/// The overrides recorded in an earlier `auto` correction, by joint name.
pub fn overrides(previous: &Correction) -> HashMap<String, Variant> {
    (previous.joints.iter())
        .filter_map(|j| {
            let a = j.auto.as_ref()?;
            a.overridden.map(|_| (j.joint.clone(), a.chosen))
        })
        .collect()
}

/// The candidates' whole runs, in [`CANDIDATES`] order (`none` is the trial
/// itself and has no run). `hinge-heading` removes the headings of the
/// `drift-heading-centroid` run rather than fitting them again.
fn candidate_runs(
    trial: &Trial,
    model: &Model,
    limits: &LimitTable,
    settings: &Settings,
    control: &RunControl,
) -> Result<Vec<(Variant, Correction)>, Cancelled> {
    let solved: Vec<Variant> = CANDIDATES
        .iter()
        .copied()
        .filter(|v| *v != Variant::None)
        .collect();
    // Solve drift-heading-centroid first: hinge-heading starts from it.
    let mut order = solved.clone();
    order.sort_by_key(|v| *v != Variant::DriftHeadingCentroid);
    let mut runs: HashMap<Variant, Correction> = HashMap::new();
    let count = order.len();
    for (i, &v) in order.iter().enumerate() {
        // Each run reports its share of the whole: 1000 steps per run.
        let share = |d: usize, n: usize| {
            if let Some(p) = control.progress {
                p(1000 * i + 1000 * d / n.max(1), 1000 * count)
            }
        };
        let pass = RunControl {
            cancel: control.cancel,
            progress: Some(&share),
        };
        let c = match (v, runs.get(&Variant::DriftHeadingCentroid)) {
            (Variant::HingeHeading, Some(first)) => {
                correct_deheaded_from(trial, model, limits, settings, (v, first), &pass)?
            }
            _ => correct_chain(trial, model, limits, settings, v, &pass)?,
        };
        runs.insert(v, c);
    }
    Ok(solved
        .into_iter()
        .map(|v| (v, runs.remove(&v).expect("solved")))
        .collect())
}

/// The `auto` correction from the candidates' runs: per joint in model
/// order (parents first) the chosen run's joint rotation on the proximal IMU
/// as corrected so far.
fn compose(
    trial: &Trial,
    model: &Model,
    limits: &LimitTable,
    settings: &Settings,
    runs: &[(Variant, &Correction)],
    forced: &HashMap<String, Variant>,
) -> Correction {
    let first = &runs[0].1;
    let mut corrected = trial.clone();
    let mut joints = Vec::new();
    let mut headings: Vec<ImuHeading> = Vec::new();
    for joint in &model.joints {
        // The joints every run corrected (the same set: skipping depends on
        // the trial and the table only).
        if first.joint(&joint.name).is_none() {
            continue;
        }
        let raw = &trial.imu(&joint.distal).expect("corrected").orientation;
        let mut candidates: Vec<Candidate> = runs
            .iter()
            .map(|(v, c)| Candidate {
                variant: *v,
                parent: &c
                    .corrected
                    .imu(&joint.proximal)
                    .expect("present")
                    .orientation,
                distal: &c.corrected.imu(&joint.distal).expect("present").orientation,
                windows: &c.joint(&joint.name).expect("corrected").windows,
                heading: c.heading(&joint.distal).filter(|_| v.heading()),
            })
            .collect();
        let raw_parent = &trial.imu(&joint.proximal).expect("present").orientation;
        candidates.push(Candidate {
            variant: Variant::None,
            parent: raw_parent,
            distal: raw,
            windows: &[],
            heading: None,
        });
        let view = JointCandidates {
            joint,
            limits: limits.joint_limits(&joint.name, &joint.kind, true),
            raw,
            candidates,
        };
        let choice = super::auto::choose(&view, forced.get(&joint.name).copied());
        let picked = &view.candidates[choice.chosen_index];
        let parent_now = &corrected.imu(&joint.proximal).expect("present").orientation;
        let distal: Vec<Quat> = parent_now
            .iter()
            .zip(picked.parent.iter().zip(picked.distal))
            .map(|(now, (p, d))| Quat::new_normalize((now * p.inverse() * d).into_inner()))
            .collect();
        let run = runs.iter().find(|(v, _)| *v == choice.record.chosen);
        let mut result = match run {
            Some((_, c)) => c.joint(&joint.name).expect("corrected").clone(),
            None => uncorrected_result(trial, (joint, limits, settings), first),
        };
        if let Some((_, c)) = run.filter(|(v, _)| v.fits_headings()) {
            headings.extend(c.heading(&joint.distal).cloned());
        }
        let gyro = match run {
            Some((_, c)) => c
                .corrected
                .imu(&joint.distal)
                .expect("present")
                .gyro
                .clone(),
            None => trial.imu(&joint.distal).expect("present").gyro.clone(),
        };
        drop(view);
        result.auto = Some(choice.record);
        let imu = corrected.imu_mut(&joint.distal).expect("present");
        imu.orientation = distal;
        imu.gyro = gyro;
        joints.push(result);
    }
    Correction {
        variant: Variant::Auto,
        settings: *settings,
        corrected,
        joints,
        skipped: first.skipped.clone(),
        headings,
        ik: None,
    }
}

/// A joint's result when `none` was chosen (the joint as measured): the
/// first run's record without hinge or baseline, its windows' corrections
/// the identity at the cost of the measured joint rotations
/// `G_R_prox^-1 G_R_dist`, limits without the centroid term.
fn uncorrected_result(
    trial: &Trial,
    (joint, limits, settings): (&Joint, &LimitTable, &Settings),
    first: &Correction,
) -> super::JointResult {
    let mut r = first.joint(&joint.name).expect("corrected").clone();
    let parent = &trial.imu(&joint.proximal).expect("present").orientation;
    let child = &trial.imu(&joint.distal).expect("present").orientation;
    let lim = limits.cost_limits(joint, false).expect("a corrected joint");
    r.windows = layout(&trial.time_s, settings.window_s, settings.hop_s)
        .iter()
        .map(|w| {
            let measured: Vec<Quat> = (w.first..w.end)
                .map(|i| parent[i].inverse() * child[i])
                .collect();
            let cost = WindowCost::new(&measured, &lim, settings.lambda1).eval(&Quat::identity());
            WindowSolution {
                start_s: w.start_s,
                end_s: w.end_s,
                centre_s: w.centre_s,
                samples: w.len(),
                correction: [1.0, 0.0, 0.0, 0.0],
                angle_deg: 0.0,
                cost,
                cost_uncorrected: cost,
                evaluations: 1,
            }
        })
        .collect();
    r.hinge = None;
    r.baseline = None;
    r.axis_from = None;
    r.lambda2 = 0.0;
    r
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulate::{preset, simulate};

    #[test]
    fn a_joint_left_as_measured_records_the_measured_window_costs() {
        let mut cfg = preset("full_body_clean").unwrap();
        cfg.duration_s = 40.0;
        let trial = simulate(&cfg).unwrap().trial;
        let (model, table, settings) = (
            Model::infant13(),
            LimitTable::default_table(),
            Settings::default(),
        );
        let drift = correct_chain(
            &trial,
            &model,
            &table,
            &settings,
            Variant::Drift,
            &RunControl::default(),
        )
        .unwrap();
        // The back's proximal IMU is the base, which no run corrects: its
        // measured windows are those `drift` solved, whose uncorrected
        // cost is the same cost at the identity.
        let back = model.joint("back").unwrap();
        let none = uncorrected_result(&trial, (back, &table, &settings), &drift);
        let solved = &drift.joint("back").unwrap().windows;
        assert_eq!(none.windows.len(), solved.len());
        assert!(solved.iter().any(|w| w.cost_uncorrected > 0.0));
        for (n, s) in none.windows.iter().zip(solved) {
            assert_eq!(n.correction, [1.0, 0.0, 0.0, 0.0]);
            assert_eq!((n.start_s, n.samples), (s.start_s, s.samples));
            let tol = 1e-12 * s.cost_uncorrected.abs().max(1.0);
            assert!((n.cost - s.cost_uncorrected).abs() <= tol, "{n:?} {s:?}");
        }
    }
}
