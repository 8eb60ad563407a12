//! Rivest (2005) knee correction, as the source applies it (thesis eq. 2.10-2.19,
//! docs/method.md section 11.1).
//!
//! The knee should neither ab/adduct nor rotate. Small misalignments of the thigh
//! IMU (corrections `a1`, `a2`, rotated with flexion) and of the calf IMU
//! (constant corrections `b1`, `b2`) show up in the measured Z-Y-X angles as
//!
//! ```text
//! psi_m - psi_t = b1 + a1 cos(theta_m) - a2 sin(theta_m)     (ab/adduction, Z; eq. 2.10)
//! phi_m - phi_t = b2 + a1 sin(theta_m) + a2 cos(theta_m)     (rotation, X; eq. 2.11)
//! ```
//!
//! with `theta_m` the measured flexion (Y). Taking `psi_t = phi_t = 0`, the four
//! corrections are the least-squares solution of eq. 2.12, which has the closed
//! form of eq. 2.13-2.16. The correction subtracts the fitted offsets from the
//! ab/adduction and rotation angles and leaves flexion as measured: Rivest's
//! model assumes `theta_m = theta_t`, so a flexion error is never corrected.
//!
//! Angles are degrees (`[x, y, z] = [phi, theta, psi]`, as [`crate::rotation`]);
//! `a1, a2, b1, b2` are degrees too.

use serde::{Deserialize, Serialize};

/// The four corrections of eq. 2.10-2.11, degrees: `a1`, `a2` for the thigh
/// (proximal) IMU, `b1`, `b2` for the calf (distal) IMU.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct RivestFit {
    pub a1: f64,
    pub a2: f64,
    pub b1: f64,
    pub b2: f64,
}

impl RivestFit {
    /// The fitted offsets `(psi_m - psi_t, phi_m - phi_t)` at flexion `theta_deg`, degrees.
    pub fn offsets(&self, theta_deg: f64) -> (f64, f64) {
        let (s, c) = theta_deg.to_radians().sin_cos();
        (
            self.b1 + self.a1 * c - self.a2 * s,
            self.b2 + self.a1 * s + self.a2 * c,
        )
    }

    /// Corrected Z-Y-X angles `[x, y, z]` (degrees) of measured ones: X and Z
    /// less their fitted offsets, Y unchanged.
    pub fn correct(&self, angles: [f64; 3]) -> [f64; 3] {
        let [phi, theta, psi] = angles;
        let (d_psi, d_phi) = self.offsets(theta);
        [phi - d_phi, theta, psi - d_psi]
    }

    /// The cost of eq. 2.12 per sample (mean squared residual of ab/adduction and
    /// rotation, deg^2) over measured angles `[x, y, z]`.
    pub fn cost(&self, angles: &[[f64; 3]]) -> f64 {
        let sum: f64 = angles
            .iter()
            .map(|a| {
                let (d_psi, d_phi) = self.offsets(a[1]);
                (a[2] - d_psi).powi(2) + (a[0] - d_phi).powi(2)
            })
            .sum();
        sum / angles.len().max(1) as f64
    }

    /// Linear interpolation between two fits: `self` at `f = 0`, `other` at `f = 1`.
    pub fn lerp(&self, other: &RivestFit, f: f64) -> RivestFit {
        let l = |x: f64, y: f64| x + (y - x) * f;
        RivestFit {
            a1: l(self.a1, other.a1),
            a2: l(self.a2, other.a2),
            b1: l(self.b1, other.b1),
            b2: l(self.b2, other.b2),
        }
    }
}

/// The closed-form least-squares fit (eq. 2.13-2.19) to measured knee angles
/// `[x, y, z]` (degrees).
///
/// With `R^2 = (sum cos theta)^2 + (sum sin theta)^2` the thigh terms are
/// `a1 = sum((psi - mean psi) cos theta + (phi - mean phi) sin theta) / (n - R^2 / n)`
/// and `a2 = sum((phi - mean phi) cos theta - (psi - mean psi) sin theta) / (n - R^2 / n)`;
/// the calf terms are the means left over. When the flexion never varies
/// (`n - R^2 / n` vanishes) thigh and calf cannot be told apart: the thigh terms
/// are 0 and the calf terms take the whole mean offset.
pub fn fit(angles: &[[f64; 3]]) -> RivestFit {
    let n = angles.len();
    if n == 0 {
        return RivestFit::default();
    }
    let nf = n as f64;
    let (mut sc, mut ss, mut m_psi, mut m_phi) = (0.0, 0.0, 0.0, 0.0);
    for a in angles {
        let (s, c) = a[1].to_radians().sin_cos();
        sc += c;
        ss += s;
        m_psi += a[2];
        m_phi += a[0];
    }
    m_psi /= nf;
    m_phi /= nf;
    let denom = nf - (sc * sc + ss * ss) / nf;
    let (mut a1, mut a2) = (0.0, 0.0);
    // Relative to n: below this the flexion is constant to rounding.
    if denom > 1e-12 * nf {
        for a in angles {
            let (s, c) = a[1].to_radians().sin_cos();
            let (dpsi, dphi) = (a[2] - m_psi, a[0] - m_phi);
            a1 += dpsi * c + dphi * s;
            a2 += dphi * c - dpsi * s;
        }
        a1 /= denom;
        a2 /= denom;
    }
    RivestFit {
        a1,
        a2,
        b1: m_psi - (a1 * sc - a2 * ss) / nf,
        b2: m_phi - (a1 * ss + a2 * sc) / nf,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{DMatrix, DVector};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Eq. 2.12 solved numerically: the 2n x 4 design matrix of the model,
    /// least squares by SVD (independent of the closed form's algebra).
    fn numerical(angles: &[[f64; 3]]) -> RivestFit {
        let n = angles.len();
        let mut design = DMatrix::zeros(2 * n, 4);
        let mut rhs = DVector::zeros(2 * n);
        for (i, a) in angles.iter().enumerate() {
            let (s, c) = a[1].to_radians().sin_cos();
            // columns: a1, a2, b1, b2
            design.set_row(i, &nalgebra::RowDVector::from_row_slice(&[c, -s, 1.0, 0.0]));
            design.set_row(
                n + i,
                &nalgebra::RowDVector::from_row_slice(&[s, c, 0.0, 1.0]),
            );
            rhs[i] = a[2];
            rhs[n + i] = a[0];
        }
        let x = design.svd(true, true).solve(&rhs, 1e-14).unwrap();
        RivestFit {
            a1: x[0],
            a2: x[1],
            b1: x[2],
            b2: x[3],
        }
    }

    #[test]
    fn closed_form_equals_numerical_least_squares() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for case in 0..200 {
            let n = rng.random_range(5..400);
            let lo = rng.random_range(-10.0..60.0);
            let span = rng.random_range(5.0..90.0);
            // Small angles: ab/adduction and rotation within +-10 degrees plus noise.
            let truth = RivestFit {
                a1: rng.random_range(-8.0..8.0),
                a2: rng.random_range(-8.0..8.0),
                b1: rng.random_range(-8.0..8.0),
                b2: rng.random_range(-8.0..8.0),
            };
            let angles: Vec<[f64; 3]> = (0..n)
                .map(|_| {
                    let theta = lo + span * rng.random::<f64>();
                    let (d_psi, d_phi) = truth.offsets(theta);
                    [
                        d_phi + rng.random_range(-2.0..2.0),
                        theta,
                        d_psi + rng.random_range(-2.0..2.0),
                    ]
                })
                .collect();
            let closed = fit(&angles);
            let num = numerical(&angles);
            for (c, m) in [
                (closed.a1, num.a1),
                (closed.a2, num.a2),
                (closed.b1, num.b1),
                (closed.b2, num.b2),
            ] {
                assert!((c - m).abs() < 1e-6, "case {case}: {closed:?} vs {num:?}");
            }
            // And it is the minimum: the cost rises in every direction.
            let c0 = closed.cost(&angles);
            for d in [
                RivestFit {
                    a1: 1e-3,
                    ..Default::default()
                },
                RivestFit {
                    a2: -1e-3,
                    ..Default::default()
                },
                RivestFit {
                    b1: 1e-3,
                    ..Default::default()
                },
                RivestFit {
                    b2: -1e-3,
                    ..Default::default()
                },
            ] {
                let moved = RivestFit {
                    a1: closed.a1 + d.a1,
                    a2: closed.a2 + d.a2,
                    b1: closed.b1 + d.b1,
                    b2: closed.b2 + d.b2,
                };
                assert!(moved.cost(&angles) > c0);
            }
        }
    }

    #[test]
    fn exact_model_is_recovered_and_removed() {
        let truth = RivestFit {
            a1: 3.0,
            a2: -2.0,
            b1: 4.0,
            b2: 1.5,
        };
        let angles: Vec<[f64; 3]> = (0..500)
            .map(|i| {
                let theta = 15.0 + 60.0 * (i as f64 * 0.05).sin().abs();
                let (d_psi, d_phi) = truth.offsets(theta);
                [d_phi, theta, d_psi]
            })
            .collect();
        let f = fit(&angles);
        assert!((f.a1 - 3.0).abs() < 1e-9 && (f.a2 + 2.0).abs() < 1e-9);
        assert!((f.b1 - 4.0).abs() < 1e-9 && (f.b2 - 1.5).abs() < 1e-9);
        for a in &angles {
            let c = f.correct(*a);
            assert!(c[0].abs() < 1e-9 && c[2].abs() < 1e-9 && c[1] == a[1]);
        }
    }

    #[test]
    fn constant_flexion_puts_everything_on_the_calf() {
        let angles = vec![[2.0, 40.0, -3.0]; 10];
        let f = fit(&angles);
        assert_eq!((f.a1, f.a2), (0.0, 0.0));
        assert!((f.b1 + 3.0).abs() < 1e-12 && (f.b2 - 2.0).abs() < 1e-12);
        assert_eq!(fit(&[]), RivestFit::default());
    }
}
