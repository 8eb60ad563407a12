//! The heading variants' fit with the gradient solver against the same fit
//! with Nelder-Mead (the previous C steps and the pattern search on values,
//! the oracle): on every joint that `drift-heading` and
//! `drift-heading-centroid` correct in the sample trials and in simulated
//! trials, the two fits are run on the same inputs (the parent corrected as
//! the engine corrected it, the joints below it as its lookahead sees them)
//! and the gradient fit's objective is no higher than the oracle's: summed
//! over all those joints within `SUM_REL`, on each joint within `REL` (see
//! there).

use acm_workbench::acm::heading::{HeadingOptions, HeadingProblem};
use acm_workbench::acm::lookahead::{ChildJoint, Lookahead};
use acm_workbench::acm::minimise::Solver;
use acm_workbench::acm::window::layout;
use acm_workbench::acm::{RunControl, Variant};
use acm_workbench::correct::correct_trial;
use acm_workbench::limits::{JointLimits, LimitTable, Settings};
use acm_workbench::model::Model;
use acm_workbench::rotation::Quat;
use acm_workbench::simulate::{simulate, HeadingDrift, SimConfig};
use acm_workbench::trial::{read_trial, Trial};
use std::path::Path;

/// Relative margin allowed to the oracle on the sum over the compared joints.
/// Over all joints the gradient fit's sum was 1.3e-5 relative below the
/// oracle's; the joints near the other Z-Y-X triplet (see
/// [`near_the_other_triplet`]) held most of that lead, and over the others it
/// is 4.0e-6 above (2021.4672 against 2021.4592): the per-joint spread of
/// `REL` summed, not a worse minimiser. This bound is that figure's order.
const SUM_REL: f64 = 1e-5;

/// Relative margin allowed to the oracle on one joint. Both fits are block
/// coordinate descents, C step then heading steps, that stop after one
/// full-resolution round, not at a common exact minimum: a first-round scan
/// that finds two basins nearly tied, or C steps ending 1e-9 rad rather than
/// 2e-7 rad from their optimum, start the two alternations on different paths,
/// and where each stops depends on the path more than on the C-step
/// minimiser. Measured over the 200 joints here the gradient fit is lower on
/// 80, by up to 6.4e-3 relative, and higher on the others by up to 1.6e-3
/// (median difference 1e-7): this bound is that spread, and the sum over
/// joints (`SUM_REL`) is where "no worse" is asserted.
const REL: f64 = 2e-3;

/// Whether [`JointLimits::near_the_other_triplet`] holds for some sample of
/// the joint (as measured or as corrected; for this joint or one its
/// lookahead sees). The objective then has one basin per reading; the
/// alternation keeps to the one its start is in while Nelder-Mead's restarts
/// may find a lower one that is further from the truth (tests/solver_oracle.rs
/// says more). Such joints are counted, not compared.
fn near_the_other_triplet(parent: &[Quat], child: &[Quat], lim: &JointLimits) -> bool {
    parent
        .iter()
        .zip(child)
        .any(|(p, c)| lim.near_the_other_triplet(&(p.inverse() * c)))
}

struct Tally {
    /// Joints near the other triplet (see [`near_the_other_triplet`]) and
    /// those of them where the gradient fit ends higher than `REL` allows.
    two_readings: usize,
    two_readings_higher: usize,
    joints: usize,
    lower: usize,
    worst_rel: f64,
    c_evals: [usize; 2],
    /// Sums of the objectives, gradient and oracle.
    sums: [f64; 2],
    /// The joints where the gradient fit costs more than allowed.
    worse: Vec<String>,
}

fn limits_of(table: &LimitTable, model: &Model, joint: &str, variant: Variant) -> JointLimits {
    let j = model.joint(joint).unwrap();
    table.cost_limits(j, variant.centroid()).unwrap()
}

fn check_trial(name: &str, trial: &Trial, model: &Model, tally: &mut Tally) {
    let table = LimitTable::default_table();
    let settings = Settings::default();
    let windows = layout(&trial.time_s, settings.window_s, settings.hop_s);
    for variant in [Variant::DriftHeading, Variant::DriftHeadingCentroid] {
        let run = correct_trial(
            trial,
            model,
            &table,
            &settings,
            variant,
            &RunControl::default(),
        )
        .unwrap();
        for jr in &run.joints {
            let joint = model.joint(&jr.joint).unwrap();
            let lim = limits_of(&table, model, &joint.name, variant);
            let below: Vec<(String, JointLimits)> = model
                .joints
                .iter()
                .filter(|c| c.proximal == joint.distal && run.joint(&c.name).is_some())
                .map(|c| (c.distal.clone(), limits_of(&table, model, &c.name, variant)))
                .collect();
            let children: Vec<ChildJoint> = below
                .iter()
                .map(|(imu, limits)| ChildJoint {
                    child: &trial.imu(imu).unwrap().orientation,
                    limits,
                })
                .collect();
            let lookahead = Lookahead {
                own: HeadingProblem {
                    parent: &run.corrected.imu(&joint.proximal).unwrap().orientation,
                    child: &trial.imu(&joint.distal).unwrap().orientation,
                    windows: &windows,
                    limits: &lim,
                    lambda1: settings.lambda1,
                    vertical: settings.vertical,
                },
                children: &children,
            };
            let fit = |solver| lookahead.fit(&HeadingOptions::for_solver(solver));
            let (g, o) = (fit(Solver::Gradient), fit(Solver::NelderMead));
            let parent = &run.corrected.imu(&joint.proximal).unwrap().orientation;
            let children = [
                &trial.imu(&joint.distal).unwrap().orientation,
                &run.corrected.imu(&joint.distal).unwrap().orientation,
            ];
            // The lookahead's joints below count too.
            let own_distal = &run.corrected.imu(&joint.distal).unwrap().orientation;
            let below_near = below.iter().any(|(imu, limits)| {
                [
                    &trial.imu(imu).unwrap().orientation,
                    &run.corrected.imu(imu).unwrap().orientation,
                ]
                .iter()
                .any(|child| near_the_other_triplet(own_distal, child, limits))
            });
            if below_near
                || children
                    .iter()
                    .any(|child| near_the_other_triplet(parent, child, &lim))
            {
                tally.two_readings += 1;
                if g.objective > o.objective * (1.0 + REL) {
                    tally.two_readings_higher += 1;
                }
                continue;
            }
            tally.joints += 1;
            tally.c_evals[0] += g.c_evaluations;
            tally.c_evals[1] += o.c_evaluations;
            tally.sums[0] += g.objective;
            tally.sums[1] += o.objective;
            let rel = (g.objective - o.objective) / o.objective.abs().max(1e-12);
            tally.worst_rel = tally.worst_rel.max(rel);
            if g.objective < o.objective {
                tally.lower += 1;
            }
            if g.objective > o.objective + REL * o.objective.abs() + 1e-15 {
                tally.worse.push(format!(
                    "{name} {variant} {}: gradient {} > Nelder-Mead {} ({rel:e} relative)",
                    jr.joint, g.objective, o.objective
                ));
            }
        }
    }
}

/// Simulated trials: full bodies of two minutes (every other one with a
/// heading drift on a calf and a forearm), an elbow and a knee.
fn simulated_trials() -> Vec<SimConfig> {
    use acm_workbench::simulate::{KneeAxis, KneeImu};
    let mut out = Vec::new();
    for seed in 0..6 {
        let mut c = SimConfig::full_body(200 + seed);
        c.duration_s = 120.0;
        if seed % 2 == 1 {
            c.drifts = ["l_calf", "r_forearm"]
                .map(|imu| HeadingDrift {
                    imu: imu.into(),
                    start_s: 20.0,
                    rate_deg_s: 0.1 + 0.03 * seed as f64,
                })
                .into();
        }
        out.push(c);
    }
    out.push(SimConfig::elbow(41, 25.0));
    out.push(SimConfig::knee(KneeImu::Calf, KneeAxis::Z, 18.0));
    out
}

#[test]
fn heading_fit_with_the_gradient_solver_is_never_worse_than_nelder_mead() {
    let model = Model::infant13();
    let mut tally = Tally {
        two_readings: 0,
        two_readings_higher: 0,
        joints: 0,
        lower: 0,
        worst_rel: f64::NEG_INFINITY,
        c_evals: [0, 0],
        sums: [0.0, 0.0],
        worse: Vec::new(),
    };
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("sample_trials");
    for name in [
        "knee_calf_z15.csv.gz",
        "full_body_clean.csv.gz",
        "full_body_drift.csv.gz",
        "elbow_20.csv.gz",
    ] {
        let trial = read_trial(&dir.join(name), &model).unwrap();
        check_trial(name, &trial, &model, &mut tally);
    }
    for (k, config) in simulated_trials().iter().enumerate() {
        let trial = simulate(config).unwrap().trial;
        check_trial(&format!("simulated trial {k}"), &trial, &model, &mut tally);
    }
    assert!(tally.joints > 100, "{} joints", tally.joints);
    assert!(tally.worse.is_empty(), "{}", tally.worse.join("\n"));
    let [gradient, oracle] = tally.sums;
    assert!(
        gradient <= oracle * (1.0 + SUM_REL),
        "sum over joints: gradient {gradient} > Nelder-Mead {oracle}"
    );
    eprintln!(
        "{} joints: gradient lower on {}, worst relative excess {:e}; C-step evaluations {} vs {}; sums {} vs {}",
        tally.joints, tally.lower, tally.worst_rel, tally.c_evals[0], tally.c_evals[1], tally.sums[0], tally.sums[1]
    );
    eprintln!(
        "{} joints near the other triplet not compared; the gradient fit higher on {} of them",
        tally.two_readings, tally.two_readings_higher
    );
    assert!(
        tally.two_readings * 2 < tally.joints,
        "{} joints near the other triplet against {} compared",
        tally.two_readings,
        tally.joints
    );
}
