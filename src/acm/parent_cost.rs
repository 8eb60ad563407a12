//! The ACM cost of a child joint over one window as a function of its
//! **proximal** IMU's sensor-frame correction `C_p` (the lookahead of
//! [`super::lookahead`]).
//!
//! With the proximal IMU corrected as `G_R_prox' = R_up(-h) G_R_prox C_p` and the
//! distal one as `G_R_dist' = R_up(-h_d) G_R_dist C_d`, the joint rotation is
//! `Rt = C_p^T B` with `B = G_R_prox^T R_up(h - h_d) G_R_dist C_d`, fixed here.
//! Only the five entries of `Rt` the Z-Y-X angles need are formed, from the rows
//! of `C_p^T` and the columns of `B`; the centroid term uses
//! `(c_p^-1 b) . q_c = b . (c_p q_c)`, one 4-vector per evaluation.
//!
//! With swing-twist limits ([`crate::limits::swing_twist`]) the excursion is
//! that model's, of the quaternion `c_p^-1 b` per sample.
//!
//! The value is the mean per-sample part of the window cost of docs/method.md
//! section 5, without any `lambda1` term (the penalties of `C_p` and of the
//! distal IMU's correction are counted by the caller, once each):
//! `(1/n) sum_i (Ex_i + Ey_i + Ez_i + lambda2 * RMSq_i)`, degrees.

use super::cost::{matrix_vectors, LimitTerms, BLOCK};
use super::swing_cost::SwingTerms;
use crate::limits::JointLimits;
use crate::rotation::Quat;
use nalgebra::{Quaternion, Vector3};

/// The samples laid out for the evaluation loop (structure of arrays):
/// `b[3 * j + i]` holds entry `(i, j)` of every sample's `B` (column `j`),
/// `q[k]` component `k` of its quaternion `[w, x, y, z]`.
#[derive(Debug, Clone, Default)]
struct Samples {
    b: [Vec<f64>; 9],
    q: [Vec<f64>; 4],
}

/// A child joint's window cost as a function of the proximal IMU's correction.
#[derive(Debug, Clone)]
pub struct ParentCost {
    /// The factors `B_i` in the limits' axes (`Q^T B_i Q`).
    samples: Samples,
    terms: LimitTerms,
    /// The child joint's limit axes: `C_p` is evaluated as `Q^T C_p Q`.
    axes: Option<crate::model::TableAxes>,
    /// Swing-twist limits, in place of `terms`' ranges (its centroid stays).
    swing: Option<SwingTerms>,
}

impl ParentCost {
    /// Prepares the cost for the fixed right factors `B_i` (see the module docs).
    pub fn new(b: impl Iterator<Item = Quat>, limits: &JointLimits) -> Self {
        let mut samples = Samples::default();
        for q in b.map(|q| limits.to_axes(&q)) {
            let cols = matrix_vectors(&q, false);
            for (j, col) in cols.iter().enumerate() {
                for (i, v) in col.iter().enumerate() {
                    samples.b[3 * j + i].push(*v);
                }
            }
            for (k, v) in [q.w, q.i, q.j, q.k].into_iter().enumerate() {
                samples.q[k].push(v);
            }
        }
        ParentCost {
            samples,
            terms: LimitTerms::new(limits),
            axes: limits.axes,
            swing: limits.swing_twist.map(SwingTerms::new),
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.samples.q[0].len()
    }

    /// True when the window holds no sample.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Mean excursion (plus centroid term) of `Rt = C_p^T B` over the samples,
    /// degrees; 0 for an empty window.
    pub fn eval(&self, c_p: &Quat) -> f64 {
        self.data(&self.in_axes(c_p), None)
    }

    /// A correction `c_p` (proximal segment frame) in the limits' axes: `Q^T C_p Q`.
    fn in_axes(&self, c_p: &Quat) -> Quat {
        match &self.axes {
            Some(a) => a.to_table(c_p),
            None => *c_p,
        }
    }

    /// [`ParentCost::eval`] and its gradient with respect to a rotation vector
    /// `v` (radians) of `C_p * exp(v)` at `v = 0`, degrees per radian. At a
    /// kink (a sample exactly on a limit or at the centroid) it is the
    /// gradient of one side.
    pub fn eval_grad(&self, c_p: &Quat) -> (f64, Vector3<f64>) {
        let mut g = Vector3::zeros();
        let f = self.data(&self.in_axes(c_p), Some(&mut g));
        // In the axes `C_p exp(v)` is `Q^T C_p Q exp(Q^T v)`: the gradient turns by Q.
        if let Some(a) = &self.axes {
            g = a.q * g;
        }
        (f, g)
    }

    /// The mean per-sample cost at `c_p`; with `grad`, its gradient too.
    ///
    /// `C_p exp(v)` turns `Rt` into `exp(-v) Rt = Rt exp(-Rt^T v)`, so with
    /// `g_i` a sample's gradient in the right tangent of `Rt` (what
    /// [`LimitTerms::excursion_grad`] gives) the gradient in `v` is
    /// `-C_p^T sum_i B_i g_i`: one 3-vector per sample beyond a limit.
    // Indexed loops over the parallel arrays of a block: the form the
    // compiler vectorises.
    #[allow(clippy::needless_range_loop)]
    fn data(&self, c_p: &Quat, grad: Option<&mut Vector3<f64>>) -> f64 {
        let n = self.len();
        if n == 0 {
            return 0.0;
        }
        // Rows of C_p^T are the columns of C_p.
        let [row0, row1, row2] = matrix_vectors(c_p, false);
        let b = &self.samples.b;
        let mut sum = 0.0;
        let mut bg = [0.0; 3];
        let mut e = [[0.0; BLOCK]; 5];
        // Swing-twist limits take the samples' excursions in place of the
        // Euler ranges' loop below, which then has nothing left to do.
        let mut start = match &self.swing {
            Some(st) => {
                sum += self.swing_sum(st, c_p, grad.is_some().then_some(&mut bg));
                n
            }
            None => 0,
        };
        while start < n {
            let len = BLOCK.min(n - start);
            let col = |k: usize| &b[k][start..start + len];
            let (c0, c1, c2) = (
                (col(0), col(1), col(2)),
                (col(3), col(4), col(5)),
                (col(6), col(7), col(8)),
            );
            for i in 0..len {
                e[0][i] = row0[0] * c0.0[i] + row0[1] * c0.1[i] + row0[2] * c0.2[i];
                e[1][i] = row1[0] * c0.0[i] + row1[1] * c0.1[i] + row1[2] * c0.2[i];
                e[2][i] = row2[0] * c0.0[i] + row2[1] * c0.1[i] + row2[2] * c0.2[i];
                e[3][i] = row2[0] * c1.0[i] + row2[1] * c1.1[i] + row2[2] * c1.2[i];
                e[4][i] = row2[0] * c2.0[i] + row2[1] * c2.1[i] + row2[2] * c2.2[i];
            }
            // Samples inside every range add nothing: only the others, in order.
            let mut outside = [0u8; BLOCK];
            let m = self.terms.outside(&e, len, &mut outside);
            for &i in &outside[..m] {
                let i = usize::from(i);
                let entries = [e[0][i], e[1][i], e[2][i], e[3][i], e[4][i]];
                if grad.is_none() {
                    sum += self.terms.excursion(entries);
                    continue;
                }
                let mut g = [0.0; 3];
                sum += self.terms.excursion_grad(entries, &mut g);
                if g != [0.0; 3] {
                    bg[0] += c0.0[i] * g[0] + c1.0[i] * g[1] + c2.0[i] * g[2];
                    bg[1] += c0.1[i] * g[0] + c1.1[i] * g[1] + c2.1[i] * g[2];
                    bg[2] += c0.2[i] * g[0] + c1.2[i] * g[1] + c2.2[i] * g[2];
                }
            }
            start += len;
        }
        let mut g = Vector3::zeros();
        if grad.is_some() {
            // -C_p^T (sum B_i g_i): the rows of C_p^T dotted with the sum.
            for (k, row) in [row0, row1, row2].iter().enumerate() {
                g[k] = -(row[0] * bg[0] + row[1] * bg[1] + row[2] * bg[2]);
            }
        }
        if let Some(qc) = self.terms.centroid {
            // (c_p^-1 b) . qc = b . (c_p qc): one 4-vector per evaluation.
            let p = c_p * qc;
            let p4 = [p.w, p.i, p.j, p.k];
            if grad.is_none() {
                sum += self.terms.centroid_sum_soa(&self.samples.q, &p4, None);
            } else {
                let mut weighted = [0.0; 4];
                sum += self
                    .terms
                    .centroid_sum_soa(&self.samples.q, &p4, Some(&mut weighted));
                // d/dv of c_p exp(v) qc along e_k: c_p (0, e_k / 2) qc.
                for k in 0..3 {
                    let mut axis = [0.0; 3];
                    axis[k] = 0.5;
                    let u = c_p.into_inner()
                        * Quaternion::new(0.0, axis[0], axis[1], axis[2])
                        * qc.into_inner();
                    g[k] += u.w * weighted[0]
                        + u.i * weighted[1]
                        + u.j * weighted[2]
                        + u.k * weighted[3];
                }
            }
        }
        let n = n as f64;
        if let Some(out) = grad {
            *out = g / n;
        }
        sum / n
    }
}

impl ParentCost {
    /// `sum_i excursion(c_p^-1 b_i)` on swing-twist limits (degrees); with
    /// `bg`, adds `sum_i B_i g_i` to it (`g_i` the sample's gradient in the
    /// right tangent of `Rt_i`, degrees per radian).
    // Indexed loops over the parallel arrays of the samples.
    #[allow(clippy::needless_range_loop)]
    fn swing_sum(&self, st: &SwingTerms, c_p: &Quat, bg: Option<&mut [f64; 3]>) -> f64 {
        let q = &self.samples.q;
        let b = &self.samples.b;
        // conj(c_p) * b_i, componentwise.
        let (cw, cx, cy, cz) = (c_p.w, -c_p.i, -c_p.j, -c_p.k);
        let qt = |i: usize| -> [f64; 4] {
            let (w, x, y, z) = (q[0][i], q[1][i], q[2][i], q[3][i]);
            [
                cw * w - cx * x - cy * y - cz * z,
                cw * x + cx * w + cy * z - cz * y,
                cw * y - cx * z + cy * w + cz * x,
                cw * z + cx * y - cy * x + cz * w,
            ]
        };
        let mut sum = 0.0;
        match bg {
            None => {
                for i in 0..self.len() {
                    sum += st.excursion(qt(i));
                }
            }
            Some(bg) => {
                for i in 0..self.len() {
                    let (e, g) = st.excursion_grad(qt(i));
                    sum += e;
                    if g != [0.0; 3] {
                        // B_i g: entry (r, j) of B_i is b[3 j + r].
                        for (r, out) in bg.iter_mut().enumerate() {
                            *out += b[r][i] * g[0] + b[3 + r][i] * g[1] + b[6 + r][i] * g[2];
                        }
                    }
                }
            }
        }
        sum
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::acm::cost::{cost_direct, random_quat, test_axes};
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn check(limits: JointLimits) {
        for axes in test_axes() {
            check_in(JointLimits { axes, ..limits });
        }
    }

    fn check_in(limits: JointLimits) {
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        let b: Vec<Quat> = (0..300).map(|_| random_quat(&mut rng, 180.0)).collect();
        let cost = ParentCost::new(b.iter().copied(), &limits);
        for _ in 0..30 {
            let c = random_quat(&mut rng, 60.0);
            let turned: Vec<Quat> = b.iter().map(|q| c.inverse() * q).collect();
            let direct = cost_direct(&turned, &Quat::identity(), &limits, 0.0);
            let fast = cost.eval(&c);
            assert!((fast - direct).abs() < 1e-9, "{fast} vs {direct}");
        }
    }

    #[test]
    fn parent_cost_equals_the_direct_formula() {
        check(JointLimits {
            range_deg: [[-5.0, 5.0], [0.0, 130.0], [-5.0, 5.0]],
            centroid_deg: None,
            lambda2: 0.0,
            axes: None,
            swing_twist: None,
        });
        check(JointLimits {
            range_deg: [[-45.0, 160.0], [-60.0, 60.0], [-170.0, 90.0]],
            centroid_deg: Some([47.0, -1.0, -31.0]),
            lambda2: 30.0,
            axes: None,
            swing_twist: None,
        });
    }

    /// The gradient against central differences over 1e-7 rad; a point
    /// where the one-sided differences disagree has a kink within the step
    /// and is skipped (few may be). In every test axes (proper and mirrored).
    fn check_gradient(limits: JointLimits) {
        for axes in test_axes() {
            check_gradient_in(JointLimits { axes, ..limits });
        }
    }

    fn check_gradient_in(limits: JointLimits) {
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let b: Vec<Quat> = (0..300).map(|_| random_quat(&mut rng, 120.0)).collect();
        let cost = ParentCost::new(b.iter().copied(), &limits);
        let mut near_kink = 0;
        for _ in 0..30 {
            let c = random_quat(&mut rng, 60.0);
            let (f, g) = cost.eval_grad(&c);
            assert_eq!(f, cost.eval(&c));
            let h = 1e-7;
            for k in 0..3 {
                let mut v = nalgebra::Vector3::zeros();
                v[k] = h;
                let up = (cost.eval(&(c * Quat::from_scaled_axis(v))) - f) / h;
                let down = (f - cost.eval(&(c * Quat::from_scaled_axis(-v)))) / h;
                let tol = 1e-4 * (1.0 + g[k].abs());
                if (up - down).abs() > tol {
                    near_kink += 1;
                    continue;
                }
                let fd = 0.5 * (up + down);
                assert!((fd - g[k]).abs() < tol, "axis {k}: {fd} vs {}", g[k]);
            }
        }
        assert!(near_kink < 5, "{near_kink} of 90 near a kink");
    }

    #[test]
    fn parent_cost_gradient_matches_finite_differences() {
        check_gradient(JointLimits {
            range_deg: [[-5.0, 5.0], [0.0, 130.0], [-5.0, 5.0]],
            centroid_deg: None,
            lambda2: 0.0,
            axes: None,
            swing_twist: None,
        });
        check_gradient(JointLimits {
            range_deg: [[-45.0, 160.0], [-60.0, 60.0], [-170.0, 90.0]],
            centroid_deg: Some([47.0, -1.0, -31.0]),
            lambda2: 30.0,
            axes: None,
            swing_twist: None,
        });
        check_gradient(JointLimits {
            range_deg: [[-180.0, 180.0], [-10.0, 30.0], [-180.0, 180.0]],
            centroid_deg: None,
            lambda2: 0.0,
            axes: None,
            swing_twist: None,
        });
    }
}
