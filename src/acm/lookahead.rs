//! The child-joint lookahead of the heading-drift variants: an IMU's constant
//! correction `C` and headings `h_k` are fitted against its own joint **and**
//! the joints below it (where it is the proximal sensor), evaluated with each
//! child IMU's own data.
//!
//! Why: a heading drift (or a misalignment) of an IMU whose own joint has wide
//! limits (a shoulder, a hip) barely shows at that joint, but it shows at the
//! joint below (an elbow, a knee: narrow limits). Solved in chain order without
//! looking ahead, the parent keeps it and the child's fit, made against the
//! wrong parent, takes it: the drift is pushed down the chain.
//!
//! The objective of IMU `X` with child IMUs `Y_j` (joint `X -> Y_j` each):
//! `J = sum_k e_k(C, h_k) + sum_j sum_k f_jk`, with `e_k` the window cost of
//! [`super::heading`] and, for each child joint and window,
//! `f_jk = (1/n_k) sum_i (Ex + Ey + Ez + lambda2 RMSq)(Rt_i)
//!         + lambda1 angle(C_j) + lambda1 |h_k + r_jk|`,
//! `Rt_i = (R_up(-h_k) X_i C)^T R_up(-h_k - r_jk) Y_ji C_j = C^T X_i^T R_up(-r_jk) Y_ji C_j`,
//! where `C_j` (a constant correction of the child, re-fitted here) and `r_jk`
//! (the child's heading relative to `X`'s) are auxiliary: they are dropped after
//! the fit, and the child is then solved as usual against the corrected `X`.
//!
//! The penalties are shared so that each IMU pays for its own correction once:
//! `lambda1 angle(C)` and `lambda1 |h_k|` for `X` are in `e_k` only (the child
//! terms add none for `X`), and the child pays `lambda1 |h_k + r_jk|`, its own
//! absolute heading. A relative drift `d` seen at a child joint then costs
//! `lambda1 (|h_k| + |h_k - d|)` whichever of the two IMUs takes it, so the
//! drift goes where `X`'s own joint (its limits, its centroid) says, not to the
//! child by default. (Penalising `X`'s heading in the child terms too would
//! make the child the cheaper place for any drift: pushed down the chain again.)
//!
//! Solver: block coordinate descent over `(C, h, C_j, r_j)` in the coordinates
//! where the blocks decouple: the child joint's angles depend on the headings
//! only through `r_jk`, so each heading step is a 1-D search on `X`'s own
//! window cost plus the penalty of the children's absolute headings, and each
//! `r_jk` step a 1-D search on the child joint's window cost
//! ([`HeadingCost`] with the proximal side `X_i C`). The phases (coarse stride,
//! a scan of the whole circle in the first round, then a full-resolution
//! round) are those of [`super::heading`]; no step raises `J`. The first round
//! fits `C` on `X`'s own joint alone (the children's corrections are not known
//! yet), as the solver without lookahead does.

use super::cost::WindowCost;
use super::heading::{heading_search, CStep, HeadingFit, HeadingOptions, HeadingProblem};
use super::heading_cost::HeadingCost;
use super::parent_cost::ParentCost;
use super::window::Window;
use crate::limits::JointLimits;
use crate::rotation::{angle_deg, Quat};
use rayon::prelude::*;

/// The weight of each child joint's terms in the objective (see the module docs).
pub const CHILD_WEIGHT: f64 = 0.5;

/// A joint below the IMU being fitted (the IMU is its proximal sensor).
#[derive(Clone, Copy)]
pub struct ChildJoint<'a> {
    /// Raw orientations `G_R` of the joint's distal IMU, per sample.
    pub child: &'a [Quat],
    /// The joint's limits (with its centroid where the variant uses one).
    pub limits: &'a JointLimits,
}

/// One IMU's heading fit with its child joints.
#[derive(Clone, Copy)]
pub struct Lookahead<'a> {
    /// The IMU's own joint against its corrected parent.
    pub own: HeadingProblem<'a>,
    /// The joints below it; none gives the fit of [`HeadingProblem::fit`].
    pub children: &'a [ChildJoint<'a>],
}

/// The auxiliary state of one child: its constant correction and its heading
/// relative to the IMU's, per window (degrees).
#[derive(Debug, Clone)]
struct Child {
    c: Quat,
    r: Vec<f64>,
}

/// The state of the descent.
struct State {
    c: Quat,
    h: Vec<f64>,
    children: Vec<Child>,
    window_evaluations: Vec<usize>,
    c_evaluations: usize,
    rounds: usize,
    sample_evaluations: usize,
}

impl Lookahead<'_> {
    /// Fits the IMU's C and per-window headings (the children's auxiliary
    /// corrections are dropped). The reported window costs are those of the
    /// IMU's own joint, `e_k(C, h_k)`.
    pub fn fit(&self, opts: &HeadingOptions) -> HeadingFit {
        if self.children.is_empty() {
            return self.own.fit(opts);
        }
        let n = self.own.windows.len();
        let mut s = State {
            c: Quat::identity(),
            h: vec![0.0; n],
            children: vec![
                Child {
                    c: Quat::identity(),
                    r: vec![0.0; n],
                };
                self.children.len()
            ],
            window_evaluations: vec![0; n],
            c_evaluations: 0,
            rounds: 0,
            sample_evaluations: 0,
        };
        let objective = opts.run_phases(|stride, scan| self.round(&mut s, stride, scan, opts));
        let window_costs = self.own.window_costs(&s.c, &s.h);
        let window_costs_uncorrected = self.own.window_costs(&Quat::identity(), &vec![0.0; n]);
        HeadingFit {
            c: s.c,
            headings_deg: s.h,
            objective,
            window_costs,
            window_costs_uncorrected,
            window_evaluations: s.window_evaluations,
            c_evaluations: s.c_evaluations,
            rounds: s.rounds,
            sample_evaluations: s.sample_evaluations,
        }
    }

    /// One round: the IMU's C, its headings, then each child's C and relative
    /// headings. Returns J on every `stride`-th sample.
    fn round(&self, s: &mut State, stride: usize, scan: bool, opts: &HeadingOptions) -> f64 {
        s.rounds += 1;
        let first = s.rounds == 1;
        self.c_step(s, stride, first && opts.first_window_start, opts);
        let own = self.heading_step(s, stride, scan, opts);
        let mut children = Vec::with_capacity(self.children.len() * s.h.len());
        for j in 0..self.children.len() {
            let fixed = self.fixed_parent(&s.c);
            self.child_c_step(s, j, &fixed, stride, opts);
            children.extend(self.child_heading_step(s, j, &fixed, (stride, scan), opts));
        }
        // J from the window costs the steps built: the IMU's own terms do not
        // change after its heading step, nor child j's after its own.
        own.iter().sum::<f64>() + CHILD_WEIGHT * children.iter().sum::<f64>()
    }

    /// `X_i C`: the IMU corrected but for its heading, per sample.
    fn fixed_parent(&self, c: &Quat) -> Vec<Quat> {
        self.own.child.iter().map(|x| x * c).collect()
    }

    /// The C step: the IMU's own windows plus, after the first round, every
    /// child joint's (the child terms hold no penalty of C).
    fn c_step(&self, s: &mut State, stride: usize, first_window_only: bool, opts: &HeadingOptions) {
        let mut own = self.own.c_costs(&s.h, stride);
        let mut children: Vec<ParentCost> = Vec::new();
        if s.rounds == 1 {
            if first_window_only {
                own.truncate(1);
            }
        } else {
            children = self
                .children
                .iter()
                .zip(&s.children)
                .flat_map(|(cj, st)| {
                    self.own
                        .windows
                        .iter()
                        .zip(&st.r)
                        .map(move |(w, &r)| self.parent_cost(cj, st, w, r, stride))
                })
                .collect();
        }
        let step = CStep {
            own: &own,
            children: &children,
            child_weight: CHILD_WEIGHT,
        };
        let m = step.solve(&s.c, s.rounds, stride, opts.solver);
        s.c_evaluations += m.evaluations;
        s.sample_evaluations += m.evaluations * step.samples();
        s.c = m.c;
    }

    /// A child joint's window cost as a function of the IMU's C:
    /// `B_i = X_i^T R_up(-r) Y_i C_j`.
    fn parent_cost(
        &self,
        cj: &ChildJoint,
        st: &Child,
        w: &Window,
        r: f64,
        stride: usize,
    ) -> ParentCost {
        let turn = self.own.vertical.heading_rotation(-r);
        let b = self.own.child[w.first..w.end]
            .iter()
            .zip(&cj.child[w.first..w.end])
            .step_by(stride.max(1))
            .map(|(x, y)| x.inverse() * turn * y * st.c);
        ParentCost::new(b, cj.limits)
    }

    /// `lambda1 sum_j |h + r_jk|`: the children's absolute headings in window k.
    fn children_penalty(&self, s: &State, k: usize, h: f64) -> f64 {
        s.children
            .iter()
            .map(|st| CHILD_WEIGHT * self.own.lambda1 * (h + st.r[k]).abs())
            .sum()
    }

    /// [`Lookahead::children_penalty`] and its derivative in `h` (one side's
    /// at a kink, as `signum`).
    fn children_penalty_slope(&self, s: &State, k: usize, h: f64) -> (f64, f64) {
        let w = CHILD_WEIGHT * self.own.lambda1;
        let slope = s.children.iter().map(|st| w * (h + st.r[k]).signum()).sum();
        (self.children_penalty(s, k, h), slope)
    }

    /// The heading step: each `h_k` on the IMU's own window cost plus the
    /// children's heading penalties (their relative headings held). Returns
    /// the own window costs `e_k(C, h_k)` at the new headings.
    fn heading_step(
        &self,
        s: &mut State,
        stride: usize,
        scan: bool,
        opts: &HeadingOptions,
    ) -> Vec<f64> {
        let (c, h) = (&s.c, &s.h);
        let state: &State = s;
        let steps: Vec<(f64, usize, usize, f64)> = (0..h.len())
            .into_par_iter()
            .map(|k| {
                let cost = self.own.heading_cost(&self.own.windows[k], c, stride);
                let value = |x: f64| cost.eval(x) + self.children_penalty(state, k, x);
                let slope = |x: f64| {
                    let (f, d) = cost.eval_slope(x);
                    let (p, dp) = self.children_penalty_slope(state, k, x);
                    (f + p, d + dp)
                };
                let scan = (scan, opts.scan_step_deg);
                let starts = neighbour_starts(h, k);
                let (hk, e) = heading_search(&value, &slope, &starts, scan, opts.solver);
                (hk, e, e * cost.len(), cost.eval(hk))
            })
            .collect();
        let mut own = Vec::with_capacity(steps.len());
        for (k, (hk, e, work, cost)) in steps.into_iter().enumerate() {
            s.h[k] = hk;
            s.window_evaluations[k] += e;
            s.sample_evaluations += work;
            own.push(cost);
        }
        own
    }

    /// Child j's constant correction on all windows: `Rm_i = (X_i C)^T R_up(-r_jk) Y_i`.
    fn child_c_step(
        &self,
        s: &mut State,
        j: usize,
        fixed: &[Quat],
        stride: usize,
        opts: &HeadingOptions,
    ) {
        let cj = &self.children[j];
        let costs: Vec<WindowCost> = self
            .own
            .windows
            .iter()
            .zip(&s.children[j].r)
            .map(|(w, &r)| {
                let turn = self.own.vertical.heading_rotation(-r);
                let measured: Vec<Quat> = fixed[w.first..w.end]
                    .iter()
                    .zip(&cj.child[w.first..w.end])
                    .step_by(stride.max(1))
                    .map(|(p, y)| p.inverse() * turn * y)
                    .collect();
                WindowCost::new(&measured, cj.limits, self.own.lambda1)
            })
            .collect();
        let step = CStep {
            own: &costs,
            children: &[],
            child_weight: 0.0,
        };
        let m = step.solve(&s.children[j].c, s.rounds, stride, opts.solver);
        s.c_evaluations += m.evaluations;
        s.sample_evaluations += m.evaluations * step.samples();
        s.children[j].c = m.c;
    }

    /// Child j's heading relative to the IMU's, per window. Returns its
    /// terms of J per window at the new headings (its window cost plus
    /// `lambda1 |h_k + r_jk|`).
    fn child_heading_step(
        &self,
        s: &mut State,
        j: usize,
        fixed: &[Quat],
        (stride, scan): (usize, bool),
        opts: &HeadingOptions,
    ) -> Vec<f64> {
        let st = &s.children[j];
        let h = &s.h;
        let steps: Vec<(f64, usize, usize, f64)> = (0..h.len())
            .into_par_iter()
            .map(|k| {
                let cost = self.child_cost(j, st, fixed, k, stride);
                let lambda1 = self.own.lambda1;
                let value = |x: f64| cost.eval(x) + lambda1 * (h[k] + x).abs();
                let slope = |x: f64| {
                    let (f, d) = cost.eval_slope(x);
                    (
                        f + lambda1 * (h[k] + x).abs(),
                        d + lambda1 * (h[k] + x).signum(),
                    )
                };
                let scan = (scan, opts.scan_step_deg);
                let starts = neighbour_starts(&st.r, k);
                let (rk, e) = heading_search(&value, &slope, &starts, scan, opts.solver);
                (rk, e, e * cost.len(), value(rk))
            })
            .collect();
        let mut terms = Vec::with_capacity(steps.len());
        for (k, (rk, e, work, term)) in steps.into_iter().enumerate() {
            s.children[j].r[k] = rk;
            s.sample_evaluations += work;
            s.window_evaluations[k] += e;
            terms.push(term);
        }
        terms
    }

    /// Child joint j's window k as a function of its relative heading, with the
    /// penalty of its constant correction (not of its heading).
    fn child_cost(
        &self,
        j: usize,
        st: &Child,
        fixed: &[Quat],
        k: usize,
        stride: usize,
    ) -> ChildWindow {
        let cj = &self.children[j];
        let w = &self.own.windows[k];
        let cost = HeadingCost::new(
            &fixed[w.first..w.end],
            &cj.child[w.first..w.end],
            &st.c,
            self.own.vertical.up(),
            cj.limits,
            0.0,
            stride,
        );
        ChildWindow {
            cost,
            c_penalty: self.own.lambda1 * angle_deg(&st.c),
        }
    }
}

/// A child joint's window cost over its relative heading (no heading penalty).
struct ChildWindow {
    cost: HeadingCost,
    c_penalty: f64,
}

impl ChildWindow {
    fn eval(&self, r: f64) -> f64 {
        self.cost.eval(r) + self.c_penalty
    }

    /// [`ChildWindow::eval`] and its derivative in `r` (per degree).
    fn eval_slope(&self, r: f64) -> (f64, f64) {
        let (f, d) = self.cost.eval_slope(r);
        (f + self.c_penalty, d)
    }

    fn len(&self) -> usize {
        self.cost.len()
    }
}

/// Start points of a window's 1-D search: its current value, then its
/// neighbours'.
fn neighbour_starts(v: &[f64], k: usize) -> Vec<f64> {
    let mut starts = vec![v[k]];
    starts.extend([k.wrapping_sub(1), k + 1].iter().filter_map(|&j| v.get(j)));
    starts
}
