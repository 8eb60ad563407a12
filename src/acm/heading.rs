//! The heading-drift model of one IMU: a constant sensor-frame correction C for
//! the whole trial plus one heading correction `h_k` (degrees about the global
//! up axis) per window, interpolated linearly between window centres:
//! `G_R_dist'(t) = R_up(-h(t)) * G_R_dist(t) * C`.
//!
//! Magnetic disturbance and gyroscope bias turn a sensor's reported orientation
//! about the global vertical (gravity keeps inclination honest), while the
//! strap's misalignment is fixed in the sensor frame; this is that physics, with
//! 3 + K degrees of freedom per IMU where the `drift` variant has 3K.
//!
//! The objective is the sum of the window costs of docs/method.md section 5 with the
//! heading term, each window at its own constant heading:
//! `J(C, h) = sum_k e_k(C, h_k)`,
//! `e_k = (1/n_k) sum_{i in k} (Ex + Ey + Ez + lambda2 RMSq)(P_i'^T R_up(-h_k) D_i C)
//!        + lambda1 angle(C) + lambda1 |h_k|`.
//!
//! Solver: block coordinate descent, alternating C over all windows (3-D,
//! `CStep`: the shape-aware quasi-Newton minimiser by default, Nelder-Mead
//! with [`Solver::NelderMead`]) with each `h_k` on its window (1-D on
//! [`HeadingCost`]: a bracketing search on its derivative by default,
//! `slope_search`, or the pattern search on values, `line_search`);
//! neither step can raise J. Two things make it better than
//! plain alternation from zero: the first heading step scans the whole circle
//! (a drift of tens of degrees is not found by a local search from the biased
//! first C), and the early rounds run on every `coarse_stride`-th sample before
//! the last rounds polish on every `fine_stride`-th (20 and 2 by default).
//! `tests` shows the result costs within 1e-4 (relative) of plain alternation
//! run to convergence on every sample, at a fraction of the work.
//!
//! This is the fit of an IMU on its own joint. The engine fits every IMU that
//! has joints below it with [`super::lookahead`] instead, which adds those
//! joints to the objective and falls back to this fit for a leaf IMU.

use super::circle_grid::{grid_minimum, refined_grid_minimum};
use super::cost::WindowCost;
use super::heading_cost::HeadingCost;
use super::minimise::{
    minimise, minimise_shaped, MinimiseOptions, ShapedCost, ShapedOptions, Solution, Solver,
};
use super::parent_cost::ParentCost;
use super::window::Window;
use super::ImuHeading;
use crate::limits::JointLimits;
use crate::rotation::Quat;
use crate::trial::Trial;
use crate::vertical::Vertical;
use nalgebra::Vector3;
use rayon::prelude::*;

/// Tuning of the heading solver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HeadingOptions {
    /// Sample stride of the coarse phase (1 = no coarse phase).
    pub coarse_stride: usize,
    /// Most rounds (each one C step and one heading step) of the coarse phase.
    pub coarse_rounds: usize,
    /// Most rounds of the fine phase that follows.
    pub fine_rounds: usize,
    /// Sample stride of the fine phase (1 = every sample). The reported
    /// window costs are always over every sample.
    pub fine_stride: usize,
    /// Scan the whole circle for each heading in the first round.
    pub global_scan: bool,
    /// Grid step of that scan, degrees.
    pub scan_step_deg: f64,
    /// A coarse round gaining less than this ends the coarse phase.
    pub coarse_tol: f64,
    /// A full-resolution round gaining less than this ends the search.
    pub tol: f64,
    /// Start C from the first window alone (at zero heading).
    pub first_window_start: bool,
    /// The minimiser of the C steps; with [`Solver::Gradient`] the heading
    /// steps search on the derivative (`slope_search`), with
    /// [`Solver::NelderMead`] on values (`line_search`, the reference).
    pub solver: Solver,
}

impl Default for HeadingOptions {
    fn default() -> Self {
        HeadingOptions {
            coarse_stride: 20,
            coarse_rounds: 16,
            fine_rounds: 1,
            fine_stride: 2,
            global_scan: true,
            scan_step_deg: 4.0,
            coarse_tol: 1e-5,
            tol: 1e-7,
            first_window_start: true,
            solver: Solver::default(),
        }
    }
}

impl HeadingOptions {
    /// Runs a descent through the coarse and the fine phase: `round(stride,
    /// scan)` does one round on every `stride`-th sample (`scan`: scan the
    /// whole circle for each heading; the very first round only, when
    /// `global_scan`) and returns the objective; a phase ends when a round
    /// gains less than its tolerance or its rounds run out. Returns the last
    /// round's objective.
    pub(super) fn run_phases(&self, mut round: impl FnMut(usize, bool) -> f64) -> f64 {
        let phases = [
            (self.coarse_stride, self.coarse_rounds, self.coarse_tol),
            (self.fine_stride, self.fine_rounds, self.tol),
        ];
        let mut first = true;
        let mut j = f64::INFINITY;
        for (stride, max_rounds, tol) in phases {
            let mut last = f64::INFINITY;
            for _ in 0..max_rounds {
                j = round(stride, self.global_scan && first);
                first = false;
                if last - j < tol {
                    break;
                }
                last = j;
            }
        }
        j
    }

    /// The default options with `solver`.
    pub fn for_solver(solver: Solver) -> Self {
        HeadingOptions {
            solver,
            ..HeadingOptions::default()
        }
    }

    /// Plain alternation from zero heading at full resolution, to convergence:
    /// the reference the default solver is tested against.
    pub fn plain_alternation() -> Self {
        HeadingOptions {
            coarse_stride: 1,
            coarse_rounds: 0,
            fine_rounds: 60,
            fine_stride: 1,
            global_scan: false,
            scan_step_deg: 4.0,
            coarse_tol: 1e-9,
            tol: 1e-9,
            first_window_start: false,
            solver: Solver::default(),
        }
    }
}

/// The fitted heading model of one IMU.
#[derive(Debug, Clone, PartialEq)]
pub struct HeadingFit {
    /// The constant correction C (distal sensor frame).
    pub c: Quat,
    /// Heading correction per window, degrees about the up axis.
    pub headings_deg: Vec<f64>,
    /// `e_k(C, h_k)` per window.
    pub window_costs: Vec<f64>,
    /// `e_k(identity, 0)` per window.
    pub window_costs_uncorrected: Vec<f64>,
    /// Heading-step cost evaluations per window.
    pub window_evaluations: Vec<usize>,
    /// C-step cost evaluations (each over every window).
    pub c_evaluations: usize,
    /// Alternation rounds run.
    pub rounds: usize,
    /// Samples evaluated in all, over every step (the solver's work).
    pub sample_evaluations: usize,
    /// The objective at the solution as the last round measured it (on every
    /// `fine_stride`-th sample): `J(C, h)` plus, with the lookahead, the child
    /// joints' weighted terms at their auxiliary fit (degrees; what the
    /// solvers are compared on).
    pub objective: f64,
}

impl HeadingFit {
    /// `J(C, h)`, the sum of the window costs.
    pub fn total_cost(&self) -> f64 {
        self.window_costs.iter().sum()
    }
}

/// The inputs of one IMU's fit.
#[derive(Clone, Copy)]
pub struct HeadingProblem<'a> {
    /// Corrected parent orientations `G_R_prox'`, per sample.
    pub parent: &'a [Quat],
    /// Raw distal orientations `G_R_dist`, per sample.
    pub child: &'a [Quat],
    pub windows: &'a [Window],
    pub limits: &'a JointLimits,
    pub lambda1: f64,
    pub vertical: Vertical,
}

impl HeadingProblem<'_> {
    /// The C-step costs: per window `Rm_i = P_i'^T R_up(-h_k) D_i`.
    pub(super) fn c_costs(&self, headings: &[f64], stride: usize) -> Vec<WindowCost> {
        self.windows
            .par_iter()
            .zip(headings)
            .map(|(w, &h)| {
                let r = self.vertical.heading_rotation(-h);
                let measured: Vec<Quat> = self.parent[w.first..w.end]
                    .iter()
                    .zip(&self.child[w.first..w.end])
                    .step_by(stride.max(1))
                    .map(|(p, d)| p.inverse() * r * d)
                    .collect();
                WindowCost::new(&measured, self.limits, self.lambda1)
            })
            .collect()
    }

    pub(super) fn heading_cost(&self, w: &Window, c: &Quat, stride: usize) -> HeadingCost {
        HeadingCost::new(
            &self.parent[w.first..w.end],
            &self.child[w.first..w.end],
            c,
            self.vertical.up(),
            self.limits,
            self.lambda1,
            stride,
        )
    }

    /// `e_k(C, h_k)` per window at full resolution.
    pub fn window_costs(&self, c: &Quat, headings: &[f64]) -> Vec<f64> {
        self.windows
            .par_iter()
            .zip(headings)
            .map(|(w, &h)| self.heading_cost(w, c, 1).eval(h))
            .collect()
    }

    /// Fits C and the per-window headings.
    pub fn fit(&self, opts: &HeadingOptions) -> HeadingFit {
        let n = self.windows.len();
        let mut state = Alternation {
            c: Quat::identity(),
            h: vec![0.0; n],
            window_evaluations: vec![0; n],
            c_evaluations: 0,
            rounds: 0,
            sample_evaluations: 0,
            first_window_start: opts.first_window_start,
        };
        let objective = opts.run_phases(|stride, scan| state.round(self, stride, scan, opts));
        let Alternation {
            c,
            h,
            window_evaluations,
            c_evaluations,
            rounds,
            sample_evaluations,
            ..
        } = state;
        let window_costs = self.window_costs(&c, &h);
        let window_costs_uncorrected = self.window_costs(&Quat::identity(), &vec![0.0; n]);
        HeadingFit {
            c,
            headings_deg: h,
            objective,
            window_costs,
            window_costs_uncorrected,
            window_evaluations,
            c_evaluations,
            rounds,
            sample_evaluations,
        }
    }
}

/// First simplex size of the C steps after the first round, radians (~1 deg).
const WARM_STEP_RAD: f64 = 0.02;

/// Simplex size that ends a C step of the coarse phase, radians (~0.001 deg).
const COARSE_TOL_RAD: f64 = 2e-5;

/// The Nelder-Mead options of a C step in round `round` (from 1) on every
/// `stride`-th sample.
pub(super) fn c_step_options(round: usize, stride: usize) -> MinimiseOptions {
    let mut nm = MinimiseOptions::default();
    if round > 1 {
        // Warm start: C moves little between rounds, and the next round
        // restarts from here anyway.
        nm.initial_step_rad = WARM_STEP_RAD;
        nm.max_restarts = 1;
    }
    if stride > 1 {
        // The coarse phase only brings the solution near the optimum.
        nm.tol_x_rad = COARSE_TOL_RAD;
        nm.tol_f = 1e-8;
    }
    nm
}

/// The quasi-Newton options of a C step in round `round` (from 1) on every
/// `stride`-th sample: as [`c_step_options`], a warm first step after the
/// first round and a coarse tolerance in the coarse phase.
fn c_step_shaped_options(round: usize, stride: usize) -> ShapedOptions {
    let mut o = ShapedOptions::default();
    if round > 1 {
        o.initial_step_rad = WARM_STEP_RAD;
    }
    if stride > 1 {
        o.tol_x_rad = COARSE_TOL_RAD;
        o.tol_f_rel = 1e-9;
    }
    o
}

/// The objective of a C step (degrees): the sum of window costs `own`, each
/// with its `lambda1 * angle(C)`, plus `child_weight` times the sum of the
/// child joints' costs as functions of C ([`ParentCost`], no penalty).
pub(super) struct CStep<'a> {
    pub own: &'a [WindowCost],
    pub children: &'a [ParentCost],
    pub child_weight: f64,
}

impl CStep<'_> {
    /// The objective at `q`.
    fn value(&self, q: &Quat) -> f64 {
        self.own.iter().map(|k| k.eval(q)).sum::<f64>()
            + self.child_weight * self.children.iter().map(|k| k.eval(q)).sum::<f64>()
    }

    /// The objective without its `angle(C)` terms, and that part's gradient
    /// in the right tangent of `q` (degrees per radian). The windows are
    /// evaluated in parallel and summed in order (the same bits for any
    /// thread count).
    fn data_grad(&self, q: &Quat) -> (f64, Vector3<f64>) {
        let own: Vec<(f64, Vector3<f64>)> = self.own.par_iter().map(|k| k.data_grad(q)).collect();
        let children: Vec<(f64, Vector3<f64>)> =
            self.children.par_iter().map(|k| k.eval_grad(q)).collect();
        let (mut f, mut g) = (0.0, Vector3::zeros());
        for (fk, gk) in own {
            f += fk;
            g += gk;
        }
        for (fk, gk) in children {
            f += self.child_weight * fk;
            g += gk * self.child_weight;
        }
        (f, g)
    }

    /// Samples in one evaluation of the objective.
    pub(super) fn samples(&self) -> usize {
        self.own.iter().map(WindowCost::len).sum::<usize>()
            + self.children.iter().map(ParentCost::len).sum::<usize>()
    }

    /// Minimises the objective from `start` with `solver`, tuned for round
    /// `round` (from 1) on every `stride`-th sample.
    pub(super) fn solve(
        &self,
        start: &Quat,
        round: usize,
        stride: usize,
        solver: Solver,
    ) -> Solution {
        match solver {
            Solver::NelderMead => minimise(
                &|q| self.value(q),
                &[*start],
                &c_step_options(round, stride),
            ),
            Solver::Gradient => {
                let data = |q: &Quat| self.data_grad(q);
                let lambda1 = self.own.first().map_or(0.0, WindowCost::lambda1);
                let shaped = ShapedCost {
                    data: &data,
                    cone: lambda1 * self.own.len() as f64,
                };
                minimise_shaped(&shaped, &[*start], &c_step_shaped_options(round, stride))
            }
        }
    }
}

/// Minimises a window's 1-D heading cost from `starts` (the current value
/// first) with the search of `solver`: `value` gives the cost, `slope` the
/// cost and its derivative (per degree). Returns the heading and the
/// evaluations spent.
pub(super) fn heading_search(
    value: &dyn Fn(f64) -> f64,
    slope: &dyn Fn(f64) -> (f64, f64),
    starts: &[f64],
    (scan, scan_step): (bool, f64),
    solver: Solver,
) -> (f64, usize) {
    match solver {
        Solver::NelderMead => line_search(value, starts, scan, scan_step),
        Solver::Gradient => slope_search(value, slope, starts, scan, scan_step),
    }
}

/// The state of the alternation.
struct Alternation {
    c: Quat,
    h: Vec<f64>,
    window_evaluations: Vec<usize>,
    c_evaluations: usize,
    rounds: usize,
    sample_evaluations: usize,
    first_window_start: bool,
}

impl Alternation {
    /// One C step then one heading step on every `stride`-th sample; returns J
    /// there. Neither step raises J.
    fn round(
        &mut self,
        p: &HeadingProblem,
        stride: usize,
        scan: bool,
        opts: &HeadingOptions,
    ) -> f64 {
        self.rounds += 1;
        let mut costs = p.c_costs(&self.h, stride);
        if self.rounds == 1 && self.first_window_start {
            // A sensor's heading is freshest at the start of a recording: take C
            // from the first window alone, then every window's heading from it.
            costs.truncate(1);
        }
        let step = CStep {
            own: &costs,
            children: &[],
            child_weight: 0.0,
        };
        let s = step.solve(&self.c, self.rounds, stride, opts.solver);
        self.c_evaluations += s.evaluations;
        self.sample_evaluations += s.evaluations * step.samples();
        self.c = s.c;
        let (c, h) = (&self.c, &self.h);
        let steps: Vec<(f64, usize, usize, f64)> = (0..h.len())
            .into_par_iter()
            .map(|k| {
                let cost = p.heading_cost(&p.windows[k], c, stride);
                let mut starts = vec![h[k]];
                starts.extend([k.wrapping_sub(1), k + 1].iter().filter_map(|&j| h.get(j)));
                let value = |x: f64| cost.eval(x);
                let slope = |x: f64| cost.eval_slope(x);
                let scan = (scan, opts.scan_step_deg);
                let (hk, e) = heading_search(&value, &slope, &starts, scan, opts.solver);
                (hk, e, e * cost.len(), cost.eval(hk))
            })
            .collect();
        let mut costs = Vec::with_capacity(steps.len());
        for (k, (hk, e, work, cost)) in steps.into_iter().enumerate() {
            self.h[k] = hk;
            self.window_evaluations[k] += e;
            self.sample_evaluations += work;
            costs.push(cost);
        }
        // J, from the window costs the heading step built.
        costs.iter().sum()
    }
}

/// Minimises a 1-D cost of a heading (degrees): optionally a grid over the whole
/// circle first, then a pattern search (step halved until 1e-6 deg) from the
/// cheapest of `starts` and the grid's two best local minima. Never returns a
/// point costlier than `starts[0]`. Returns the heading and the evaluations spent.
pub(super) fn line_search(
    f: &dyn Fn(f64) -> f64,
    starts: &[f64],
    scan: bool,
    scan_step: f64,
) -> (f64, usize) {
    let mut evals = 0;
    let mut eval = |x: f64| {
        evals += 1;
        f(x)
    };
    let (mut x, mut fx) = best_start(&mut eval, starts, scan.then_some(Scan::Full(scan_step)));
    let mut step = first_step(scan, scan_step);
    while step > SEARCH_TOL_DEG {
        let up = eval(x + step);
        if up < fx {
            (x, fx) = (x + step, up);
            step *= 2.0;
            continue;
        }
        let down = eval(x - step);
        if down < fx {
            (x, fx) = (x - step, down);
            step *= 2.0;
            continue;
        }
        step *= 0.5;
    }
    (x, evals)
}

/// As `line_search`, descending on the derivative: `value` gives the cost
/// (the grid's), `slope` the cost and its derivative (per degree), from the
/// same start as `line_search` ([`descend_on_slope`]). Never returns a
/// point costlier than `starts[0]`.
pub(super) fn slope_search(
    value: &dyn Fn(f64) -> f64,
    slope: &dyn Fn(f64) -> (f64, f64),
    starts: &[f64],
    scan: bool,
    scan_step: f64,
) -> (f64, usize) {
    let mut evals = 0;
    let mut eval = |x: f64| {
        evals += 1;
        value(x)
    };
    let (x0, _) = best_start(&mut eval, starts, scan.then_some(Scan::Refined(scan_step)));
    let (x, more) = descend_on_slope(slope, x0, first_step(scan, scan_step));
    (x, evals + more)
}

/// Where a 1-D heading search ends: a step or bracket this narrow, degrees.
const SEARCH_TOL_DEG: f64 = 1e-6;

/// The first step of a 1-D heading search from its start, degrees.
fn first_step(scan: bool, scan_step: f64) -> f64 {
    if scan {
        scan_step / 2.0
    } else {
        0.5
    }
}

/// How a 1-D heading search scans the whole circle for its start.
#[derive(Debug, Clone, Copy)]
enum Scan {
    /// Every point of a grid this many degrees apart.
    Full(f64),
    /// The same grid's lowest point looked for coarse to fine
    /// ([`super::circle_grid::refined_grid_minimum`]).
    Refined(f64),
}

/// The cheapest of `starts` and, with `scan`, of the lowest point of a grid
/// over the whole circle; the first on ties (a start before the grid, the
/// grid's first lowest point). Returns it and its cost.
fn best_start(eval: &mut impl FnMut(f64) -> f64, starts: &[f64], scan: Option<Scan>) -> (f64, f64) {
    let mut cands: Vec<(f64, f64)> = starts.iter().map(|&x| (x, eval(x))).collect();
    match scan {
        Some(Scan::Full(step)) => cands.extend(grid_minimum(eval, step)),
        Some(Scan::Refined(step)) => cands.extend(refined_grid_minimum(eval, step)),
        None => {}
    }
    let (mut x, mut fx) = cands[0];
    for &(c, fc) in &cands[1..] {
        if fc < fx {
            (x, fx) = (c, fc);
        }
    }
    (x, fx)
}

/// Most evaluations of one [`descend_on_slope`].
const MAX_SLOPE_EVALS: usize = 200;

/// A point of a 1-D descent: position (degrees), value, and derivative along
/// the descent's direction.
#[derive(Clone, Copy)]
struct Probe {
    x: f64,
    f: f64,
    s: f64,
}

/// Descends a 1-D cost from `x0`, `f` giving its value and derivative (per
/// degree; one side's at a kink): steps downhill doubling from `step` until
/// the derivative turns or the value rises, which brackets a local minimum,
/// then narrows the bracket to [`SEARCH_TOL_DEG`] with secant steps on the
/// derivative, a bisection whenever one fails to halve it, and a probe just
/// past the low end when only the far end moves (a minimum on a kink, such
/// as `h = 0` of `lambda1 |h|`). Assumes the cost continuous. Returns the
/// lowest point evaluated (never costlier than `x0`) and the evaluations.
fn descend_on_slope(f: &dyn Fn(f64) -> (f64, f64), x0: f64, step: f64) -> (f64, usize) {
    let (f0, d0) = f(x0);
    let mut evals = 1;
    if d0 == 0.0 || !d0.is_finite() {
        return (x0, evals);
    }
    let dir = -d0.signum();
    let mut best = (x0, f0);
    let mut probe = |x: f64, evals: &mut usize| {
        *evals += 1;
        let (fx, dx) = f(x);
        if fx < best.1 {
            best = (x, fx);
        }
        Probe {
            x,
            f: fx,
            s: dx * dir,
        }
    };
    // `lo`: the downhill end (slope along `dir` below zero); `hi`: beyond the minimum.
    let mut lo = Probe {
        x: x0,
        f: f0,
        s: d0 * dir,
    };
    let mut t = step;
    let mut hi = loop {
        let p = probe(lo.x + dir * t, &mut evals);
        if p.f > lo.f || p.s >= 0.0 || !p.f.is_finite() {
            break p;
        }
        if evals >= MAX_SLOPE_EVALS {
            return (best.0, evals);
        }
        lo = p;
        t *= 2.0;
    };
    let (mut secant, mut far_moves) = (true, 0);
    while (hi.x - lo.x).abs() > SEARCH_TOL_DEG && evals < MAX_SLOPE_EVALS {
        let width = hi.x - lo.x;
        let x = if far_moves >= 2 {
            lo.x + 0.5 * SEARCH_TOL_DEG * dir
        } else if secant && hi.s >= 0.0 && hi.f.is_finite() {
            lo.x + width * (lo.s / (lo.s - hi.s)).clamp(0.05, 0.95)
        } else {
            lo.x + 0.5 * width
        };
        let p = probe(x, &mut evals);
        if p.f > lo.f || p.s >= 0.0 {
            hi = p;
            far_moves += 1;
        } else {
            lo = p;
            far_moves = 0;
        }
        secant = (hi.x - lo.x).abs() <= 0.5 * width.abs();
    }
    (best.0, evals)
}

/// The heading at each sample: `h_1` before the first centre, `h_N` from the last
/// centre on, linear between neighbouring centres (the slerp of docs/method.md
/// section 7 for rotations about one axis). Times relative to the first sample.
pub fn heading_series(time_s: &[f64], centres_s: &[f64], headings_deg: &[f64]) -> Vec<f64> {
    assert_eq!(centres_s.len(), headings_deg.len());
    let Some(&t0) = time_s.first() else {
        return Vec::new();
    };
    let mut k = 0;
    time_s
        .iter()
        .map(|&t| {
            let rel = t - t0;
            if rel < centres_s[0] {
                return headings_deg[0];
            }
            while k + 1 < centres_s.len() && rel >= centres_s[k + 1] {
                k += 1;
            }
            if k + 1 == centres_s.len() {
                return headings_deg[k];
            }
            let f = (rel - centres_s[k]) / (centres_s[k + 1] - centres_s[k]);
            headings_deg[k] + f * (headings_deg[k + 1] - headings_deg[k])
        })
        .collect()
}

/// `trial` with each fitted IMU's heading drift removed, `R_up(-h(t)) G_R(t)`,
/// `h(t)` its [`heading_series`] (the fits' constant corrections are not
/// applied). Gyroscope readings (sensor frame) are kept: the drift's own rate,
/// a fraction of a degree per second, is left out as in the heading variants.
pub fn remove_headings(trial: &Trial, headings: &[ImuHeading]) -> Trial {
    let mut out = trial.clone();
    for h in headings {
        let Some(imu) = out.imu_mut(&h.imu).filter(|_| !h.windows.is_empty()) else {
            continue;
        };
        let centres: Vec<f64> = h.windows.iter().map(|w| w.centre_s).collect();
        let degrees: Vec<f64> = h.windows.iter().map(|w| w.heading_deg).collect();
        let series = heading_series(&trial.time_s, &centres, &degrees);
        for (q, &d) in imu.orientation.iter_mut().zip(&series) {
            *q = Quat::new_normalize((h.vertical.heading_rotation(-d) * *q).into_inner());
        }
    }
    out
}

/// The corrected distal orientations `R_up(-h(t)) * G_R_dist(t) * C`.
pub fn apply(child: &[Quat], c: &Quat, heading_deg: &[f64], vertical: Vertical) -> Vec<Quat> {
    child
        .iter()
        .zip(heading_deg)
        .map(|(d, &h)| Quat::new_normalize((vertical.heading_rotation(-h) * d * c).into_inner()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::acm::window::layout;
    use crate::limits::LimitTable;
    use crate::model::Model;
    use crate::simulate::{simulate, HeadingDrift, SimConfig};
    use crate::trial::Trial;

    /// The left knee of a 3-minute simulated body, the calf drifting 0.1 deg/s from 30 s.
    fn knee_problem() -> (Trial, Vec<Window>, JointLimits) {
        let mut cfg = SimConfig::full_body(4);
        cfg.duration_s = 180.0;
        cfg.drifts = vec![HeadingDrift {
            imu: "l_calf".into(),
            start_s: 30.0,
            rate_deg_s: 0.1,
        }];
        let trial = simulate(&cfg).unwrap().trial;
        let windows = layout(&trial.time_s, 60.0, 30.0);
        let model = Model::infant13();
        let j = model.joint("l_knee").unwrap();
        let lim = LimitTable::default_table().cost_limits(j, false).unwrap();
        (trial, windows, lim)
    }

    #[test]
    fn default_solver_beats_plain_alternation_at_equal_work() {
        let (trial, windows, limits) = knee_problem();
        // The thigh's misalignment stays in the parent: fine for comparing solvers.
        let p = HeadingProblem {
            parent: &trial.imu("l_thigh").unwrap().orientation,
            child: &trial.imu("l_calf").unwrap().orientation,
            windows: &windows,
            limits: &limits,
            lambda1: 0.05,
            vertical: Vertical::ZUp,
        };
        let fast = p.fit(&HeadingOptions::default());
        let converged = p.fit(&HeadingOptions::plain_alternation());
        // Plain alternation given the same work (rounds until it has spent as much).
        let mut rounds = 1;
        let same_work = loop {
            let f = p.fit(&HeadingOptions {
                fine_rounds: rounds,
                ..HeadingOptions::plain_alternation()
            });
            if f.sample_evaluations >= fast.sample_evaluations {
                break f;
            }
            rounds += 1;
        };
        eprintln!(
            "default: J {:.9} ({} rounds, {} sample evaluations); plain alternation: J {:.9} at equal work ({} rounds), {:.9} converged ({} rounds, {} sample evaluations)",
            fast.total_cost(),
            fast.rounds,
            fast.sample_evaluations,
            same_work.total_cost(),
            same_work.rounds,
            converged.total_cost(),
            converged.rounds,
            converged.sample_evaluations,
        );
        assert!(fast.total_cost() <= same_work.total_cost());
        // Against alternation run to convergence (several times the work): the
        // default stops after one full-resolution round, within 1e-4 of J
        // relative (1e-4 deg per sample of mean excursion per window, far
        // below anything a sensor resolves).
        assert!(fast.total_cost() <= converged.total_cost() * (1.0 + 1e-4));
        assert!(fast.sample_evaluations * 3 < converged.sample_evaluations);
        // Both lower the cost below the uncorrected one, and the reported
        // window costs are the objective at the solution.
        let none: f64 = fast.window_costs_uncorrected.iter().sum();
        assert!(fast.total_cost() < none);
        let again: f64 = p.window_costs(&fast.c, &fast.headings_deg).iter().sum();
        assert_eq!(again, fast.total_cost());
    }

    #[test]
    fn line_search_finds_a_far_kinked_minimum_with_the_scan() {
        let f = |x: f64| (x - 100.0).abs() + 0.05 * x.abs() + 10.0 * ((x / 7.0).sin() + 1.0);
        let (x, _) = line_search(&f, &[0.0], true, 4.0);
        let (local, _) = line_search(&f, &[0.0], false, 4.0);
        assert!(f(x) <= f(local), "{x} vs {local}");
        assert!(f(x) < f(0.0));
    }

    #[test]
    fn slope_search_finds_smooth_kinked_and_far_minima() {
        // A smooth bowl, from 0 without the scan.
        let bowl = |x: f64| ((x - 12.3).powi(2), 2.0 * (x - 12.3));
        let (x, _) = slope_search(&|x| bowl(x).0, &bowl, &[0.0], false, 4.0);
        assert!((x - 12.3).abs() < 1e-6, "{x}");
        // A minimum on the kink of lambda1 |h| at 0 (the common case of no
        // drift): found exactly, as the point evaluated there.
        let cone = |x: f64| (0.05 * x.abs() + 0.01 * x * x, 0.05 * x.signum() + 0.02 * x);
        let (x, _) = slope_search(&|x| cone(x).0, &cone, &[3.0], false, 4.0);
        assert!(x.abs() < 1e-6, "{x}");
        let (x, _) = slope_search(&|x| cone(x).0, &cone, &[0.0], false, 4.0);
        assert_eq!(x, 0.0);
        // A far kinked minimum behind a ripple: with the scan, as good as the
        // pattern search.
        let far = |x: f64| {
            let f = (x - 100.0).abs() + 0.05 * x.abs() + 10.0 * ((x / 7.0).sin() + 1.0);
            let d = (x - 100.0).signum() + 0.05 * x.signum() + 10.0 / 7.0 * (x / 7.0).cos();
            (f, d)
        };
        let value = |x: f64| far(x).0;
        let (x, evals) = slope_search(&value, &far, &[0.0], true, 4.0);
        let (y, pattern_evals) = line_search(&value, &[0.0], true, 4.0);
        assert!(value(x) <= value(y) + 1e-9, "{x} {y}");
        assert!(evals < pattern_evals, "{evals} vs {pattern_evals}");
    }

    #[test]
    fn heading_series_is_linear_between_centres_and_held_outside() {
        let t: Vec<f64> = (0..1200).map(|i| i as f64 / 10.0).collect();
        let s = heading_series(&t, &[30.0, 90.0], &[2.0, 8.0]);
        assert_eq!(s[0], 2.0);
        assert!((s[600] - 5.0).abs() < 1e-12);
        assert_eq!(s[1199], 8.0);
    }
}
