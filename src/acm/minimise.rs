//! Minimising the ACM cost over rotations.
//!
//! The cost is piecewise smooth with kinks (excursions switch on and off, the
//! `lambda1 * angle(C)` term has a cone at identity) and flat regions, so the
//! minimiser uses no gradients: Nelder-Mead over a rotation vector `v` (radians)
//! in the tangent space of a reference rotation, `C = C_ref * exp(v)`. The
//! reference is moved to the best point at every restart, so the
//! parameterisation never nears its singularity. A restart with a fresh simplex
//! follows every convergence until it no longer lowers the cost, which takes
//! care of simplices that collapse on a kink.

use crate::rotation::{quat_from_rotvec, Quat};
use nalgebra::Vector3;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{angle_between_deg, angle_deg, quat_axis_angle_deg};

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
}
