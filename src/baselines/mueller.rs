//! Mueller et al. (2017) hinge-axis estimation for two-degree-of-freedom joints
//! such as the elbow (thesis eq. 2.20-2.32, docs/method.md section 11.2).
//!
//! In the Z-Y-X convention of the workbench a joint rotation
//! `R = Rz(psi) Ry(theta) Rx(phi)` with no Y movement turns about an axis fixed
//! in the proximal frame (Z: the elbow's pronation/supination) and one fixed in
//! the distal frame (X: the elbow's flexion). With misaligned sensors those axes
//! are unknown unit vectors: `a` in the proximal IMU frame, `b` in the distal IMU
//! frame. The relative angular rate, in the proximal IMU frame (eq. 2.20-2.21),
//!
//! ```text
//! w_k = -w_prox,k + Rm_k w_dist,k = alpha_k a + beta_k Rm_k b + e_k
//! ```
//!
//! lies in the plane of `a` and `Rm_k b`. The axes minimise the mean squared
//! normalised residual `J = (1/N) sum |e_k|^2 / |w_k|^2` (eq. 2.25), with
//! `alpha_k`, `beta_k` the least-squares rates of each sample (eq. 2.23-2.24).
//! Each axis is written in spherical coordinates (eq. 2.26, 2.30-2.31) and the
//! four angles found by gradient descent on the gradient of eq. 2.29.
//!
//! The joint angles then follow from the axes: each IMU is turned by the least
//! rotation that takes its estimated axis onto the segment's (`a` onto Z, `b`
//! onto X), and the Z-Y-X angles of the corrected joint rotation are read as
//! usual.
//!
//! Z and X are the axes of frames whose elbow holds its Y angle (the thesis's
//! prone frames). Where a model's frames put the elbow's constant angle on
//! another segment axis (standing models: [`crate::model::Joint::two_axis_hinge`]),
//! the two moving axes take their place: the earlier of them in Z-Y-X order is
//! the proximal one. Every function here takes the segment axes `nominal`
//! (proximal, distal) and the fit records them. A misalignment that turns an IMU about its own hinge axis changes no
//! angular rate direction: it is an angle offset that no axis estimate can see,
//! and it passes into the angles unchanged.
//!
//! Rates are rad/s, angles radians inside and degrees in records.

use crate::rotation::Quat;
use nalgebra::{Matrix2, Matrix3, Unit, Vector2, Vector3};
use serde::{Deserialize, Serialize};

/// The axes of the workbench's Z-Y-X convention when the Y angle is the
/// constant one: the proximal-fixed first axis (Z) and the distal-fixed last
/// axis (X). Sidecars written before fits recorded their axes used these.
pub const NOMINAL_AXES: ([f64; 3], [f64; 3]) = ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]);

fn nominal_proximal() -> [f64; 3] {
    NOMINAL_AXES.0
}

fn nominal_distal() -> [f64; 3] {
    NOMINAL_AXES.1
}

/// Tuning of the estimation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MuellerOptions {
    /// Samples whose relative rate is below this (deg/s) are left out of J:
    /// their direction is mostly noise.
    pub min_rate_deg_s: f64,
    /// At most this many samples (evenly spaced) enter J.
    pub max_samples: usize,
    /// Gradient-descent iterations per start.
    pub max_iterations: usize,
    /// Half the span (seconds) of the central difference that derives rates
    /// from orientations.
    pub rate_half_span_s: f64,
}

impl Default for MuellerOptions {
    fn default() -> Self {
        MuellerOptions {
            min_rate_deg_s: 20.0,
            max_samples: 4000,
            max_iterations: 3000,
            rate_half_span_s: 0.05,
        }
    }
}

/// The estimated axes and how the estimate went.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MuellerFit {
    /// Unit axis `a` fixed in the proximal IMU frame (Z of the joint).
    pub proximal_axis: [f64; 3],
    /// Unit axis `b` fixed in the distal IMU frame (X of the joint).
    pub distal_axis: [f64; 3],
    /// The proximal segment axis `a` stands for (unit, segment frame; Z
    /// unless the model's frames hold another angle constant).
    #[serde(default = "nominal_proximal")]
    pub proximal_nominal: [f64; 3],
    /// The distal segment axis `b` stands for (unit, segment frame; X unless
    /// the model's frames hold another angle constant).
    #[serde(default = "nominal_distal")]
    pub distal_nominal: [f64; 3],
    /// Angle between `a` and the proximal IMU's own nominal axis, degrees.
    pub proximal_tilt_deg: f64,
    /// Angle between `b` and the distal IMU's own nominal axis, degrees.
    pub distal_tilt_deg: f64,
    /// J at the estimate (eq. 2.25), dimensionless, in [0, 1].
    pub cost: f64,
    /// J at the IMUs' own axes (no correction).
    pub cost_nominal: f64,
    /// Gradient-descent iterations, all starts together.
    pub iterations: usize,
    /// Samples that entered J.
    pub samples: usize,
}

/// Relative angular rates (rad/s, proximal IMU frame) derived from the joint
/// rotations `Rm` (distal to proximal IMU frame) by a central difference over
/// `2 h` samples, `h = max(1, round(half_span_s / dt))`, one-sided at the ends:
/// `w_k = log(Rm_{k+h} Rm_{k-h}^-1) / (t_{k+h} - t_{k-h})`.
pub fn rates_from_orientations(time_s: &[f64], rm: &[Quat], half_span_s: f64) -> Vec<Vector3<f64>> {
    let n = rm.len().min(time_s.len());
    if n < 2 {
        return vec![Vector3::zeros(); n];
    }
    let dt = crate::trial::median_dt(&time_s[..n]);
    let h = if dt > 0.0 {
        ((half_span_s / dt).round() as usize).max(1)
    } else {
        1
    };
    (0..n)
        .map(|k| {
            let lo = k.saturating_sub(h);
            let hi = (k + h).min(n - 1);
            let span = time_s[hi] - time_s[lo];
            if span <= 0.0 {
                return Vector3::zeros();
            }
            (rm[hi] * rm[lo].inverse()).scaled_axis() / span
        })
        .collect()
}

/// Relative angular rates (eq. 2.20) from gyroscope readings, each in its own
/// sensor frame (rad/s): `w_k = -w_prox,k + Rm_k w_dist,k`, proximal IMU frame.
pub fn rates_from_gyros(
    rm: &[Quat],
    gyro_proximal: &[Vector3<f64>],
    gyro_distal: &[Vector3<f64>],
) -> Vec<Vector3<f64>> {
    rm.iter()
        .zip(gyro_proximal)
        .zip(gyro_distal)
        .map(|((r, wp), wd)| r * wd - wp)
        .collect()
}

/// One sample entering J: the joint rotation, the rate and `1 / |w|^2`.
struct Sample {
    rm: Matrix3<f64>,
    w: Vector3<f64>,
    inv_norm2: f64,
}

/// An axis in spherical coordinates about a fixed basis `P`:
/// `axis = P (sin t cos r, sin t sin r, cos t)`; `(t, r) = (pi/2, 0)` is P's first column.
#[derive(Clone, Copy)]
struct Spherical {
    basis: Matrix3<f64>,
}

impl Spherical {
    /// A basis whose first column is `nominal`, so the start sits on the equator,
    /// away from the coordinates' poles.
    fn around(nominal: &Vector3<f64>) -> Spherical {
        let n = nominal.normalize();
        let helper = if n.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        let u = helper.cross(&n).normalize();
        let v = n.cross(&u);
        Spherical {
            basis: Matrix3::from_columns(&[n, u, v]),
        }
    }

    /// The axis and its partial derivatives in t and r (eq. 2.30-2.31).
    fn eval(&self, t: f64, r: f64) -> [Vector3<f64>; 3] {
        let (st, ct) = t.sin_cos();
        let (sr, cr) = r.sin_cos();
        [
            self.basis * Vector3::new(st * cr, st * sr, ct),
            self.basis * Vector3::new(ct * cr, ct * sr, -st),
            self.basis * Vector3::new(-st * sr, st * cr, 0.0),
        ]
    }
}

/// J and its gradient in `(t_a, r_a, t_b, r_b)` (eq. 2.25, 2.29).
fn cost_and_gradient(
    samples: &[Sample],
    pa: &Spherical,
    pb: &Spherical,
    p: &[f64; 4],
) -> (f64, [f64; 4]) {
    let [a, da_t, da_r] = pa.eval(p[0], p[1]);
    let [b, db_t, db_r] = pb.eval(p[2], p[3]);
    let mut j = 0.0;
    let mut g = [0.0; 4];
    for s in samples {
        let c = s.rm * b;
        let ac = a.dot(&c);
        let rhs = Vector2::new(a.dot(&s.w), c.dot(&s.w));
        // Least-squares rates about a and c = Rm b (eq. 2.23-2.24); one column
        // when the two axes (nearly) coincide.
        let det = 1.0 - ac * ac;
        let (alpha, beta) = if det > 1e-9 {
            let x = Matrix2::new(1.0, ac, ac, 1.0)
                .try_inverse()
                .map(|m| m * rhs)
                .unwrap_or_else(|| Vector2::new(rhs.x, 0.0));
            (x.x, x.y)
        } else {
            (rhs.x, 0.0)
        };
        let e = s.w - a * alpha - c * beta;
        j += e.norm_squared() * s.inv_norm2;
        // e is orthogonal to a and c, so only the axes' own movement counts (eq. 2.29).
        let et = s.rm.transpose() * e;
        let k = -2.0 * s.inv_norm2;
        g[0] += k * alpha * e.dot(&da_t);
        g[1] += k * alpha * e.dot(&da_r);
        g[2] += k * beta * et.dot(&db_t);
        g[3] += k * beta * et.dot(&db_r);
    }
    let n = samples.len().max(1) as f64;
    (j / n, g.map(|x| x / n))
}

/// Gradient descent with a backtracking (Armijo) step from `p`; returns the
/// end point, its J and the iterations spent.
fn descend(
    samples: &[Sample],
    pa: &Spherical,
    pb: &Spherical,
    mut p: [f64; 4],
    max_iterations: usize,
) -> ([f64; 4], f64, usize) {
    let (mut j, mut g) = cost_and_gradient(samples, pa, pb, &p);
    let mut step = 0.1;
    let mut it = 0;
    while it < max_iterations {
        it += 1;
        let g2: f64 = g.iter().map(|x| x * x).sum();
        if g2.sqrt() < 1e-10 {
            break;
        }
        let mut accepted = false;
        while step > 1e-12 {
            let q = [0, 1, 2, 3].map(|k| p[k] - step * g[k]);
            let (jq, gq) = cost_and_gradient(samples, pa, pb, &q);
            if jq <= j - 1e-4 * step * g2 {
                let gain = j - jq;
                p = q;
                j = jq;
                g = gq;
                step = (step * 1.5).min(10.0);
                accepted = true;
                if gain <= 1e-13 * j.max(1e-300) {
                    return (p, j, it);
                }
                break;
            }
            step *= 0.5;
        }
        if !accepted {
            break;
        }
    }
    (p, j, it)
}

/// Estimates the axes from joint rotations `Rm` (distal to proximal IMU frame)
/// and relative rates `rates` (rad/s, proximal IMU frame), starting from the
/// IMUs' own axes `nominal` (proximal, distal: unit segment axes, e.g.
/// [`NOMINAL_AXES`]) and from a few tilted starts; the lowest J wins. `None`
/// when fewer than 10 samples move faster than the minimum rate.
pub fn estimate_axes(
    rm: &[Quat],
    rates: &[Vector3<f64>],
    nominal: (Vector3<f64>, Vector3<f64>),
    opts: &MuellerOptions,
) -> Option<MuellerFit> {
    let min_rate = opts.min_rate_deg_s.to_radians();
    let moving: Vec<usize> = (0..rm.len().min(rates.len()))
        .filter(|&k| rates[k].norm() > min_rate)
        .collect();
    if moving.len() < 10 {
        return None;
    }
    let stride = moving.len().div_ceil(opts.max_samples.max(1));
    let samples: Vec<Sample> = moving
        .iter()
        .step_by(stride)
        .map(|&k| Sample {
            rm: *rm[k].to_rotation_matrix().matrix(),
            w: rates[k],
            inv_norm2: 1.0 / rates[k].norm_squared(),
        })
        .collect();
    let (nominal_a, nominal_b) = (nominal.0.normalize(), nominal.1.normalize());
    let pa = Spherical::around(&nominal_a);
    let pb = Spherical::around(&nominal_b);
    let eq = std::f64::consts::FRAC_PI_2;
    let start = [eq, 0.0, eq, 0.0];
    let (cost_nominal, _) = cost_and_gradient(&samples, &pa, &pb, &start);
    // The IMUs' own axes, and each axis tilted 35 degrees four ways.
    let tilt = 35f64.to_radians();
    let mut starts = vec![start];
    for (dt, dr) in [(tilt, 0.0), (-tilt, 0.0), (0.0, tilt), (0.0, -tilt)] {
        starts.push([eq + dt, dr, eq - dr, dt]);
    }
    let mut best: Option<([f64; 4], f64)> = None;
    let mut iterations = 0;
    for s in starts {
        let (p, j, it) = descend(&samples, &pa, &pb, s, opts.max_iterations);
        iterations += it;
        if best.is_none_or(|(_, bj)| j < bj) {
            best = Some((p, j));
        }
    }
    let (p, cost) = best.expect("at least one start");
    let mut a = pa.eval(p[0], p[1])[0];
    let mut b = pb.eval(p[2], p[3])[0];
    // a and -a are one axis: keep the one nearer the IMU's own.
    if a.dot(&nominal_a) < 0.0 {
        a = -a;
    }
    if b.dot(&nominal_b) < 0.0 {
        b = -b;
    }
    Some(MuellerFit {
        proximal_axis: a.into(),
        distal_axis: b.into(),
        proximal_nominal: nominal_a.into(),
        distal_nominal: nominal_b.into(),
        proximal_tilt_deg: angle_between_axes_deg(&a, &nominal_a),
        distal_tilt_deg: angle_between_axes_deg(&b, &nominal_b),
        cost,
        cost_nominal,
        iterations,
        samples: samples.len(),
    })
}

/// Angle between two directions, degrees, in [0, 180].
pub fn angle_between_axes_deg(u: &Vector3<f64>, v: &Vector3<f64>) -> f64 {
    u.normalize()
        .dot(&v.normalize())
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

/// The least rotation taking direction `from` onto direction `to`.
pub fn swing(from: &Vector3<f64>, to: &Vector3<f64>) -> Quat {
    Quat::rotation_between(from, to).unwrap_or_else(|| {
        // Opposite directions: half a turn about any perpendicular axis.
        let helper = if from.x.abs() < 0.9 {
            Vector3::x()
        } else {
            Vector3::y()
        };
        Quat::from_axis_angle(
            &Unit::new_normalize(from.cross(&helper)),
            std::f64::consts::PI,
        )
    })
}

impl MuellerFit {
    /// The corrections `(C_prox, C_dist)` of the two IMU frames: the least
    /// rotations taking `a` and `b` onto their segment axes (Z and X unless
    /// the model's frames hold another angle constant).
    pub fn corrections(&self) -> (Quat, Quat) {
        let a = Vector3::from(self.proximal_axis);
        let b = Vector3::from(self.distal_axis);
        (
            swing(&a, &Vector3::from(self.proximal_nominal)),
            swing(&b, &Vector3::from(self.distal_nominal)),
        )
    }

    /// The corrected joint rotation `C_prox Rm C_dist^-1` of a measured one.
    pub fn correct(&self, rm: &Quat) -> Quat {
        let (cp, cd) = self.corrections();
        cp * rm * cd.inverse()
    }

    /// The distal IMU's angular rate (rad/s) in its corrected frame, when its
    /// orientation becomes `G_R_prox Rt'` with `Rt' = C_prox Rm C_dist^-1`
    /// (both corrections carried by the distal IMU): from the gyros `w_p`
    /// (proximal frame) and `w_d` (distal frame),
    /// `w' = C_dist (w_d + Rm^-1 (C_prox^-1 w_p - w_p))`; exact, no derivative
    /// of the orientations taken.
    pub fn corrected_distal_rates(
        &self,
        rm: &[Quat],
        w_p: &[Vector3<f64>],
        w_d: &[Vector3<f64>],
    ) -> Vec<Vector3<f64>> {
        let (cp, cd) = self.corrections();
        let cp_inv = cp.inverse();
        rm.iter()
            .zip(w_p)
            .zip(w_d)
            .map(|((r, p), d)| cd * (d + r.inverse() * (cp_inv * p - p)))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{quat_axis_angle_deg, quat_from_euler_zyx_deg};

    fn zx() -> (Vector3<f64>, Vector3<f64>) {
        (NOMINAL_AXES.0.into(), NOMINAL_AXES.1.into())
    }

    /// An elbow moving in flexion and pronation, sensors tilted off the axes.
    fn elbow(n: usize, dt: f64) -> (Vec<f64>, Vec<Quat>, Quat, Quat) {
        let ma = quat_axis_angle_deg([1.0, 1.0, 0.0], 20.0);
        let mb = quat_axis_angle_deg([0.0, 1.0, -1.0], 20.0);
        let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
        let rm = t
            .iter()
            .map(|&s| {
                let flex = 70.0 + 60.0 * (1.3 * s).sin();
                let pro = 25.0 * (0.7 * s + 1.0).sin();
                ma.inverse() * quat_from_euler_zyx_deg([flex, 0.0, pro]) * mb
            })
            .collect();
        (t, rm, ma, mb)
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let (t, rm, ..) = elbow(400, 0.02);
        let rates = rates_from_orientations(&t, &rm, 0.02);
        let samples: Vec<Sample> = rm
            .iter()
            .zip(&rates)
            .filter(|(_, w)| w.norm() > 0.1)
            .map(|(r, w)| Sample {
                rm: *r.to_rotation_matrix().matrix(),
                w: *w,
                inv_norm2: 1.0 / w.norm_squared(),
            })
            .collect();
        let pa = Spherical::around(&Vector3::z());
        let pb = Spherical::around(&Vector3::x());
        let p = [1.4, 0.2, 1.7, -0.3];
        let (_, g) = cost_and_gradient(&samples, &pa, &pb, &p);
        for k in 0..4 {
            let h = 1e-6;
            let mut up = p;
            let mut dn = p;
            up[k] += h;
            dn[k] -= h;
            let num = (cost_and_gradient(&samples, &pa, &pb, &up).0
                - cost_and_gradient(&samples, &pa, &pb, &dn).0)
                / (2.0 * h);
            assert!((num - g[k]).abs() < 1e-6, "d{k}: {num} vs {}", g[k]);
        }
    }

    #[test]
    fn noiseless_axes_are_found_from_orientations_and_from_gyros() {
        let (t, rm, ma, mb) = elbow(3000, 0.02);
        let want_a = ma.inverse() * Vector3::z();
        let want_b = mb.inverse() * Vector3::x();
        let opts = MuellerOptions::default();
        let fit = estimate_axes(&rm, &rates_from_orientations(&t, &rm, 0.02), zx(), &opts).unwrap();
        assert!(angle_between_axes_deg(&fit.proximal_axis.into(), &want_a) < 0.5);
        assert!(angle_between_axes_deg(&fit.distal_axis.into(), &want_b) < 0.5);
        assert!(fit.cost < 1e-3 && fit.cost_nominal > 10.0 * fit.cost);
        // Gyros: body rates of a static upper arm (zero) and of the forearm,
        // w_dist = log(Rm_k^-1 Rm_k+1) / dt, taken at the midpoint.
        let gyro_p = vec![Vector3::zeros(); rm.len() - 1];
        let gyro_d: Vec<Vector3<f64>> = rm
            .windows(2)
            .map(|w| (w[0].inverse() * w[1]).scaled_axis() / 0.02)
            .collect();
        let mid: Vec<Quat> = rm
            .windows(2)
            .map(|w| w[0] * Quat::from_scaled_axis((w[0].inverse() * w[1]).scaled_axis() * 0.5))
            .collect();
        let g =
            estimate_axes(&mid, &rates_from_gyros(&mid, &gyro_p, &gyro_d), zx(), &opts).unwrap();
        assert!(angle_between_axes_deg(&g.proximal_axis.into(), &want_a) < 0.5);
        assert!(angle_between_axes_deg(&g.distal_axis.into(), &want_b) < 0.5);
    }

    #[test]
    fn swing_is_the_least_rotation() {
        let from = Vector3::new(0.2, -0.1, 1.0);
        let q = swing(&from, &Vector3::z());
        assert!(((q * from.normalize()) - Vector3::z()).norm() < 1e-12);
        // Its axis is perpendicular to both directions.
        let axis = q.axis().unwrap();
        assert!(axis.dot(&Vector3::z()).abs() < 1e-12 && axis.dot(&from).abs() < 1e-12);
        let flip = swing(&Vector3::x(), &(-Vector3::x()));
        assert!(((flip * Vector3::x()) + Vector3::x()).norm() < 1e-12);
    }

    #[test]
    fn too_little_movement_gives_no_estimate() {
        let rm = vec![Quat::identity(); 100];
        let rates = vec![Vector3::zeros(); 100];
        assert!(estimate_axes(&rm, &rates, zx(), &MuellerOptions::default()).is_none());
    }
}
