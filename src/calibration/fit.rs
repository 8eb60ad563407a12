//! The sensor-to-functional-frame rotation of one IMU from its axis estimates:
//! the weighted Levenberg-Marquardt fit of Ricci et al. 2014 (section 2.2.4,
//! eq. 3-12) and the classical TRIAD it improves on.
//!
//! Frames: `R` (quaternion `q`) maps vectors from the sensor frame (SF) into the
//! functional frame (FF): `v_FF = R * v_SF`. Each pair holds a functional-frame
//! reference axis `v_ref` (FF), its estimate `v_est` (SF) and its weight `rho`.

use crate::rotation::Quat;
use nalgebra::{Matrix3, Matrix4, Quaternion, Vector3, Vector4};

/// One reference axis, its estimate and weight.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisPair {
    /// Unit axis in the functional frame.
    pub reference: Vector3<f64>,
    /// Its estimate in the sensor frame (unit).
    pub estimate: Vector3<f64>,
    /// Weight (the estimate's reliability rho).
    pub weight: f64,
}

/// Settings of the LM fit (defaults: the paper's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LmOptions {
    /// Initial damping lambda (the paper: 0.001, after Hartley and Zisserman A6).
    pub damping: f64,
    /// Stop when `|C_k - C_k+1| / C_k` falls below this (the paper: 1e-4).
    pub relative_tolerance: f64,
    /// Give up after this many iterations.
    pub max_iterations: usize,
}

impl Default for LmOptions {
    fn default() -> Self {
        LmOptions {
            damping: 1e-3,
            relative_tolerance: 1e-4,
            max_iterations: 100,
        }
    }
}

/// The result of the LM fit.
#[derive(Debug, Clone, PartialEq)]
pub struct LmFit {
    /// The rotation SF -> FF.
    pub q: Quat,
    /// Accepted LM steps until the stop criterion held.
    pub iterations: usize,
    /// Cost `C = e^T W e` at the identity start and after each accepted step.
    pub costs: Vec<f64>,
}

/// `R(q)` of eq. 8 for a quaternion `[w, x, y, z]` of any norm (a rotation
/// times `|q|^2`).
pub fn rot(q: &Vector4<f64>) -> Matrix3<f64> {
    let (w, x, y, z) = (q[0], q[1], q[2], q[3]);
    Matrix3::new(
        w * w + x * x - y * y - z * z,
        2.0 * (x * y - z * w),
        2.0 * (x * z + y * w),
        2.0 * (x * y + z * w),
        w * w - x * x + y * y - z * z,
        2.0 * (y * z - x * w),
        2.0 * (x * z - y * w),
        2.0 * (y * z + x * w),
        w * w - x * x - y * y + z * z,
    )
}

/// `d(R(q) v) / dq`, 3 x 4 (columns w, x, y, z).
pub fn rot_jacobian(q: &Vector4<f64>, v: &Vector3<f64>) -> nalgebra::Matrix3x4<f64> {
    let (w, x, y, z) = (q[0], q[1], q[2], q[3]);
    let (a, b, c) = (v[0], v[1], v[2]);
    nalgebra::Matrix3x4::new(
        w * a - z * b + y * c,
        x * a + y * b + z * c,
        -y * a + x * b + w * c,
        -z * a - w * b + x * c,
        z * a + w * b - x * c,
        y * a - x * b - w * c,
        x * a + y * b + z * c,
        w * a - z * b + y * c,
        -y * a + x * b + w * c,
        z * a + w * b - x * c,
        -w * a + z * b - y * c,
        x * a + y * b + z * c,
    ) * 2.0
}

/// The cost `C = sum_k rho_k |v_ref,k - R(q) v_est,k|^2` (eq. 5-7).
pub fn cost(pairs: &[AxisPair], q: &Vector4<f64>) -> f64 {
    let r = rot(q);
    pairs
        .iter()
        .map(|p| p.weight * (p.reference - r * p.estimate).norm_squared())
        .sum()
}

fn unit(q: Vector4<f64>) -> Vector4<f64> {
    q / q.norm()
}

/// The weighted LM fit of eq. 9-11: start at the identity, step
/// `q <- q - (J^T W J + lambda diag(J^T W J))^-1 J^T W e`, renormalise; stop when
/// the cost changes by less than the relative tolerance. The damping starts at
/// `options.damping` and is divided by 10 after an accepted step and multiplied
/// by 10 when a step would raise the cost (Hartley and Zisserman, A6.2).
pub fn fit_lm(pairs: &[AxisPair], options: &LmOptions) -> LmFit {
    let mut q = Vector4::new(1.0, 0.0, 0.0, 0.0);
    let mut c = cost(pairs, &q);
    let mut costs = vec![c];
    let mut lambda = options.damping;
    let mut iterations = 0;
    while iterations < options.max_iterations && c > 1e-300 {
        let r = rot(&q);
        let mut h = Matrix4::zeros();
        let mut g = Vector4::zeros();
        for p in pairs {
            let e = p.reference - r * p.estimate;
            let j = -rot_jacobian(&q, &p.estimate);
            h += j.transpose() * j * p.weight;
            g += j.transpose() * e * p.weight;
        }
        let mut accepted = None;
        for _ in 0..40 {
            let a = h + Matrix4::from_diagonal(&h.diagonal()) * lambda;
            if let Some(delta) = a.lu().solve(&g) {
                let next = unit(q - delta);
                let cn = cost(pairs, &next);
                if cn.is_finite() && cn <= c {
                    accepted = Some((next, cn));
                    lambda = (lambda / 10.0).max(1e-12);
                    break;
                }
            }
            lambda *= 10.0;
        }
        let Some((next, cn)) = accepted else {
            break;
        };
        iterations += 1;
        let relative = (c - cn).abs() / c;
        q = next;
        c = cn;
        costs.push(c);
        if relative < options.relative_tolerance {
            break;
        }
    }
    LmFit {
        q: Quat::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3])),
        iterations,
        costs,
    }
}

/// TRIAD: the rotation that maps `primary.estimate` exactly onto
/// `primary.reference` and puts `secondary` in the same plane as its reference.
/// `None` when either pair is parallel.
pub fn triad(primary: &AxisPair, secondary: &AxisPair) -> Option<Quat> {
    let frame = |a: &Vector3<f64>, b: &Vector3<f64>| -> Option<Matrix3<f64>> {
        let t1 = a.normalize();
        let c = t1.cross(b);
        if c.norm() < 1e-9 {
            return None;
        }
        let t2 = c.normalize();
        Some(Matrix3::from_columns(&[t1, t2, t1.cross(&t2)]))
    };
    let s = frame(&primary.reference, &secondary.reference)?;
    let t = frame(&primary.estimate, &secondary.estimate)?;
    let r = nalgebra::Rotation3::from_matrix_unchecked(s * t.transpose());
    Some(Quat::from_rotation_matrix(&r))
}

/// Angle between `reference` and `R * estimate`, degrees (the paper's eq. 13).
pub fn residual_deg(q: &Quat, pair: &AxisPair) -> f64 {
    let v = q * pair.estimate;
    v.dot(&pair.reference).clamp(-1.0, 1.0).acos().to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{angle_between_deg, quat_axis_angle_deg};

    fn pairs_for(q: &Quat, refs: &[(Vector3<f64>, f64)]) -> Vec<AxisPair> {
        refs.iter()
            .map(|(r, w)| AxisPair {
                reference: *r,
                estimate: q.inverse() * r,
                weight: *w,
            })
            .collect()
    }

    #[test]
    fn rot_is_the_rotation_matrix_and_jacobian_is_its_derivative() {
        let q = quat_axis_angle_deg([0.3, -1.0, 0.4], 73.0);
        let v4 = q.into_inner().coords;
        let v4 = Vector4::new(v4[3], v4[0], v4[1], v4[2]);
        assert!((rot(&v4) - q.to_rotation_matrix().into_inner()).norm() < 1e-12);
        let v = Vector3::new(0.2, -0.7, 1.3);
        let j = rot_jacobian(&v4, &v);
        for k in 0..4 {
            let mut d = Vector4::zeros();
            d[k] = 1e-6;
            let num = (rot(&(v4 + d)) * v - rot(&(v4 - d)) * v) / 2e-6;
            assert!((num - j.column(k)).norm() < 1e-8, "column {k}");
        }
    }

    #[test]
    fn exact_axes_give_the_rotation() {
        let truth = quat_axis_angle_deg([1.0, 2.0, -0.5], 140.0);
        let pairs = pairs_for(
            &truth,
            &[
                (Vector3::x(), 0.8),
                (Vector3::y(), 0.6),
                (Vector3::z(), 0.98),
            ],
        );
        let f = fit_lm(&pairs, &LmOptions::default());
        assert!(angle_between_deg(&f.q, &truth) < 1e-4, "{:?}", f);
        assert!(f.iterations >= 2 && f.iterations < 30, "{}", f.iterations);
        assert!(f.costs.windows(2).all(|c| c[1] <= c[0]));
        let t = triad(&pairs[2], &pairs[0]).unwrap();
        assert!(angle_between_deg(&t, &truth) < 1e-9);
        assert!(residual_deg(&t, &pairs[1]) < 1e-6);
    }

    #[test]
    fn triad_rejects_parallel_axes() {
        let p = AxisPair {
            reference: Vector3::x(),
            estimate: Vector3::x(),
            weight: 1.0,
        };
        let q = AxisPair {
            reference: -Vector3::x(),
            ..p
        };
        assert!(triad(&p, &q).is_none());
    }
}
