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
use crate::rotation::{
    angle_deg, beyond_arc, beyond_arc_slope, beyond_line, beyond_line_slope, euler_zyx_deg,
    quat_from_euler_zyx_deg, Quat,
};
use nalgebra::Vector3;

/// Degrees per radian.
const DEG: f64 = 180.0 / std::f64::consts::PI;

/// Per-sample excursion of Z-Y-X angles `[x, y, z]` (degrees) beyond
/// `[lo, hi]` per axis (x and z on the circle, see
/// [`crate::rotation::box_excursion`]).
pub fn excursion(angles_deg: [f64; 3], range_deg: &[[f64; 2]; 3]) -> [f64; 3] {
    crate::rotation::box_excursion(angles_deg, range_deg)
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
            let qt = limits.to_axes(&(qm * c));
            let angles = crate::rotation::read_in_box(euler_zyx_deg(&qt), &limits.range_deg);
            let e: f64 = excursion(angles, &limits.range_deg).iter().sum();
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
        beyond_arc(s.atan2(c).to_degrees(), self.lo, self.hi)
    }

    /// As [`ArcRange::excursion`], with the excursion's slope in the angle
    /// (+1, -1, or 0 inside).
    #[inline(always)]
    fn excursion_slope(&self, s: f64, c: f64) -> (f64, f64) {
        if self.inside(s, c) {
            return (0.0, 0.0);
        }
        beyond_arc_slope(s.atan2(c).to_degrees(), self.lo, self.hi)
    }

    /// As [`ArcRange::excursion_slope`] for the other Z-Y-X triplet's angle,
    /// `atan2(-s, -c)` (the angle plus 180, in `(-180, 180]`).
    #[inline(always)]
    fn other_excursion_slope(&self, s: f64, c: f64) -> (f64, f64) {
        if self.inside(-s, -c) {
            return (0.0, 0.0);
        }
        let mut a = (-s).atan2(-c).to_degrees();
        if a <= -180.0 {
            a = 180.0;
        }
        beyond_arc_slope(a, self.lo, self.hi)
    }

    /// [`ArcRange::inside`] without branches on the sample (bitwise tests),
    /// for a pass over a block that the compiler keeps free of jumps.
    #[inline(always)]
    fn inside_flat(&self, s: f64, c: f64) -> bool {
        let after_lo = (self.lo_dir[0] * s - self.lo_dir[1] * c) >= 0.0;
        let before_hi = (c * self.hi_dir[1] - s * self.hi_dir[0]) >= 0.0;
        let either = after_lo | before_hi;
        let both = after_lo & before_hi;
        let inside = (self.wide & either) | (!self.wide & both);
        self.full | (inside & ((s != 0.0) | (c != 0.0)))
    }

    #[inline(always)]
    fn inside(&self, s: f64, c: f64) -> bool {
        if self.full {
            return true;
        }
        let after_lo = self.lo_dir[0] * s - self.lo_dir[1] * c;
        let before_hi = c * self.hi_dir[1] - s * self.hi_dir[0];
        let inside = if self.wide {
            after_lo >= 0.0 || before_hi >= 0.0
        } else {
            after_lo >= 0.0 && before_hi >= 0.0
        };
        inside && (s != 0.0 || c != 0.0)
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
        beyond_line(-r20.clamp(-1.0, 1.0).asin().to_degrees(), self.lo, self.hi)
    }

    #[inline(always)]
    fn inside(&self, r20: f64) -> bool {
        r20 <= self.r20_max && r20 >= self.r20_min
    }

    /// [`PitchRange::inside`] without branches (bitwise tests).
    #[inline(always)]
    fn inside_flat(&self, r20: f64) -> bool {
        (r20 <= self.r20_max) & (r20 >= self.r20_min)
    }

    /// As [`PitchRange::excursion`], with the slope in theta.
    #[inline(always)]
    fn excursion_slope(&self, r20: f64) -> (f64, f64) {
        if r20 <= self.r20_max && r20 >= self.r20_min {
            return (0.0, 0.0);
        }
        beyond_line_slope(-r20.clamp(-1.0, 1.0).asin().to_degrees(), self.lo, self.hi)
    }
}

/// Test of the other Z-Y-X triplet's middle angle against a range that
/// reaches beyond +-90 (docs/method.md section 2.5): with `theta =
/// -asin(r20)`, the other triplet's is `theta' = 180 - theta` for `theta >= 0`
/// (`r20 <= 0`) and `-180 - theta` below, so `theta'` lies in `[lo, hi]` when
/// `theta` lies in `[180 - hi, 180 - lo]`, or in `[-180 - hi, -180 - lo]`:
/// two tests on `r20` without trigonometry.
#[derive(Debug, Clone, Copy)]
struct OtherPitch {
    lo: f64,
    hi: f64,
    /// `theta >= 0`: `theta'` in range.
    up: PitchRange,
    /// `theta < 0`: `theta'` in range.
    down: PitchRange,
}

impl OtherPitch {
    fn new([lo, hi]: [f64; 2]) -> Self {
        OtherPitch {
            lo,
            hi,
            up: PitchRange::new([180.0 - hi, 180.0 - lo]),
            down: PitchRange::new([-180.0 - hi, -180.0 - lo]),
        }
    }

    #[inline(always)]
    fn inside(&self, r20: f64) -> bool {
        if r20 <= 0.0 {
            self.up.inside(r20)
        } else {
            self.down.inside(r20)
        }
    }

    /// The other triplet's middle-angle excursion and its slope in `theta`
    /// (the principal middle angle): `d theta' / d theta = -1`.
    #[inline(always)]
    fn excursion_slope(&self, r20: f64) -> (f64, f64) {
        if self.inside(r20) {
            return (0.0, 0.0);
        }
        let theta = -r20.clamp(-1.0, 1.0).asin().to_degrees();
        let other = if theta >= 0.0 {
            180.0 - theta
        } else {
            -180.0 - theta
        };
        let (e, s) = beyond_line_slope(other, self.lo, self.hi);
        (e, -s)
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
    /// The other Z-Y-X triplet's middle-angle test, when the Y range
    /// reaches beyond +-90 ([`crate::rotation::read_in_box`]): a sample's
    /// excursion is then the smaller of its two triplets'.
    other: Option<OtherPitch>,
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
            other: crate::rotation::y_beyond_90(&limits.range_deg)
                .then(|| OtherPitch::new(limits.range_deg[1])),
        }
    }

    /// True when the principal Z-Y-X triplet of the rotation with entries
    /// `[r00, r10, r20, r21, r22]` lies inside all three ranges: the sample
    /// then adds nothing to the excursion or its gradient. Without branches,
    /// so a block's samples are sorted into inside and outside in one pass
    /// free of mispredicted jumps.
    #[inline(always)]
    fn inside_flat(&self, [r00, r10, r20, r21, r22]: [f64; 5]) -> bool {
        self.x.inside_flat(r21, r22) & self.y.inside_flat(r20) & self.z.inside_flat(r10, r00)
    }

    /// The indices (in order) of the first `len` samples of a block of
    /// entries `e` (`[r00, r10, r20, r21, r22]` per sample, as
    /// [`LimitTerms::excursion`] takes them) whose principal triplet is not
    /// inside all three ranges, written to `out`; returns their number. The
    /// others add nothing to the excursion or its gradient.
    // Indexed over the block's parallel arrays, as the loops that fill them.
    #[allow(clippy::needless_range_loop)]
    #[inline(always)]
    pub(super) fn outside(
        &self,
        e: &[[f64; BLOCK]; 5],
        len: usize,
        out: &mut [u8; BLOCK],
    ) -> usize {
        let mut m = 0;
        for i in 0..len.min(BLOCK) {
            out[m] = i as u8;
            m += usize::from(!self.inside_flat([e[0][i], e[1][i], e[2][i], e[3][i], e[4][i]]));
        }
        m
    }

    /// `Ex + Ey + Ez` (degrees) of the Z-Y-X angles of a rotation, from its
    /// entries `[r00, r10, r20, r21, r22]`; where the Y range reaches beyond
    /// +-90, of the triplet the limits read (the smaller total of the two;
    /// no trigonometry when either triplet is inside).
    #[inline(always)]
    pub(super) fn excursion(&self, [r00, r10, r20, r21, r22]: [f64; 5]) -> f64 {
        let Some(other) = &self.other else {
            return self.x.excursion(r21, r22) + self.y.excursion(r20) + self.z.excursion(r10, r00);
        };
        if self.x.inside(r21, r22) && self.y.inside(r20) && self.z.inside(r10, r00) {
            return 0.0;
        }
        if self.x.inside(-r21, -r22) && other.inside(r20) && self.z.inside(-r10, -r00) {
            return 0.0;
        }
        let p = self.x.excursion(r21, r22) + self.y.excursion(r20) + self.z.excursion(r10, r00);
        let q = self.x.other_excursion_slope(r21, r22).0
            + other.excursion_slope(r20).0
            + self.z.other_excursion_slope(r10, r00).0;
        if q < p {
            q
        } else {
            p
        }
    }

    /// The excursions `(E, s)` of the three angles and their slopes in the
    /// principal triplet's angles (`phi`, `theta`, `psi`): of the principal
    /// triplet, or of the other one where the limits read it (its angles move
    /// as `phi`, `-theta`, `psi`).
    #[inline(always)]
    fn slopes(&self, [r00, r10, r20, r21, r22]: [f64; 5]) -> [(f64, f64); 3] {
        let Some(other) = &self.other else {
            return [
                self.x.excursion_slope(r21, r22),
                self.y.excursion_slope(r20),
                self.z.excursion_slope(r10, r00),
            ];
        };
        // Either triplet inside its ranges: no excursion, and no
        // trigonometry for the other (the same values as below).
        if (self.x.inside(r21, r22) && self.y.inside(r20) && self.z.inside(r10, r00))
            || (self.x.inside(-r21, -r22) && other.inside(r20) && self.z.inside(-r10, -r00))
        {
            return [(0.0, 0.0); 3];
        }
        let principal = [
            self.x.excursion_slope(r21, r22),
            self.y.excursion_slope(r20),
            self.z.excursion_slope(r10, r00),
        ];
        let p = principal[0].0 + principal[1].0 + principal[2].0;
        if p == 0.0 {
            return principal;
        }
        let alt = [
            self.x.other_excursion_slope(r21, r22),
            other.excursion_slope(r20),
            self.z.other_excursion_slope(r10, r00),
        ];
        if alt[0].0 + alt[1].0 + alt[2].0 < p {
            alt
        } else {
            principal
        }
    }

    /// As [`LimitTerms::excursion`] for a rotation `Rt`, adding to `g` the
    /// excursion's gradient (degrees per radian) with respect to a rotation
    /// vector `v` of `Rt * exp(v)` at `v = 0`. From `dRt = Rt [v]x`:
    /// `d phi = (1, -r20 r21 / rho, -r20 r22 / rho) . v`,
    /// `d theta = (0, r22, -r21) . v / sqrt(rho)`, `d psi = (0, r21, r22) . v / sigma`,
    /// `rho = r21^2 + r22^2`, `sigma = r00^2 + r10^2` (both `cos^2 theta`).
    #[inline(always)]
    pub(super) fn excursion_grad(
        &self,
        [r00, r10, r20, r21, r22]: [f64; 5],
        g: &mut [f64; 3],
    ) -> f64 {
        let [(ex, sx), (ey, sy), (ez, sz)] = self.slopes([r00, r10, r20, r21, r22]);
        if sx != 0.0 {
            let rho = r21 * r21 + r22 * r22;
            if rho > 0.0 {
                let k = sx * DEG;
                g[0] += k;
                g[1] -= k * r20 * r21 / rho;
                g[2] -= k * r20 * r22 / rho;
            }
        }
        if sy != 0.0 {
            let rho = r21 * r21 + r22 * r22;
            if rho > 0.0 {
                let k = sy * DEG / rho.sqrt();
                g[1] += k * r22;
                g[2] -= k * r21;
            }
        }
        if sz != 0.0 {
            let sigma = r00 * r00 + r10 * r10;
            if sigma > 0.0 {
                let k = sz * DEG / sigma;
                g[1] += k * r21;
                g[2] += k * r22;
            }
        }
        ex + ey + ez
    }

    /// As [`LimitTerms::excursion`], with the excursion's derivative
    /// (degrees per radian) along a path on which the entries move at rates
    /// `d` (per radian): `d phi = (r22 d21 - r21 d22) / rho`,
    /// `d theta = -d20 / sqrt(rho)`, `d psi = (r00 d10 - r10 d00) / sigma`,
    /// `rho = r21^2 + r22^2`, `sigma = r00^2 + r10^2`. At a kink it is the
    /// derivative of one side.
    #[inline(always)]
    pub(super) fn excursion_along(
        &self,
        [r00, r10, r20, r21, r22]: [f64; 5],
        [d00, d10, d20, d21, d22]: [f64; 5],
    ) -> (f64, f64) {
        let [(ex, sx), (ey, sy), (ez, sz)] = self.slopes([r00, r10, r20, r21, r22]);
        let mut slope = 0.0;
        let rho = r21 * r21 + r22 * r22;
        if sx != 0.0 && rho > 0.0 {
            slope += sx * (r22 * d21 - r21 * d22) / rho;
        }
        if sy != 0.0 && rho > 0.0 {
            slope -= sy * d20 / rho.sqrt();
        }
        if sz != 0.0 {
            let sigma = r00 * r00 + r10 * r10;
            if sigma > 0.0 {
                slope += sz * (r00 * d10 - r10 * d00) / sigma;
            }
        }
        (ex + ey + ez, slope * DEG)
    }

    /// `lambda2 * sum RMSq` over quaternions held as component arrays `q`
    /// (`[w, x, y, z]`) dotted with `p`. With `weighted`, adds to it the sum
    /// of `d(lambda2 RMSq_i)/d(d_i) * q_i` (`d_i = q_i . p`), from which the
    /// gradient follows by the chain rule; a sample exactly on the centroid
    /// (the cone's tip) adds nothing.
    pub(super) fn centroid_sum_soa(
        &self,
        q: &[Vec<f64>; 4],
        p: &[f64; 4],
        weighted: Option<&mut [f64; 4]>,
    ) -> f64 {
        let n = q[0].len();
        let (qw, qx, qy, qz) = (&q[0][..n], &q[1][..n], &q[2][..n], &q[3][..n]);
        let mut sum = 0.0;
        match weighted {
            None => {
                for i in 0..n {
                    sum += rmsq_of_dot(qw[i] * p[0] + qx[i] * p[1] + qy[i] * p[2] + qz[i] * p[3]);
                }
            }
            Some(w) => {
                let mut acc = [0.0; 4];
                for i in 0..n {
                    let d = qw[i] * p[0] + qx[i] * p[1] + qy[i] * p[2] + qz[i] * p[3];
                    let r = rmsq_of_dot(d);
                    sum += r;
                    if r > 1e-12 {
                        // d sqrt(2 - 2|d|) / dd = -sign(d) / sqrt(2 - 2|d|)
                        let k = -d.signum() / r;
                        acc[0] += k * qw[i];
                        acc[1] += k * qx[i];
                        acc[2] += k * qy[i];
                        acc[3] += k * qz[i];
                    }
                }
                for (wk, ak) in w.iter_mut().zip(acc) {
                    *wk += self.lambda2 * ak;
                }
            }
        }
        self.lambda2 * sum
    }

    /// `lambda2 * RMSq` for the dot product `d` of a rotation's quaternion and
    /// the centroid's.
    #[inline(always)]
    pub(super) fn centroid_term(&self, d: f64) -> f64 {
        self.lambda2 * rmsq_of_dot(d)
    }

    /// [`LimitTerms::centroid_term`] and its derivative along a path on which
    /// `d` moves at rate `dd`; 0 at the centroid itself (the cone's tip).
    #[inline(always)]
    pub(super) fn centroid_term_along(&self, d: f64, dd: f64) -> (f64, f64) {
        let r = rmsq_of_dot(d);
        let slope = if r > 1e-12 { -d.signum() * dd / r } else { 0.0 };
        (self.lambda2 * r, self.lambda2 * slope)
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

/// The samples of a window laid out for the evaluation loop (structure of
/// arrays): `r[3 * i + j]` holds entry `(i, j)` of every sample's `Rm`, `q[k]`
/// component `k` of its quaternion `[w, x, y, z]`.
#[derive(Debug, Clone, Default)]
struct Samples {
    r: [Vec<f64>; 9],
    q: [Vec<f64>; 4],
}

impl Samples {
    fn push(&mut self, q: &Quat) {
        let m = q.to_rotation_matrix();
        let m = m.matrix();
        for i in 0..3 {
            for j in 0..3 {
                self.r[3 * i + j].push(m[(i, j)]);
            }
        }
        for (k, v) in [q.w, q.i, q.j, q.k].into_iter().enumerate() {
            self.q[k].push(v);
        }
    }

    fn len(&self) -> usize {
        self.q[0].len()
    }
}

/// Samples evaluated together: the matrix products of a block are formed in
/// one loop the compiler can vectorise, then the range tests run over them.
pub(super) const BLOCK: usize = 64;
// A block's sample indices are held as `u8`.
const _: () = assert!(BLOCK <= 256);

/// The cost of one joint over one window, prepared for many evaluations.
#[derive(Debug, Clone)]
pub struct WindowCost {
    /// The measured rotations in the limits' axes (`Q^T Rm_i Q`).
    samples: Samples,
    terms: LimitTerms,
    lambda1: f64,
    /// The limits' axes: a correction `C` is evaluated as `Q^T C Q`.
    axes: Option<crate::model::TableAxes>,
    /// Swing-twist limits, in place of `terms`' ranges (its centroid stays).
    swing: Option<super::swing_cost::SwingTerms>,
}

impl WindowCost {
    /// Prepares the cost for measured joint rotations `Rm_i` (parent to child).
    pub fn new(measured: &[Quat], limits: &JointLimits, lambda1: f64) -> Self {
        WindowCost::from_iter(measured.iter(), limits, lambda1)
    }

    /// A coarse copy of this cost: every `stride`-th of its samples, the
    /// same limits and `lambda1`.
    pub fn coarse(&self, stride: usize) -> Self {
        let stride = stride.max(1);
        let take = |v: &Vec<f64>| v.iter().step_by(stride).copied().collect::<Vec<f64>>();
        WindowCost {
            samples: Samples {
                r: std::array::from_fn(|k| take(&self.samples.r[k])),
                q: std::array::from_fn(|k| take(&self.samples.q[k])),
            },
            terms: self.terms.clone(),
            lambda1: self.lambda1,
            axes: self.axes,
            swing: self.swing,
        }
    }

    fn from_iter<'a>(
        measured: impl Iterator<Item = &'a Quat>,
        limits: &JointLimits,
        lambda1: f64,
    ) -> Self {
        let mut samples = Samples::default();
        for q in measured {
            samples.push(&limits.to_axes(q));
        }
        WindowCost {
            samples,
            terms: LimitTerms::new(limits),
            lambda1,
            axes: limits.axes,
            swing: limits.swing_twist.map(super::swing_cost::SwingTerms::new),
        }
    }

    /// A correction `c` (distal segment frame) in the limits' axes: `Q^T C Q`.
    fn in_axes(&self, c: &Quat) -> Quat {
        match &self.axes {
            Some(a) => a.to_table(c),
            None => *c,
        }
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// True when the window holds no sample.
    pub fn is_empty(&self) -> bool {
        self.samples.len() == 0
    }

    /// The weight of `angle(C)` (degrees) in the cost.
    pub fn lambda1(&self) -> f64 {
        self.lambda1
    }

    /// `e(C)`: mean excursion (plus centroid term) over the samples, plus
    /// `lambda1 * angle(C)`; degrees.
    pub fn eval(&self, c: &Quat) -> f64 {
        self.data(&self.in_axes(c), None) + self.lambda1 * angle_deg(c)
    }

    /// `e(C)` without its `lambda1 * angle(C)` term (degrees), and that part's
    /// gradient with respect to a rotation vector `v` (radians) of
    /// `C * exp(v)` at `v = 0`, degrees per radian. At a kink (a sample exactly
    /// on a limit or at the centroid) it is the gradient of one side.
    pub fn data_grad(&self, c: &Quat) -> (f64, Vector3<f64>) {
        let mut g = Vector3::zeros();
        let f = self.data(&self.in_axes(c), Some(&mut g));
        // In the axes `C exp(v)` is `Q^T C Q exp(Q^T v)`: the gradient turns by Q.
        if let Some(a) = &self.axes {
            g = a.q * g;
        }
        (f, g)
    }

    /// The mean per-sample part of the cost at `c`; with `grad`, its gradient
    /// (see [`WindowCost::data_grad`]) too.
    // Indexed loops over the parallel arrays of a block: the form the
    // compiler vectorises.
    #[allow(clippy::needless_range_loop)]
    fn data(&self, c: &Quat, mut grad: Option<&mut Vector3<f64>>) -> f64 {
        let n = self.samples.len();
        if n == 0 {
            return 0.0;
        }
        let [col0, col1, col2] = matrix_vectors(c, false);
        let r = &self.samples.r;
        let mut sum = 0.0;
        let mut g = [0.0; 3];
        let mut e = [[0.0; BLOCK]; 5];
        // Swing-twist limits take the samples' excursions in place of the
        // Euler ranges' loop below, which then has nothing left to do.
        let mut start = match &self.swing {
            Some(st) => {
                sum += st.sum(&self.samples.q, c, grad.is_some().then_some(&mut g));
                n
            }
            None => 0,
        };
        while start < n {
            let len = BLOCK.min(n - start);
            let row = |k: usize| &r[k][start..start + len];
            let (r0, r1, r2) = (
                (row(0), row(1), row(2)),
                (row(3), row(4), row(5)),
                (row(6), row(7), row(8)),
            );
            for i in 0..len {
                e[0][i] = r0.0[i] * col0[0] + r0.1[i] * col0[1] + r0.2[i] * col0[2];
                e[1][i] = r1.0[i] * col0[0] + r1.1[i] * col0[1] + r1.2[i] * col0[2];
                e[2][i] = r2.0[i] * col0[0] + r2.1[i] * col0[1] + r2.2[i] * col0[2];
                e[3][i] = r2.0[i] * col1[0] + r2.1[i] * col1[1] + r2.2[i] * col1[2];
                e[4][i] = r2.0[i] * col2[0] + r2.1[i] * col2[1] + r2.2[i] * col2[2];
            }
            // The samples inside every range add nothing (exactly: no term,
            // no gradient): only the others, in order, take the slow path.
            let mut outside = [0u8; BLOCK];
            let m = self.terms.outside(&e, len, &mut outside);
            for &i in &outside[..m] {
                let i = usize::from(i);
                let entries = [e[0][i], e[1][i], e[2][i], e[3][i], e[4][i]];
                sum += match grad {
                    Some(_) => self.terms.excursion_grad(entries, &mut g),
                    None => self.terms.excursion(entries),
                };
            }
            start += len;
        }
        if let Some(qc) = self.terms.centroid {
            // qt . qc = qm . (qc * c^-1), so one 4-vector per evaluation.
            let p = qc * c.inverse();
            let q = &self.samples.q;
            let p4 = [p.w, p.i, p.j, p.k];
            match grad.as_deref_mut() {
                None => {
                    sum += self.terms.centroid_sum_soa(q, &p4, None);
                }
                Some(_) => {
                    let mut weighted = [0.0; 4];
                    sum += self.terms.centroid_sum_soa(q, &p4, Some(&mut weighted));
                    // d/dv of qc * exp(-v) * c^-1 along e_k: qc * (0, -e_k / 2) * c^-1.
                    let ci = c.inverse();
                    for (k, gk) in g.iter_mut().enumerate() {
                        let mut axis = [0.0; 3];
                        axis[k] = -0.5;
                        let u = qc.into_inner()
                            * nalgebra::Quaternion::new(0.0, axis[0], axis[1], axis[2])
                            * ci.into_inner();
                        *gk += u.w * weighted[0]
                            + u.i * weighted[1]
                            + u.j * weighted[2]
                            + u.k * weighted[3];
                    }
                }
            }
        }
        let n = n as f64;
        if let Some(out) = grad {
            *out = Vector3::new(g[0], g[1], g[2]) / n;
        }
        sum / n
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

/// Limit axes to test the costs in: none, a mirror image (`full_body16`'s
/// `r_elbow`, `["-y", "-x", "+z"]`) and a proper rotation (its `r_hip`,
/// `["-z", "-y", "-x"]`) of the segment frames.
#[cfg(test)]
pub(super) fn test_axes() -> [Option<crate::model::TableAxes>; 3] {
    let of = |a: [&str; 3]| crate::model::TableAxes::of(&a.map(|s| s.parse().expect("an axis")));
    [None, of(["-y", "-x", "+z"]), of(["-z", "-y", "-x"])]
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
        for axes in test_axes() {
            check_fast_equals_direct_in(JointLimits { axes, ..limits });
        }
    }

    fn check_fast_equals_direct_in(limits: JointLimits) {
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
            axes: None,
            swing_twist: None,
        });
        check_fast_equals_direct(JointLimits {
            range_deg: [[-45.0, 160.0], [-60.0, 60.0], [-170.0, 90.0]],
            centroid_deg: Some([47.0, -1.0, -31.0]),
            lambda2: 30.0,
            axes: None,
            swing_twist: None,
        });
        check_fast_equals_direct(JointLimits {
            range_deg: [[-180.0, 180.0], [-90.0, 90.0], [100.0, 120.0]],
            centroid_deg: Some([0.0, 5.0, 0.0]),
            lambda2: 30.0,
            axes: None,
            swing_twist: None,
        });
    }

    fn check_gradient(limits: JointLimits) {
        for axes in test_axes() {
            check_gradient_in(JointLimits { axes, ..limits });
        }
    }

    fn check_gradient_in(limits: JointLimits) {
        let mut rng = ChaCha8Rng::seed_from_u64(12);
        let measured: Vec<Quat> = (0..300).map(|_| random_quat(&mut rng, 120.0)).collect();
        check_gradient_on(&measured, limits, &mut rng, 60.0);
    }

    fn check_gradient_on(
        measured: &[Quat],
        limits: JointLimits,
        rng: &mut ChaCha8Rng,
        max_correction_deg: f64,
    ) {
        let cost = WindowCost::new(measured, &limits, 0.05);
        let mut near_kink = 0;
        for _ in 0..30 {
            let c = random_quat(rng, max_correction_deg);
            let (f, g) = cost.data_grad(&c);
            assert_eq!(f + 0.05 * angle_deg(&c), cost.eval(&c));
            // One-sided differences over 1e-7 rad; where they disagree a
            // sample's kink lies within the step and the point is skipped.
            let h = 1e-7;
            for k in 0..3 {
                let mut v = Vector3::zeros();
                v[k] = h;
                let up = (cost.data_grad(&(c * Quat::from_scaled_axis(v))).0 - f) / h;
                let down = (f - cost.data_grad(&(c * Quat::from_scaled_axis(-v))).0) / h;
                let tol = 1e-4 * (1.0 + g[k].abs());
                if (up - down).abs() > tol {
                    near_kink += 1;
                    continue;
                }
                let fd = 0.5 * (up + down);
                assert!((fd - g[k]).abs() < tol, "axis {k}: {fd} vs {}", g[k]);
            }
        }
        assert!(near_kink < 5, "{near_kink} of 90 near a kink");
    }

    #[test]
    fn gradient_matches_finite_differences() {
        for (r, cen) in [
            ([[-5.0, 5.0], [-90.0, 90.0], [-180.0, 180.0]], None),
            ([[-180.0, 180.0], [-10.0, 30.0], [-180.0, 180.0]], None),
            ([[-180.0, 180.0], [-90.0, 90.0], [-5.0, 5.0]], None),
            (
                [[-180.0, 180.0], [-90.0, 90.0], [-180.0, 180.0]],
                Some([47.0, -1.0, -31.0]),
            ),
        ] {
            eprintln!("{r:?} {cen:?}");
            check_gradient(JointLimits {
                range_deg: r,
                centroid_deg: cen,
                lambda2: if cen.is_some() { 30.0 } else { 0.0 },
                axes: None,
                swing_twist: None,
            });
        }
        check_gradient(JointLimits {
            range_deg: [[-5.0, 5.0], [0.0, 130.0], [-5.0, 5.0]],
            centroid_deg: None,
            lambda2: 0.0,
            axes: None,
            swing_twist: None,
        });
        check_gradient(JointLimits {
            range_deg: [[-45.0, 160.0], [-60.0, 60.0], [-170.0, 90.0]],
            centroid_deg: Some([47.0, -1.0, -31.0]),
            lambda2: 30.0,
            axes: None,
            swing_twist: None,
        });
    }

    /// Knee- and hip-like samples flexed 40-170 deg (with X and Z up to
    /// +-12 deg) given in the table's axes: their principal Z-Y-X triplets
    /// fold back beyond 90 deg of flexion.
    fn deep_flexion(
        rng: &mut ChaCha8Rng,
        n: usize,
        axes: Option<crate::model::TableAxes>,
    ) -> Vec<Quat> {
        use rand::Rng;
        (0..n)
            .map(|_| {
                let t = [
                    rng.random_range(-12.0..12.0),
                    rng.random_range(40.0..170.0),
                    rng.random_range(-12.0..12.0),
                ];
                match &axes {
                    // The engine reads `Q^T R Q`, whose angles are the
                    // table's times det(P).
                    Some(a) => a.from_table(&quat_from_euler_zyx_deg(t.map(|v| a.det * v))),
                    None => quat_from_euler_zyx_deg(t),
                }
            })
            .collect()
    }

    /// Table limits as the engine holds them in `axes` (negated for a mirror
    /// image, as `JointLimits::in_table_axes` gives them).
    fn engine_limits(
        range: [[f64; 2]; 3],
        centroid: Option<[f64; 3]>,
        axes: Option<crate::model::TableAxes>,
    ) -> JointLimits {
        let flip = axes.is_some_and(|a| a.det < 0.0);
        JointLimits {
            range_deg: range.map(|[lo, hi]| if flip { [-hi, -lo] } else { [lo, hi] }),
            centroid_deg: centroid.map(|c| c.map(|v| if flip { -v } else { v })),
            lambda2: if centroid.is_some() { 30.0 } else { 0.0 },
            axes,
            swing_twist: None,
        }
    }

    /// Where the Y range reaches beyond 90 (knee 0..130, hip -30..100) a
    /// sample costs the excursion of the triplet with the smaller total
    /// (docs/method.md section 2.5): the fast cost equals that formula, per
    /// sample from both triplets, across the switch between them; and a knee
    /// flexed 100-130 deg costs nothing at the identity (it did cost before:
    /// the principal triplet reads X and Z half a turn away).
    #[test]
    fn cost_reads_the_triplet_the_limits_read_across_the_switch() {
        use crate::rotation::other_zyx_deg;
        let mut rng = ChaCha8Rng::seed_from_u64(14);
        let knee = [[-5.0, 5.0], [0.0, 130.0], [-5.0, 5.0]];
        let hip = [[-50.0, 40.0], [-30.0, 100.0], [-20.0, 50.0]];
        for (range, centroid) in [(knee, None), (hip, Some([-5.0, 12.0, -5.0]))] {
            for axes in test_axes() {
                let limits = engine_limits(range, centroid, axes);
                let measured = deep_flexion(&mut rng, 300, axes);
                let cost = WindowCost::new(&measured, &limits, 0.05);
                let centroid_q = limits.centroid_deg.map(quat_from_euler_zyx_deg);
                let (mut principal_read, mut other_read) = (0, 0);
                for _ in 0..40 {
                    let c = random_quat(&mut rng, 25.0);
                    let want: f64 = measured
                        .iter()
                        .map(|m| {
                            let qt = limits.to_axes(&(m * c));
                            let p = euler_zyx_deg(&qt);
                            let total = |a: [f64; 3]| -> f64 {
                                excursion(a, &limits.range_deg).iter().sum()
                            };
                            let (ep, eo) = (total(p), total(other_zyx_deg(p)));
                            if ep > 0.0 && eo < ep {
                                other_read += 1;
                            } else if ep > 0.0 {
                                principal_read += 1;
                            }
                            let e = ep.min(eo);
                            e + centroid_q.map_or(0.0, |qc| limits.lambda2 * rmsq(&qt, &qc))
                        })
                        .sum::<f64>()
                        / measured.len() as f64
                        + 0.05 * angle_deg(&c);
                    let fast = cost.eval(&c);
                    assert!((fast - want).abs() < 1e-9, "{fast} vs {want}");
                    let direct = cost_direct(&measured, &c, &limits, 0.05);
                    assert!((direct - want).abs() < 1e-9, "{direct} vs {want}");
                }
                // Both triplets are read, on many samples each.
                assert!(
                    other_read > 1000 && principal_read > 1000,
                    "{other_read} {principal_read}"
                );
            }
        }
        // Pure knee flexion 100..130 deg: inside the limits, so no cost.
        let flexed: Vec<Quat> = (0..=30)
            .map(|i| quat_axis_angle_deg([0.0, 1.0, 0.0], 100.0 + i as f64))
            .collect();
        let limits = JointLimits {
            range_deg: knee,
            centroid_deg: None,
            lambda2: 0.0,
            axes: None,
            swing_twist: None,
        };
        let cost = WindowCost::new(&flexed, &limits, 0.05);
        assert_eq!(cost.eval(&Quat::identity()), 0.0);
        let (f, g) = cost.data_grad(&Quat::identity());
        assert_eq!((f, g.norm()), (0.0, 0.0));
    }

    /// The gradient follows the triplet each sample's cost reads: finite
    /// differences across the switch between the two (deep flexion, with
    /// corrections up to 40 deg moving samples from one to the other).
    #[test]
    fn gradient_matches_finite_differences_across_the_switch() {
        let mut rng = ChaCha8Rng::seed_from_u64(15);
        for (range, centroid) in [
            ([[-5.0, 5.0], [0.0, 130.0], [-5.0, 5.0]], None),
            (
                [[-50.0, 40.0], [-30.0, 100.0], [-20.0, 50.0]],
                Some([-5.0, 12.0, -5.0]),
            ),
        ] {
            for axes in test_axes() {
                let measured = deep_flexion(&mut rng, 300, axes);
                let limits = engine_limits(range, centroid, axes);
                check_gradient_on(&measured, limits, &mut rng, 40.0);
            }
        }
    }

    #[test]
    fn identity_inside_limits_costs_nothing() {
        let measured = vec![quat_from_euler_zyx_deg([1.0, 40.0, -2.0]); 10];
        let limits = JointLimits {
            range_deg: [[-5.0, 5.0], [0.0, 130.0], [-5.0, 5.0]],
            centroid_deg: None,
            lambda2: 0.0,
            axes: None,
            swing_twist: None,
        };
        let cost = WindowCost::new(&measured, &limits, 0.05);
        assert_eq!(cost.eval(&Quat::identity()), 0.0);
        let c = quat_axis_angle_deg([0.0, 1.0, 0.0], 10.0);
        assert!((cost.eval(&c) - 0.5).abs() < 1e-9);
    }

    /// The engine's cost in the table's axes (`JointLimits::in_table_axes`) is
    /// the cost of the joint's table-convention angles against the table's
    /// limits and centroid, for joints whose axes are a proper rotation and a
    /// mirror image of the segment frames.
    #[test]
    fn cost_in_table_axes_is_the_cost_of_the_table_angles() {
        let model = crate::model::Model::builtin("full_body16").unwrap();
        let table = crate::limits::LimitTable::default_table();
        let mut rng = ChaCha8Rng::seed_from_u64(13);
        for name in [
            "r_elbow",
            "l_elbow",
            "r_hip",
            "r_knee",
            "l_shoulder",
            "l_ankle",
        ] {
            let j = model.joint(name).unwrap();
            let mut lim = table.joint_limits(&j.name, &j.kind, true).unwrap();
            lim.centroid_deg = Some([20.0, -10.0, 35.0]);
            lim.lambda2 = 30.0;
            let framed = lim.in_table_axes(j);
            assert!(framed.axes.is_some());
            let measured: Vec<Quat> = (0..200).map(|_| random_quat(&mut rng, 180.0)).collect();
            let cost = WindowCost::new(&measured, &framed, 0.05);
            let centroid = j.rotation(lim.centroid_deg.unwrap());
            for _ in 0..20 {
                let c = random_quat(&mut rng, 60.0);
                let want: f64 = measured
                    .iter()
                    .map(|m| {
                        let rt = m * c;
                        let e: f64 = excursion(j.table_angles(&rt), &lim.range_deg).iter().sum();
                        e + 30.0 * rmsq(&rt, &centroid)
                    })
                    .sum::<f64>()
                    / measured.len() as f64
                    + 0.05 * angle_deg(&c);
                let got = cost.eval(&c);
                assert!((got - want).abs() < 1e-9, "{name}: {got} vs {want}");
            }
        }
    }
}
