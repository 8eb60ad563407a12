//! Rotations: unit quaternions, Z-Y-X Euler angles, slerp (docs/method.md sections 2, 7).
//!
//! Quaternions are Hamilton, scalar first (`[w, x, y, z]`), unit norm. An IMU's
//! orientation `G_R_imu` maps vectors from the sensor frame into the global frame G.
//! Joint angles are Z-Y-X Euler angles: `R = Rz(psi) * Ry(theta) * Rx(phi)`, reported
//! as `[x, y, z] = [phi, theta, psi]` in **degrees**.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};

/// A unit quaternion (rotation), Hamilton convention.
pub type Quat = UnitQuaternion<f64>;

/// Builds a unit quaternion from `[w, x, y, z]`, normalising it.
pub fn quat_from_wxyz(q: [f64; 4]) -> Quat {
    UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]))
}

/// The `[w, x, y, z]` components of a unit quaternion.
pub fn wxyz(q: &Quat) -> [f64; 4] {
    [q.w, q.i, q.j, q.k]
}

/// The same rotation with a non-negative scalar part (q and -q are one rotation).
pub fn canonical(q: &Quat) -> Quat {
    if q.w < 0.0 {
        Quat::new_unchecked(-q.into_inner())
    } else {
        *q
    }
}

/// Z-Y-X Euler angles `[x, y, z]` (degrees) of the rotation `q` (docs/method.md section 2.3):
/// `theta = -asin(R20)`, `phi = atan2(R21, R22)`, `psi = atan2(R10, R00)`.
pub fn euler_zyx_deg(q: &Quat) -> [f64; 3] {
    let (w, x, y, z) = (q.w, q.i, q.j, q.k);
    let r20 = 2.0 * (x * z - w * y);
    let r21 = 2.0 * (y * z + w * x);
    let r22 = 1.0 - 2.0 * (x * x + y * y);
    let r10 = 2.0 * (x * y + w * z);
    let r00 = 1.0 - 2.0 * (y * y + z * z);
    [
        r21.atan2(r22).to_degrees(),
        -r20.clamp(-1.0, 1.0).asin().to_degrees(),
        r10.atan2(r00).to_degrees(),
    ]
}

/// The other Z-Y-X triplet of the same rotation (docs/method.md section 2.5):
/// `[x + 180, 180 - y, z + 180]` for `y >= 0` and `[x + 180, -180 - y, z + 180]`
/// for `y < 0`, x and z wrapped into `(-180, 180]`; degrees. Its middle
/// angle lies beyond +-90 (on +-90 both triplets give the same rotation too).
pub fn other_zyx_deg([x, y, z]: [f64; 3]) -> [f64; 3] {
    let half_turn = |a: f64| if a > 0.0 { a - 180.0 } else { a + 180.0 };
    let y2 = if y >= 0.0 { 180.0 - y } else { -180.0 - y };
    [half_turn(x), y2, half_turn(z)]
}

/// The whole turn (0 or +-360 degrees) that takes an angle `a`, read in
/// `(-180, 180]`, to its copy nearest the arc `[lo, hi]`: the copy whose
/// plain excursion ([`beyond_line`]) is the shorter way round to the arc.
/// 0 while `a` is on the near side of the forbidden arc's middle (always,
/// for a range symmetric about 0); -360 past the middle above `hi`, +360
/// past it below `lo`. So an angle just across +-180 from a limit near it is
/// that little beyond it, and the excursion is continuous where the reading
/// wraps; a range reaching beyond +-180 holds the wrapped copy.
#[inline(always)]
pub fn arc_turn(a: f64, lo: f64, hi: f64) -> f64 {
    if a > hi && lo + 360.0 - a < a - hi {
        -360.0
    } else if a < lo && a + 360.0 - hi < lo - a {
        360.0
    } else {
        0.0
    }
}

/// Excursion (degrees) of an angle `a` read on the circle beyond the arc
/// `[lo, hi]`, the shorter way round ([`arc_turn`]), and its slope in `a`.
#[inline(always)]
pub fn beyond_arc_slope(a: f64, lo: f64, hi: f64) -> (f64, f64) {
    beyond_line_slope(a + arc_turn(a, lo, hi), lo, hi)
}

/// The excursion of [`beyond_arc_slope`] alone, degrees.
#[inline(always)]
pub fn beyond_arc(a: f64, lo: f64, hi: f64) -> f64 {
    beyond_line(a + arc_turn(a, lo, hi), lo, hi)
}

/// Excursion (degrees) of the middle angle `a` beyond `[lo, hi]`: `a - hi`
/// above, `lo - a` below, 0 inside (it does not wrap).
#[inline(always)]
pub fn beyond_line(a: f64, lo: f64, hi: f64) -> f64 {
    beyond_line_slope(a, lo, hi).0
}

/// [`beyond_line`] and its slope in `a`: +1 above the range, -1 below, 0
/// inside.
#[inline(always)]
pub fn beyond_line_slope(a: f64, lo: f64, hi: f64) -> (f64, f64) {
    if a > hi {
        (a - hi, 1.0)
    } else if a < lo {
        (lo - a, -1.0)
    } else {
        (0.0, 0.0)
    }
}

/// Per-axis excursion (degrees) of Z-Y-X angles `[x, y, z]` beyond a box:
/// the first and last angle on the circle ([`beyond_arc`]), the middle one
/// on the line ([`beyond_line`]).
pub fn box_excursion(angles: [f64; 3], range_deg: &[[f64; 2]; 3]) -> [f64; 3] {
    let [x, y, z] = angles;
    let [rx, ry, rz] = range_deg;
    [
        beyond_arc(x, rx[0], rx[1]),
        beyond_line(y, ry[0], ry[1]),
        beyond_arc(z, rz[0], rz[1]),
    ]
}

/// `Ex + Ey + Ez`: the summed excursion (degrees) of angles beyond a box
/// ([`box_excursion`]).
fn total_excursion(angles: [f64; 3], range_deg: &[[f64; 2]; 3]) -> f64 {
    box_excursion(angles, range_deg).iter().sum()
}

/// Whether a box's Y range (degrees) reaches beyond +-90: only then can the
/// other Z-Y-X triplet of a rotation ([`other_zyx_deg`],
/// middle angle beyond +-90) be read in it (hip and knee flexion in Table 3-2).
pub fn y_beyond_90(range_deg: &[[f64; 2]; 3]) -> bool {
    range_deg[1][0] < -90.0 || range_deg[1][1] > 90.0
}

/// The Z-Y-X triplet (degrees) the limit box `range_deg` reads of a rotation
/// whose principal triplet (middle angle in [-90, 90]) is `principal`
/// (docs/method.md section 2.5): the principal one, unless the box's Y range
/// reaches beyond +-90 and the other triplet has less total excursion beyond
/// the limits (ties: the principal one).
/// Either triplet may be given: one whose middle angle lies beyond +-90 is
/// taken back to the principal one first.
pub fn read_in_box(angles: [f64; 3], range_deg: &[[f64; 2]; 3]) -> [f64; 3] {
    let principal = if angles[1].abs() > 90.0 {
        other_zyx_deg(angles)
    } else {
        angles
    };
    if !y_beyond_90(range_deg) {
        return principal;
    }
    let total = total_excursion(principal, range_deg);
    if total == 0.0 {
        return principal;
    }
    let other = other_zyx_deg(principal);
    if total_excursion(other, range_deg) < total {
        other
    } else {
        principal
    }
}

/// The rotation `Rz(z) * Ry(y) * Rx(x)` for Z-Y-X Euler angles in degrees.
pub fn quat_from_euler_zyx_deg(angles: [f64; 3]) -> Quat {
    let [x, y, z] = angles;
    let qx = Quat::from_axis_angle(&Vector3::x_axis(), x.to_radians());
    let qy = Quat::from_axis_angle(&Vector3::y_axis(), y.to_radians());
    let qz = Quat::from_axis_angle(&Vector3::z_axis(), z.to_radians());
    qz * qy * qx
}

/// Rotation angle of `q` in degrees, in `[0, 180]`.
pub fn angle_deg(q: &Quat) -> f64 {
    let v = (q.i * q.i + q.j * q.j + q.k * q.k).sqrt();
    (2.0 * v.atan2(q.w.abs())).to_degrees()
}

/// Rotation from a rotation vector in radians (axis times angle).
pub fn quat_from_rotvec(v: &Vector3<f64>) -> Quat {
    Quat::from_scaled_axis(*v)
}

/// Rotation about `axis` (need not be unit) by `angle_deg` degrees.
pub fn quat_axis_angle_deg(axis: [f64; 3], angle_deg: f64) -> Quat {
    let a = Vector3::new(axis[0], axis[1], axis[2]).normalize();
    Quat::from_scaled_axis(a * angle_deg.to_radians())
}

/// Wraps an angle in degrees into `[-180, 180)`.
pub fn wrap180(a: f64) -> f64 {
    (a + 180.0).rem_euclid(360.0) - 180.0
}

/// Shorter-arc spherical linear interpolation from `q0` (f = 0) to `q1` (f = 1).
///
/// Falls back to normalised linear interpolation when the two nearly coincide
/// (dot product above 0.9995), as docs/method.md section 7 says.
pub fn slerp(q0: &Quat, q1: &Quat, f: f64) -> Quat {
    let a = q0.into_inner();
    let mut b = q1.into_inner();
    let mut d = a.dot(&b);
    if d < 0.0 {
        b = -b;
        d = -d;
    }
    if d > 0.9995 {
        return Quat::from_quaternion(a + (b - a) * f);
    }
    let om = d.min(1.0).acos();
    let s = om.sin();
    Quat::from_quaternion(a * (((1.0 - f) * om).sin() / s) + b * ((f * om).sin() / s))
}

/// Angle in degrees between two rotations (the angle of `q0^-1 * q1`).
pub fn angle_between_deg(q0: &Quat, q1: &Quat) -> f64 {
    angle_deg(&(q0.inverse() * q1))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn euler_round_trip_away_from_singularity() {
        for &x in &[-170.0, -45.0, 0.0, 12.5, 90.0, 179.0] {
            for &y in &[-80.0, -30.0, 0.0, 10.0, 85.0] {
                for &z in &[-179.0, -60.0, 0.0, 33.0, 175.0] {
                    let e = euler_zyx_deg(&quat_from_euler_zyx_deg([x, y, z]));
                    for (got, want) in e.iter().zip([x, y, z]) {
                        assert!((got - want).abs() < 1e-9, "{e:?} vs {x} {y} {z}");
                    }
                }
            }
        }
    }

    #[test]
    fn euler_matches_matrix_formula() {
        let q = quat_from_euler_zyx_deg([20.0, -35.0, 110.0]);
        let r = q.to_rotation_matrix();
        let m = r.matrix();
        let theta = -m[(2, 0)].asin().to_degrees();
        let phi = m[(2, 1)].atan2(m[(2, 2)]).to_degrees();
        let psi = m[(1, 0)].atan2(m[(0, 0)]).to_degrees();
        let e = euler_zyx_deg(&q);
        assert!((e[0] - phi).abs() < 1e-9 && (e[1] - theta).abs() < 1e-9);
        assert!((e[2] - psi).abs() < 1e-9);
    }

    #[test]
    fn euler_singularity_is_exposed() {
        // Just short of theta = 90 deg the angles still describe the rotation ...
        let q = quat_from_euler_zyx_deg([30.0, 89.9, 10.0]);
        let e = euler_zyx_deg(&q);
        assert!(angle_between_deg(&q, &quat_from_euler_zyx_deg(e)) < 1e-6);
        // ... but there a 0.1 deg rotation about the X axis moves phi and psi by
        // tens of degrees: the artefact thesis 4.1 shows, reported, not hidden.
        let nudged = q * quat_axis_angle_deg([0.0, 0.0, 1.0], 0.1);
        let e2 = euler_zyx_deg(&nudged);
        assert!((e2[0] - e[0]).abs() > 10.0, "{e:?} {e2:?}");
        assert!((e2[1] - e[1]).abs() < 0.2);
    }

    #[test]
    fn slerp_end_and_mid_points() {
        let q0 = quat_axis_angle_deg([0.0, 0.0, 1.0], 10.0);
        let q1 = quat_axis_angle_deg([0.0, 0.0, 1.0], 50.0);
        assert!(angle_between_deg(&slerp(&q0, &q1, 0.0), &q0) < 1e-9);
        assert!(angle_between_deg(&slerp(&q0, &q1, 1.0), &q1) < 1e-9);
        let mid = slerp(&q0, &q1, 0.5);
        assert!((angle_deg(&mid) - 30.0).abs() < 1e-9);
    }

    #[test]
    fn slerp_takes_shorter_arc() {
        let q0 = quat_axis_angle_deg([1.0, 0.0, 0.0], 170.0);
        let q1 = quat_axis_angle_deg([1.0, 0.0, 0.0], -170.0);
        let mid = slerp(&q0, &q1, 0.5);
        // The short way passes through 180 deg, not through 0.
        assert!((angle_deg(&mid) - 180.0).abs() < 1e-6);
        // Negated end point is the same rotation and gives the same result.
        let q1n = Quat::new_unchecked(-q1.into_inner());
        assert!(angle_between_deg(&slerp(&q0, &q1n, 0.3), &slerp(&q0, &q1, 0.3)) < 1e-9);
    }

    #[test]
    fn slerp_nearly_equal_falls_back_to_linear() {
        let q0 = quat_axis_angle_deg([0.0, 1.0, 0.0], 1.0);
        let q1 = quat_axis_angle_deg([0.0, 1.0, 0.0], 1.5);
        let mid = slerp(&q0, &q1, 0.5);
        assert!((angle_deg(&mid) - 1.25).abs() < 1e-6);
        assert!((mid.into_inner().norm() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn wrap_and_angles() {
        assert_eq!(wrap180(190.0), -170.0);
        assert_eq!(wrap180(-190.0), 170.0);
        assert!((angle_deg(&quat_axis_angle_deg([1.0, 1.0, 0.0], 37.0)) - 37.0).abs() < 1e-9);
        let q = quat_from_wxyz([-0.5, 0.5, 0.5, 0.5]);
        assert!(canonical(&q).w > 0.0);
        assert!(angle_between_deg(&q, &canonical(&q)) < 1e-9);
    }

    #[test]
    fn arc_excursion_is_plain_for_a_symmetric_range() {
        for a in [-179.0, -120.0, -31.0, -30.0, 0.0, 30.0, 45.0, 179.5, 180.0] {
            assert_eq!(
                beyond_arc(a, -30.0, 30.0),
                beyond_line(a, -30.0, 30.0),
                "{a}"
            );
        }
        assert_eq!(beyond_arc_slope(100.0, -30.0, 30.0), (70.0, 1.0));
        assert_eq!(beyond_arc_slope(-100.0, -30.0, 30.0), (70.0, -1.0));
        assert_eq!(beyond_arc_slope(10.0, -30.0, 30.0), (0.0, 0.0));
    }

    #[test]
    fn arc_excursion_goes_the_shorter_way_round() {
        // Elbow flexion [0, 160]: -150 deg is 150 below 0 but only 50 past 160.
        assert_eq!(beyond_arc_slope(-150.0, 0.0, 160.0), (50.0, 1.0));
        assert_eq!(beyond_arc_slope(170.0, 0.0, 160.0), (10.0, 1.0));
        assert_eq!(beyond_arc_slope(-10.0, 0.0, 160.0), (10.0, -1.0));
        // The middle of the forbidden arc (-100) is 100 from both limits.
        assert_eq!(beyond_arc(-100.0, 0.0, 160.0), 100.0);
        // Continuous across the reading's wrap at +-180: both sides 20 past 160.
        let below = beyond_arc(180.0, 0.0, 160.0);
        let above = beyond_arc(-180.0 + 1e-9, 0.0, 160.0);
        assert_eq!(below, 20.0);
        assert!((above - 20.0).abs() < 1e-8, "{above}");
        // And everywhere: no jump larger than the step between neighbours.
        let mut last = beyond_arc(-180.0, 0.0, 160.0);
        for k in 1..=3600 {
            let a = -180.0 + k as f64 * 0.1;
            let e = beyond_arc(a, 0.0, 160.0);
            assert!((e - last).abs() <= 0.1 + 1e-9, "{a}: {last} -> {e}");
            last = e;
        }
    }

    #[test]
    fn arc_excursion_knows_a_range_that_wraps() {
        // [-10, 200] covers -180..-160 as well: inside by the wrap.
        assert_eq!(beyond_arc_slope(-170.0, -10.0, 200.0), (0.0, 0.0));
        assert_eq!(beyond_arc_slope(-100.0, -10.0, 200.0), (60.0, 1.0));
        assert_eq!(beyond_arc_slope(-20.0, -10.0, 200.0), (10.0, -1.0));
    }

    #[test]
    fn box_excursion_reads_only_the_middle_angle_on_the_line() {
        let range = [[0.0, 160.0], [0.0, 160.0], [0.0, 160.0]];
        assert_eq!(
            box_excursion([-150.0, -150.0, -150.0], &range),
            [50.0, 150.0, 50.0]
        );
    }
}
