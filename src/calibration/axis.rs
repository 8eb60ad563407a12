//! One movement's axis estimate and its reliability (Ricci et al. 2014,
//! section 2.2.3, eq. 1-2; docs/method.md section 13).
//!
//! The N readings (accelerometer for a still posture, gyroscope for a
//! mono-axial movement; sensor frame) are normalised to unit length and stacked
//! into an N x 3 matrix; its first right singular vector is the axis estimate
//! and `rho = s1 / (s1 + s2 + s3)`, in `[1/3, 1]`, its reliability.

use super::protocol::MovementKind;
use nalgebra::{DMatrix, Vector3};

/// An axis estimated from one movement, in the sensor frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisEstimate {
    /// Unit axis in the sensor frame, signed as [`estimate_axis`] describes.
    pub axis: Vector3<f64>,
    /// Reliability `s1 / (s1 + s2 + s3)`, in `[1/3, 1]`.
    pub rho: f64,
    /// Singular values `s1 >= s2 >= s3` of the normalised readings.
    pub singular_values: [f64; 3],
    /// Readings used (those above the minimum norm).
    pub samples: usize,
}

/// Fraction of the largest reading's norm that marks the first phase of a
/// functional movement (its sign is taken from the first reading this fast).
const FIRST_PHASE_FRACTION: f64 = 0.5;

/// Estimates the axis of one movement from its readings (sensor frame).
///
/// Readings whose norm is not above `min_norm` (and exact zeros) are left out:
/// they have no direction. The singular vector's sign is arbitrary, so it is
/// fixed by the movement's kind: for [`MovementKind::Static`] the axis points
/// along the mean normalised reading; for [`MovementKind::Functional`] along the
/// first reading whose norm reaches half of the largest (the first phase of the
/// movement). `None` when no reading is left.
pub fn estimate_axis(
    readings: &[[f64; 3]],
    kind: MovementKind,
    min_norm: f64,
) -> Option<AxisEstimate> {
    let min_norm = min_norm.max(1e-12);
    let kept: Vec<(Vector3<f64>, f64)> = readings
        .iter()
        .map(|r| Vector3::new(r[0], r[1], r[2]))
        .filter_map(|v| {
            let n = v.norm();
            (n > min_norm).then(|| (v / n, n))
        })
        .collect();
    if kept.is_empty() {
        return None;
    }
    // At least three rows, so that the thin SVD has three singular values (zero
    // rows change neither the singular values nor the right singular vectors).
    let rows = kept.len().max(3);
    let a = DMatrix::from_fn(rows, 3, |i, j| kept.get(i).map_or(0.0, |k| k.0[j]));
    let svd = a.svd(false, true);
    let v_t = svd.v_t.expect("V requested");
    let mut order = [0usize, 1, 2];
    order.sort_by(|&i, &j| svd.singular_values[j].total_cmp(&svd.singular_values[i]));
    let s = order.map(|k| svd.singular_values[k]);
    let k = order[0];
    let mut axis = Vector3::new(v_t[(k, 0)], v_t[(k, 1)], v_t[(k, 2)]).normalize();
    let reference = match kind {
        MovementKind::Static => kept.iter().map(|(u, _)| u).sum::<Vector3<f64>>(),
        MovementKind::Functional => {
            let peak = kept.iter().map(|(_, n)| *n).fold(0.0, f64::max);
            kept.iter()
                .find(|(_, n)| *n >= FIRST_PHASE_FRACTION * peak)
                .map_or(axis, |(u, _)| *u)
        }
    };
    if axis.dot(&reference) < 0.0 {
        axis = -axis;
    }
    Some(AxisEstimate {
        axis,
        rho: s[0] / (s[0] + s[1] + s[2]),
        singular_values: s,
        samples: kept.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn still_posture_gives_gravity_with_rho_one() {
        let r = vec![[0.0, 0.0, 9.81]; 100];
        let e = estimate_axis(&r, MovementKind::Static, 0.0).unwrap();
        assert!((e.axis - Vector3::z()).norm() < 1e-12);
        assert!((e.rho - 1.0).abs() < 1e-12);
        assert_eq!(e.samples, 100);
        // The other sign of the same gravity: the mean decides.
        let r = vec![[0.0, -9.81, 0.0]; 10];
        let e = estimate_axis(&r, MovementKind::Static, 0.0).unwrap();
        assert!((e.axis + Vector3::y()).norm() < 1e-12);
    }

    #[test]
    fn back_and_forth_rotation_signed_by_first_phase() {
        // Flexion first (+x), then extension (-x): the axis is +x whatever the
        // singular vector's sign; starting with extension gives -x.
        let w: Vec<[f64; 3]> = (0..200)
            .map(|i| [50.0 * (i as f64 * 0.0314).cos(), 0.0, 0.0])
            .collect();
        let e = estimate_axis(&w, MovementKind::Functional, 0.0).unwrap();
        assert!((e.axis - Vector3::x()).norm() < 1e-12, "{:?}", e.axis);
        assert!((e.rho - 1.0).abs() < 1e-9);
        let neg: Vec<[f64; 3]> = w.iter().map(|v| [-v[0], 0.0, 0.0]).collect();
        let e = estimate_axis(&neg, MovementKind::Functional, 0.0).unwrap();
        assert!((e.axis + Vector3::x()).norm() < 1e-12);
    }

    #[test]
    fn rho_bounds() {
        // Three orthogonal axes in equal parts: the paper's limit case, rho = 1/3.
        let r: Vec<[f64; 3]> = (0..300)
            .map(|i| {
                let mut v = [0.0; 3];
                v[i % 3] = 1.0;
                v
            })
            .collect();
        let e = estimate_axis(&r, MovementKind::Functional, 0.0).unwrap();
        assert!((e.rho - 1.0 / 3.0).abs() < 1e-9, "{}", e.rho);
        // Readings below the minimum norm are left out; none left is None.
        assert!(estimate_axis(&[[0.0; 3]; 5], MovementKind::Static, 0.0).is_none());
        let e = estimate_axis(
            &[[1.0, 0.0, 0.0], [0.0, 0.1, 0.0]],
            MovementKind::Static,
            0.5,
        )
        .unwrap();
        assert_eq!(e.samples, 1);
    }
}
