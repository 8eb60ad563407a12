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

    /// The excursion (degrees) of one rotation with quaternion `q` (`[w, x,
    /// y, z]`, the limits' axes).
    #[inline]
    pub(super) fn excursion(&self, q: [f64; 4]) -> f64 {
        self.limits.excursion(q)
    }

    /// The excursion of `q` and its gradient (degrees per radian) with
    /// respect to a rotation vector `v` of `R * exp(v)` at `v = 0`.
    #[inline]
    pub(super) fn excursion_grad(&self, q: [f64; 4]) -> (f64, [f64; 3]) {
        self.limits.excursion_grad(q)
    }

    /// The excursion of `q` and its derivative (degrees per radian) along a
    /// path on which the unit quaternion moves at rate `dq` (per radian):
    /// `dq = q * (0, w / 2)` with `w = 2 Im(q^-1 dq)`, so the derivative is
    /// the gradient dotted with `w`.
    #[inline]
    pub(super) fn excursion_along(&self, q: [f64; 4], dq: [f64; 4]) -> (f64, f64) {
        let (e, g) = self.limits.excursion_grad(q);
        if g == [0.0; 3] {
            return (e, 0.0);
        }
        let [w, x, y, z] = q;
        let [dw, dx, dy, dz] = dq;
        // Im(conj(q) dq) = w dv - dw v - v x dv.
        let rate = [
            2.0 * (w * dx - dw * x - (y * dz - z * dy)),
            2.0 * (w * dy - dw * y - (z * dx - x * dz)),
            2.0 * (w * dz - dw * z - (x * dy - y * dx)),
        ];
        (e, g[0] * rate[0] + g[1] * rate[1] + g[2] * rate[2])
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
