//! The ACM's per-sample limit term on swing-twist limits
//! ([`crate::limits::swing_twist`]): the excursion of `Rt_i = Rm_i * C`
//! beyond the swing region plus beyond the twist range, degrees, and its
//! gradient. [`super::cost::WindowCost`] uses it in place of the Euler ranges
//! when the joint's limits are of this model; the centroid term is the same.

use crate::limits::swing_twist::SwingTwistLimits;
use crate::rotation::Quat;

/// The swing-twist limit term of one joint.
#[derive(Debug, Clone, Copy)]
pub(super) struct SwingTerms {
    limits: SwingTwistLimits,
}

impl SwingTerms {
    pub(super) fn new(limits: SwingTwistLimits) -> Self {
        SwingTerms { limits }
    }

    /// `sum_i excursion(q_i * c)` (degrees) over quaternions held as
    /// component arrays `q` (`[w, x, y, z]`, the limits' axes), `c` the
    /// correction in the same axes. With `grad`, adds to it the sum's
    /// gradient with respect to a rotation vector `v` (radians) of
    /// `C * exp(v)` at `v = 0`, degrees per radian.
    pub(super) fn sum(&self, q: &[Vec<f64>; 4], c: &Quat, grad: Option<&mut [f64; 3]>) -> f64 {
        let n = q[0].len();
        let (cw, cx, cy, cz) = (c.w, c.i, c.j, c.k);
        let qt = |i: usize| -> [f64; 4] {
            let (w, x, y, z) = (q[0][i], q[1][i], q[2][i], q[3][i]);
            [
                w * cw - x * cx - y * cy - z * cz,
                w * cx + x * cw + y * cz - z * cy,
                w * cy - x * cz + y * cw + z * cx,
                w * cz + x * cy - y * cx + z * cw,
            ]
        };
        let mut sum = 0.0;
        match grad {
            None => {
                for i in 0..n {
                    sum += self.limits.excursion(qt(i));
                }
            }
            Some(g) => {
                // `Rt exp(v) = Rm C exp(v)`: the sample's gradient is the
                // correction's.
                for i in 0..n {
                    let (e, gi) = self.limits.excursion_grad(qt(i));
                    sum += e;
                    for (gk, gik) in g.iter_mut().zip(gi) {
                        *gk += gik;
                    }
                }
            }
        }
        sum
    }
}
