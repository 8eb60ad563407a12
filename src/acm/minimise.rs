//! Minimising the ACM cost over rotations.
//!
//! Two minimisers, both over a rotation vector `v` (radians) in the tangent
//! space of a reference rotation, `C = C_ref * exp(v)`; the reference is moved
//! to the best point at every restart, so the parameterisation never nears its
//! singularity, and a restart follows every convergence until it no longer
//! lowers the cost.
//!
//! - [`minimise_shaped`] (the default, [`Solver::Gradient`]) knows the cost's
//!   shape, [`ShapedCost`]: a piecewise smooth part whose value and gradient
//!   come in one pass, plus `w * angle(C)`, a cone at identity it handles
//!   itself. Quasi-Newton (BFGS) steps with a weak Wolfe line search, which
//!   converge on kinks too (the model's curvature grows across them); at the
//!   cone's tip it steps along the least subgradient, or stops there when that
//!   is zero (the tip is then a minimum).
//! - [`minimise`] ([`Solver::NelderMead`]) uses values only: Nelder-Mead, the
//!   previous solver, kept selectable and as the oracle the gradient solver
//!   is tested against (the heading variants' C steps use either, as
//!   [`super::heading::HeadingOptions::solver`] says).

use crate::rotation::{angle_between_deg, angle_deg, quat_from_rotvec, Quat};
use nalgebra::{Matrix3, Vector3};

pub use crate::limits::Solver;

/// Tuning of the minimiser.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MinimiseOptions {
    /// Size of the first simplex, radians.
    pub initial_step_rad: f64,
    /// Size of the simplex at each restart, radians.
    pub restart_step_rad: f64,
    /// Convergence: simplex size below this, radians.
    pub tol_x_rad: f64,
    /// Convergence: spread of the simplex's costs below this.
    pub tol_f: f64,
    /// A restart that gains less than this ends the search.
    pub min_gain: f64,
    /// Most restarts after the first descent.
    pub max_restarts: usize,
    /// Most cost evaluations of one descent.
    pub max_evals_per_descent: usize,
}

impl Default for MinimiseOptions {
    fn default() -> Self {
        MinimiseOptions {
            initial_step_rad: 0.15,
            restart_step_rad: 0.03,
            tol_x_rad: 2e-7,
            tol_f: 1e-11,
            min_gain: 1e-9,
            max_restarts: 6,
            max_evals_per_descent: 1500,
        }
    }
}

/// The result of a minimisation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Solution {
    /// The best correction found.
    pub c: Quat,
    /// Its cost.
    pub cost: f64,
    /// Cost evaluations spent.
    pub evaluations: usize,
}

/// Minimises `cost` starting from each of `starts` (at least one), keeping the best.
///
/// Deterministic: the same starts and cost give the same result.
pub fn minimise(cost: &dyn Fn(&Quat) -> f64, starts: &[Quat], opts: &MinimiseOptions) -> Solution {
    assert!(!starts.is_empty(), "minimise needs a start");
    let mut evaluations = 0;
    let mut best: Option<(Quat, f64)> = None;
    for s in starts {
        let (c, f, n) = descend(cost, s, opts.initial_step_rad, opts);
        evaluations += n;
        if best.is_none_or(|(_, bf)| f < bf) {
            best = Some((c, f));
        }
    }
    let (mut c, mut f) = best.expect("at least one start");
    for _ in 0..opts.max_restarts {
        let (c2, f2, n) = descend(cost, &c, opts.restart_step_rad, opts);
        evaluations += n;
        let gain = f - f2;
        if gain > 0.0 {
            c = c2;
            f = f2;
        }
        if gain < opts.min_gain {
            break;
        }
    }
    Solution {
        c,
        cost: f,
        evaluations,
    }
}

/// One Nelder-Mead descent from `base` with a simplex of size `step` (radians).
/// Returns the best rotation, its cost and the evaluations spent.
fn descend(
    cost: &dyn Fn(&Quat) -> f64,
    base: &Quat,
    step: f64,
    opts: &MinimiseOptions,
) -> (Quat, f64, usize) {
    let at = |v: &Vector3<f64>| base * quat_from_rotvec(v);
    let evals = std::cell::Cell::new(0usize);
    let f = |v: &Vector3<f64>| {
        evals.set(evals.get() + 1);
        cost(&at(v))
    };
    let mut simplex: Vec<(Vector3<f64>, f64)> = Vec::with_capacity(4);
    let origin = Vector3::zeros();
    simplex.push((origin, f(&origin)));
    for k in 0..3 {
        let mut v = Vector3::zeros();
        v[k] = step;
        let fv = f(&v);
        simplex.push((v, fv));
    }
    loop {
        simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
        let spread = simplex[3].1 - simplex[0].1;
        let size = simplex[1..]
            .iter()
            .map(|(v, _)| (v - simplex[0].0).amax())
            .fold(0.0, f64::max);
        if (size < opts.tol_x_rad && spread < opts.tol_f.max(1e-15)) || size < opts.tol_x_rad * 1e-3
        {
            break;
        }
        if evals.get() >= opts.max_evals_per_descent {
            break;
        }
        let centroid = (simplex[0].0 + simplex[1].0 + simplex[2].0) / 3.0;
        let worst = simplex[3];
        let reflected = centroid + (centroid - worst.0);
        let fr = f(&reflected);
        if fr < simplex[0].1 {
            let expanded = centroid + (centroid - worst.0) * 2.0;
            let fe = f(&expanded);
            simplex[3] = if fe < fr {
                (expanded, fe)
            } else {
                (reflected, fr)
            };
        } else if fr < simplex[2].1 {
            simplex[3] = (reflected, fr);
        } else {
            let (contracted, fc) = if fr < worst.1 {
                let p = centroid + (reflected - centroid) * 0.5;
                (p, f(&p))
            } else {
                let p = centroid + (worst.0 - centroid) * 0.5;
                (p, f(&p))
            };
            if fc < worst.1.min(fr) {
                simplex[3] = (contracted, fc);
            } else {
                let best = simplex[0].0;
                for item in simplex.iter_mut().skip(1) {
                    let p = best + (item.0 - best) * 0.5;
                    *item = (p, f(&p));
                }
            }
        }
    }
    simplex.sort_by(|a, b| a.1.total_cmp(&b.1));
    let (v, fv) = simplex[0];
    (at(&v), fv, evals.get())
}

/// A cost of the shape [`minimise_shaped`] assumes:
/// `f(C) = data(C) + cone * angle_deg(C)`, with `data` continuous and
/// piecewise smooth (kinks where a sample crosses a limit allowed) and
/// `cone >= 0`.
pub struct ShapedCost<'a> {
    /// `data(C)` and its gradient with respect to `v` in `C * exp(v)` at
    /// `v = 0` (per radian).
    pub data: &'a dyn Fn(&Quat) -> (f64, Vector3<f64>),
    /// Weight of `angle_deg(C)`.
    pub cone: f64,
}

impl ShapedCost<'_> {
    /// `f(C)` and a gradient in the tangent at `C`: the cone's at `C != I`;
    /// at `C = I` the least-norm subgradient (zero when the tip is a minimum).
    fn at(&self, c: &Quat) -> (f64, Vector3<f64>) {
        let (f, g) = (self.data)(c);
        let angle = angle_deg(c);
        let w = self.cone * DEG;
        let axis = Vector3::new(c.i, c.j, c.k) * c.w.signum();
        let norm = axis.norm();
        let cone_grad = if norm > 0.0 {
            axis * (w / norm)
        } else {
            let gn = g.norm();
            return (
                f,
                if gn > w {
                    g * (1.0 - w / gn)
                } else {
                    Vector3::zeros()
                },
            );
        };
        (f + self.cone * angle, g + cone_grad)
    }
}

/// Degrees per radian.
const DEG: f64 = 180.0 / std::f64::consts::PI;

/// The right Jacobian of `exp` at `v`: `exp(v + dv) = exp(v) exp(J_r(v) dv)`.
fn right_jacobian(v: &Vector3<f64>) -> Matrix3<f64> {
    let t = v.norm();
    let k = v.cross_matrix();
    let (a, b) = if t < 1e-4 {
        (0.5 - t * t / 24.0, 1.0 / 6.0 - t * t / 120.0)
    } else {
        ((1.0 - t.cos()) / (t * t), (t - t.sin()) / (t * t * t))
    };
    Matrix3::identity() - k * a + k * k * b
}

/// Tuning of [`minimise_shaped`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShapedOptions {
    /// Length of the first step, radians.
    pub initial_step_rad: f64,
    /// The longest step, radians.
    pub max_step_rad: f64,
    /// A step shorter than this ends a descent, radians.
    pub tol_x_rad: f64,
    /// Three steps that together gain less than this fraction of the cost
    /// end a descent.
    pub tol_f_rel: f64,
    /// A restart that gains less than this ends the search.
    pub min_gain: f64,
    /// Most restarts after the first descent.
    pub max_restarts: usize,
    /// Most quasi-Newton iterations of one descent.
    pub max_iterations: usize,
    /// Most evaluations of one line search.
    pub max_line_evals: usize,
}

impl Default for ShapedOptions {
    fn default() -> Self {
        ShapedOptions {
            initial_step_rad: 0.05,
            max_step_rad: 0.5,
            tol_x_rad: 1e-9,
            tol_f_rel: 1e-11,
            min_gain: 1e-12,
            max_restarts: 0,
            max_iterations: 200,
            max_line_evals: 40,
        }
    }
}

/// Minimises a cost of the shape [`ShapedCost`] from each of `starts` (at
/// least one), keeping the best; restarts (a fresh curvature model at the
/// best point) follow until one gains less than `min_gain`.
///
/// Deterministic: the same starts and cost give the same result.
pub fn minimise_shaped(cost: &ShapedCost, starts: &[Quat], opts: &ShapedOptions) -> Solution {
    assert!(!starts.is_empty(), "minimise needs a start");
    let mut evaluations = 0;
    let mut best: Option<(Quat, f64)> = None;
    for s in starts {
        let (c, f, n) = quasi_newton(cost, s, opts);
        evaluations += n;
        if best.is_none_or(|(_, bf)| f < bf) {
            best = Some((c, f));
        }
    }
    let (mut c, mut f) = best.expect("at least one start");
    for _ in 0..opts.max_restarts {
        let (c2, f2, n) = quasi_newton(cost, &c, opts);
        evaluations += n;
        let gain = f - f2;
        if gain > 0.0 {
            c = c2;
            f = f2;
        }
        if gain < opts.min_gain {
            break;
        }
    }
    Solution {
        c,
        cost: f,
        evaluations,
    }
}

/// Tuning of [`screen_basins`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScreenOptions {
    /// Distances of the probes from the descent's end, degrees.
    pub radii_deg: [f64; 3],
    /// Most probes descended from per round.
    pub keep: usize,
    /// Most rounds (each from the best point so far).
    pub rounds: usize,
    /// Farthest a lower basin's end may lie from the descent's end, degrees.
    pub reach_deg: f64,
}

impl Default for ScreenOptions {
    fn default() -> Self {
        ScreenOptions {
            radii_deg: [5.0, 12.0, 24.0],
            keep: 2,
            rounds: 3,
            reach_deg: 30.0,
        }
    }
}

/// The 26 directions from the centre of a cube to its faces, edges and
/// corners, unit length.
fn cube_directions() -> [Vector3<f64>; 26] {
    let mut out = [Vector3::zeros(); 26];
    let mut n = 0;
    for i in -1..=1 {
        for j in -1..=1 {
            for k in -1..=1 {
                if (i, j, k) != (0, 0, 0) {
                    out[n] = Vector3::new(i as f64, j as f64, k as f64).normalize();
                    n += 1;
                }
            }
        }
    }
    out
}

/// Looks for a lower basin around the end of a descent, `found`.
///
/// A window's cost can have separate minima (wide limits, a parent not yet
/// corrected), and a descent from identity stops in the first it reaches.
/// Probes `C * exp(r d)` at the radii of `screen` (degrees) along the 26
/// directions of a cube are scored on `coarse`, a cheap copy of the cost
/// (every few samples of the window); the lowest `keep` that `coarse` puts
/// below `C` and the full cost confirms below `found` are descended from with
/// [`minimise_shaped`]'s descent. A lower end within `reach_deg` of `found`
/// moves `C` there and the screen runs again, up to `rounds` times. The
/// result is never above `found`.
///
/// The screen repairs a descent that stopped short (against a kink, or in a
/// shallow dent beside the basin it was heading for); it does not trade the
/// descent's basin for a far one. A basin much farther away is another
/// reading of the joint rather than the sensor's misalignment: the centroid
/// prior of a standing hip pulls a crawling hip's correction 64 deg away, to
/// a cost half the near basin's.
///
/// `evaluations` counts evaluations of the full cost only (the probes cost
/// about `78 * coarse samples` per round).
pub fn screen_basins(
    cost: &ShapedCost,
    coarse: &dyn Fn(&Quat) -> f64,
    found: Solution,
    (opts, screen): (&ShapedOptions, &ScreenOptions),
) -> Solution {
    let directions = cube_directions();
    let mut best = found;
    for _ in 0..screen.rounds {
        let here = coarse(&best.c);
        let mut probes: Vec<(f64, Quat)> = screen
            .radii_deg
            .iter()
            .flat_map(|r| directions.iter().map(move |d| d * r.to_radians()))
            .map(|v| best.c * quat_from_rotvec(&v))
            .map(|p| (coarse(&p), p))
            .filter(|(s, _)| *s < here)
            .collect();
        probes.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut improved = false;
        for (_, p) in probes.iter().take(screen.keep) {
            best.evaluations += 1;
            if cost.at(p).0 >= best.cost {
                continue;
            }
            let (c, f, n) = quasi_newton(cost, p, opts);
            best.evaluations += n;
            let near = angle_between_deg(&c, &found.c) <= screen.reach_deg;
            if near && f < best.cost - opts.min_gain {
                best.c = c;
                best.cost = f;
                improved = true;
            }
        }
        if !improved {
            break;
        }
    }
    best
}

/// One BFGS descent from `base` over `v` in `base * exp(v)`. Returns the best
/// rotation, its cost and the evaluations spent.
fn quasi_newton(cost: &ShapedCost, base: &Quat, opts: &ShapedOptions) -> (Quat, f64, usize) {
    let mut evals = 0usize;
    let mut eval = |v: &Vector3<f64>| {
        evals += 1;
        let (f, g) = cost.at(&(base * quat_from_rotvec(v)));
        (f, right_jacobian(v).transpose() * g)
    };
    let mut x = Vector3::zeros();
    let (mut f, mut g) = eval(&x);
    let mut h: Option<Matrix3<f64>> = None;
    // Length of the steepest-descent trial step: the first step's, then the
    // last accepted step's (near a kink the right scale is the recent one).
    let mut scale = opts.initial_step_rad;
    let mut gains = [f64::INFINITY; 3];
    for iteration in 0..opts.max_iterations {
        let gn = g.norm();
        if gn == 0.0 || !gn.is_finite() {
            break;
        }
        let mut d = match &h {
            Some(h) => -(h * g),
            None => -g * (scale / gn),
        };
        if d.dot(&g) >= 0.0 {
            h = None;
            d = -g * (scale / gn);
        }
        let len = d.norm();
        if len > opts.max_step_rad {
            d *= opts.max_step_rad / len;
        }
        let line = Line {
            max_evals: opts.max_line_evals,
            min_step_rad: opts.tol_x_rad,
        };
        let Some((t, ft, gt)) = wolfe(&mut eval, (&x, f, &g), &d, &line) else {
            if h.is_some() {
                // The model misled the step: try once more along the gradient.
                h = None;
                continue;
            }
            break;
        };
        let s = d * t;
        let y = gt - g;
        x += s;
        gains[iteration % 3] = f - ft;
        f = ft;
        g = gt;
        scale = s.norm().max(opts.tol_x_rad);
        let sy = s.dot(&y);
        if sy > 1e-300 {
            let h0 = h.unwrap_or_else(|| Matrix3::identity() * (sy / y.dot(&y)));
            let rho = 1.0 / sy;
            let i = Matrix3::identity();
            let a = i - s * y.transpose() * rho;
            h = Some(a * h0 * a.transpose() + s * s.transpose() * rho);
        }
        let recent: f64 = gains.iter().sum();
        if s.amax() < opts.tol_x_rad || recent <= opts.tol_f_rel * f.abs() + 1e-15 {
            break;
        }
    }
    (base * quat_from_rotvec(&x), f, evals)
}

/// Limits of one line search.
struct Line {
    max_evals: usize,
    /// A bracket narrower than this (radians) ends the search.
    min_step_rad: f64,
}

/// A weak Wolfe line search along `d` from `x` (value `f`, gradient `g`):
/// the step `t` and the value and gradient there, or none when no step
/// lowers the cost. Bisects on a bracket, doubles without one.
fn wolfe(
    eval: &mut impl FnMut(&Vector3<f64>) -> (f64, Vector3<f64>),
    (x, f, g): (&Vector3<f64>, f64, &Vector3<f64>),
    d: &Vector3<f64>,
    line: &Line,
) -> Option<(f64, f64, Vector3<f64>)> {
    const C1: f64 = 1e-4;
    const C2: f64 = 0.9;
    let slope = g.dot(d);
    let (mut lo, mut hi) = (0.0, f64::INFINITY);
    let mut t = 1.0;
    let mut best: Option<(f64, f64, Vector3<f64>)> = None;
    for _ in 0..line.max_evals {
        let (ft, gt) = eval(&(x + d * t));
        if ft < f && best.as_ref().is_none_or(|b| ft < b.1) {
            best = Some((t, ft, gt));
        }
        if ft > f + C1 * t * slope || !ft.is_finite() {
            hi = t;
        } else if gt.dot(d) < C2 * slope {
            lo = t;
        } else {
            return Some((t, ft, gt));
        }
        t = if hi.is_finite() {
            0.5 * (lo + hi)
        } else {
            2.0 * lo
        };
        if hi.is_finite() && (hi - lo) * d.amax() < line.min_step_rad {
            break;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::quat_axis_angle_deg;

    #[test]
    fn finds_a_smooth_minimum() {
        let target = quat_axis_angle_deg([1.0, 2.0, -1.0], 40.0);
        let cost = |c: &Quat| angle_between_deg(c, &target).powi(2);
        let s = minimise(&cost, &[Quat::identity()], &MinimiseOptions::default());
        assert!(angle_between_deg(&s.c, &target) < 1e-4, "{s:?}");
    }

    #[test]
    fn finds_a_kinked_minimum() {
        // |angle to target| + 0.05 * angle(C): a cone with its tip at the target.
        let target = quat_axis_angle_deg([0.0, 0.0, 1.0], -15.0);
        let cost = |c: &Quat| angle_between_deg(c, &target) + 0.05 * angle_deg(c);
        let s = minimise(&cost, &[Quat::identity()], &MinimiseOptions::default());
        assert!(angle_between_deg(&s.c, &target) < 1e-3, "{s:?}");
        assert!((s.cost - 0.75).abs() < 1e-3);
    }

    #[test]
    fn keeps_the_best_start() {
        let far = quat_axis_angle_deg([0.0, 1.0, 0.0], 170.0);
        let cost = |c: &Quat| angle_between_deg(c, &far);
        let s = minimise(
            &cost,
            &[
                Quat::identity(),
                quat_axis_angle_deg([0.0, 1.0, 0.0], 160.0),
            ],
            &MinimiseOptions::default(),
        );
        assert!(s.cost < 1e-3, "{s:?}");
    }

    /// [`basins`] with B 20 deg about Y, 22 deg from A.
    fn two_basins(c: &Quat) -> (f64, Vector3<f64>) {
        basins(c, 20.0)
    }

    /// `min(0.1 + dA^2, dB^2)` in radians to A, 10 deg about X, and B,
    /// `b_deg` about Y, with a central-difference gradient: a shallow basin at
    /// A, the lower one at B.
    fn basins(c: &Quat, b_deg: f64) -> (f64, Vector3<f64>) {
        let a = quat_axis_angle_deg([1.0, 0.0, 0.0], 10.0);
        let b = quat_axis_angle_deg([0.0, 1.0, 0.0], b_deg);
        let f = |c: &Quat| {
            let da = angle_between_deg(c, &a).to_radians();
            let db = angle_between_deg(c, &b).to_radians();
            (0.1 + da * da).min(db * db)
        };
        let h = 1e-6;
        let g = Vector3::from_fn(|k, _| {
            let step = Vector3::from_fn(|j, _| if j == k { h } else { 0.0 });
            (f(&(c * quat_from_rotvec(&step))) - f(&(c * quat_from_rotvec(&-step)))) / (2.0 * h)
        });
        (f(c), g)
    }

    /// [`screen_basins`] with `screen` from `c` at `cost` on `data` (no cone),
    /// scoring the probes on `data`'s own values.
    fn screen_at(
        data: &dyn Fn(&Quat) -> (f64, Vector3<f64>),
        (c, cost): (Quat, f64),
        screen: &ScreenOptions,
    ) -> Solution {
        let shaped = ShapedCost { data, cone: 0.0 };
        let found = Solution {
            c,
            cost,
            evaluations: 0,
        };
        let opts = ShapedOptions::default();
        screen_basins(&shaped, &|c| data(c).0, found, (&opts, screen))
    }

    #[test]
    fn the_screen_leaves_a_shallow_basin_for_a_lower_one() {
        let a = quat_axis_angle_deg([1.0, 0.0, 0.0], 10.0);
        let s = screen_at(&two_basins, (a, 0.1), &ScreenOptions::default());
        let b = quat_axis_angle_deg([0.0, 1.0, 0.0], 20.0);
        assert!(s.cost < 1e-8, "{s:?}");
        assert!(angle_between_deg(&s.c, &b) < 1e-2, "{s:?}");
        assert!(s.evaluations > 0);
    }

    #[test]
    fn the_screen_leaves_a_far_basin_alone() {
        // B 35 deg about Y is 36 deg from A: beyond the screen's reach, though
        // a probe 24 deg towards it is below A.
        let far = |c: &Quat| basins(c, 35.0);
        let a = quat_axis_angle_deg([1.0, 0.0, 0.0], 10.0);
        let s = screen_at(&far, (a, 0.1), &ScreenOptions::default());
        assert_eq!((s.c, s.cost), (a, 0.1), "{s:?}");
        assert!(s.evaluations > 0, "it descended from a probe");
        // Within reach it is found.
        let reach = ScreenOptions {
            reach_deg: 60.0,
            ..ScreenOptions::default()
        };
        assert!(screen_at(&far, (a, 0.1), &reach).cost < 1e-8);
    }

    #[test]
    fn the_screen_never_returns_worse_than_it_was_given() {
        // At B's minimum nothing around is lower: the answer is kept as is.
        let b = quat_axis_angle_deg([0.0, 1.0, 0.0], 20.0);
        let s = screen_at(&two_basins, (b, 0.0), &ScreenOptions::default());
        assert_eq!((s.c, s.cost, s.evaluations), (b, 0.0, 0));
        // A coarse copy that misjudges (it puts every probe below) costs full
        // evaluations but cannot make the answer worse.
        let shaped = ShapedCost {
            data: &two_basins,
            cone: 0.0,
        };
        let found = Solution {
            c: b,
            cost: 0.0,
            evaluations: 0,
        };
        let liar = |c: &Quat| -angle_deg(c);
        let opts = (&ShapedOptions::default(), &ScreenOptions::default());
        let s = screen_basins(&shaped, &liar, found, opts);
        assert_eq!((s.c, s.cost), (b, 0.0));
        assert!(s.evaluations > 0);
    }
}
