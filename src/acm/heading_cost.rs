//! The ACM cost of one joint over one window as a function of the distal IMU's
//! heading correction `h` (degrees), its sensor-frame correction C held fixed.
//!
//! With the heading model the corrected distal orientation is
//! `G_R_dist' = R_up(-h) * G_R_dist * C`, so the joint rotation is
//! `Rt(h) = P'^T * R_up(-h) * B` with `P' = G_R_prox'` (the corrected parent) and
//! `B = G_R_dist * C`. By Rodrigues, `R_up(-h) = I - sin(h) K + (1 - cos(h)) K^2`
//! with `K = [up]x`, so `Rt(h) = M0 + sin(h) M1 + (1 - cos(h)) M2` with three
//! matrices per sample prepared once; only the five entries the Z-Y-X angles need
//! are kept. The quaternion of `Rt(h)` is `cos(h/2) a + sin(h/2) b` likewise, so
//! the centroid term costs two dot products per sample prepared once.
//!
//! With swing-twist limits ([`crate::limits::swing_twist`]) the excursion is
//! that model's, of the quaternion `cos(h/2) a + sin(h/2) b` (kept per sample
//! instead of the entries), its derivative in `h` through the model's gradient.
//!
//! The value is the window cost of docs/method.md section 5 with the heading term:
//! `e(C, h) = (1/n) sum_i (Ex_i + Ey_i + Ez_i + lambda2 * RMSq_i)
//!            + lambda1 * angle(C) + lambda1 * |h|` (degrees).

use super::cost::LimitTerms;
use super::swing_cost::SwingTerms;
use crate::limits::JointLimits;
use crate::rotation::{angle_deg, Quat};
use nalgebra::{Quaternion, Vector3};

/// The entries `r00, r10, r20, r21, r22` of a rotation matrix.
type Entries = [f64; 5];

/// One sample prepared for evaluation at any heading.
#[derive(Debug, Clone, Copy)]
struct Sample {
    m0: Entries,
    m1: Entries,
    m2: Entries,
    /// `a . qc` and `b . qc` (0 without centroid term).
    centroid_dots: [f64; 2],
}

impl Sample {
    /// The sample of parent orientation `p` and right factor `b = G_R_dist C`:
    /// the entries of `P^T X` for `X = B, -K B, K^2 B`, formed from the rows of
    /// `P^T` (the columns of `P`) and the columns of `B` turned by `up x`
    /// (`K v = up x v`), and the centroid's two dot products.
    fn new(p: &Quat, b: &Quat, up: &Vector3<f64>, centroid: Option<&Quat>) -> Self {
        let pm = p.to_rotation_matrix().into_inner();
        let bm = b.to_rotation_matrix().into_inner();
        let rows = [pm.column(0), pm.column(1), pm.column(2)];
        let cols: [Vector3<f64>; 3] = std::array::from_fn(|j| bm.column(j).into_owned());
        let kb = cols.map(|v| up.cross(&v));
        let k2b = kb.map(|v| up.cross(&v));
        let entries = |x: &[Vector3<f64>; 3], sign: f64| -> Entries {
            [
                sign * rows[0].dot(&x[0]),
                sign * rows[1].dot(&x[0]),
                sign * rows[2].dot(&x[0]),
                sign * rows[2].dot(&x[1]),
                sign * rows[2].dot(&x[2]),
            ]
        };
        let centroid_dots = match centroid {
            Some(qc) => {
                let pt = p.inverse().into_inner();
                let minus_up = Quaternion::new(0.0, -up[0], -up[1], -up[2]);
                let qa = pt * b.into_inner();
                let qb = pt * minus_up * b.into_inner();
                [qa.coords.dot(&qc.coords), qb.coords.dot(&qc.coords)]
            }
            None => [0.0, 0.0],
        };
        Sample {
            m0: entries(&cols, 1.0),
            m1: entries(&kb, -1.0),
            m2: entries(&k2b, 1.0),
            centroid_dots,
        }
    }
}

/// The two quaternions `a = P^T B` and `b = P^T (0, -up) B` (`[w, x, y, z]`)
/// of a sample: its joint rotation at heading `h` has the quaternion
/// `cos(h/2) a + sin(h/2) b`.
fn heading_quats(p: &Quat, b: &Quat, up: &Vector3<f64>) -> [[f64; 4]; 2] {
    let pt = p.inverse().into_inner();
    let minus_up = Quaternion::new(0.0, -up[0], -up[1], -up[2]);
    let qa = pt * b.into_inner();
    let qb = pt * minus_up * b.into_inner();
    [[qa.w, qa.i, qa.j, qa.k], [qb.w, qb.i, qb.j, qb.k]]
}

/// `ch a + sh b`, componentwise.
#[inline(always)]
fn mix([a, b]: &[[f64; 4]; 2], ch: f64, sh: f64) -> [f64; 4] {
    std::array::from_fn(|k| ch * a[k] + sh * b[k])
}

/// The cost of one joint over one window as a function of the heading correction.
#[derive(Debug, Clone)]
pub struct HeadingCost {
    samples: Vec<Sample>,
    /// Swing-twist limits, in place of `terms`' ranges (its centroid stays),
    /// with each sample's two quaternions ([`heading_quats`]).
    swing: Option<(SwingTerms, Vec<[[f64; 4]; 2]>)>,
    terms: LimitTerms,
    lambda1: f64,
    /// `lambda1 * angle(C)`.
    c_penalty: f64,
}

impl HeadingCost {
    /// Prepares the cost for corrected parent orientations `parent` (`G_R_prox'`),
    /// raw distal orientations `child` (`G_R_dist`), the fixed correction `c`
    /// (distal sensor frame) and the global up vector `up`; every `stride`-th
    /// sample is taken (1 = all).
    pub fn new(
        parent: &[Quat],
        child: &[Quat],
        c: &Quat,
        up: [f64; 3],
        limits: &JointLimits,
        lambda1: f64,
        stride: usize,
    ) -> Self {
        let up = Vector3::new(up[0], up[1], up[2]);
        let terms = LimitTerms::new(limits);
        let centroid = terms.centroid;
        let samples = parent
            .iter()
            .zip(child)
            .step_by(stride.max(1))
            .map(|(p, d)| {
                // In the limits' axes `Rt` is `(P Q)^T R_up(-h) (D C Q)`.
                match &limits.axes {
                    Some(a) => Sample::new(&(p * a.q), &(d * c * a.q), &up, centroid.as_ref()),
                    None => Sample::new(p, &(d * c), &up, centroid.as_ref()),
                }
            })
            .collect();
        let swing = limits.swing_twist.map(|st| {
            let quats = parent
                .iter()
                .zip(child)
                .step_by(stride.max(1))
                .map(|(p, d)| match &limits.axes {
                    Some(a) => heading_quats(&(p * a.q), &(d * c * a.q), &up),
                    None => heading_quats(p, &(d * c), &up),
                })
                .collect();
            (SwingTerms::new(st), quats)
        });
        HeadingCost {
            samples,
            swing,
            terms,
            lambda1,
            c_penalty: lambda1 * angle_deg(c),
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

    /// `e(C, h)` for the heading correction `h_deg` (degrees about the up axis).
    pub fn eval(&self, h_deg: f64) -> f64 {
        let penalty = self.c_penalty + self.lambda1 * h_deg.abs();
        if self.samples.is_empty() {
            return penalty;
        }
        let (s, c) = h_deg.to_radians().sin_cos();
        let v = 1.0 - c;
        let (sh, ch) = (0.5 * h_deg.to_radians()).sin_cos();
        let centroid = self.terms.centroid.is_some();
        let mut sum = 0.0;
        if let Some((st, quats)) = &self.swing {
            for q in quats {
                sum += st.excursion(mix(q, ch, sh));
            }
        }
        let euler = self.swing.is_none();
        for p in &self.samples {
            if euler {
                let r = |j: usize| p.m0[j] + s * p.m1[j] + v * p.m2[j];
                sum += self.terms.excursion([r(0), r(1), r(2), r(3), r(4)]);
            }
            if centroid {
                sum += self
                    .terms
                    .centroid_term(ch * p.centroid_dots[0] + sh * p.centroid_dots[1]);
            }
        }
        sum / self.samples.len() as f64 + penalty
    }

    /// [`HeadingCost::eval`] and its derivative in `h` (degrees per degree),
    /// from `dRt/dh = cos(h) M1 + sin(h) M2` (per radian) and
    /// `dq/dh = (-sin(h/2) a + cos(h/2) b) / 2`. At a kink (a sample on a
    /// limit, `h = 0`) it is the derivative of one side (`+lambda1` at `h = 0`).
    pub fn eval_slope(&self, h_deg: f64) -> (f64, f64) {
        let penalty = self.c_penalty + self.lambda1 * h_deg.abs();
        let penalty_slope = self.lambda1 * h_deg.signum();
        if self.samples.is_empty() {
            return (penalty, penalty_slope);
        }
        let (s, c) = h_deg.to_radians().sin_cos();
        let v = 1.0 - c;
        let (sh, ch) = (0.5 * h_deg.to_radians()).sin_cos();
        let centroid = self.terms.centroid.is_some();
        let (mut sum, mut slope) = (0.0, 0.0);
        if let Some((st, quats)) = &self.swing {
            // dq/dh = (-sin(h/2) a + cos(h/2) b) / 2, per radian.
            for q in quats {
                let (e, de) = st.excursion_along(mix(q, ch, sh), mix(q, -0.5 * sh, 0.5 * ch));
                sum += e;
                slope += de;
            }
        }
        let euler = self.swing.is_none();
        for p in &self.samples {
            if euler {
                let r = |j: usize| p.m0[j] + s * p.m1[j] + v * p.m2[j];
                let d = |j: usize| c * p.m1[j] + s * p.m2[j];
                let (e, de) = self.terms.excursion_along(
                    [r(0), r(1), r(2), r(3), r(4)],
                    [d(0), d(1), d(2), d(3), d(4)],
                );
                sum += e;
                slope += de;
            }
            if centroid {
                let [a, b] = p.centroid_dots;
                let (e, de) = self
                    .terms
                    .centroid_term_along(ch * a + sh * b, 0.5 * (ch * b - sh * a));
                sum += e;
                slope += de;
            }
        }
        let n = self.samples.len() as f64;
        (sum / n + penalty, (slope / n).to_radians() + penalty_slope)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::acm::cost::{cost_direct, random_quat, test_axes};
    use crate::vertical::Vertical;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    fn check(limits: JointLimits, vertical: Vertical) {
        for axes in test_axes() {
            check_in(JointLimits { axes, ..limits }, vertical);
        }
    }

    fn check_in(limits: JointLimits, vertical: Vertical) {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let parent: Vec<Quat> = (0..300).map(|_| random_quat(&mut rng, 180.0)).collect();
        let child: Vec<Quat> = (0..300).map(|_| random_quat(&mut rng, 180.0)).collect();
        for _ in 0..10 {
            let c = random_quat(&mut rng, 40.0);
            let cost = HeadingCost::new(&parent, &child, &c, vertical.up(), &limits, 0.05, 1);
            for h in [-170.0, -33.0, 0.0, 4.5, 90.0] {
                let r = vertical.heading_rotation(-h);
                let measured: Vec<Quat> = parent
                    .iter()
                    .zip(&child)
                    .map(|(p, d)| p.inverse() * r * d)
                    .collect();
                let direct = cost_direct(&measured, &c, &limits, 0.05) + 0.05 * f64::abs(h);
                let fast = cost.eval(h);
                assert!((fast - direct).abs() < 1e-9, "h {h}: {fast} vs {direct}");
            }
        }
    }

    #[test]
    fn heading_slope_matches_finite_differences() {
        let shoulder = JointLimits {
            range_deg: [[-10.0, 100.0], [-40.0, 60.0], [-70.0, 70.0]],
            centroid_deg: Some([47.0, -1.0, -31.0]),
            lambda2: 30.0,
            axes: None,
            swing_twist: None,
        };
        let knee = JointLimits {
            range_deg: [[-5.0, 5.0], [0.0, 130.0], [-5.0, 5.0]],
            centroid_deg: None,
            lambda2: 0.0,
            axes: None,
            swing_twist: None,
        };
        // In every test axes (the segment frames', proper and mirrored ones).
        let all: Vec<JointLimits> = [shoulder, knee]
            .into_iter()
            .flat_map(|l| {
                test_axes()
                    .into_iter()
                    .map(move |axes| JointLimits { axes, ..l })
            })
            .collect();
        let mut rng = ChaCha8Rng::seed_from_u64(6);
        let parent: Vec<Quat> = (0..300).map(|_| random_quat(&mut rng, 180.0)).collect();
        let child: Vec<Quat> = (0..300).map(|_| random_quat(&mut rng, 180.0)).collect();
        let mut near_kink = 0;
        for limits in &all {
            let c = random_quat(&mut rng, 40.0);
            let cost = HeadingCost::new(&parent, &child, &c, [0.0, 0.0, 1.0], limits, 0.05, 1);
            for h in [-170.0, -33.3, 4.5, 17.0, 90.2] {
                let (f, slope) = cost.eval_slope(h);
                assert_eq!(f, cost.eval(h));
                // One-sided differences over 1e-6 deg; a kink within the step
                // makes them disagree, and the point is skipped.
                let step = 1e-6;
                let up = (cost.eval(h + step) - f) / step;
                let down = (f - cost.eval(h - step)) / step;
                let tol = 1e-4 * (1.0 + slope.abs());
                if (up - down).abs() > tol {
                    near_kink += 1;
                    continue;
                }
                assert!(
                    (0.5 * (up + down) - slope).abs() < tol,
                    "h {h}: {up} vs {slope}"
                );
            }
        }
        let points = 5 * all.len();
        assert!(
            near_kink * 5 < points,
            "{near_kink} of {points} near a kink"
        );
    }

    #[test]
    fn heading_cost_equals_the_direct_formula() {
        let knee = JointLimits {
            range_deg: [[-5.0, 5.0], [0.0, 130.0], [-5.0, 5.0]],
            centroid_deg: None,
            lambda2: 0.0,
            axes: None,
            swing_twist: None,
        };
        let shoulder = JointLimits {
            range_deg: [[-10.0, 100.0], [-40.0, 60.0], [-70.0, 70.0]],
            centroid_deg: Some([47.0, -1.0, -31.0]),
            lambda2: 30.0,
            axes: None,
            swing_twist: None,
        };
        check(knee, Vertical::ZUp);
        check(shoulder, Vertical::ZUp);
        check(shoulder, Vertical::ZDown);
        check(knee, Vertical::ZDown);
    }
}
