//! Correcting a whole trial down the model's chain (docs/method.md section 8).
//!
//! Joints are taken in the model's correction order. Joints at the same depth of
//! the chain never depend on each other and run in parallel, as do the windows
//! of one joint; every window's result depends only on its inputs, so the output
//! is bit-identical for any thread count.
//!
//! Gyroscope readings (sensor frame) follow their IMU's correction: a distal IMU
//! corrected by the ACM as `G_R_dist C(t)` reads `C(t)^-1 w` in its corrected
//! frame (heading fits, `Rz(-h(t)) G_R_dist C`, likewise with their constant
//! C); the correction's own rate (C changes over tens of seconds, h at
//! fractions of a degree per second) is left out. A baseline's `C(t)` turns
//! with the joint: the baseline gives the corrected readings itself (Mueller,
//! from both IMUs' gyros) or they are dropped (Rivest). The Mueller baseline
//! takes its proximal gyros from the corrected trial, so they are in the frame
//! its joint rotations are measured from.

use super::cost::WindowCost;
use super::heading::{apply, heading_series, remove_headings, HeadingOptions, HeadingProblem};
use super::hinge::{self, AxisFamily, HingeFits};
use super::lookahead::{ChildJoint, Lookahead};
use super::minimise::{
    minimise, minimise_shaped, screen_basins, MinimiseOptions, ScreenOptions, ShapedCost,
    ShapedOptions, Solution, Solver,
};
use super::window::{correction_series, layout, whole_trial, Window};
use super::{
    Cancelled, Correction, HeadingWindow, ImuHeading, JointResult, RunControl, SkippedJoint,
    Variant, WindowSolution,
};
use crate::baselines;
use crate::limits::{JointLimits, LimitTable, Settings};
use crate::model::{Joint, Model};
use crate::rotation::{angle_deg, canonical, quat_from_wxyz, wrap180, wxyz, Quat};
use crate::trial::Trial;
use nalgebra::Vector3;
use rayon::prelude::*;
use std::collections::{BTreeSet, HashMap};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The solved correction of one joint: per-window solutions and the per-sample series.
#[derive(Debug, Clone, PartialEq)]
pub struct JointSolution {
    pub windows: Vec<WindowSolution>,
    /// `C(t)` per sample (sensor frame of the distal IMU).
    pub series: Vec<Quat>,
}

/// Corrects every joint of `model` present in `trial` with `variant`, down
/// the chain: the solver of the ACM, heading and baseline kinds.
pub fn correct_chain(
    trial: &Trial,
    model: &Model,
    limits: &LimitTable,
    settings: &Settings,
    variant: Variant,
    control: &RunControl,
) -> Result<Correction, Cancelled> {
    if variant.headings_first() {
        return correct_deheaded(trial, model, limits, settings, variant, control);
    }
    run(trial, model, limits, settings, variant, None, control)
}

/// `h` with its first window's heading taken from every window's: the drift
/// since the start. A heading fit reads a misaligned parent as a constant
/// heading of the child (on the knee test, a thigh 30 deg off about Z as a
/// calf heading of -16.6 deg in every window); turning the child alone by
/// it would break the hinge the second pass fits, while the drift that moves
/// a hinge's axes is the change of heading over the trial.
fn drift_since_start(mut h: ImuHeading) -> ImuHeading {
    let first = h.windows.first().map_or(0.0, |w| w.heading_deg);
    for w in &mut h.windows {
        w.heading_deg -= first;
    }
    h
}

/// A variant that removes heading drift first (`hinge-heading`): each IMU's
/// heading drift since its first window, as `drift-heading-centroid`
/// estimates it, is removed from the trial ([`remove_headings`]), and `hinge`
/// corrects what is left; the result carries those headings. Both passes
/// solve the same joints over the same windows, so progress counts each as
/// half of the run.
fn correct_deheaded(
    trial: &Trial,
    model: &Model,
    limits: &LimitTable,
    settings: &Settings,
    variant: Variant,
    control: &RunControl,
) -> Result<Correction, Cancelled> {
    let report = |done: usize, total: usize| {
        if let Some(p) = control.progress {
            p(done, total)
        }
    };
    let first = |d: usize, n: usize| report(d, 2 * n);
    let pass = RunControl {
        cancel: control.cancel,
        progress: Some(&first),
    };
    let first_pass = run(
        trial,
        model,
        limits,
        settings,
        Variant::DriftHeadingCentroid,
        None,
        &pass,
    )?;
    let second = |d: usize, n: usize| report(n + d, 2 * n);
    let pass = RunControl {
        cancel: control.cancel,
        progress: Some(&second),
    };
    correct_deheaded_from(
        trial,
        model,
        limits,
        settings,
        (variant, &first_pass),
        &pass,
    )
}

/// The second pass of [`correct_deheaded`]: `hinge` on the trial with the
/// heading drift since the start that `first_pass` (a
/// `drift-heading-centroid` correction of the same trial, model, limits and
/// settings) fitted removed; the result is `variant`'s and carries those
/// headings.
pub(crate) fn correct_deheaded_from(
    trial: &Trial,
    model: &Model,
    limits: &LimitTable,
    settings: &Settings,
    (variant, first_pass): (Variant, &Correction),
    control: &RunControl,
) -> Result<Correction, Cancelled> {
    let headings: Vec<ImuHeading> = (first_pass.headings.iter().cloned())
        .map(drift_since_start)
        .collect();
    let deheaded = remove_headings(trial, &headings);
    let mut c = run(
        &deheaded,
        model,
        limits,
        settings,
        Variant::Hinge,
        None,
        control,
    )?;
    c.variant = variant;
    c.headings = headings;
    Ok(c)
}

/// The `none` variant: the trial as it is, every joint left uncorrected (the
/// joints that could not be corrected in any variant are listed as skipped).
pub fn uncorrected(
    trial: &Trial,
    model: &Model,
    limits: &LimitTable,
    settings: &Settings,
) -> Correction {
    Correction {
        headings: Vec::new(),
        variant: Variant::None,
        settings: *settings,
        corrected: trial.clone(),
        joints: Vec::new(),
        skipped: model
            .joints
            .iter()
            .filter_map(|j| {
                skip_reason(trial, j, limits).map(|reason| SkippedJoint {
                    joint: j.name.clone(),
                    reason,
                })
            })
            .collect(),
        ik: None,
    }
}

/// Re-corrects the named joints and everything below them, reusing `previous`
/// for the rest (after a limit edit, say). For the heading variants the joint
/// above each named one is redone too, with everything below it: its IMU's fit
/// looks ahead at the named joint's limits ([`super::lookahead`]); a variant
/// that removes heading drift first is redone whole. `previous` must come
/// from the same trial, model and variant, one of the chain's kinds.
pub fn recorrect_chain(
    trial: &Trial,
    model: &Model,
    limits: &LimitTable,
    settings: &Settings,
    previous: &Correction,
    joints: &[&str],
    control: &RunControl,
) -> Result<Correction, Cancelled> {
    if previous.variant.headings_first() {
        // The headings are fitted with every joint's limits: all is redone.
        return correct_chain(trial, model, limits, settings, previous.variant, control);
    }
    let mut redo = BTreeSet::new();
    for (k, j) in model.joints.iter().enumerate() {
        if joints.contains(&j.name.as_str()) {
            // The heading variants fit a joint's parent IMU with this joint's
            // limits too (the lookahead): the parent joint is redone as well.
            let parent = model
                .joints
                .iter()
                .position(|p| p.distal == j.proximal)
                .filter(|_| previous.variant.heading())
                .unwrap_or(k);
            redo.insert(parent);
            redo.extend(model.descendants(parent));
        }
    }
    run(
        trial,
        model,
        limits,
        settings,
        previous.variant,
        Some((previous, &redo)),
        control,
    )
}

/// Why a joint cannot be corrected in this trial, if it cannot.
fn skip_reason(trial: &Trial, joint: &Joint, limits: &LimitTable) -> Option<String> {
    for imu in [&joint.proximal, &joint.distal] {
        if trial.imu(imu).is_none() {
            return Some(format!("IMU '{imu}' is not in the trial"));
        }
    }
    if limits
        .joint_limits(&joint.name, &joint.kind, false)
        .is_none()
    {
        return Some(format!("the limit table has no rows for '{}'", joint.kind));
    }
    None
}

fn run(
    trial: &Trial,
    model: &Model,
    limits: &LimitTable,
    settings: &Settings,
    variant: Variant,
    reuse: Option<(&Correction, &BTreeSet<usize>)>,
    control: &RunControl,
) -> Result<Correction, Cancelled> {
    let windows = if variant.windowed() {
        layout(&trial.time_s, settings.window_s, settings.hop_s)
    } else {
        whole_trial(&trial.time_s)
    };
    // The joints with their limits (with or without the centroid term)
    // and, for `hinge`, their axes.
    let (todo, skipped) = plan_joints(trial, model, limits, variant);
    let mut hinges = hinge_fits(trial, model, &todo, variant, &windows);
    let solve_count = todo
        .iter()
        .filter(|(k, _)| reuse.is_none_or(|(_, redo)| redo.contains(k)))
        .count();
    let progress = Progress {
        done: AtomicUsize::new(0),
        total: solve_count * windows.len(),
        control,
    };
    let mut corrected = trial.clone();
    let depths = model.joint_depths();
    let mut results: HashMap<usize, JointResult> = HashMap::new();
    let mut headings: HashMap<usize, ImuHeading> = HashMap::new();
    let max_depth = depths.iter().copied().max().unwrap_or(0);
    for depth in 0..=max_depth {
        let level: Vec<usize> = (0..todo.len())
            .filter(|&i| depths[todo[i].0] == depth)
            .collect();
        for &i in &level {
            turn_uncorrected_proximal(
                &mut corrected,
                trial,
                model,
                &todo,
                todo[i].0,
                &mut hinges,
                (&windows, settings.lambda1),
            );
        }
        let pass = Pass {
            trial,
            model,
            settings,
            variant,
            reuse,
            windows: &windows,
            todo: &todo,
            hinges: &hinges,
            corrected: &corrected,
            results: &results,
            progress: &progress,
        };
        let solved: Vec<Solved> = level
            .par_iter()
            .map(|&i| {
                let (k, lim) = &pass.todo[i];
                pass.solve_joint(*k, lim)
            })
            .collect::<Result<_, Cancelled>>()?;
        for (k, result, applied, heading) in solved {
            if let Some(h) = heading {
                headings.insert(k, h);
            }
            let distal = &model.joints[k].distal;
            apply_to(corrected.imu_mut(distal).expect("present"), applied);
            results.insert(k, result);
        }
    }
    let mut joints: Vec<(usize, JointResult)> = results.into_iter().collect();
    joints.sort_by_key(|(k, _)| *k);
    let mut headings: Vec<(usize, ImuHeading)> = headings.into_iter().collect();
    headings.sort_by_key(|(k, _)| *k);
    Ok(Correction {
        headings: headings.into_iter().map(|(_, h)| h).collect(),
        variant,
        settings: *settings,
        corrected,
        joints: joints.into_iter().map(|(_, r)| r).collect(),
        skipped,
        ik: None,
    })
}

/// The joints to correct, each with its limits (by index in the model's
/// joints), and those skipped with the reason.
fn plan_joints(
    trial: &Trial,
    model: &Model,
    limits: &LimitTable,
    variant: Variant,
) -> (Vec<(usize, JointLimits)>, Vec<SkippedJoint>) {
    let mut skipped = Vec::new();
    let mut todo: Vec<(usize, JointLimits)> = Vec::new();
    for (k, joint) in model.joints.iter().enumerate() {
        match skip_reason(trial, joint, limits) {
            Some(reason) => skipped.push(SkippedJoint {
                joint: joint.name.clone(),
                reason,
            }),
            None => {
                // The engine's costs read the joint rotations in the
                // table's axes (docs/method.md section 2.5).
                let lim = limits
                    .cost_limits(joint, variant.centroid())
                    .expect("checked by skip_reason");
                todo.push((k, lim));
            }
        }
    }
    (todo, skipped)
}

/// Windows solved so far over the whole run, reported through the run's control.
struct Progress<'a> {
    done: AtomicUsize,
    /// Windows to solve in all.
    total: usize,
    control: &'a RunControl<'a>,
}

impl Progress<'_> {
    /// Counts one window solved and reports it.
    fn window_done(&self) {
        let d = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        if let Some(p) = self.control.progress {
            p(d, self.total);
        }
    }
}

/// One joint's outcome: its index, result, what to apply to its distal IMU
/// and, for the heading variants, its heading fit.
type Solved = (usize, JointResult, Applied, Option<ImuHeading>);

/// What every joint of one depth of the chain reads while the joints of that
/// depth are solved in parallel.
struct Pass<'a> {
    trial: &'a Trial,
    model: &'a Model,
    settings: &'a Settings,
    variant: Variant,
    reuse: Option<(&'a Correction, &'a BTreeSet<usize>)>,
    windows: &'a [Window],
    todo: &'a [(usize, JointLimits)],
    hinges: &'a HashMap<usize, HingeFits>,
    /// The trial with the joints above this depth corrected.
    corrected: &'a Trial,
    /// The joints solved above this depth.
    results: &'a HashMap<usize, JointResult>,
    progress: &'a Progress<'a>,
}

impl Pass<'_> {
    /// Solves joint `k` (or keeps an earlier run's result for it) with the
    /// variant's solver.
    fn solve_joint(&self, k: usize, lim: &JointLimits) -> Result<Solved, Cancelled> {
        let joint = &self.model.joints[k];
        if let Some(kept) = self.kept(k) {
            return Ok(kept);
        }
        let families = axis_families(self.model, self.todo, self.hinges, k, self.settings.lambda1);
        let result = |windows, baseline| JointResult {
            joint: joint.name.clone(),
            proximal: joint.proximal.clone(),
            distal: joint.distal.clone(),
            lambda2: lim.lambda2,
            parent_corrected: results_has_imu(self.results, self.model, &joint.proximal),
            windows,
            baseline,
            hinge: self.hinges.get(&k).map(|f| f.record.clone()),
            axis_from: families.as_ref().and_then(|f| f.from_child.clone()),
            auto: None,
        };
        if self.variant.heading() {
            let (windows, applied, heading) = self.solve_heading_joint(joint, lim)?;
            return Ok((k, result(windows, None), applied, Some(heading)));
        }
        let parent_series = self.corrected.imu(&joint.proximal).expect("present");
        let child_series = self.trial.imu(&joint.distal).expect("present");
        let measured: Vec<Quat> = parent_series
            .orientation
            .iter()
            .zip(&child_series.orientation)
            .map(|(p, c)| p.inverse() * c)
            .collect();
        let control = self.progress.control;
        let progress = || self.progress.window_done();
        if let Some(method) = baselines::method_for(self.variant, joint) {
            let gyros = match (&parent_series.gyro, &child_series.gyro) {
                (Some(p), Some(c)) => Some(baselines::JointGyros {
                    proximal: p,
                    distal: c,
                }),
                _ => None,
            };
            let (sol, baseline, gyro) = solve_baseline(
                method,
                (&self.trial.time_s, &measured, gyros),
                self.windows,
                control,
                &progress,
            )?;
            let applied = Applied::Series(sol.series, GyroUpdate::Replace(gyro));
            return Ok((k, result(sol.windows, baseline), applied, None));
        }
        let settings = self.settings;
        let sol = match &families {
            Some(f) => solve_windows_with_axes(
                (&self.trial.time_s, &measured),
                self.windows,
                (lim, settings.lambda1, settings.solver),
                (&f.per_window, self.child_term(f).as_ref(), f.turn_weight),
                control,
                &progress,
            )?,
            None => solve_windows(
                &self.trial.time_s,
                &measured,
                self.windows,
                (lim, settings.lambda1, settings.solver),
                control,
                &progress,
            )?,
        };
        let applied = Applied::Series(sol.series, GyroUpdate::Turn);
        Ok((k, result(sol.windows, None), applied, None))
    }

    /// The limits of the two-axis hinge below whose axis gave `families`.
    fn child_term(&self, families: &Families) -> Option<ChildTerm> {
        let c = families.two_axis_child?;
        ChildTerm::new(
            self.trial,
            self.model,
            self.todo,
            self.hinges.get(&c)?,
            c,
            self.windows,
        )
    }

    /// An earlier run's result for joint `k`, when the run re-solves other joints only.
    fn kept(&self, k: usize) -> Option<Solved> {
        let (prev, redo) = self.reuse?;
        if redo.contains(&k) {
            return None;
        }
        let joint = &self.model.joints[k];
        let r = prev.joint(&joint.name)?;
        let kept = prev.corrected.imu(&joint.distal).expect("present");
        let heading = prev.heading(&joint.distal).cloned();
        let applied = Applied::Kept(kept.orientation.clone(), kept.gyro.clone());
        Some((k, r.clone(), applied, heading))
    }

    /// The heading variants' fit of `joint`'s distal IMU, looking ahead to the
    /// joints below it: the window solutions, the corrected series and the fit.
    fn solve_heading_joint(
        &self,
        joint: &Joint,
        lim: &JointLimits,
    ) -> Result<(Vec<WindowSolution>, Applied, ImuHeading), Cancelled> {
        if self.progress.control.cancelled() {
            return Err(Cancelled);
        }
        let (trial, model) = (self.trial, self.model);
        let child_series = trial.imu(&joint.distal).expect("present");
        let problem = HeadingProblem {
            parent: &self
                .corrected
                .imu(&joint.proximal)
                .expect("present")
                .orientation,
            child: &child_series.orientation,
            windows: self.windows,
            limits: lim,
            lambda1: self.settings.lambda1,
            vertical: self.settings.vertical,
        };
        let children: Vec<ChildJoint> = self
            .todo
            .iter()
            .filter(|(c, _)| model.joints[*c].proximal == joint.distal)
            .map(|(c, limits)| ChildJoint {
                child: &trial
                    .imu(&model.joints[*c].distal)
                    .expect("present")
                    .orientation,
                limits,
            })
            .collect();
        let lookahead = Lookahead {
            own: problem,
            children: &children,
        };
        let opts = HeadingOptions::for_solver(self.settings.solver);
        let (sol, heading, orientation) = solve_heading(
            &trial.time_s,
            &lookahead,
            &opts,
            (&joint.name, &joint.distal),
        );
        self.windows
            .iter()
            .for_each(|_| self.progress.window_done());
        let c_inv = quat_from_wxyz(heading.correction).inverse();
        let gyro = (child_series.gyro.as_ref()).map(|g| g.iter().map(|w| c_inv * w).collect());
        Ok((sol, Applied::Kept(orientation, gyro), heading))
    }
}

/// Applies a joint's outcome to its distal IMU's orientations and gyros.
fn apply_to(imu: &mut crate::trial::ImuSeries, applied: Applied) {
    match applied {
        Applied::Series(series, gyro) => {
            for (q, c) in imu.orientation.iter_mut().zip(&series) {
                *q = Quat::new_normalize((*q * c).into_inner());
            }
            match (gyro, &mut imu.gyro) {
                (GyroUpdate::Turn, Some(g)) => {
                    for (w, c) in g.iter_mut().zip(&series) {
                        *w = c.inverse() * *w;
                    }
                }
                (GyroUpdate::Turn, None) => {}
                (GyroUpdate::Replace(g), _) => imu.gyro = g,
            }
        }
        Applied::Kept(orientation, gyro) => {
            imu.orientation = orientation;
            imu.gyro = gyro;
        }
    }
}

/// The hinge joints' axes per window (the `hinge` variant; empty otherwise),
/// estimated from the raw trial: each IMU's axis is in its own sensor frame,
/// which its corrections start from.
fn hinge_fits(
    trial: &Trial,
    model: &Model,
    todo: &[(usize, JointLimits)],
    variant: Variant,
    windows: &[Window],
) -> HashMap<usize, HingeFits> {
    if !variant.hinge() {
        return HashMap::new();
    }
    let fits: Vec<(usize, HingeFits)> = todo
        .par_iter()
        .filter_map(|(k, _)| {
            let joint = &model.joints[*k];
            let h = joint.hinge?;
            let p = trial.imu(&joint.proximal)?;
            let d = trial.imu(&joint.distal)?;
            let rm: Vec<Quat> = (p.orientation.iter().zip(&d.orientation))
                .map(|(p, d)| p.inverse() * d)
                .collect();
            let gyros = match (&p.gyro, &d.gyro) {
                (Some(proximal), Some(distal)) => Some(baselines::JointGyros { proximal, distal }),
                _ => None,
            };
            let fits = hinge::estimate_windows(h, &trial.time_s, &rm, gyros, windows);
            Some((*k, fits))
        })
        .collect();
    fits.into_iter().collect()
}

/// Where a joint's distal IMU has a hinge axis, the family of corrections
/// that keep it per window: the joint's own distal axis first, else the
/// proximal axis of a hinge joint below it (named in `from_child`).
struct Families {
    per_window: Vec<Option<AxisFamily>>,
    from_child: Option<String>,
    /// The hinge joint below whose proximal axis gave the families, when it
    /// has two axes: its limits on the turn about that axis join the cost.
    two_axis_child: Option<usize>,
    /// The weight of the turn about the axis in the size term, per degree:
    /// `lambda1`, times [`TWO_AXIS_TURN_WEIGHT`] for a two-axis hinge's axis.
    turn_weight: f64,
}

/// The limits of a two-axis hinge joint as a cost on the correction `C` of
/// its proximal IMU (docs/method.md section 18): the turn of the proximal IMU
/// about the hinge's proximal axis moves only the joint's proximal-axis angle
/// (the elbow's pronation), which the distal IMU's turn about its own axis
/// cannot reach, so the joint's own limits must decide it. Per window: the raw
/// joint rotations `Rm_i` (raw proximal to raw distal IMU frame, at most
/// [`CHILD_TERM_SAMPLES`] of them) and the least rotation `S_d` putting the
/// distal axis on its segment axis; the cost of `C` is the joint's window cost
/// of `C^-1 Rm_i S_d` without a size term.
struct ChildTerm {
    windows: Vec<(Vec<Quat>, Quat)>,
    limits: JointLimits,
}

/// The weight of the turn about a two-axis hinge's axis in the size term, as
/// a fraction of `lambda1` (docs/method.md section 18). The turn each axis
/// leaves free moves one joint angle alone (the elbow's forearm: flexion; its
/// upper arm: pronation), so the joint's limits on that angle are all there is
/// to decide it; at the full `lambda1` (0.05 per degree) a turn is only taken
/// while more than 5 % of the samples lie beyond a limit, and a forearm 20 deg
/// off about its flexion axis kept all 20 (the flexion reading 18-181 deg
/// against 0-160). At this fraction the turn goes where at most 0.1 % of the
/// samples are beyond, and the size term still picks the least turn when the
/// limits leave a range of them.
pub const TWO_AXIS_TURN_WEIGHT: f64 = 0.02;

/// Most samples per window in a [`ChildTerm`] (evenly spaced).
const CHILD_TERM_SAMPLES: usize = 600;

impl ChildTerm {
    fn new(
        trial: &Trial,
        model: &Model,
        todo: &[(usize, JointLimits)],
        fits: &HingeFits,
        c: usize,
        windows: &[Window],
    ) -> Option<ChildTerm> {
        let joint = &model.joints[c];
        let limits = todo.iter().find(|(j, _)| *j == c)?.1;
        let p = trial.imu(&joint.proximal)?;
        let d = trial.imu(&joint.distal)?;
        let nd = Vector3::from(fits.hinge.segment_axes().1);
        let windows = (windows.iter().zip(&fits.axes))
            .map(|(w, axes)| {
                let stride = w.len().div_ceil(CHILD_TERM_SAMPLES).max(1);
                let rm = (w.first..w.end)
                    .step_by(stride)
                    .map(|i| p.orientation[i].inverse() * d.orientation[i])
                    .collect();
                let sd = axes
                    .distal
                    .map_or(Quat::identity(), |b| AxisFamily::new(&nd, &b).swing());
                (rm, sd)
            })
            .collect();
        Some(ChildTerm { windows, limits })
    }

    /// The joint's limit cost in window `k` with its proximal IMU corrected by
    /// `c` (degrees, as the window cost without its size term).
    fn eval(&self, k: usize, c: &Quat) -> f64 {
        let (rm, sd) = &self.windows[k];
        let ci = c.inverse();
        let rt: Vec<Quat> = rm.iter().map(|m| ci * m * sd).collect();
        WindowCost::new(&rt, &self.limits, 0.0).eval(&Quat::identity())
    }
}

fn axis_families(
    model: &Model,
    todo: &[(usize, JointLimits)],
    hinges: &HashMap<usize, HingeFits>,
    k: usize,
    lambda1: f64,
) -> Option<Families> {
    let own = hinges.get(&k);
    let child = todo
        .iter()
        .map(|(c, _)| *c)
        .find(|c| model.joints[*c].proximal == model.joints[k].distal && hinges.contains_key(c));
    let child_fits = child.and_then(|c| hinges.get(&c));
    let windows = own.or(child_fits)?.axes.len();
    let mut from_child = false;
    let per_window: Vec<Option<AxisFamily>> = (0..windows)
        .map(|w| {
            let mine = own.and_then(|f| {
                let nd = Vector3::from(f.hinge.segment_axes().1);
                f.axes[w].distal.map(|b| AxisFamily::new(&nd, &b))
            });
            mine.or_else(|| {
                let f = child_fits?;
                let np = Vector3::from(f.hinge.segment_axes().0);
                let fam = f.axes[w].proximal.map(|a| AxisFamily::new(&np, &a));
                from_child |= fam.is_some();
                fam
            })
        })
        .collect();
    if per_window.iter().all(Option::is_none) {
        return None;
    }
    let two_axes = |f: &HingeFits| matches!(f.hinge, crate::model::Hinge::Two { .. });
    let two_axis_child = child.filter(|c| from_child && two_axes(&hinges[c]));
    let turn_weight = if own.is_some_and(two_axes) || two_axis_child.is_some() {
        lambda1 * TWO_AXIS_TURN_WEIGHT
    } else {
        lambda1
    };
    Some(Families {
        per_window,
        from_child: from_child.then(|| model.joints[child.expect("found")].name.clone()),
        two_axis_child,
        turn_weight,
    })
}

/// Turns the proximal IMU of hinge joint `k` by its axis alone when no joint
/// above corrects it (and it is not the base): per window the least rotation
/// taking the segment axis onto the estimated one, slerped; gyros turn with it.
fn turn_uncorrected_proximal(
    corrected: &mut Trial,
    trial: &Trial,
    model: &Model,
    todo: &[(usize, JointLimits)],
    k: usize,
    hinges: &mut HashMap<usize, HingeFits>,
    (windows, lambda1): (&[Window], f64),
) {
    let joint = &model.joints[k];
    let Some(fits) = hinges.get_mut(&k) else {
        return;
    };
    let above = todo
        .iter()
        .any(|(j, _)| model.joints[*j].distal == joint.proximal);
    if above || joint.proximal == model.base || fits.axes.iter().all(|a| a.proximal.is_none()) {
        return;
    }
    let np = Vector3::from(fits.hinge.segment_axes().0);
    // A two-axis hinge's own limits decide the turn about its proximal axis
    // (see `ChildTerm`); a one-axis hinge's turn is the distal IMU's to take.
    let term = matches!(fits.hinge, crate::model::Hinge::Two { .. })
        .then(|| ChildTerm::new(trial, model, todo, fits, k, windows))
        .flatten();
    let qs: Vec<Quat> = (fits.axes.iter().enumerate())
        .map(|(w, a)| {
            a.proximal.map_or(Quat::identity(), |a| {
                let family = AxisFamily::new(&np, &a);
                match &term {
                    Some(t) => {
                        let weight = lambda1 * TWO_AXIS_TURN_WEIGHT;
                        let cost = |c: &Quat, phi: f64| t.eval(w, c) + weight * phi.abs();
                        hinge::minimise_about_axis(&cost, &family).c
                    }
                    None => family.swing(),
                }
            })
        })
        .collect();
    let centres: Vec<f64> = windows.iter().map(|w| w.centre_s).collect();
    let series = correction_series(&trial.time_s, &centres, &qs);
    let imu = corrected.imu_mut(&joint.proximal).expect("present");
    for (q, c) in imu.orientation.iter_mut().zip(&series) {
        *q = Quat::new_normalize((*q * c).into_inner());
    }
    if let Some(g) = &mut imu.gyro {
        for (w, c) in g.iter_mut().zip(&series) {
            *w = c.inverse() * *w;
        }
    }
    fits.record.proximal_turned_by_axis = true;
}

/// Solves one joint whose distal IMU has a hinge axis in some windows: there
/// the correction is searched over the turn about the axis only
/// ([`hinge::minimise_about_axis`]); the other windows get the usual
/// three-degree-of-freedom solution.
fn solve_windows_with_axes(
    (time_s, measured): (&[f64], &[Quat]),
    windows: &[Window],
    (limits, lambda1, solver): (&JointLimits, f64, Solver),
    (families, child, turn_weight): (&[Option<AxisFamily>], Option<&ChildTerm>, f64),
    control: &RunControl,
    progress: &(dyn Fn() + Sync),
) -> Result<JointSolution, Cancelled> {
    let free = if families.iter().any(Option::is_none) {
        Some(solve_windows(
            time_s,
            measured,
            windows,
            (limits, lambda1, solver),
            control,
            progress,
        )?)
    } else {
        None
    };
    // A two-axis hinge's turn (lighter size term) is held towards the turn
    // the windows ask for together (see `pooled_turn`); its window costs are
    // built once for both searches. Other joints build each where it is
    // solved (peak memory).
    let prebuilt: Option<Vec<Option<WindowCost>>> = (turn_weight < lambda1).then(|| {
        (windows.par_iter().zip(families))
            .map(|(w, f)| {
                f.as_ref()
                    .map(|_| WindowCost::new(&measured[w.first..w.end], limits, lambda1))
            })
            .collect()
    });
    let held_deg = prebuilt.as_ref().map_or(0.0, |costs| {
        pooled_turn(costs, families, child, (lambda1, turn_weight))
    });
    let solutions: Vec<WindowSolution> = (windows.par_iter().zip(families).enumerate())
        .map(|(k, (w, family))| {
            let Some(family) = family else {
                return Ok(free.as_ref().expect("solved").windows[k].clone());
            };
            if control.cancelled() {
                return Err(Cancelled);
            }
            let built;
            let cost = match &prebuilt {
                Some(costs) => costs[k]
                    .as_ref()
                    .expect("built for every window with an axis"),
                None => {
                    built = WindowCost::new(&measured[w.first..w.end], limits, lambda1);
                    &built
                }
            };
            // The size term counts the turn about the axis only (see `hinge`),
            // from the held turn.
            let about_axis = |c: &Quat, phi: f64| {
                turn_cost(cost, c, (k, child), lambda1)
                    + turn_weight * wrap180(phi - held_deg).abs()
            };
            let s = hinge::minimise_about_axis(&about_axis, family);
            if free.is_none() {
                progress();
            }
            let c = canonical(&s.c);
            Ok(WindowSolution {
                start_s: w.start_s,
                end_s: w.end_s,
                centre_s: w.centre_s,
                samples: w.len(),
                correction: wxyz(&c),
                angle_deg: angle_deg(&c),
                cost: s.cost,
                cost_uncorrected: cost.eval(&Quat::identity()),
                evaluations: s.evaluations,
            })
        })
        .collect::<Result<_, Cancelled>>()?;
    let centres: Vec<f64> = solutions.iter().map(|w| w.centre_s).collect();
    let qs: Vec<Quat> = (solutions.iter())
        .map(|w| quat_from_wxyz(w.correction))
        .collect();
    Ok(JointSolution {
        series: correction_series(time_s, &centres, &qs),
        windows: solutions,
    })
}

/// The turn about a two-axis hinge's axis (degrees) that the windows with an
/// axis ask for together: the sum over them of the window cost (without its
/// size term) and of the child's limits, at one turn for all, plus the size
/// term of that turn once per window. A turn about a hinge axis moves one
/// joint angle alone, so only the windows where that angle nears a limit see
/// it; an IMU that sits still on its segment has the same turn in every
/// window, which the windows that see it give the others (docs/method.md
/// section 18). Each window is then held towards it by the size term.
fn pooled_turn(
    costs: &[Option<WindowCost>],
    families: &[Option<AxisFamily>],
    child: Option<&ChildTerm>,
    (lambda1, turn_weight): (f64, f64),
) -> f64 {
    let with_axis: Vec<(usize, &WindowCost, &AxisFamily)> =
        (costs.iter().zip(families).enumerate())
            .filter_map(|(k, (cost, f))| Some((k, cost.as_ref()?, f.as_ref()?)))
            .collect();
    let total = |phi: f64| -> f64 {
        let parts: Vec<f64> = with_axis
            .par_iter()
            .map(|(k, cost, family)| turn_cost(cost, &family.at(phi), (*k, child), lambda1))
            .collect();
        parts.iter().sum::<f64>() + turn_weight * with_axis.len() as f64 * wrap180(phi).abs()
    };
    hinge::minimise_turn(&total).0
}

/// The cost of window `k`'s correction `c` about a hinge axis, without its
/// size term (degrees): the window cost less `lambda1 * angle(c)`, plus the
/// limits of a two-axis hinge below on the turn about its proximal axis (see
/// `ChildTerm`).
fn turn_cost(
    cost: &WindowCost,
    c: &Quat,
    (k, child): (usize, Option<&ChildTerm>),
    lambda1: f64,
) -> f64 {
    cost.eval(c) - lambda1 * angle_deg(c) + child.map_or(0.0, |t| t.eval(k, c))
}

fn results_has_imu(results: &HashMap<usize, JointResult>, model: &Model, imu: &str) -> bool {
    results.keys().any(|&k| model.joints[k].distal == imu)
}

/// Gyroscope readings of one IMU (rad/s, sensor frame), or none.
type Gyros = Option<Vec<Vector3<f64>>>;

/// What a joint's run gives its distal IMU.
enum Applied {
    /// A fresh per-sample correction `C(t)`, to apply as `G_R_dist * C(t)`,
    /// and what becomes of the gyros.
    Series(Vec<Quat>, GyroUpdate),
    /// Corrected orientations and gyroscope readings to take as they are (a
    /// heading fit, or an earlier run's kept result).
    Kept(Vec<Quat>, Gyros),
}

/// What a per-sample correction `C(t)` does to the distal IMU's gyros.
enum GyroUpdate {
    /// Turned with the sensor frame: `C(t)^-1 w` (the ACM).
    Turn,
    /// Replaced by a baseline's own readings (`None`: dropped), since its
    /// `C(t)` turns with the joint.
    Replace(Gyros),
}

/// Fits the heading model of one joint's distal IMU: the window solutions (each
/// holding the constant C and its window's cost), the IMU's heading record and
/// its corrected orientations `R_up(-h(t)) G_R_dist C`.
fn solve_heading(
    time_s: &[f64],
    lookahead: &Lookahead,
    opts: &HeadingOptions,
    (joint, imu): (&str, &str),
) -> (Vec<WindowSolution>, ImuHeading, Vec<Quat>) {
    let fit = lookahead.fit(opts);
    let problem = &lookahead.own;
    let c = canonical(&fit.c);
    let windows: Vec<WindowSolution> = problem
        .windows
        .iter()
        .enumerate()
        .map(|(k, w)| WindowSolution {
            start_s: w.start_s,
            end_s: w.end_s,
            centre_s: w.centre_s,
            samples: w.len(),
            correction: wxyz(&c),
            angle_deg: angle_deg(&c),
            cost: fit.window_costs[k],
            cost_uncorrected: fit.window_costs_uncorrected[k],
            evaluations: fit.window_evaluations[k],
        })
        .collect();
    let centres: Vec<f64> = problem.windows.iter().map(|w| w.centre_s).collect();
    let heading = ImuHeading {
        imu: imu.to_string(),
        joint: joint.to_string(),
        vertical: problem.vertical,
        correction: wxyz(&c),
        correction_angle_deg: angle_deg(&c),
        windows: (0..centres.len())
            .map(|k| HeadingWindow {
                centre_s: centres[k],
                heading_deg: fit.headings_deg[k],
                rate_deg_s: (k > 0).then(|| {
                    (fit.headings_deg[k] - fit.headings_deg[k - 1]) / (centres[k] - centres[k - 1])
                }),
            })
            .collect(),
        rounds: fit.rounds,
        c_evaluations: fit.c_evaluations,
    };
    let series = heading_series(time_s, &centres, &fit.headings_deg);
    let orientation = apply(problem.child, &c, &series, problem.vertical);
    (windows, heading, orientation)
}

/// Solves one joint with a baseline method (Rivest, Mueller) instead of the ACM,
/// from the sample times, the measured joint rotations and the joint's gyros.
fn solve_baseline(
    method: baselines::Method,
    (time_s, measured, gyros): (&[f64], &[Quat], Option<baselines::JointGyros>),
    windows: &[Window],
    control: &RunControl,
    progress: &(dyn Fn() + Sync),
) -> Result<(JointSolution, Option<baselines::BaselineRecord>, Gyros), Cancelled> {
    if control.cancelled() {
        return Err(Cancelled);
    }
    let b = baselines::solve_joint(method, time_s, measured, gyros, windows);
    windows.iter().for_each(|_| progress());
    let sol = JointSolution {
        windows: b.windows,
        series: b.series,
    };
    Ok((sol, Some(b.record), b.gyro))
}

/// Solves one joint: the measured joint rotations `Rm_i` (parent' to child), per sample.
///
/// `windows` come from [`layout`] or [`whole_trial`]. Returns the per-window
/// solutions and the slerped per-sample correction.
pub fn correct_joint(
    time_s: &[f64],
    measured: &[Quat],
    windows: &[Window],
    limits: &JointLimits,
    lambda1: f64,
) -> JointSolution {
    correct_joint_with(
        time_s,
        measured,
        windows,
        limits,
        lambda1,
        Solver::default(),
    )
}

/// As [`correct_joint`], with the given minimiser.
pub fn correct_joint_with(
    time_s: &[f64],
    measured: &[Quat],
    windows: &[Window],
    limits: &JointLimits,
    lambda1: f64,
    solver: Solver,
) -> JointSolution {
    solve_windows(
        time_s,
        measured,
        windows,
        (limits, lambda1, solver),
        &RunControl::default(),
        &|| {},
    )
    .expect("no cancel flag")
}

/// Samples of the coarse copy of a window's cost that [`screen_basins`]
/// scores its probes on (about; every `len / SCREEN_SAMPLES`-th sample).
const SCREEN_SAMPLES: usize = 100;

/// Minimises one window's cost from `starts` with `solver`; the gradient
/// solver then screens the neighbourhood of its end for a lower basin
/// ([`screen_basins`]).
pub fn solve_window(cost: &WindowCost, starts: &[Quat], solver: Solver) -> Solution {
    solve_window_screened(cost, starts, solver, true)
}

/// [`solve_window`], the gradient solver's screen only when `screen` (the
/// chain screens its first pass's descents, not its second's).
pub fn solve_window_screened(
    cost: &WindowCost,
    starts: &[Quat],
    solver: Solver,
    screen: bool,
) -> Solution {
    match solver {
        Solver::NelderMead => minimise(&|c| cost.eval(c), starts, &MinimiseOptions::default()),
        Solver::Gradient => {
            let data = |c: &Quat| cost.data_grad(c);
            let shaped = ShapedCost {
                data: &data,
                cone: cost.lambda1(),
            };
            let opts = ShapedOptions::default();
            let found = minimise_shaped(&shaped, starts, &opts);
            if !screen {
                return found;
            }
            let stride = cost.len() / SCREEN_SAMPLES;
            let thinned = (stride > 1).then(|| cost.coarse(stride));
            let coarse = thinned.as_ref().unwrap_or(cost);
            let screen = (&opts, &ScreenOptions::default());
            screen_basins(&shaped, &|c| coarse.eval(c), found, screen)
        }
    }
}

fn solve_windows(
    time_s: &[f64],
    measured: &[Quat],
    windows: &[Window],
    (limits, lambda1, solver): (&JointLimits, f64, Solver),
    control: &RunControl,
    progress: &(dyn Fn() + Sync),
) -> Result<JointSolution, Cancelled> {
    // A window's cost holds a copy of its samples laid out for the loop: it
    // is built where the window is solved and dropped after, so only the
    // windows being solved at once hold one (peak memory).
    let cost_of = |k: usize| {
        let w = &windows[k];
        WindowCost::new(&measured[w.first..w.end], limits, lambda1)
    };
    // Pass 1: every window from identity, in parallel. Windows solved on the
    // same samples (thin windows in a long gap all borrow one span) have one
    // solution, found once.
    let mut span_index = std::collections::HashMap::new();
    let mut distinct: Vec<usize> = Vec::new();
    let slot: Vec<usize> = windows
        .iter()
        .enumerate()
        .map(|(k, w)| {
            *span_index.entry((w.first, w.end)).or_insert_with(|| {
                distinct.push(k);
                distinct.len() - 1
            })
        })
        .collect();
    let solved: Vec<Solution> = distinct
        .par_iter()
        .map(|&k| {
            if control.cancelled() {
                return Err(Cancelled);
            }
            let s = solve_window(&cost_of(k), &[Quat::identity()], solver);
            progress();
            Ok(s)
        })
        .collect::<Result<_, Cancelled>>()?;
    (distinct.len()..windows.len()).for_each(|_| progress());
    let first: Vec<Solution> = slot.iter().map(|&u| solved[u]).collect();
    // Pass 2: where a neighbour's solution is cheaper here, descend from it.
    // Each window's solution and its cost uncorrected.
    let second: Vec<(Solution, f64)> = (0..windows.len())
        .into_par_iter()
        .map(|k| {
            let cost = cost_of(k);
            let uncorrected = cost.eval(&Quat::identity());
            let neighbours = [k.wrapping_sub(1), k + 1]
                .into_iter()
                .filter(|&n| n < windows.len())
                .map(|n| first[n].c)
                .filter(|c| cost.eval(c) < first[k].cost - 1e-12)
                .collect::<Vec<_>>();
            if neighbours.is_empty() {
                return (first[k], uncorrected);
            }
            // The first pass's solution was screened; a descent from a
            // neighbour's replaces it only where it ends lower.
            let s = solve_window_screened(&cost, &neighbours, solver, false);
            let best = if s.cost < first[k].cost {
                Solution {
                    evaluations: s.evaluations + first[k].evaluations,
                    ..s
                }
            } else {
                first[k]
            };
            (best, uncorrected)
        })
        .collect();
    let solutions: Vec<WindowSolution> = windows
        .iter()
        .zip(&second)
        .map(|(w, (s, uncorrected))| {
            let c = canonical(&s.c);
            WindowSolution {
                start_s: w.start_s,
                end_s: w.end_s,
                centre_s: w.centre_s,
                samples: w.len(),
                correction: wxyz(&c),
                angle_deg: angle_deg(&c),
                cost: s.cost,
                cost_uncorrected: *uncorrected,
                evaluations: s.evaluations,
            }
        })
        .collect();
    let centres: Vec<f64> = solutions.iter().map(|w| w.centre_s).collect();
    let qs: Vec<Quat> = solutions
        .iter()
        .map(|w| quat_from_wxyz(w.correction))
        .collect();
    Ok(JointSolution {
        series: correction_series(time_s, &centres, &qs),
        windows: solutions,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulate::{preset, simulate};

    fn fixture() -> (Trial, Model, LimitTable) {
        let mut cfg = preset("full_body_clean").unwrap();
        cfg.duration_s = 70.0;
        (
            simulate(&cfg).unwrap().trial,
            Model::infant13(),
            LimitTable::default_table(),
        )
    }

    fn run_with(trial: &Trial, model: &Model, table: &LimitTable, threads: usize) -> Correction {
        run_variant(trial, model, table, threads, Variant::DriftCentroid)
    }

    fn run_variant(
        trial: &Trial,
        model: &Model,
        table: &LimitTable,
        threads: usize,
        variant: Variant,
    ) -> Correction {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| {
                correct_chain(
                    trial,
                    model,
                    table,
                    &Settings::default(),
                    variant,
                    &RunControl::default(),
                )
                .unwrap()
            })
    }

    #[test]
    fn children_are_measured_against_the_corrected_parent() {
        let (trial, model, table) = fixture();
        let run = run_with(&trial, &model, &table, 2);
        let order: Vec<&str> = run.joints.iter().map(|j| j.joint.as_str()).collect();
        let model_order: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
        assert_eq!(order, model_order);
        let knee = model.joint("l_knee").unwrap();
        let thigh = &run.corrected.imu("l_thigh").unwrap().orientation;
        let calf = &trial.imu("l_calf").unwrap().orientation;
        let measured: Vec<Quat> = thigh
            .iter()
            .zip(calf)
            .map(|(p, c)| p.inverse() * c)
            .collect();
        let lim = table.cost_limits(knee, true).unwrap();
        let windows = layout(&trial.time_s, 60.0, 30.0);
        let alone = correct_joint(&trial.time_s, &measured, &windows, &lim, 0.05);
        assert_eq!(alone.windows, run.joint("l_knee").unwrap().windows);
        assert!(run.joint("l_knee").unwrap().parent_corrected);
        assert!(!run.joint("l_hip").unwrap().parent_corrected);
        // G_R_dist' = G_R_dist * C(t)
        let cal = &run.corrected.imu("l_calf").unwrap().orientation;
        for i in [0, 1234, trial.len() - 1] {
            let expect = calf[i] * alone.series[i];
            assert!(crate::rotation::angle_between_deg(&cal[i], &expect) < 1e-9);
        }
        // The base is never corrected.
        assert!(run.corrected.imu("base") == trial.imu("base"));
    }

    #[test]
    fn output_does_not_depend_on_thread_count() {
        let (trial, model, table) = fixture();
        let one = run_with(&trial, &model, &table, 1);
        let two = run_with(&trial, &model, &table, 2);
        let three = run_with(&trial, &model, &table, 3);
        assert!(one == two, "1 vs 2 threads");
        assert!(one == three, "1 vs 3 threads");
    }

    #[test]
    fn heading_output_does_not_depend_on_thread_count() {
        let (trial, model, table) = fixture();
        let one = run_variant(&trial, &model, &table, 1, Variant::DriftHeading);
        let three = run_variant(&trial, &model, &table, 3, Variant::DriftHeading);
        assert!(!one.headings.is_empty());
        assert!(one == three, "1 vs 3 threads");
    }

    /// `previous` with the left knee re-corrected against `table`.
    fn recorrect_l_knee(
        trial: &Trial,
        model: &Model,
        table: &LimitTable,
        previous: &Correction,
    ) -> Correction {
        let settings = Settings::default();
        recorrect_chain(
            trial,
            model,
            table,
            &settings,
            previous,
            &["l_knee"],
            &RunControl::default(),
        )
        .unwrap()
    }

    /// The knee's table rows narrowed to a flexion range of 20-60 deg.
    fn narrow_l_knee(table: &mut LimitTable) {
        for axis in [0, 2] {
            let mut r = table.row("knee", "knee", axis).unwrap().clone();
            r.joint = "l_knee".into();
            table.rows.push(r);
        }
        table.rows.push(crate::limits::LimitRow {
            joint: "l_knee".into(),
            axis: 1,
            movement: "flexion/extension".into(),
            lower_deg: 20.0,
            upper_deg: 60.0,
            centroid_deg: None,
            lambda2: 0.0,
        });
    }

    #[test]
    fn recorrect_with_a_heading_variant_redoes_the_parent_joint_too() {
        let (trial, model, mut table) = fixture();
        let full = run_variant(&trial, &model, &table, 2, Variant::DriftHeading);
        narrow_l_knee(&mut table);
        let edited = recorrect_l_knee(&trial, &model, &table, &full);
        // The thigh's fit looks ahead at the knee: the hip changes with it.
        for j in &model.joints {
            let changed = edited.joint(&j.name) != full.joint(&j.name);
            let redone = ["l_hip", "l_knee", "l_ankle"].contains(&j.name.as_str());
            assert!(redone || !changed, "{}", j.name);
            if j.name == "l_hip" || j.name == "l_knee" {
                assert!(changed, "{}", j.name);
            }
        }
        let again = run_variant(&trial, &model, &table, 2, Variant::DriftHeading);
        assert!(edited == again, "recorrect vs full run");
    }

    #[test]
    fn recorrect_redoes_a_joint_and_its_descendants_only() {
        let (trial, model, mut table) = fixture();
        let full = run_with(&trial, &model, &table, 2);
        let same = recorrect_l_knee(&trial, &model, &table, &full);
        assert!(same == full, "recorrect without a change");
        // Narrow the knee's flexion range: knee and ankle change, nothing else.
        narrow_l_knee(&mut table);
        let edited = recorrect_l_knee(&trial, &model, &table, &full);
        for j in &model.joints {
            let changed = edited.joint(&j.name) != full.joint(&j.name);
            assert_eq!(
                changed,
                ["l_knee", "l_ankle"].contains(&j.name.as_str()),
                "{}",
                j.name
            );
        }
        assert!(
            edited == run_with(&trial, &model, &table, 2),
            "recorrect vs full run"
        );
    }

    #[test]
    fn missing_imus_skip_their_joints_and_cancel_stops() {
        let (mut trial, model, table) = fixture();
        trial
            .imus
            .retain(|s| s.name != "head" && s.name != "l_thigh");
        let run = run_with(&trial, &model, &table, 2);
        let skipped: Vec<&str> = run.skipped.iter().map(|s| s.joint.as_str()).collect();
        assert_eq!(skipped, ["neck", "l_hip", "l_knee"]);
        assert!(run.skipped[0].reason.contains("'head'"));
        let cancel = std::sync::atomic::AtomicBool::new(true);
        let control = RunControl {
            cancel: Some(&cancel),
            progress: None,
        };
        let r = correct_chain(
            &trial,
            &model,
            &table,
            &Settings::default(),
            Variant::Drift,
            &control,
        );
        assert!(matches!(r, Err(Cancelled)));
    }
}
