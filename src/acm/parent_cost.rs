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
//! The value is the mean per-sample part of the window cost of docs/method.md
//! section 5, without any `lambda1` term (the penalties of `C_p` and of the
//! distal IMU's correction are counted by the caller, once each):
//! `(1/n) sum_i (Ex_i + Ey_i + Ez_i + lambda2 * RMSq_i)`, degrees.

use super::cost::{dot3, matrix_vectors, LimitTerms};
use crate::limits::JointLimits;
use crate::rotation::Quat;

/// One sample: the columns of `B` and its quaternion `[w, x, y, z]`.
#[derive(Debug, Clone, Copy)]
struct Sample {
    col0: [f64; 3],
    col1: [f64; 3],
    col2: [f64; 3],
    q: [f64; 4],
}

/// A child joint's window cost as a function of the proximal IMU's correction.
#[derive(Debug, Clone)]
pub struct ParentCost {
    /// The factors `B_i` in the limits' axes (`Q^T B_i Q`).
    samples: Vec<Sample>,
    terms: LimitTerms,
    /// The child joint's limit axes: `C_p` is evaluated as `Q^T C_p Q`.
    axes: Option<crate::model::TableAxes>,
}

impl ParentCost {
    /// Prepares the cost for the fixed right factors `B_i` (see the module docs).
    pub fn new(b: impl Iterator<Item = Quat>, limits: &JointLimits) -> Self {
        let samples = b
            .map(|q| limits.to_axes(&q))
            .map(|q| {
                let [col0, col1, col2] = matrix_vectors(&q, false);
                Sample {
                    col0,
                    col1,
                    col2,
                    q: [q.w, q.i, q.j, q.k],
                }
            })
            .collect();
        ParentCost {
            samples,
            terms: LimitTerms::new(limits),
            axes: limits.axes,
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// True when the window holds no sample.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// Mean excursion (plus centroid term) of `Rt = C_p^T B` over the samples,
    /// degrees; 0 for an empty window.
    pub fn eval(&self, c_p: &Quat) -> f64 {
        if self.samples.is_empty() {
            return 0.0;
        }
        // In the limits' axes `Rt` is `(Q^T C_p Q)^T (Q^T B Q)`.
        let c_p = &match &self.axes {
            Some(a) => a.to_table(c_p),
            None => *c_p,
        };
        // Rows of C_p^T are the columns of C_p.
        let [row0, row1, row2] = matrix_vectors(c_p, false);
        let mut sum = 0.0;
        for s in &self.samples {
            sum += self.terms.excursion([
                dot3(&row0, &s.col0),
                dot3(&row1, &s.col0),
                dot3(&row2, &s.col0),
                dot3(&row2, &s.col1),
                dot3(&row2, &s.col2),
            ]);
        }
        if let Some(qc) = self.terms.centroid {
            sum += self
                .terms
                .centroid_sum(self.samples.iter().map(|s| &s.q), &(c_p * qc));
        }
        sum / self.samples.len() as f64
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
        });
        check(JointLimits {
            range_deg: [[-45.0, 160.0], [-60.0, 60.0], [-170.0, 90.0]],
            centroid_deg: Some([47.0, -1.0, -31.0]),
            lambda2: 30.0,
            axes: None,
        });
    }
}
