//! The ACM cost of one joint over one window (docs/method.md section 5; thesis eq. 3.9, 3.16).
//!
//! `e(C) = (1/n) sum_i (Ex_i + Ey_i + Ez_i + lambda2 * RMSq_i) + lambda1 * angle(C)`
//! where the excursions are of the Z-Y-X angles (degrees) of `Rt_i = Rm_i * C`,
//! `RMSq_i` is the sign-invariant distance between the quaternion of `Rt_i` and the
//! centroid's, and `angle(C)` is in degrees.
//!
//! The evaluation is the hot loop of the whole program, so it avoids trigonometry
//! for samples inside the limits: whether an angle lies in its range is decided
//! from the rotation matrix entries directly, and `atan2` / `asin` run only for
//! the samples that exceed a limit. The value is the same as the direct formula.

use crate::limits::JointLimits;
use crate::rotation::{angle_deg, euler_zyx_deg, quat_from_euler_zyx_deg, Quat};

/// Excursion of one angle `a` beyond `[lo, hi]` (degrees): `a - hi` above,
/// `lo - a` below, 0 inside.
#[inline(always)]
pub fn beyond(a: f64, lo: f64, hi: f64) -> f64 {
    if a > hi {
        a - hi
    } else if a < lo {
        lo - a
    } else {
        0.0
    }
}

/// Per-sample excursion of angles `[x, y, z]` (degrees) beyond `[lo, hi]` per axis.
pub fn excursion(angles_deg: [f64; 3], range_deg: &[[f64; 2]; 3]) -> [f64; 3] {
    std::array::from_fn(|axis| beyond(angles_deg[axis], range_deg[axis][0], range_deg[axis][1]))
}

/// Sign-invariant Euclidean distance between unit quaternions (eq. 3.17-3.21):
/// the smaller of `|q - c|` and `|q + c|`.
pub fn rmsq(q: &Quat, c: &Quat) -> f64 {
    let a = q.into_inner();
    let b = c.into_inner();
    (a - b).norm().min((a + b).norm())
}

/// The cost of correction `c` computed the direct way, sample by sample. Slow;
/// the reference that [`WindowCost::eval`] is tested against.
pub fn cost_direct(measured: &[Quat], c: &Quat, limits: &JointLimits, lambda1: f64) -> f64 {
    let centroid = limits.centroid_deg.map(quat_from_euler_zyx_deg);
    let sum: f64 = measured
        .iter()
        .map(|qm| {
            let qt = qm * c;
            let e: f64 = excursion(euler_zyx_deg(&qt), &limits.range_deg)
                .iter()
                .sum();
            match centroid {
                Some(qc) if limits.lambda2 > 0.0 => e + limits.lambda2 * rmsq(&qt, &qc),
                _ => e,
            }
        })
        .sum();
    sum / measured.len().max(1) as f64 + lambda1 * angle_deg(c)
}

/// Test of an angle `atan2(s, c)` against a range, without trigonometry.
#[derive(Debug, Clone, Copy)]
pub(super) struct ArcRange {
    lo: f64,
    hi: f64,
    lo_dir: [f64; 2],
    hi_dir: [f64; 2],
    /// The range spans the whole circle.
    full: bool,
    /// The range is wider than 180 degrees.
    wide: bool,
}

impl ArcRange {
    pub(super) fn new([lo, hi]: [f64; 2]) -> Self {
        let (sl, cl) = lo.to_radians().sin_cos();
        let (sh, ch) = hi.to_radians().sin_cos();
        ArcRange {
            lo,
            hi,
            lo_dir: [cl, sl],
            hi_dir: [ch, sh],
            full: hi - lo >= 360.0,
            wide: hi - lo > 180.0,
        }
    }

    /// Excursion (degrees) of the angle of the direction `(c, s)` = `atan2(s, c)`.
    #[inline(always)]
    pub(super) fn excursion(&self, s: f64, c: f64) -> f64 {
        if self.full {
            return 0.0;
        }
        let after_lo = self.lo_dir[0] * s - self.lo_dir[1] * c; // |d| sin(a - lo)
        let before_hi = c * self.hi_dir[1] - s * self.hi_dir[0]; // |d| sin(hi - a)
        let inside = if self.wide {
            after_lo >= 0.0 || before_hi >= 0.0
        } else {
            after_lo >= 0.0 && before_hi >= 0.0
        };
        if inside && (s != 0.0 || c != 0.0) {
            return 0.0;
        }
        beyond(s.atan2(c).to_degrees(), self.lo, self.hi)
    }
}

/// Test of `theta = -asin(r20)` against a range, without trigonometry.
#[derive(Debug, Clone, Copy)]
pub(super) struct PitchRange {
    lo: f64,
    hi: f64,
    /// theta >= lo  <=>  r20 <= r20_max
    r20_max: f64,
    /// theta <= hi  <=>  r20 >= r20_min
    r20_min: f64,
}

impl PitchRange {
    pub(super) fn new([lo, hi]: [f64; 2]) -> Self {
        let r20_max = if lo <= -90.0 {
            f64::INFINITY
        } else if lo >= 90.0 {
            f64::NEG_INFINITY
        } else {
            -lo.to_radians().sin()
        };
        let r20_min = if hi >= 90.0 {
            f64::NEG_INFINITY
        } else if hi <= -90.0 {
            f64::INFINITY
        } else {
            -hi.to_radians().sin()
        };
        PitchRange {
            lo,
            hi,
            r20_max,
            r20_min,
        }
    }

    #[inline(always)]
    pub(super) fn excursion(&self, r20: f64) -> f64 {
        if r20 <= self.r20_max && r20 >= self.r20_min {
            return 0.0;
        }
        beyond(-r20.clamp(-1.0, 1.0).asin().to_degrees(), self.lo, self.hi)
    }
}

/// The per-sample terms of a joint's limits (docs/method.md section 5): the
/// excursions beyond the three ranges and the centroid term.
#[derive(Debug, Clone)]
pub(super) struct LimitTerms {
    x: ArcRange,
    y: PitchRange,
    z: ArcRange,
    /// The centroid's rotation, when the term is on (`lambda2 > 0`).
    pub(super) centroid: Option<Quat>,
    lambda2: f64,
}

impl LimitTerms {
    pub(super) fn new(limits: &JointLimits) -> Self {
        LimitTerms {
            x: ArcRange::new(limits.range_deg[0]),
            y: PitchRange::new(limits.range_deg[1]),
            z: ArcRange::new(limits.range_deg[2]),
            centroid: match limits.centroid_deg {
                Some(c) if limits.lambda2 > 0.0 => Some(quat_from_euler_zyx_deg(c)),
                _ => None,
            },
            lambda2: limits.lambda2,
        }
    }

    /// `Ex + Ey + Ez` (degrees) of the Z-Y-X angles of a rotation, from its
    /// entries `[r00, r10, r20, r21, r22]`.
    #[inline(always)]
    pub(super) fn excursion(&self, [r00, r10, r20, r21, r22]: [f64; 5]) -> f64 {
        self.x.excursion(r21, r22) + self.y.excursion(r20) + self.z.excursion(r10, r00)
    }

    /// `lambda2 * RMSq` for the dot product `d` of a rotation's quaternion and
    /// the centroid's.
    #[inline(always)]
    pub(super) fn centroid_term(&self, d: f64) -> f64 {
        self.lambda2 * rmsq_of_dot(d)
    }

    /// The centroid terms summed over quaternions `qs` (`[w, x, y, z]`) dotted
    /// with `p` (0 without the term).
    pub(super) fn centroid_sum<'a>(&self, qs: impl Iterator<Item = &'a [f64; 4]>, p: &Quat) -> f64 {
        if self.centroid.is_none() {
            return 0.0;
        }
        let p = [p.w, p.i, p.j, p.k];
        let mut sum = 0.0;
        for q in qs {
            sum += rmsq_of_dot(q[0] * p[0] + q[1] * p[1] + q[2] * p[2] + q[3] * p[3]);
        }
        self.lambda2 * sum
    }
}

/// [`rmsq`] of two unit quaternions from their dot product `d`: `sqrt(2 - 2|d|)`.
#[inline(always)]
fn rmsq_of_dot(d: f64) -> f64 {
    (2.0 - 2.0 * d.abs()).max(0.0).sqrt()
}

/// The rows (`rows = true`) or the columns of a rotation's matrix.
pub(super) fn matrix_vectors(q: &Quat, rows: bool) -> [[f64; 3]; 3] {
    let m = q.to_rotation_matrix();
    let m = m.matrix();
    let v = |i: usize| {
        if rows {
            [m[(i, 0)], m[(i, 1)], m[(i, 2)]]
        } else {
            [m[(0, i)], m[(1, i)], m[(2, i)]]
        }
    };
    [v(0), v(1), v(2)]
}

/// `a . b` of 3-vectors.
#[inline(always)]
pub(super) fn dot3(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// One sample prepared for fast evaluation: rows of `Rm` and its quaternion.
#[derive(Debug, Clone, Copy)]
struct Sample {
    row0: [f64; 3],
    row1: [f64; 3],
    row2: [f64; 3],
    q: [f64; 4],
}

/// The cost of one joint over one window, prepared for many evaluations.
#[derive(Debug, Clone)]
pub struct WindowCost {
    samples: Vec<Sample>,
    terms: LimitTerms,
    lambda1: f64,
}

impl WindowCost {
    /// Prepares the cost for measured joint rotations `Rm_i` (parent to child).
    pub fn new(measured: &[Quat], limits: &JointLimits, lambda1: f64) -> Self {
        WindowCost::from_iter(measured.iter(), limits, lambda1)
    }

    /// As [`WindowCost::new`], taking every `stride`-th sample (a coarse copy).
    pub fn strided(measured: &[Quat], stride: usize, limits: &JointLimits, lambda1: f64) -> Self {
        WindowCost::from_iter(measured.iter().step_by(stride.max(1)), limits, lambda1)
    }

    fn from_iter<'a>(
        measured: impl Iterator<Item = &'a Quat>,
        limits: &JointLimits,
        lambda1: f64,
    ) -> Self {
        let samples = measured
            .map(|q| {
                let [row0, row1, row2] = matrix_vectors(q, true);
                Sample {
                    row0,
                    row1,
                    row2,
                    q: [q.w, q.i, q.j, q.k],
                }
            })
            .collect();
        WindowCost {
            samples,
            terms: LimitTerms::new(limits),
            lambda1,
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

    /// `e(C)`: mean excursion (plus centroid term) over the samples, plus
    /// `lambda1 * angle(C)`; degrees.
    pub fn eval(&self, c: &Quat) -> f64 {
        let penalty = self.lambda1 * angle_deg(c);
        if self.samples.is_empty() {
            return penalty;
        }
        let [col0, col1, col2] = matrix_vectors(c, false);
        let mut sum = 0.0;
        for s in &self.samples {
            sum += self.terms.excursion([
                dot3(&s.row0, &col0),
                dot3(&s.row1, &col0),
                dot3(&s.row2, &col0),
                dot3(&s.row2, &col1),
                dot3(&s.row2, &col2),
            ]);
        }
        if let Some(qc) = self.terms.centroid {
            // qt . qc = qm . (qc * c^-1), so one 4-vector per evaluation.
            sum += self
                .terms
                .centroid_sum(self.samples.iter().map(|s| &s.q), &(qc * c.inverse()));
        }
        sum / self.samples.len() as f64 + penalty
    }
}

/// A random rotation of up to `max_deg` degrees about a random axis (tests of
/// the fast costs against the direct formula).
#[cfg(test)]
pub(super) fn random_quat(rng: &mut rand_chacha::ChaCha8Rng, max_deg: f64) -> Quat {
    use rand::Rng;
    let axis = [
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    ];
    crate::rotation::quat_axis_angle_deg(axis, rng.random_range(0.0..max_deg))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{quat_axis_angle_deg, quat_from_euler_zyx_deg};
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn excursion_formula() {
        let r = [[-5.0, 5.0], [0.0, 130.0], [-5.0, 5.0]];
        assert_eq!(excursion([7.0, -3.0, 0.0], &r), [2.0, 3.0, 0.0]);
        assert_eq!(excursion([-5.0, 130.0, 5.0], &r), [0.0, 0.0, 0.0]);
        assert_eq!(excursion([-9.5, 131.0, 6.0], &r), [4.5, 1.0, 1.0]);
    }

    #[test]
    fn rmsq_is_sign_invariant() {
        let q = quat_from_euler_zyx_deg([10.0, 20.0, -30.0]);
        let c = quat_from_euler_zyx_deg([0.0, 5.0, 0.0]);
        let neg = Quat::new_unchecked(-q.into_inner());
        assert!((rmsq(&q, &c) - rmsq(&neg, &c)).abs() < 1e-15);
        assert!(rmsq(&q, &q) < 1e-15 && rmsq(&neg, &q) < 1e-15);
        assert!(rmsq(&q, &c) > 0.1);
    }

    fn check_fast_equals_direct(limits: JointLimits) {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let measured: Vec<Quat> = (0..400).map(|_| random_quat(&mut rng, 180.0)).collect();
        let cost = WindowCost::new(&measured, &limits, 0.05);
        for _ in 0..50 {
            let c = random_quat(&mut rng, 60.0);
            let fast = cost.eval(&c);
            let direct = cost_direct(&measured, &c, &limits, 0.05);
            assert!((fast - direct).abs() < 1e-9, "{fast} vs {direct}");
        }
    }

    #[test]
    fn fast_cost_equals_direct_formula() {
        // Narrow (knee), wide (> 180 deg), full and centroid cases.
        check_fast_equals_direct(JointLimits {
            range_deg: [[-5.0, 5.0], [0.0, 130.0], [-5.0, 5.0]],
            centroid_deg: None,
            lambda2: 0.0,
        });
        check_fast_equals_direct(JointLimits {
            range_deg: [[-45.0, 160.0], [-60.0, 60.0], [-170.0, 90.0]],
            centroid_deg: Some([47.0, -1.0, -31.0]),
            lambda2: 30.0,
        });
        check_fast_equals_direct(JointLimits {
            range_deg: [[-180.0, 180.0], [-90.0, 90.0], [100.0, 120.0]],
            centroid_deg: Some([0.0, 5.0, 0.0]),
            lambda2: 30.0,
        });
    }

    #[test]
    fn identity_inside_limits_costs_nothing() {
        let measured = vec![quat_from_euler_zyx_deg([1.0, 40.0, -2.0]); 10];
        let limits = JointLimits {
            range_deg: [[-5.0, 5.0], [0.0, 130.0], [-5.0, 5.0]],
            centroid_deg: None,
            lambda2: 0.0,
        };
        let cost = WindowCost::new(&measured, &limits, 0.05);
        assert_eq!(cost.eval(&Quat::identity()), 0.0);
        let c = quat_axis_angle_deg([0.0, 1.0, 0.0], 10.0);
        assert!((cost.eval(&c) - 0.5).abs() < 1e-9);
    }
}
