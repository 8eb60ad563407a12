//! Swing-twist joint limits (docs/method.md section 5.1): a limit model with
//! no Euler singularity.
//!
//! A joint rotation `R`, in the table's axes (`Q^T R Q`, see
//! [`crate::model::TableAxes`]), is split as `R = swing * twist`: `twist` a
//! rotation about the joint's twist axis `t` (one of the table's X, Y, Z: the
//! segment's long axis, the "rotation" row of Table 3-2), `swing` a rotation
//! about an axis perpendicular to `t`. For a twist about Z the order is
//! `R = twist * swing` (the twist in the proximal segment's frame, where the
//! table's Z-Y-X sequence turns about Z; [`twist_in_proximal`]). The swing's rotation vector, in
//! degrees, has two components, on the other two table axes in X, Y, Z order
//! (`swing_1`, `swing_2`: Y and Z for a twist about X, X and Z for Y, X and Y
//! for Z); the twist is an angle about `t`, degrees in `(-180, 180]`. For a
//! table whose axes are a mirror image of the segment frames (`det(P) = -1`)
//! all three count the other way, as the Euler table's angles do.
//!
//! The limits: the swing inside an ellipse in the `(swing_1, swing_2)` plane
//! (centre and two half-angles, degrees; a cone about `t` when the half-angles
//! are equal and the centre is 0), the twist in `[lo(s), hi(s)]`, where the
//! bounds move linearly from the range at the ellipse's centre (`s = 0`) to
//! the range on its edge (`s = 1`, and beyond), `s` the swing's relative
//! radius `sqrt(((swing_1 - c_1)/a_1)^2 + ((swing_2 - c_2)/a_2)^2)`.
//!
//! The excursion of a rotation (degrees) is the distance of its swing from the
//! ellipse in that plane (0 inside) plus its twist's distance from the twist
//! range (0 inside). The plane is the azimuthal equidistant map of the twist
//! axis' direction about `t`: along a line through the origin the distance is
//! exactly the swing angle beyond the region, for a cone centred at 0 it is
//! the angle between the twist axis' direction and the cone everywhere.

use serde::{Deserialize, Serialize};
use std::ops::{Add, Div, Mul, Neg, Sub};

/// Degrees per radian.
const DEG: f64 = 180.0 / std::f64::consts::PI;

/// The limits of one joint in the swing-twist model, degrees.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SwingTwistLimits {
    /// The twist axis in the table's axes: 0 = X, 1 = Y, 2 = Z.
    pub twist_axis: usize,
    /// Centre of the swing ellipse `[swing_1, swing_2]`, degrees.
    pub centre_deg: [f64; 2],
    /// Half-angles of the swing ellipse along `swing_1` and `swing_2`,
    /// degrees, both > 0.
    pub half_deg: [f64; 2],
    /// The region's shape: `None` for the ellipse; `Some(r)` for the box
    /// `centre +- half` with corners rounded to radius `r` (degrees, `0 <= r
    /// <= min(half)`: 0 a sharp box, `min(half)` a stadium).
    pub corner_deg: Option<f64>,
    /// Twist range `[lo, hi]` at the ellipse's centre, degrees.
    pub twist_deg: [f64; 2],
    /// Twist range `[lo, hi]` on the ellipse's edge and beyond, degrees.
    pub edge_twist_deg: [f64; 2],
    /// The region read as the table's Z-Y-X box (`swing_corner_deg` `zyx`;
    /// twist about X only, one twist range): the swing's coordinates are
    /// the direction of the distal X axis as its Z-Y-X angles Y and Z
    /// (latitude and longitude), the twist is read as the Z-Y-X angle X,
    /// i.e. the twist less the twist of `Rz(z) Ry(y)`. Inside the caps |Y| >
    /// [`ZYX_CAP_DEG`] that twist shift and the Z excursion are weighed down
    /// by `cos(Y) / cos(cap)` (0 at the poles), so the excursion has no
    /// singularity; outside them it is the Euler box's excursion exactly.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub zyx_box: bool,
}

/// The latitude (degrees, the Z-Y-X angle Y) beyond which a
/// [`SwingTwistLimits::zyx_box`] region gives way to a reading without the
/// Euler singularity.
pub const ZYX_CAP_DEG: f64 = 60.0;

/// The excursion of one rotation beyond swing-twist limits in its parts,
/// degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExcursionParts {
    /// The swing's distance beyond the region (0 inside).
    pub swing_deg: f64,
    /// The swing less the region's nearest point, on `swing_1` and `swing_2`
    /// (its length is `swing_deg`; 0 inside).
    pub swing_offset_deg: [f64; 2],
    /// The twist beyond its range at the swing's radius (0 inside).
    pub twist_deg: f64,
}

impl ExcursionParts {
    /// Per table axis X, Y, Z: the twist's excursion on the twist axis, the
    /// size of the swing offset's component on each swing axis, degrees.
    pub fn per_axis(&self, twist_axis: usize) -> [f64; 3] {
        let mut out = [0.0; 3];
        out[twist_axis] = self.twist_deg;
        for (k, a) in swing_axes(twist_axis).into_iter().enumerate() {
            out[a] = self.swing_offset_deg[k].abs();
        }
        out
    }
}

/// The swing-twist coordinates of a rotation, degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SwingTwist {
    /// The swing's rotation vector on the two table axes other than the
    /// twist axis, in X, Y, Z order.
    pub swing_deg: [f64; 2],
    /// The twist about the twist axis, in `(-180, 180]`.
    pub twist_deg: f64,
}

/// The two table axes the swing's components are on, for twist axis `t`, in
/// X, Y, Z order.
pub fn swing_axes(t: usize) -> [usize; 2] {
    match t {
        0 => [1, 2],
        1 => [0, 2],
        _ => [0, 1],
    }
}

impl SwingTwistLimits {
    /// The same limits counted the other way (a table whose axes are a mirror
    /// image of the segment frames, `det(P) = -1`): centre negated, each range
    /// `[lo, hi]` becomes `[-hi, -lo]`.
    pub fn mirrored(&self) -> SwingTwistLimits {
        let flip = |[lo, hi]: [f64; 2]| [-hi, -lo];
        SwingTwistLimits {
            twist_axis: self.twist_axis,
            centre_deg: self.centre_deg.map(|c| -c),
            half_deg: self.half_deg,
            corner_deg: self.corner_deg,
            twist_deg: flip(self.twist_deg),
            edge_twist_deg: flip(self.edge_twist_deg),
            zyx_box: self.zyx_box,
        }
    }

    /// The Z-Y-X box `[x, y, z]` (degrees) a [`SwingTwistLimits::zyx_box`]
    /// region reads: the twist range on X, the region's extent on `swing_1`
    /// (Y) and `swing_2` (Z).
    pub fn zyx_ranges(&self) -> [[f64; 2]; 3] {
        let [c1, c2] = self.centre_deg;
        let [h1, h2] = self.half_deg;
        [self.twist_deg, [c1 - h1, c1 + h1], [c2 - h2, c2 + h2]]
    }

    /// The swing-twist coordinates of a unit quaternion `[w, x, y, z]` (the
    /// rotation in the table's axes).
    pub fn decompose(&self, q: [f64; 4]) -> SwingTwist {
        if self.zyx_box {
            let (r, _) = self.zyx_readings(q);
            return SwingTwist {
                swing_deg: [r.pitch, r.yaw],
                twist_deg: r.roll,
            };
        }
        let [s1, s2, t] = coordinates(self.twist_axis, q);
        SwingTwist {
            swing_deg: [s1, s2],
            twist_deg: t,
        }
    }

    /// The twist range `[lo, hi]` (degrees) at relative swing radius `s`.
    pub fn twist_range(&self, s: f64) -> [f64; 2] {
        let f = s.clamp(0.0, 1.0);
        let [l0, h0] = self.twist_deg;
        let [l1, h1] = self.edge_twist_deg;
        [l0 + (l1 - l0) * f, h0 + (h1 - h0) * f]
    }

    /// The relative radius of a swing in the ellipse through the region's
    /// extremes (1 there; the twist range's interpolation variable).
    pub fn relative_radius(&self, swing_deg: [f64; 2]) -> f64 {
        let u = (swing_deg[0] - self.centre_deg[0]) / self.half_deg[0];
        let v = (swing_deg[1] - self.centre_deg[1]) / self.half_deg[1];
        (u * u + v * v).sqrt()
    }

    /// Excursion (degrees) of the rotation with quaternion `q` (`[w, x, y,
    /// z]`, the table's axes): swing distance beyond the ellipse plus twist
    /// beyond its range.
    pub fn excursion(&self, q: [f64; 4]) -> f64 {
        self.excursion_of(q)
    }

    /// [`SwingTwistLimits::excursion`] and its gradient with respect to the
    /// rotation vector `v` (radians) of `R * exp(v)` at `v = 0`, degrees per
    /// radian. At a kink (on the region's edge) it is the gradient of one side.
    pub fn excursion_grad(&self, q: [f64; 4]) -> (f64, [f64; 3]) {
        let [w, x, y, z] = q;
        // d q / d v_k = q * (0, e_k / 2).
        let dq = |k: usize| -> [f64; 4] {
            let mut e = [0.0; 3];
            e[k] = 0.5;
            [
                -x * e[0] - y * e[1] - z * e[2],
                w * e[0] + y * e[2] - z * e[1],
                w * e[1] + z * e[0] - x * e[2],
                w * e[2] + x * e[1] - y * e[0],
            ]
        };
        let d = [dq(0), dq(1), dq(2)];
        let qd: [Dual; 4] = std::array::from_fn(|c| Dual {
            v: q[c],
            d: [d[0][c], d[1][c], d[2][c]],
        });
        let e = self.excursion_of(qd);
        (e.v, e.d)
    }

    /// The excursion of the rotation with quaternion `q` (`[w, x, y, z]`,
    /// the table's axes) in its parts, degrees: what the report's per-axis
    /// figures count. `swing_deg + twist_deg` is [`SwingTwistLimits::excursion`].
    pub fn excursion_parts(&self, q: [f64; 4]) -> ExcursionParts {
        if self.zyx_box {
            let e = self.zyx_excursion(q);
            return ExcursionParts {
                swing_deg: e.pitch + e.yaw,
                swing_offset_deg: e.offset,
                twist_deg: e.roll,
            };
        }
        let (swing_deg, twist_deg, swing) = self.parts_of(q);
        let p = [swing[0] - self.centre_deg[0], swing[1] - self.centre_deg[1]];
        let swing_offset_deg = match self.nearest(p) {
            Some((_, near)) => [p[0] - near[0], p[1] - near[1]],
            None => [0.0, 0.0],
        };
        ExcursionParts {
            swing_deg,
            swing_offset_deg,
            twist_deg,
        }
    }

    fn excursion_of<S: Scalar>(&self, q: [S; 4]) -> S {
        if self.zyx_box {
            let e = self.zyx_excursion(q);
            return e.pitch + e.yaw + e.roll;
        }
        let (swing_e, twist_e, _) = self.parts_of(q);
        swing_e + twist_e
    }

    /// The Z-Y-X readings of `q` for a [`SwingTwistLimits::zyx_box`] region:
    /// the principal one, and the other triplet (`x + 180`, `+-180 - y`,
    /// `z + 180`) where the Y range reaches beyond +-90 deg.
    fn zyx_readings<S: Scalar>(&self, q: [S; 4]) -> (ZyxReading<S>, Option<ZyxReading<S>>) {
        let q = if q[0].val() < 0.0 { q.map(|c| -c) } else { q };
        let [w, x, y, z] = q;
        let (one, two) = (S::from(1.0), S::from(2.0));
        let r00 = one - two * (y * y + z * z);
        let r10 = two * (x * y + w * z);
        let r20 = two * (x * z - w * y);
        let r21 = two * (y * z + w * x);
        let r22 = one - two * (x * x + y * y);
        let cos_pitch = (r00 * r00 + r10 * r10).sqrt();
        let deg = S::from(DEG);
        let pitch = deg * S::atan2(-r20, cos_pitch);
        let yaw = deg * S::atan2(r10, r00);
        let roll = deg * S::atan2(r21, r22);
        let cap = ZYX_CAP_DEG.to_radians().cos();
        // Inside the caps the roll gives way to the twist: roll = twist -
        // shift, the shift (the twist of Rz(z) Ry(y)) weighed down. Outside
        // them the twist is not needed.
        let inside_cap = (cos_pitch.val() < cap).then(|| {
            (
                cos_pitch / S::from(cap),
                S::from(2.0 * DEG) * S::atan2(x, w),
            )
        });
        let weight = inside_cap.map(|(k, _)| k);
        let read = |roll: S, pitch: S, yaw: S| -> ZyxReading<S> {
            let roll = match inside_cap {
                None => roll,
                Some((k, twist)) => {
                    let shift = twist - roll;
                    let shift = shift + S::from(half_turn_wrap(shift.val()));
                    twist - k * shift
                }
            };
            ZyxReading {
                roll,
                pitch,
                yaw,
                weight,
            }
        };
        let principal = read(roll, pitch, yaw);
        if !crate::rotation::y_beyond_90(&self.zyx_ranges()) {
            return (principal, None);
        }
        let other_pitch = if pitch.val() >= 0.0 {
            S::from(180.0) - pitch
        } else {
            S::from(-180.0) - pitch
        };
        let turn = |a: S| {
            let a = a + S::from(180.0);
            a + S::from(half_turn_wrap(a.val()))
        };
        (principal, Some(read(turn(roll), other_pitch, turn(yaw))))
    }

    /// The excursion of a [`SwingTwistLimits::zyx_box`] region per Z-Y-X
    /// angle: of the reading with the smaller total.
    fn zyx_excursion<S: Scalar>(&self, q: [S; 4]) -> ZyxExcursion<S> {
        let (principal, other) = self.zyx_readings(q);
        let p = self.zyx_reading_excursion(&principal);
        let Some(other) = other else {
            return p;
        };
        let total = |e: &ZyxExcursion<S>| (e.roll + e.pitch + e.yaw).val();
        if total(&p) == 0.0 {
            return p;
        }
        let o = self.zyx_reading_excursion(&other);
        if total(&o) < total(&p) {
            o
        } else {
            p
        }
    }

    fn zyx_reading_excursion<S: Scalar>(&self, r: &ZyxReading<S>) -> ZyxExcursion<S> {
        let [x, y, z] = self.zyx_ranges().map(|r| r.map(S::from));
        let (roll, _) = beyond_range(r.roll, x[0], x[1], true);
        let (pitch, pitch_off) = beyond_range(r.pitch, y[0], y[1], false);
        let (yaw, yaw_off) = beyond_range(r.yaw, z[0], z[1], true);
        let (yaw, yaw_off) = match r.weight {
            None => (yaw, yaw_off),
            Some(k) => (k * yaw, k.val() * yaw_off),
        };
        ZyxExcursion {
            roll,
            pitch,
            yaw,
            offset: [pitch_off, yaw_off],
        }
    }

    /// The swing's excursion, the twist's and the swing's coordinates.
    fn parts_of<S: Scalar>(&self, q: [S; 4]) -> (S, S, [f64; 2]) {
        let [s1, s2, tw] = coordinates(self.twist_axis, q);
        let swing = [s1, s2];
        let swing_e = self.beyond_ellipse(swing);
        let u = (s1 - S::from(self.centre_deg[0])) / S::from(self.half_deg[0]);
        let v = (s2 - S::from(self.centre_deg[1])) / S::from(self.half_deg[1]);
        let r2 = u * u + v * v;
        let f = if r2.val() >= 1.0 {
            S::from(1.0)
        } else if r2.val() > 1e-24 {
            r2.sqrt()
        } else {
            S::from(0.0)
        };
        let [l0, h0] = self.twist_deg;
        let [l1, h1] = self.edge_twist_deg;
        let lo = S::from(l0) + S::from(l1 - l0) * f;
        let hi = S::from(h0) + S::from(h1 - h0) * f;
        // The twist is an angle on the circle: its excursion is the shorter
        // way round to the range, as the Euler box reads X and Z.
        let (twist_e, _) = beyond_range(tw, lo, hi, true);
        (swing_e, twist_e, [s1.val(), s2.val()])
    }

    /// The distance of a swing offset `p` from the centre (degrees) beyond
    /// the region and the region's nearest point (relative to the centre);
    /// `None` inside.
    fn nearest(&self, p: [f64; 2]) -> Option<(f64, [f64; 2])> {
        let [a, b] = self.half_deg;
        let (d, near) = match self.corner_deg {
            Some(r) => {
                // The box shrunk by r, then every point within r of it.
                let q = [
                    (p[0].abs() - (a - r)).max(0.0),
                    (p[1].abs() - (b - r)).max(0.0),
                ];
                let len = (q[0] * q[0] + q[1] * q[1]).sqrt();
                if len <= r {
                    return None;
                }
                let k = r / len;
                let near = [
                    (p[0].abs() - q[0] * (1.0 - k)).copysign(p[0]),
                    (p[1].abs() - q[1] * (1.0 - k)).copysign(p[1]),
                ];
                (len - r, near)
            }
            None => {
                if (p[0] / a).powi(2) + (p[1] / b).powi(2) <= 1.0 {
                    return None;
                }
                ellipse_distance(a, b, p)
            }
        };
        (d > 0.0).then_some((d, near))
    }

    /// Distance (degrees) of a swing beyond the ellipse, 0 inside; its
    /// derivatives are those of the distance from the nearest point of the
    /// ellipse, which moves along the outward normal.
    fn beyond_ellipse<S: Scalar>(&self, swing: [S; 2]) -> S {
        let p = [
            swing[0].val() - self.centre_deg[0],
            swing[1].val() - self.centre_deg[1],
        ];
        let Some((d, near)) = self.nearest(p) else {
            return S::from(0.0);
        };
        let n = [(p[0] - near[0]) / d, (p[1] - near[1]) / d];
        // d = n . (swing - centre - near), with near fixed to first order.
        let dc = [self.centre_deg[0] + near[0], self.centre_deg[1] + near[1]];
        S::from(n[0]) * (swing[0] - S::from(dc[0])) + S::from(n[1]) * (swing[1] - S::from(dc[1]))
    }
}

/// One Z-Y-X reading of a rotation for a [`SwingTwistLimits::zyx_box`]
/// region, degrees: `roll` is the twist less its weighed shift inside the
/// caps, `weight` the caps' weight (`None` outside them).
struct ZyxReading<S> {
    roll: S,
    pitch: S,
    yaw: S,
    weight: Option<S>,
}

/// The excursion of a [`ZyxReading`] per angle (degrees; `yaw` weighed),
/// and the signed offsets of pitch and yaw beyond their ranges.
struct ZyxExcursion<S> {
    roll: S,
    pitch: S,
    yaw: S,
    offset: [f64; 2],
}

/// The turn (a multiple of 360 degrees) that brings angle `a` into `(-180,
/// 180]`.
fn half_turn_wrap(a: f64) -> f64 {
    -360.0 * ((a - 180.0) / 360.0).ceil()
}

/// The excursion of `a` beyond `[lo, hi]` (degrees; on the circle the
/// shorter way round when `circle`, as the Euler box reads X and Z) and the
/// signed offset (positive above). The bounds may carry derivatives (a
/// twist range that moves with the swing).
fn beyond_range<S: Scalar>(a: S, lo: S, hi: S, circle: bool) -> (S, f64) {
    let a = if circle {
        a + S::from(crate::rotation::arc_turn(a.val(), lo.val(), hi.val()))
    } else {
        a
    };
    match crate::rotation::beyond_line_slope(a.val(), lo.val(), hi.val()) {
        (_, 0.0) => (S::from(0.0), 0.0),
        (e, slope) if slope > 0.0 => (a - hi, e),
        (e, _) => (lo - a, -e),
    }
}

/// Distance from a point `p` outside the ellipse with half-axes `a` (along
/// the first coordinate) and `b`, centred at the origin, and the nearest
/// point of the ellipse. Bisection on the nearest point's Lagrange
/// multiplier, which is exact to the last bit and deterministic.
pub fn ellipse_distance(a: f64, b: f64, p: [f64; 2]) -> (f64, [f64; 2]) {
    // Work with the longer axis first and in the first quadrant.
    let (swap, e0, e1, y0, y1) = if a >= b {
        (false, a, b, p[0].abs(), p[1].abs())
    } else {
        (true, b, a, p[1].abs(), p[0].abs())
    };
    let (x0, x1) = if y1 > 0.0 {
        if y0 > 0.0 {
            let z0 = y0 / e0;
            let z1 = y1 / e1;
            let r0 = (e0 / e1) * (e0 / e1);
            let s = root(r0, z0, z1);
            (r0 * y0 / (s + r0), y1 / (s + 1.0))
        } else {
            (0.0, e1)
        }
    } else {
        let numer = e0 * y0;
        let denom = e0 * e0 - e1 * e1;
        if numer < denom {
            let xd = numer / denom;
            (e0 * xd, e1 * (1.0 - xd * xd).max(0.0).sqrt())
        } else {
            (e0, 0.0)
        }
    };
    let d = ((x0 - y0).powi(2) + (x1 - y1).powi(2)).sqrt();
    let (n0, n1) = if swap { (x1, x0) } else { (x0, x1) };
    let near = [n0.copysign(p[0]), n1.copysign(p[1])];
    (d, near)
}

/// The root `s` of `(r0 z0 / (s + r0))^2 + (z1 / (s + 1))^2 = 1` for a point
/// outside the ellipse (`s > 0`), by bisection.
fn root(r0: f64, z0: f64, z1: f64) -> f64 {
    let n0 = r0 * z0;
    let mut s0 = z1 - 1.0;
    let mut s1 = (n0 * n0 + z1 * z1).sqrt() - 1.0;
    let mut s = 0.0;
    for _ in 0..2200 {
        s = 0.5 * (s0 + s1);
        if s == s0 || s == s1 {
            break;
        }
        let g = (n0 / (s + r0)).powi(2) + (z1 / (s + 1.0)).powi(2) - 1.0;
        if g > 0.0 {
            s0 = s;
        } else if g < 0.0 {
            s1 = s;
        } else {
            break;
        }
    }
    s
}

/// `[swing_1, swing_2, twist]`, degrees, of the unit quaternion `q`
/// (`[w, x, y, z]`) for twist axis `t` ([`twist_in_proximal`] says on which
/// side the twist is).
///
/// For `R = swing * twist`: with `(t, i, j)` a cyclic order of the axes and `q = (w, v)` taken with
/// `w >= 0`: twist `= 2 atan2(v_t, w)`; swing `= q * twist^-1` has the
/// quaternion `(n, ((w v_i - v_t v_j) e_i + (w v_j + v_t v_i) e_j) / n)`,
/// `n = sqrt(w^2 + v_t^2)`, so its angle is `2 atan2(sqrt(v_i^2 + v_j^2), n)`.
fn coordinates<S: Scalar>(t: usize, q: [S; 4]) -> [S; 3] {
    if twist_in_proximal(t) {
        // R = twist * swing: R^-1 = swing^-1 * twist^-1, whose coordinates
        // are the negated ones.
        let [w, x, y, z] = q;
        return coordinates_distal(t, [w, -x, -y, -z]).map(|c| -c);
    }
    coordinates_distal(t, q)
}

/// Whether the twist about table axis `t` is taken in the proximal segment's
/// frame (`R = twist * swing`) rather than the distal one's (`R = swing *
/// twist`): where the table's Z-Y-X sequence turns about that axis. Its last
/// turn, about X, is about the distal segment's axis; its first, about Z,
/// about the proximal one's; Y, between them, is taken as the distal's (on the
/// sample trials the nearer of the two to the table's Z-Y-X angles).
pub fn twist_in_proximal(t: usize) -> bool {
    t == 2
}

/// [`coordinates`] for `R = swing * twist`.
fn coordinates_distal<S: Scalar>(t: usize, q: [S; 4]) -> [S; 3] {
    let q = if q[0].val() < 0.0 { q.map(|c| -c) } else { q };
    let (i, j) = ((t + 1) % 3, (t + 2) % 3);
    let (w, vt, vi, vj) = (q[0], q[1 + t], q[1 + i], q[1 + j]);
    let n2 = w * w + vt * vt;
    let m2 = vi * vi + vj * vj;
    let mut out = [S::from(0.0); 3];
    if n2.val() < 1e-30 {
        // A swing of 180 degrees: the twist is undefined; take it as 0.
        let m = m2.sqrt();
        let k = S::from(180.0) / m;
        out_put(&mut out, t, i, j, vi * k, vj * k);
        return out;
    }
    let n = n2.sqrt();
    let twist = S::from(2.0 * DEG) * S::atan2(vt, w);
    let pi = (w * vi - vt * vj) / n;
    let pj = (w * vj + vt * vi) / n;
    // sigma / m, with its limit 2 / n at m = 0.
    let k = if m2.val() > 1e-18 {
        let m = m2.sqrt();
        S::from(2.0 * DEG) * S::atan2(m, n) / m
    } else {
        S::from(2.0 * DEG) / n
    };
    out_put(&mut out, t, i, j, pi * k, pj * k);
    out[2] = twist;
    out
}

/// Places the swing's components on table axes `i` and `j` into
/// `[swing_1, swing_2]` (X, Y, Z order, twist axis `t` left out).
fn out_put<S: Scalar>(out: &mut [S; 3], t: usize, i: usize, j: usize, si: S, sj: S) {
    let [a1, _] = swing_axes(t);
    if i == a1 {
        out[0] = si;
        out[1] = sj;
    } else {
        debug_assert_eq!(j, a1);
        out[0] = sj;
        out[1] = si;
    }
}

/// The arithmetic the model's formulas need: plain numbers, and numbers
/// carrying their derivatives along three directions.
trait Scalar:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    fn from(v: f64) -> Self;
    fn val(self) -> f64;
    fn sqrt(self) -> Self;
    fn atan2(y: Self, x: Self) -> Self;
}

impl Scalar for f64 {
    fn from(v: f64) -> Self {
        v
    }
    fn val(self) -> f64 {
        self
    }
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
    fn atan2(y: Self, x: Self) -> Self {
        f64::atan2(y, x)
    }
}

/// A value and its derivatives along three directions (forward-mode
/// differentiation).
#[derive(Debug, Clone, Copy)]
struct Dual {
    v: f64,
    d: [f64; 3],
}

impl Add for Dual {
    type Output = Dual;
    fn add(self, o: Dual) -> Dual {
        Dual {
            v: self.v + o.v,
            d: std::array::from_fn(|k| self.d[k] + o.d[k]),
        }
    }
}

impl Sub for Dual {
    type Output = Dual;
    fn sub(self, o: Dual) -> Dual {
        Dual {
            v: self.v - o.v,
            d: std::array::from_fn(|k| self.d[k] - o.d[k]),
        }
    }
}

impl Mul for Dual {
    type Output = Dual;
    // The product rule: (uv)' = u'v + uv'.
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn mul(self, o: Dual) -> Dual {
        Dual {
            v: self.v * o.v,
            d: std::array::from_fn(|k| self.d[k] * o.v + self.v * o.d[k]),
        }
    }
}

impl Div for Dual {
    type Output = Dual;
    // The quotient rule: (u/v)' = (u' - (u/v) v') / v.
    #[allow(clippy::suspicious_arithmetic_impl)]
    fn div(self, o: Dual) -> Dual {
        let inv = 1.0 / o.v;
        Dual {
            v: self.v / o.v,
            d: std::array::from_fn(|k| (self.d[k] - self.v * inv * o.d[k]) * inv),
        }
    }
}

impl Neg for Dual {
    type Output = Dual;
    fn neg(self) -> Dual {
        Dual {
            v: -self.v,
            d: self.d.map(|x| -x),
        }
    }
}

impl Scalar for Dual {
    fn from(v: f64) -> Self {
        Dual { v, d: [0.0; 3] }
    }
    fn val(self) -> f64 {
        self.v
    }
    fn sqrt(self) -> Self {
        let r = self.v.sqrt();
        let k = if r > 0.0 { 0.5 / r } else { 0.0 };
        Dual {
            v: r,
            d: self.d.map(|x| x * k),
        }
    }
    fn atan2(y: Self, x: Self) -> Self {
        let r2 = x.v * x.v + y.v * y.v;
        let k = if r2 > 0.0 { 1.0 / r2 } else { 0.0 };
        Dual {
            v: y.v.atan2(x.v),
            d: std::array::from_fn(|c| (x.v * y.d[c] - y.v * x.d[c]) * k),
        }
    }
}

/// The CSV header of a swing-twist limit table: it tells the loader the
/// table is of this model (an Euler table starts `joint,axis,...`).
pub const HEADER: [&str; 16] = [
    "joint",
    "twist_axis",
    "movement",
    "swing_1_centre_deg",
    "swing_2_centre_deg",
    "swing_1_half_deg",
    "swing_2_half_deg",
    "swing_corner_deg",
    "twist_lower_deg",
    "twist_upper_deg",
    "edge_twist_lower_deg",
    "edge_twist_upper_deg",
    "centroid_x_deg",
    "centroid_y_deg",
    "centroid_z_deg",
    "lambda2",
];

/// One row of a swing-twist table: one joint (kind, or a single joint's name
/// overriding its kind's row).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SwingTwistRow {
    pub joint: String,
    pub movement: String,
    pub limits: SwingTwistLimits,
    /// Centroid as Z-Y-X Euler angles `[x, y, z]` of the table's axes,
    /// degrees (as in the Euler tables), when the row gives one.
    pub centroid_deg: Option<[f64; 3]>,
    /// Weight of the centroid term.
    pub lambda2: f64,
}

impl SwingTwistRow {
    /// The Euler-table rows that box this row's region (the limits every
    /// view and check that reads Z-Y-X angles sees): the twist axis' range
    /// spans both twist ranges, each swing axis' the region's extent along
    /// it. Exact for movements about one axis at a time. Their movements name
    /// the twist axis a rotation and `swing_1` flexion, as the globographic
    /// view reads them ([`crate::analysis::globe::JointAxes`]).
    pub fn euler_rows(&self) -> [super::LimitRow; 3] {
        let l = &self.limits;
        let axes = swing_axes(l.twist_axis);
        std::array::from_fn(|axis| {
            let (range, movement) = if axis == l.twist_axis {
                (
                    [
                        l.twist_deg[0].min(l.edge_twist_deg[0]),
                        l.twist_deg[1].max(l.edge_twist_deg[1]),
                    ],
                    "rotation (twist)",
                )
            } else {
                let k = usize::from(axes[1] == axis);
                (
                    [
                        (l.centre_deg[k] - l.half_deg[k]).max(-180.0),
                        (l.centre_deg[k] + l.half_deg[k]).min(180.0),
                    ],
                    ["flexion/extension (swing_1)", "ab/adduction (swing_2)"][k],
                )
            };
            super::LimitRow {
                joint: self.joint.clone(),
                axis,
                movement: movement.into(),
                lower_deg: range[0],
                upper_deg: range[1],
                centroid_deg: self.centroid_deg.map(|c| c[axis]),
                lambda2: self.lambda2,
            }
        })
    }

    /// The row as a CSV line (no line break), fields as [`HEADER`].
    pub fn to_csv(&self) -> String {
        let l = &self.limits;
        let edge = if l.edge_twist_deg == l.twist_deg {
            [String::new(), String::new()]
        } else {
            l.edge_twist_deg.map(|v| v.to_string())
        };
        let centroid = match self.centroid_deg {
            Some(c) => c.map(|v| v.to_string()),
            None => [String::new(), String::new(), String::new()],
        };
        format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}",
            super::csv_field(&self.joint),
            super::axis_name(l.twist_axis),
            super::csv_field(&self.movement),
            l.centre_deg[0],
            l.centre_deg[1],
            l.half_deg[0],
            l.half_deg[1],
            if l.zyx_box {
                "zyx".to_string()
            } else {
                l.corner_deg.map(|r| r.to_string()).unwrap_or_default()
            },
            l.twist_deg[0],
            l.twist_deg[1],
            edge[0],
            edge[1],
            centroid[0],
            centroid[1],
            centroid[2],
            self.lambda2
        )
    }
}

/// Parses one record of a swing-twist table at `line`; errors name the
/// 1-based field and what was expected there.
pub(super) fn parse_row(
    rec: &csv::StringRecord,
    line: u64,
    err: &dyn Fn(u64, usize, String) -> super::LimitsError,
) -> Result<SwingTwistRow, super::LimitsError> {
    if rec.len() != HEADER.len() {
        return Err(err(
            line,
            rec.len().min(HEADER.len()) + 1,
            format!("expected {} fields, found {}", HEADER.len(), rec.len()),
        ));
    }
    let joint = rec[0].to_string();
    if joint.is_empty() {
        return Err(err(line, 1, "expected a joint name, found nothing".into()));
    }
    let twist_axis = super::parse_axis(&rec[1]).ok_or_else(|| {
        err(
            line,
            2,
            format!("expected the twist axis X, Y or Z, found '{}'", &rec[1]),
        )
    })?;
    let number = |col: usize, lo: f64, hi: f64| -> Result<f64, super::LimitsError> {
        let s = &rec[col];
        match s.parse::<f64>() {
            Ok(v) if v.is_finite() && (lo..=hi).contains(&v) => Ok(v),
            _ => Err(err(
                line,
                col + 1,
                format!(
                    "expected {} in degrees within {lo}..{hi}, found '{s}'",
                    HEADER[col]
                ),
            )),
        }
    };
    let optional = |col: usize, lo: f64, hi: f64| -> Result<Option<f64>, super::LimitsError> {
        if rec[col].is_empty() {
            Ok(None)
        } else {
            number(col, lo, hi).map(Some)
        }
    };
    let centre_deg = [number(3, -180.0, 180.0)?, number(4, -180.0, 180.0)?];
    let mut half_deg = [0.0; 2];
    for (k, half) in half_deg.iter_mut().enumerate() {
        let col = 5 + k;
        *half = number(col, 0.0, 180.0)?;
        if *half <= 0.0 {
            return Err(err(
                line,
                col + 1,
                format!("expected {} > 0 degrees, found {half}", HEADER[col]),
            ));
        }
    }
    let range = |c: usize| -> Result<Option<[f64; 2]>, super::LimitsError> {
        let (lo, hi) = (optional(c, -180.0, 180.0)?, optional(c + 1, -180.0, 180.0)?);
        match (lo, hi) {
            (None, None) => Ok(None),
            (Some(lo), Some(hi)) if lo < hi => Ok(Some([lo, hi])),
            (Some(lo), Some(hi)) => Err(err(
                line,
                c + 2,
                format!(
                    "expected {} > {}, found {hi} <= {lo}",
                    HEADER[c + 1],
                    HEADER[c]
                ),
            )),
            (None, Some(_)) => Err(err(
                line,
                c + 1,
                format!(
                    "expected {} as {} is set, found nothing",
                    HEADER[c],
                    HEADER[c + 1]
                ),
            )),
            (Some(_), None) => Err(err(
                line,
                c + 2,
                format!(
                    "expected {} as {} is set, found nothing",
                    HEADER[c + 1],
                    HEADER[c]
                ),
            )),
        }
    };
    let zyx_box = rec[7].trim().eq_ignore_ascii_case("zyx");
    if zyx_box && twist_axis != 0 {
        return Err(err(
            line,
            2,
            format!(
                "expected twist_axis X with swing_corner_deg zyx (the Z-Y-X box), found '{}'",
                &rec[1]
            ),
        ));
    }
    let corner_deg = if zyx_box {
        None
    } else {
        optional(7, 0.0, 180.0).map_err(|_| {
            err(
                line,
                8,
                format!(
                    "expected swing_corner_deg in degrees within 0..180, empty or zyx, found '{}'",
                    &rec[7]
                ),
            )
        })?
    };
    if let Some(r) = corner_deg {
        let most = half_deg[0].min(half_deg[1]);
        if r > most {
            return Err(err(
                line,
                8,
                format!(
                    "expected swing_corner_deg at most the smaller half-angle ({most}), found {r}"
                ),
            ));
        }
    }
    let twist_deg = range(8)?.ok_or_else(|| {
        err(
            line,
            9,
            "expected twist_lower_deg and twist_upper_deg, found nothing".into(),
        )
    })?;
    let edge_twist_deg = range(10)?.unwrap_or(twist_deg);
    if zyx_box && edge_twist_deg != twist_deg {
        return Err(err(
            line,
            11,
            "expected no edge twist range with swing_corner_deg zyx (the Z-Y-X box has one twist range), found one".into(),
        ));
    }
    let c = [
        optional(12, -180.0, 180.0)?,
        optional(13, -180.0, 180.0)?,
        optional(14, -180.0, 180.0)?,
    ];
    let centroid_deg = match c {
        [Some(x), Some(y), Some(z)] => Some([x, y, z]),
        [None, None, None] => None,
        _ => {
            let col = c.iter().position(Option::is_none).unwrap_or(0) + 13;
            return Err(err(
                line,
                col,
                "expected all three centroid angles or none, found some only".into(),
            ));
        }
    };
    let lambda2 = match rec[15].parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => v,
        _ => {
            return Err(err(
                line,
                16,
                format!(
                    "expected lambda2 as a finite number >= 0, found '{}'",
                    &rec[15]
                ),
            ))
        }
    };
    Ok(SwingTwistRow {
        joint,
        movement: rec[2].to_string(),
        limits: SwingTwistLimits {
            twist_axis,
            centre_deg,
            half_deg,
            corner_deg,
            twist_deg,
            edge_twist_deg,
            zyx_box,
        },
        centroid_deg,
        lambda2,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{quat_axis_angle_deg, wxyz, Quat};
    use nalgebra::Vector3;

    fn knee() -> SwingTwistLimits {
        SwingTwistLimits {
            twist_axis: 0,
            centre_deg: [65.0, 0.0],
            half_deg: [65.0, 5.0],
            corner_deg: None,
            twist_deg: [-5.0, 5.0],
            edge_twist_deg: [-5.0, 5.0],
            zyx_box: false,
        }
    }

    /// A Z-Y-X box region with the ranges `[x, y, z]` (degrees).
    fn zyx(range: [[f64; 2]; 3]) -> SwingTwistLimits {
        let [x, y, z] = range;
        SwingTwistLimits {
            twist_axis: 0,
            centre_deg: [0.5 * (y[0] + y[1]), 0.5 * (z[0] + z[1])],
            half_deg: [0.5 * (y[1] - y[0]), 0.5 * (z[1] - z[0])],
            corner_deg: None,
            twist_deg: x,
            edge_twist_deg: x,
            zyx_box: true,
        }
    }

    /// Table 3-2's boxes of the back, shoulder, hip (Y beyond 90: two
    /// readings), ankle and a knee.
    const BOXES: [[[f64; 2]; 3]; 5] = [
        [[-30.0, 30.0], [-25.0, 30.0], [-35.0, 35.0]],
        [[-10.0, 100.0], [-40.0, 60.0], [-70.0, 70.0]],
        [[-50.0, 40.0], [-30.0, 100.0], [-20.0, 50.0]],
        [[-30.0, 20.0], [-20.0, 45.0], [-10.0, 10.0]],
        [[-5.0, 5.0], [0.0, 130.0], [-5.0, 5.0]],
    ];

    fn random_rotation(k: usize) -> Quat {
        let f = |a: f64| (a * 12.9898 + k as f64 * 78.233).sin() * 43758.5453 % 1.0;
        quat_axis_angle_deg([f(1.0), f(2.0), f(3.0)], 180.0 * f(4.0).abs())
    }

    /// Away from the caps the Z-Y-X box region's excursion is the Euler
    /// box's, `Ex + Ey + Ez` of the Z-Y-X angles as the limits read them.
    #[test]
    fn a_zyx_box_is_the_euler_box_outside_the_caps() {
        let mut compared = 0;
        for range in BOXES {
            let lim = zyx(range);
            for k in 0..4000 {
                let q = random_rotation(k);
                let angles =
                    crate::rotation::read_in_box(crate::rotation::euler_zyx_deg(&q), &range);
                if crate::rotation::euler_zyx_deg(&q)[1].abs() >= ZYX_CAP_DEG {
                    continue;
                }
                let want: f64 = crate::rotation::box_excursion(angles, &range).iter().sum();
                let got = lim.excursion(wxyz(&q));
                assert!(
                    (got - want).abs() < 1e-9,
                    "{range:?} {angles:?}: {got} vs {want}"
                );
                let parts = lim.excursion_parts(wxyz(&q));
                assert!((parts.swing_deg + parts.twist_deg - got).abs() < 1e-9);
                compared += 1;
            }
        }
        assert!(compared > 10_000, "{compared}");
    }

    /// Inside the caps the excursion has no singularity: near the pole its
    /// rate stays bounded (pitch 1, the weighed yaw `1 / cos(cap)` plus the
    /// weight's rate times the yaw's excursion, the roll 1 plus the weight's
    /// rate times the shift (at most 180) plus the weighed shift's rate:
    /// under 20 deg per deg), where the Euler box's grows as one over the
    /// distance from the pole.
    #[test]
    fn a_zyx_box_has_no_singularity_at_the_poles() {
        let lim = zyx(BOXES[1]);
        let mut worst_rate: f64 = 0.0;
        let mut euler_worst: f64 = 0.0;
        let axis =
            |k: usize| -> [f64; 3] { random_rotation(k).axis().unwrap().into_inner().into() };
        for k in 0..400 {
            // 0.3 deg from the pole Y = 90, then a step of 0.01 deg.
            let near =
                quat_axis_angle_deg([0.0, 1.0, 0.0], 90.0) * quat_axis_angle_deg(axis(k), 0.3);
            let (a, b) = (near, near * quat_axis_angle_deg(axis(k + 7), 0.01));
            let rate = (lim.excursion(wxyz(&a)) - lim.excursion(wxyz(&b))).abs() / 0.01;
            worst_rate = worst_rate.max(rate);
            let e = |q: &Quat| -> f64 {
                let ang =
                    crate::rotation::read_in_box(crate::rotation::euler_zyx_deg(q), &BOXES[1]);
                crate::rotation::box_excursion(ang, &BOXES[1]).iter().sum()
            };
            euler_worst = euler_worst.max((e(&a) - e(&b)).abs() / 0.01);
        }
        eprintln!("rate near the pole: {worst_rate:.2} (Euler box {euler_worst:.1}) deg per deg");
        assert!(worst_rate <= 20.0, "{worst_rate}");
        assert!(euler_worst > 100.0, "{euler_worst}");
    }

    /// The gradient of a Z-Y-X box region against central differences,
    /// inside and outside the caps.
    #[test]
    fn a_zyx_box_gradient_is_the_finite_difference() {
        let h = 1e-6;
        let mut checked = 0;
        for range in BOXES {
            let lim = zyx(range);
            for k in 0..300 {
                let q = random_rotation(k + 99);
                let (e, g) = lim.excursion_grad(wxyz(&q));
                for (axis, gk) in g.iter().enumerate() {
                    let mut v = Vector3::zeros();
                    v[axis] = h;
                    let up = lim.excursion(wxyz(&(q * Quat::from_scaled_axis(v))));
                    let down = lim.excursion(wxyz(&(q * Quat::from_scaled_axis(-v))));
                    // Skip a kink within the step.
                    if ((up - e) - (e - down)).abs() > 1e-4 * h.max((up - e).abs()) + 1e-9 {
                        continue;
                    }
                    let fd = (up - down) / (2.0 * h);
                    assert!(
                        (fd - gk).abs() < 1e-4 * (1.0 + gk.abs()),
                        "{range:?} {k} {axis}: {gk} vs {fd}"
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 2000, "{checked}");
    }

    /// The decomposition against one built from nalgebra: twist the rotation
    /// about `t` of the quaternion's projection, swing the rest.
    #[test]
    fn coordinates_match_an_independent_decomposition() {
        for t in 0..3 {
            let lim = SwingTwistLimits {
                twist_axis: t,
                ..knee()
            };
            for (axis, angle) in [
                ([1.0, 2.0, -0.5], 70.0),
                ([0.3, -1.0, 0.2], 140.0),
                ([-1.0, 0.1, 0.9], 20.0),
                ([0.0, 0.0, 1.0], 100.0),
            ] {
                let q = quat_axis_angle_deg(axis, angle);
                let st = lim.decompose(wxyz(&q));
                let mut e = Vector3::zeros();
                e[t] = 1.0;
                let v = q.imag();
                let proj = v.dot(&e) * e;
                let twist = Quat::from_quaternion(nalgebra::Quaternion::from_parts(q.w, proj));
                let swing = if twist_in_proximal(t) {
                    twist.inverse() * q
                } else {
                    q * twist.inverse()
                };
                let sv = swing.scaled_axis() * DEG;
                let tv = twist.scaled_axis() * DEG;
                assert!(sv[t].abs() < 1e-9, "swing has no twist part");
                let [a1, a2] = swing_axes(t);
                assert!((st.swing_deg[0] - sv[a1]).abs() < 1e-9, "{t} {st:?} {sv:?}");
                assert!((st.swing_deg[1] - sv[a2]).abs() < 1e-9, "{t} {st:?} {sv:?}");
                assert!((st.twist_deg - tv[t]).abs() < 1e-9, "{t} {st:?} {tv:?}");
                // Sign-invariant.
                let neg = wxyz(&q).map(|c| -c);
                assert_eq!(lim.decompose(neg).swing_deg, st.swing_deg);
            }
        }
    }

    #[test]
    fn ellipse_distance_is_the_nearest_point() {
        for (a, b) in [(65.0_f64, 5.0_f64), (5.0, 65.0), (30.0, 30.0), (40.0, 10.0)] {
            for p in [
                [80.0, 3.0],
                [-10.0, -20.0],
                [0.0, 90.0],
                [100.0, 0.0],
                [20.0, 40.0],
            ] {
                if (p[0] / a).powi(2) + (p[1] / b).powi(2) <= 1.0 {
                    continue;
                }
                let (d, near) = ellipse_distance(a, b, p);
                assert!(((near[0] / a).powi(2) + (near[1] / b).powi(2) - 1.0).abs() < 1e-9);
                // No point of the ellipse is nearer (dense check).
                let best = (0..200_000)
                    .map(|k| {
                        let th = k as f64 * std::f64::consts::TAU / 200_000.0;
                        ((a * th.cos() - p[0]).powi(2) + (b * th.sin() - p[1]).powi(2)).sqrt()
                    })
                    .fold(f64::INFINITY, f64::min);
                assert!(
                    d <= best + 1e-9 && d > best - 1e-3,
                    "{a} {b} {p:?}: {d} vs {best}"
                );
            }
        }
    }

    #[test]
    fn an_asymmetric_twist_range_has_no_wall_where_the_twist_wraps() {
        // Elbow flexion as the twist, [0, 160]: past 180 the reading wraps to
        // -180, and the excursion goes on from 20 deg past 160 rather than
        // jumping to 180 below 0.
        let elbow = SwingTwistLimits {
            twist_axis: 0,
            centre_deg: [0.0, 0.0],
            half_deg: [5.0, 30.0],
            corner_deg: Some(0.0),
            twist_deg: [0.0, 160.0],
            edge_twist_deg: [0.0, 160.0],
            zyx_box: false,
        };
        let e = |deg: f64| elbow.excursion(wxyz(&quat_axis_angle_deg([1.0, 0.0, 0.0], deg)));
        assert!((e(170.0) - 10.0).abs() < 1e-9);
        assert!((e(179.0) - 19.0).abs() < 1e-9);
        assert!((e(181.0) - 21.0).abs() < 1e-9, "{}", e(181.0));
        assert!((e(-10.0) - 10.0).abs() < 1e-9);
        // The middle of the forbidden arc, -100 deg, is 100 from both ends.
        assert!((e(-100.0) - 100.0).abs() < 1e-9);
        let mut last = e(0.0);
        for k in 1..=720 {
            let now = e(k as f64 * 0.5);
            assert!((now - last).abs() <= 0.5 + 1e-6, "{k}: {last} -> {now}");
            last = now;
        }
        // The gradient follows the shorter way: at 200 deg (-160 read) the
        // excursion grows with the flexion.
        let (v, g) = elbow.excursion_grad(wxyz(&quat_axis_angle_deg([1.0, 0.0, 0.0], 200.0)));
        assert!((v - 40.0).abs() < 1e-9);
        assert!((g[0] - DEG).abs() < 1e-6, "{g:?}");
    }

    #[test]
    fn excursion_of_simple_movements() {
        let lim = knee();
        let e = |axis: [f64; 3], deg: f64| lim.excursion(wxyz(&quat_axis_angle_deg(axis, deg)));
        assert_eq!(e([0.0, 1.0, 0.0], 100.0), 0.0);
        assert!((e([0.0, 1.0, 0.0], 140.0) - 10.0).abs() < 1e-9);
        assert!((e([0.0, 1.0, 0.0], -10.0) - 10.0).abs() < 1e-9);
        assert!((e([1.0, 0.0, 0.0], 12.0) - 7.0).abs() < 1e-9);
        // At zero flexion the ellipse's tip leaves no ab/adduction: 8 deg
        // about Z is nearly 8 deg beyond it (the nearest point is a little
        // past the tip).
        let tip = e([0.0, 0.0, 1.0], 8.0);
        assert!(tip > 7.0 && tip < 8.0, "{tip}");
        // The rounded box: the range of each axis, corners rounded.
        let boxed = SwingTwistLimits {
            corner_deg: Some(2.0),
            ..lim
        };
        // A swing with rotation vector (0, s1, s2) degrees, no twist.
        let b = |s1: f64, s2: f64| {
            let q = Quat::from_scaled_axis(Vector3::new(0.0, s1, s2).map(f64::to_radians));
            boxed.excursion(wxyz(&q))
        };
        assert!((b(60.0, 8.0) - 3.0).abs() < 1e-9);
        assert_eq!(b(1.0, 4.0), 0.0);
        assert!((b(30.0, -8.0) - 3.0).abs() < 1e-9);
        // Beyond a corner: from the inner box's corner (2, 3), less the radius.
        assert!((b(-1.0, 6.0) - (18f64.sqrt() - 2.0)).abs() < 1e-9);
        assert_eq!(b(1.5, 4.5), 0.0);
        // A cone: the excursion is the angle beyond it in every direction.
        let cone = SwingTwistLimits {
            twist_axis: 2,
            centre_deg: [0.0, 0.0],
            half_deg: [30.0, 30.0],
            corner_deg: None,
            twist_deg: [-10.0, 10.0],
            edge_twist_deg: [-20.0, 0.0],
            zyx_box: false,
        };
        for dir in [[1.0, 0.0, 0.0], [0.6, -0.8, 0.0], [-1.0, 1.0, 0.0]] {
            let q = quat_axis_angle_deg(dir, 50.0);
            assert!((cone.excursion(wxyz(&q)) - 20.0).abs() < 1e-9);
        }
        // On the cone's edge the twist range is the edge's.
        let edge =
            quat_axis_angle_deg([1.0, 0.0, 0.0], 30.0) * quat_axis_angle_deg([0.0, 0.0, 1.0], 5.0);
        assert!((cone.excursion(wxyz(&edge)) - 5.0).abs() < 1e-9);
        let half =
            quat_axis_angle_deg([1.0, 0.0, 0.0], 15.0) * quat_axis_angle_deg([0.0, 0.0, 1.0], 5.0);
        assert_eq!(cone.excursion(wxyz(&half)), 0.0);
        assert_eq!(cone.twist_range(0.5), [-15.0, 5.0]);
    }

    #[test]
    fn gradient_matches_finite_differences() {
        let lims = [
            knee(),
            SwingTwistLimits {
                twist_axis: 1,
                centre_deg: [20.0, -10.0],
                half_deg: [30.0, 50.0],
                corner_deg: Some(10.0),
                twist_deg: [-40.0, 60.0],
                edge_twist_deg: [-10.0, 20.0],
                zyx_box: false,
            },
            SwingTwistLimits {
                twist_axis: 2,
                centre_deg: [0.0, 0.0],
                half_deg: [25.0, 25.0],
                corner_deg: None,
                twist_deg: [-10.0, 10.0],
                edge_twist_deg: [-10.0, 10.0],
                zyx_box: false,
            },
        ];
        let mut checked = 0;
        for lim in lims {
            for k in 0..60 {
                let axis = [
                    (k as f64 * 1.3).sin(),
                    (k as f64 * 0.7).cos(),
                    (k as f64 * 2.1).sin(),
                ];
                let q = quat_axis_angle_deg(axis, 5.0 + 2.7 * k as f64);
                let (f, g) = lim.excursion_grad(wxyz(&q));
                assert_eq!(f, lim.excursion(wxyz(&q)));
                let h = 1e-7;
                for c in 0..3 {
                    let mut v = Vector3::zeros();
                    v[c] = h;
                    let up = (lim.excursion(wxyz(&(q * Quat::from_scaled_axis(v)))) - f) / h;
                    let down = (f - lim.excursion(wxyz(&(q * Quat::from_scaled_axis(-v))))) / h;
                    let tol = 1e-4 * (1.0 + g[c].abs());
                    if (up - down).abs() > tol {
                        continue; // a kink within the step
                    }
                    assert!(
                        (0.5 * (up + down) - g[c]).abs() < tol,
                        "{lim:?} {k} {c}: {up} vs {}",
                        g[c]
                    );
                    checked += 1;
                }
            }
        }
        assert!(checked > 450, "{checked}");
    }
}
