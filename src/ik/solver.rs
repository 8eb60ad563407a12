//! One frame of IMU inverse kinematics (docs/method.md section 15): the
//! base rotation and joint coordinates that minimise `sum_i w_i * x_i^2`, where
//! `x_i` is the angle of IMU i's orientation error, inside the hard limits.
//!
//! Residual of IMU i (global frame, radians): `g_i = log(M_i * S_i^-1)`, the
//! rotation vector from the model segment `S_i` to the measured orientation
//! `M_i`; `|g_i| = x_i`. Moving a coordinate whose global axis is `a` rotates
//! every segment below it about `a`, and `dg_i/dq = -Jr^-1(g_i) a` (`Jr` the
//! right Jacobian of SO(3)). The base's three columns are rotations about the
//! global X, Y and Z axes (`B <- exp(d) B`).
//!
//! Levenberg-Marquardt with box constraints: coordinates at a limit whose
//! gradient points outwards are held (active set); the others take the damped
//! Gauss-Newton step `(H + lambda diag H) d = -grad` (Cholesky), the result is
//! clamped into the limits and kept only if the cost falls (else lambda x10).
//! Every pose the solver ever holds is inside the hard limits.

use super::skeleton::{Skeleton, BASE_COLUMNS};
use crate::rotation::{euler_zyx_deg, Quat};
use nalgebra::{UnitQuaternion, Vector3};

/// A pose of the tree: the base rotation and the coordinates (radians).
#[derive(Debug, Clone, PartialEq)]
pub struct Pose {
    /// `S_base`, base segment frame to global.
    pub base: Quat,
    /// Joint coordinates in [`Skeleton::coordinates`] order, radians.
    pub q: Vec<f64>,
}

/// Stopping rules of the per-frame solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SolverOptions {
    /// At most this many Gauss-Newton steps per frame.
    pub max_iterations: u32,
    /// Converged when no unknown would move by more than this, radians.
    pub step_tolerance_rad: f64,
    /// Damping at the start of each frame (relative to the diagonal of H).
    pub initial_damping: f64,
}

impl Default for SolverOptions {
    fn default() -> SolverOptions {
        SolverOptions {
            max_iterations: 50,
            // 6e-8 degrees: far below any figure reported; where a frame's
            // residuals are large, convergence is linear (about x0.3 per
            // step) and the error left is below the last step.
            step_tolerance_rad: 1e-9,
            initial_damping: 1e-6,
        }
    }
}

/// What solving one frame took.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameStats {
    /// `sum_i w_i * x_i^2`, radians squared.
    pub cost: f64,
    /// Gauss-Newton steps taken (accepted or not).
    pub iterations: u32,
}

/// The largest damping tried before a frame is declared converged.
const MAX_DAMPING: f64 = 1e10;
/// Relative rise of the cost still counted as no rise (round-off).
const ROUND_OFF: f64 = 1e-13;
/// The smallest damping a run of successful steps lowers it to.
const MIN_DAMPING: f64 = 1e-12;

/// Per-frame solver with its work buffers (no allocation per frame).
pub struct Solver<'a> {
    sk: &'a Skeleton,
    opts: SolverOptions,
    /// Segment orientations of the pose last evaluated.
    orient: Vec<Quat>,
    /// Global axis of each coordinate in that pose.
    axes: Vec<Vector3<f64>>,
    /// Residual `g_i` of each segment.
    resid: Vec<Vector3<f64>>,
    h: Vec<f64>,
    grad: Vec<f64>,
    /// Columns not held by the gradient test, and those the step moves.
    unheld: Vec<usize>,
    free: Vec<usize>,
    a: Vec<f64>,
    b: Vec<f64>,
    u: Vec<Vector3<f64>>,
    candidate: Pose,
}

impl<'a> Solver<'a> {
    pub fn new(sk: &'a Skeleton, opts: SolverOptions) -> Solver<'a> {
        let n = sk.columns();
        let segs = sk.segments.len();
        Solver {
            sk,
            opts,
            orient: vec![Quat::identity(); segs],
            axes: vec![Vector3::zeros(); sk.coordinates.len()],
            resid: vec![Vector3::zeros(); segs],
            h: vec![0.0; n * n],
            grad: vec![0.0; n],
            unheld: Vec::with_capacity(n),
            free: Vec::with_capacity(n),
            a: vec![0.0; n * n],
            b: vec![0.0; n],
            u: Vec::with_capacity(n),
            candidate: Pose {
                base: Quat::identity(),
                q: vec![0.0; sk.coordinates.len()],
            },
        }
    }

    /// Segment orientations of the pose last evaluated (segment to global).
    pub fn orientations(&self) -> &[Quat] {
        &self.orient
    }

    /// Forward kinematics: segment orientations and coordinate axes of `pose`.
    pub fn forward(&mut self, pose: &Pose) {
        forward(self.sk, pose, &mut self.orient, &mut self.axes);
    }

    /// Residuals of the pose last evaluated against `measured` (one per
    /// segment); returns the cost `sum w_i x_i^2` (radians squared).
    fn residuals(&mut self, measured: &[Quat]) -> f64 {
        let mut cost = 0.0;
        for (k, s) in self.sk.segments.iter().enumerate() {
            let g = log(&(measured[k] * self.orient[k].inverse()));
            cost += s.weight * g.norm_squared();
            self.resid[k] = g;
        }
        cost
    }

    /// A starting pose from the measurements alone: the base as measured, each
    /// joint's moving angles as measured against its parent's model segment,
    /// clamped into the hard limits.
    pub fn initial_pose(&mut self, measured: &[Quat]) -> Pose {
        let sk = self.sk;
        let mut pose = Pose {
            base: measured[0],
            q: sk.coordinates.iter().map(|c| c.default).collect(),
        };
        self.orient[0] = measured[0];
        for (k, s) in sk.segments.iter().enumerate().skip(1) {
            let p = s.parent.expect("only the base has no parent");
            let rel = self.orient[p].inverse() * measured[k];
            let in_table = s.frame.inverse() * rel * s.frame;
            let table = euler_zyx_deg(&in_table).map(|a| s.det * a);
            let e = match &s.limit_box {
                Some(b) => crate::rotation::read_in_box(table, b),
                None => table,
            }
            .map(f64::to_radians);
            for (axis, c) in s.coordinate.iter().enumerate() {
                if let Some(c) = *c {
                    let co = &sk.coordinates[c];
                    pose.q[c] = e[axis].clamp(co.lower, co.upper);
                }
            }
            let table = sk.joint_angles(k, &pose.q).map(|a| s.det * a);
            self.orient[k] = self.orient[p] * s.frame * joint_rotation(table) * s.frame.inverse();
        }
        pose
    }

    /// Solves one frame from `pose` (the warm start, inside the limits);
    /// leaves the solution in `pose` and its orientations in [`Self::orientations`].
    pub fn solve(&mut self, measured: &[Quat], pose: &mut Pose) -> FrameStats {
        let n = self.sk.columns();
        self.forward(pose);
        let mut cost = self.residuals(measured);
        let mut lambda = self.opts.initial_damping;
        let mut iterations = 0;
        let mut current = true; // buffers hold `pose`
        while iterations < self.opts.max_iterations && cost > 0.0 {
            if !current {
                self.forward(pose);
                self.residuals(measured);
                current = true;
            }
            self.normal_equations();
            self.unheld.clear();
            for c in 0..n {
                if !self.held(c, pose) {
                    self.unheld.push(c);
                }
            }
            if self.unheld.is_empty() {
                break;
            }
            let mut step = None;
            while lambda <= MAX_DAMPING {
                iterations += 1;
                if !self.damped_step(lambda, pose) {
                    lambda *= 10.0;
                    continue;
                }
                let m = self.free.len();
                let largest = self.b[..m].iter().fold(0.0f64, |m, d| m.max(d.abs()));
                if largest < self.opts.step_tolerance_rad {
                    step = Some((largest, false));
                    break;
                }
                self.apply_step(pose);
                let candidate = std::mem::replace(
                    &mut self.candidate,
                    Pose {
                        base: Quat::identity(),
                        q: vec![],
                    },
                );
                self.forward(&candidate);
                let trial_cost = self.residuals(measured);
                self.candidate = candidate;
                // Near the solution of a large-residual frame the cost stops
                // changing in its last bits while the steps still shrink:
                // round-off-sized rises are taken, so that the steps, not the
                // cost's last digit, decide convergence.
                if trial_cost < cost * (1.0 + ROUND_OFF) {
                    std::mem::swap(pose, &mut self.candidate);
                    cost = trial_cost;
                    current = true;
                    lambda = (lambda * 0.1).max(MIN_DAMPING);
                    step = Some((largest, true));
                    break;
                }
                current = false;
                lambda *= 10.0;
                if iterations >= self.opts.max_iterations {
                    break;
                }
            }
            match step {
                Some((largest, true)) if largest >= self.opts.step_tolerance_rad => {}
                _ => break,
            }
        }
        if !current {
            self.forward(pose);
        }
        FrameStats { cost, iterations }
    }

    /// Whether column `c` sits at a hard limit with the gradient pointing out.
    fn held(&self, c: usize, pose: &Pose) -> bool {
        let Some(k) = c.checked_sub(BASE_COLUMNS) else {
            return false;
        };
        let co = &self.sk.coordinates[k];
        let g = self.grad[c];
        (pose.q[k] <= co.lower && g > 0.0) || (pose.q[k] >= co.upper && g < 0.0)
    }

    /// `H = sum w J^T J` and `grad = sum w J^T g` at the pose last evaluated.
    fn normal_equations(&mut self) {
        let n = self.sk.columns();
        self.h.iter_mut().for_each(|v| *v = 0.0);
        self.grad.iter_mut().for_each(|v| *v = 0.0);
        for (k, s) in self.sk.segments.iter().enumerate() {
            let g = self.resid[k];
            let jr_inv = RightJacobianInverse::new(&g);
            self.u.clear();
            for &col in &s.columns {
                let a = if col < BASE_COLUMNS {
                    let mut e = Vector3::zeros();
                    e[col] = 1.0;
                    e
                } else {
                    self.axes[col - BASE_COLUMNS]
                };
                self.u.push(-jr_inv.apply(&a));
            }
            for (i, &ci) in s.columns.iter().enumerate() {
                let ui = self.u[i];
                self.grad[ci] += s.weight * ui.dot(&g);
                for (j, &cj) in s.columns.iter().enumerate().take(i + 1) {
                    self.h[ci * n + cj] += s.weight * ui.dot(&self.u[j]);
                }
            }
        }
    }

    /// Solves `(H_FF + lambda diag H_FF) d = -grad_F` into `b` over the free
    /// columns of `unheld`; a coordinate on a limit that the step would push
    /// out is held too, and the step solved again (projected Newton). False
    /// when the damped matrix is not positive definite.
    fn damped_step(&mut self, lambda: f64, pose: &Pose) -> bool {
        self.free.clone_from(&self.unheld);
        loop {
            if !self.solve_free(lambda) {
                return false;
            }
            let before = self.free.len();
            let mut k = 0;
            self.free.retain(|&c| {
                let d = self.b[k];
                k += 1;
                let Some(q) = c.checked_sub(BASE_COLUMNS) else {
                    return true;
                };
                let co = &self.sk.coordinates[q];
                !((pose.q[q] <= co.lower && d < 0.0) || (pose.q[q] >= co.upper && d > 0.0))
            });
            if self.free.len() == before {
                return true;
            }
            if self.free.is_empty() {
                self.b.iter_mut().for_each(|v| *v = 0.0);
                return true;
            }
        }
    }

    /// `(H_FF + lambda diag H_FF) d = -grad_F` into `b`.
    fn solve_free(&mut self, lambda: f64) -> bool {
        let n = self.sk.columns();
        let m = self.free.len();
        for (i, &ci) in self.free.iter().enumerate() {
            for (j, &cj) in self.free.iter().enumerate().take(i + 1) {
                // H is filled in its lower triangle (row >= column); columns
                // of a segment ascend, so ci >= cj here.
                self.a[i * m + j] = self.h[ci * n + cj];
            }
            let d = self.h[ci * n + ci];
            self.a[i * m + i] = d + lambda * d.max(1e-12);
            self.b[i] = -self.grad[ci];
        }
        cholesky_solve(&mut self.a[..m * m], m, &mut self.b[..m])
    }

    /// `candidate = pose + d` (base rotated about global axes), clamped.
    fn apply_step(&mut self, pose: &Pose) {
        let mut rot = Vector3::zeros();
        self.candidate.q.clone_from(&pose.q);
        for (i, &c) in self.free.iter().enumerate() {
            match c.checked_sub(BASE_COLUMNS) {
                None => rot[c] = self.b[i],
                Some(k) => self.candidate.q[k] += self.b[i],
            }
        }
        self.candidate.base = UnitQuaternion::from_scaled_axis(rot) * pose.base;
        self.sk.clamp(&mut self.candidate.q);
    }
}

/// `Rz(z) Ry(y) Rx(x)` for `[x, y, z]` in radians.
pub fn joint_rotation(a: [f64; 3]) -> Quat {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), a[2])
        * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), a[1])
        * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), a[0])
}

/// Forward kinematics into `orient` (per segment) and `axes` (per coordinate).
pub fn forward(sk: &Skeleton, pose: &Pose, orient: &mut [Quat], axes: &mut [Vector3<f64>]) {
    orient[0] = pose.base;
    for (k, s) in sk.segments.iter().enumerate().skip(1) {
        // S_d = S_p Q Rz(d z) Ry(d y) Rx(d x) Q^T (module docs).
        let p = orient[s.parent.expect("only the base has no parent")] * s.frame;
        let [x, y, z] = sk.joint_angles(k, &pose.q).map(|a| s.det * a);
        let pz = p * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), z);
        let pzy = pz * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), y);
        if let Some(c) = s.coordinate[2] {
            axes[c] = (p * Vector3::z()) * s.det;
        }
        if let Some(c) = s.coordinate[1] {
            axes[c] = (pz * Vector3::y()) * s.det;
        }
        if let Some(c) = s.coordinate[0] {
            axes[c] = (pzy * Vector3::x()) * s.det;
        }
        orient[k] =
            pzy * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), x) * s.frame.inverse();
    }
}

/// The rotation vector of `q` (radians), angle in `[0, pi]`.
pub fn log(q: &Quat) -> Vector3<f64> {
    let (w, v) = if q.w < 0.0 {
        (-q.w, -q.imag())
    } else {
        (q.w, q.imag())
    };
    let s = v.norm();
    if s < 1e-12 {
        return v * 2.0;
    }
    v * (2.0 * s.atan2(w) / s)
}

/// `Jr^-1(g) = I + 1/2 [g]x + c(theta) [g]x^2`, applied to vectors.
struct RightJacobianInverse {
    g: Vector3<f64>,
    c: f64,
}

impl RightJacobianInverse {
    fn new(g: &Vector3<f64>) -> RightJacobianInverse {
        let t2 = g.norm_squared();
        let c = if t2 < 1e-8 {
            1.0 / 12.0 + t2 / 720.0
        } else {
            let t = t2.sqrt();
            1.0 / t2 - (1.0 + t.cos()) / (2.0 * t * t.sin())
        };
        RightJacobianInverse { g: *g, c }
    }

    fn apply(&self, a: &Vector3<f64>) -> Vector3<f64> {
        let ga = self.g.cross(a);
        a + ga * 0.5 + self.g.cross(&ga) * self.c
    }
}

/// Solves `A x = b` for a symmetric positive definite `A` (row-major, lower
/// triangle read) by Cholesky, in place: `b` becomes `x`. False if `A` is not
/// positive definite.
pub fn cholesky_solve(a: &mut [f64], m: usize, b: &mut [f64]) -> bool {
    for j in 0..m {
        let mut d = a[j * m + j];
        for k in 0..j {
            d -= a[j * m + k] * a[j * m + k];
        }
        if !(d > 0.0 && d.is_finite()) {
            return false;
        }
        let d = d.sqrt();
        a[j * m + j] = d;
        for i in j + 1..m {
            let mut s = a[i * m + j];
            for k in 0..j {
                s -= a[i * m + k] * a[j * m + k];
            }
            a[i * m + j] = s / d;
        }
    }
    for i in 0..m {
        let mut s = b[i];
        for k in 0..i {
            s -= a[i * m + k] * b[k];
        }
        b[i] = s / a[i * m + i];
    }
    for i in (0..m).rev() {
        let mut s = b[i];
        for k in i + 1..m {
            s -= a[k * m + i] * b[k];
        }
        b[i] = s / a[i * m + i];
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Model;
    use crate::rotation::quat_axis_angle_deg;

    /// A pose 10-40 deg away from a random measurement: large residuals,
    /// where an approximate Jacobian would show.
    fn setup() -> (Skeleton, Vec<Quat>, Pose) {
        let model = Model::infant13();
        let sk = Skeleton::new(&model, |_| true).unwrap();
        let measured: Vec<Quat> = (0..sk.segments.len())
            .map(|k| quat_axis_angle_deg([1.0, k as f64, 2.0 - k as f64], 7.0 * k as f64))
            .collect();
        let pose = Pose {
            base: quat_axis_angle_deg([0.3, -1.0, 0.2], 25.0),
            q: (0..sk.coordinates.len())
                .map(|c| (0.3 * c as f64).sin() * 0.6)
                .collect(),
        };
        (sk, measured, pose)
    }

    #[test]
    fn gradient_matches_finite_differences_of_the_cost() {
        let (sk, measured, pose) = setup();
        let mut s = Solver::new(&sk, SolverOptions::default());
        s.forward(&pose);
        let c0 = s.residuals(&measured);
        assert!(c0 > 0.5, "residuals should be large here: {c0}");
        s.normal_equations();
        let grad = s.grad.clone();
        let h = 1e-6;
        for col in 0..sk.columns() {
            let mut shifted = |d: f64| {
                let mut p = pose.clone();
                if col < BASE_COLUMNS {
                    let mut v = Vector3::zeros();
                    v[col] = d;
                    p.base = UnitQuaternion::from_scaled_axis(v) * p.base;
                } else {
                    p.q[col - BASE_COLUMNS] += d;
                }
                s.forward(&p);
                s.residuals(&measured)
            };
            // grad is of cost / 2.
            let fd = (shifted(h) - shifted(-h)) / (4.0 * h);
            assert!(
                (fd - grad[col]).abs() < 1e-6 * (1.0 + fd.abs()),
                "column {col}: {fd} vs {}",
                grad[col]
            );
        }
    }

    #[test]
    fn cholesky_solves_a_known_system() {
        // A = L L^T with L = [[2, 0, 0], [1, 3, 0], [-1, 0.5, 1]].
        let mut a = vec![4.0, 0.0, 0.0, 2.0, 10.0, 0.0, -2.0, 0.5, 2.25];
        let x = [1.0, -2.0, 0.5];
        let mut b = vec![
            4.0 * x[0] + 2.0 * x[1] - 2.0 * x[2],
            2.0 * x[0] + 10.0 * x[1] + 0.5 * x[2],
            -2.0 * x[0] + 0.5 * x[1] + 2.25 * x[2],
        ];
        assert!(cholesky_solve(&mut a, 3, &mut b));
        for k in 0..3 {
            assert!((b[k] - x[k]).abs() < 1e-12, "{b:?}");
        }
        let mut not_pd = vec![1.0, 0.0, 2.0, 1.0];
        assert!(!cholesky_solve(&mut not_pd, 2, &mut [1.0, 1.0]));
    }

    #[test]
    fn solve_lowers_the_cost_and_stays_in_the_limits() {
        let (sk, measured, pose) = setup();
        let mut s = Solver::new(&sk, SolverOptions::default());
        let mut p = pose.clone();
        sk.clamp(&mut p.q);
        s.forward(&p);
        let before = s.residuals(&measured);
        let stats = s.solve(&measured, &mut p);
        assert!(stats.cost < 0.5 * before, "{} -> {}", before, stats.cost);
        for (v, c) in p.q.iter().zip(&sk.coordinates) {
            assert!(*v >= c.lower && *v <= c.upper);
        }
        // The orientations returned are those of the solution.
        let mut o = vec![Quat::identity(); sk.segments.len()];
        let mut a = vec![Vector3::zeros(); sk.coordinates.len()];
        forward(&sk, &p, &mut o, &mut a);
        assert_eq!(o, s.orientations());
        // Solving again from the solution does not move it.
        let again = s.solve(&measured, &mut p.clone());
        assert!((again.cost - stats.cost).abs() <= 1e-12 * stats.cost);
    }
}
