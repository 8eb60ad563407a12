//! The globographic plot (thesis 4.1, Figure 4-5 and appendix C; Baker 2011):
//! the joint at the centre of a unit sphere, the distal segment's direction as
//! a point on it, the flexion and ab/adduction limits as a band, and the
//! rotation about the segment's own axis left to the points' colour.
//!
//! Frames and units: directions are unit vectors in the proximal IMU's frame;
//! angles are the joint's Z-Y-X Euler angles `[x, y, z]` in degrees. Which of
//! the three axes is rotation, flexion or ab/adduction comes from the limit
//! table's movement names ([`JointAxes`]). The distal segment lies along its
//! rotation axis (rotation is, by definition, about the segment's long axis),
//! so its direction is `R' e_rot`, where `R'` is the joint rotation with the
//! rotation angle set to zero. When the rotation axis is X, the first axis of
//! the Z-Y-X sequence (knee, hip, ankle, back, neck), `R' e_x = R e_x`
//! exactly: the point is the segment's true direction and rotation cannot move
//! it. For other joints (shoulder: Y, elbow: Z) the point is the direction the
//! segment would have without its rotation angle.

use super::scatter::{Colouring, Grid, Raster};
use crate::limits::LimitTable;

/// Which Euler axis (0 = X, 1 = Y, 2 = Z) of a joint is which movement.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct JointAxes {
    /// Rotation about the distal segment's long axis (internal/external,
    /// lateral/medial rotation, pronation/supination).
    pub rotation: usize,
    /// Flexion/extension (drawn vertically).
    pub flexion: usize,
    /// Ab/adduction, lateral bending, eversion/inversion (drawn horizontally).
    pub abduction: usize,
}

impl Default for JointAxes {
    /// X rotation, Y flexion, Z ab/adduction (knee, hip, ankle, back, neck).
    fn default() -> Self {
        JointAxes {
            rotation: 0,
            flexion: 1,
            abduction: 2,
        }
    }
}

fn is_rotation(movement: &str) -> bool {
    let m = movement.to_ascii_lowercase();
    m.contains("rotation") || m.contains("pronation") || m.contains("supination")
}

impl JointAxes {
    /// The axes named by the movements of axes X, Y, Z: the one naming a
    /// rotation (or pronation/supination) is the rotation axis, the one naming
    /// flexion the flexion axis, the third ab/adduction. Falls back to
    /// [`JointAxes::default`] when the names do not single them out.
    pub fn from_movements(movements: [&str; 3]) -> JointAxes {
        let rot: Vec<usize> = (0..3).filter(|&k| is_rotation(movements[k])).collect();
        let flex: Vec<usize> = (0..3)
            .filter(|&k| {
                !is_rotation(movements[k]) && movements[k].to_ascii_lowercase().contains("flexion")
            })
            .collect();
        match (rot.as_slice(), flex.as_slice()) {
            ([r], [f]) => JointAxes {
                rotation: *r,
                flexion: *f,
                abduction: 3 - r - f,
            },
            _ => JointAxes::default(),
        }
    }

    /// The axes of a joint from a limit table's rows (its own, else its kind's).
    pub fn of(table: &LimitTable, joint: &str, kind: &str) -> JointAxes {
        let m = |k| {
            table
                .row(joint, kind, k)
                .map_or("", |r| r.movement.as_str())
        };
        JointAxes::from_movements([m(0), m(1), m(2)])
    }
}

/// The globographic direction of joint angles `[x, y, z]` (degrees): column
/// `axes.rotation` of `Rz(z) Ry(y) Rx(x)` with the rotation angle set to 0; a
/// unit vector in the proximal frame.
pub fn direction(angles_deg: [f64; 3], axes: JointAxes) -> [f64; 3] {
    let mut a = angles_deg;
    a[axes.rotation] = 0.0;
    let sc = a.map(|v| v.to_radians().sin_cos());
    direction_sc(sc, axes.rotation)
}

/// [`direction`] from the sines and cosines `(s, c)` of the three angles
/// (the rotation angle's must be `(0, 1)`).
fn direction_sc(sc: [(f64, f64); 3], rotation: usize) -> [f64; 3] {
    let [(sx, cx), (sy, cy), (sz, cz)] = sc;
    match rotation {
        0 => [cz * cy, sz * cy, -sy],
        1 => [cz * sy * sx - sz * cx, sz * sy * sx + cz * cx, cy * sx],
        _ => [cz * sy * cx + sz * sx, sz * sy * cx - cz * sx, cy * cx],
    }
}

/// The direction at flexion `flex` and ab/adduction `abd` (degrees).
pub fn direction_at(flex: f64, abd: f64, axes: JointAxes) -> [f64; 3] {
    let mut a = [0.0; 3];
    a[axes.flexion] = flex;
    a[axes.abduction] = abd;
    direction(a, axes)
}

/// The inverse of [`direction`]: `[flexion, ab/adduction]` in degrees of a unit
/// direction (the Euler angle about the middle Y axis lies in [-90, 90]).
pub fn globographic_angles(d: [f64; 3], axes: JointAxes) -> [f64; 2] {
    let mut a = [0.0; 3];
    match axes.rotation {
        0 => {
            a[1] = -d[2].clamp(-1.0, 1.0).asin().to_degrees();
            a[2] = d[1].atan2(d[0]).to_degrees();
        }
        1 => {
            a[0] = d[2].clamp(-1.0, 1.0).asin().to_degrees();
            a[2] = (-d[0]).atan2(d[1]).to_degrees();
        }
        _ => {
            a[0] = -d[1].clamp(-1.0, 1.0).asin().to_degrees();
            a[1] = d[0].atan2(d[2]).to_degrees();
        }
    }
    [a[axes.flexion], a[axes.abduction]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn normalised(a: [f64; 3]) -> [f64; 3] {
    let n = dot(a, a).sqrt();
    if n > 0.0 {
        a.map(|v| v / n)
    } else {
        a
    }
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// An orthographic view of the sphere: looking at `centre` from outside, with
/// increasing ab/adduction to the right and increasing flexion up.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlobeView {
    /// Unit direction at the middle of the picture (towards the viewer).
    pub centre: [f64; 3],
    /// Unit screen axes in the proximal frame.
    pub right: [f64; 3],
    pub up: [f64; 3],
}

impl GlobeView {
    /// A view centred on flexion `flex` and ab/adduction `abd` (degrees).
    pub fn centred_on(flex: f64, abd: f64, axes: JointAxes) -> GlobeView {
        let centre = direction_at(flex, abd, axes);
        // Screen axes from the local derivatives (central differences, 0.5 deg).
        let h = 0.5;
        let df = direction_at(flex + h, abd, axes)
            .iter()
            .zip(direction_at(flex - h, abd, axes))
            .map(|(a, b)| a - b)
            .collect::<Vec<f64>>();
        let da = direction_at(flex, abd + h, axes)
            .iter()
            .zip(direction_at(flex, abd - h, axes))
            .map(|(a, b)| a - b)
            .collect::<Vec<f64>>();
        let proj = |v: &[f64]| {
            let v = [v[0], v[1], v[2]];
            let k = dot(v, centre);
            [
                v[0] - k * centre[0],
                v[1] - k * centre[1],
                v[2] - k * centre[2],
            ]
        };
        let up = normalised(proj(&df));
        let mut right = normalised(cross(up, centre));
        if dot(right, proj(&da)) < 0.0 {
            right = right.map(|v| -v);
        }
        GlobeView { centre, right, up }
    }

    /// A view centred on the middle of the flexion and ab/adduction limits.
    pub fn for_limits(range_deg: &[[f64; 2]; 3], axes: JointAxes) -> GlobeView {
        let mid = |k: usize| 0.5 * (range_deg[k][0] + range_deg[k][1]);
        GlobeView::centred_on(mid(axes.flexion), mid(axes.abduction), axes)
    }

    /// Screen coordinates `(right, up)` in [-1, 1] and the depth (> 0 on the
    /// visible hemisphere) of a unit direction.
    pub fn project(&self, d: [f64; 3]) -> (f64, f64, f64) {
        (dot(d, self.right), dot(d, self.up), dot(d, self.centre))
    }

    /// The screen rectangle `(x, y)` bounds holding the visible parts of the
    /// `outlines` (each the boundary of a region within the visible
    /// hemisphere, so its image bounds the region's), padded by `pad` times
    /// the larger side, within the disc's square `[-1.05, 1.05]`.
    pub fn fit(&self, outlines: &[Vec<[f64; 3]>], pad: f64) -> ([f64; 2], [f64; 2]) {
        let mut b = [[f64::INFINITY, f64::NEG_INFINITY]; 2];
        for p in outlines.iter().flatten().filter_map(|d| self.visible(*d)) {
            b[0] = [b[0][0].min(p.0), b[0][1].max(p.0)];
            b[1] = [b[1][0].min(p.1), b[1][1].max(p.1)];
        }
        let r = 1.05;
        if !b[0][0].is_finite() {
            return ([-r, r], [-r, r]);
        }
        let m = pad * (b[0][1] - b[0][0]).max(b[1][1] - b[1][0]).max(0.05);
        let c = |v: [f64; 2]| [(v[0] - m).max(-r), (v[1] + m).min(r)];
        (c(b[0]), c(b[1]))
    }

    /// Screen coordinates of a direction on the visible hemisphere.
    pub fn visible(&self, d: [f64; 3]) -> Option<(f64, f64)> {
        let (x, y, z) = self.project(d);
        (z >= 0.0).then_some((x, y))
    }
}

/// The flexion and ab/adduction extents of samples, `[[flex lo, hi], [abd lo,
/// hi]]` in degrees (None without finite samples).
pub fn extent(angles: &[[f64; 3]], axes: JointAxes) -> Option<[[f64; 2]; 2]> {
    let mut e = [[f64::INFINITY, f64::NEG_INFINITY]; 2];
    for a in angles {
        for (k, ax) in [axes.flexion, axes.abduction].into_iter().enumerate() {
            if a[ax].is_finite() {
                e[k] = [e[k][0].min(a[ax]), e[k][1].max(a[ax])];
            }
        }
    }
    e[0][0].is_finite().then_some(e)
}

/// Whether flexion and ab/adduction are inside their limits (the band).
pub fn in_band(angles_deg: [f64; 3], range_deg: &[[f64; 2]; 3], axes: JointAxes) -> bool {
    [axes.flexion, axes.abduction]
        .iter()
        .all(|&k| angles_deg[k] >= range_deg[k][0] && angles_deg[k] <= range_deg[k][1])
}

/// Directions filling the band of the flexion and ab/adduction limits on a
/// grid of `step_deg`, edges included.
pub fn band_points(range_deg: &[[f64; 2]; 3], axes: JointAxes, step_deg: f64) -> Vec<[f64; 3]> {
    let [f0, f1] = range_deg[axes.flexion];
    let [a0, a1] = range_deg[axes.abduction];
    let steps = |lo: f64, hi: f64| ((hi - lo) / step_deg).ceil().max(1.0) as usize;
    let (nf, na) = (steps(f0, f1), steps(a0, a1));
    let mut out = Vec::with_capacity((nf + 1) * (na + 1));
    for i in 0..=nf {
        let f = f0 + (f1 - f0) * i as f64 / nf as f64;
        for j in 0..=na {
            let a = a0 + (a1 - a0) * j as f64 / na as f64;
            out.push(direction_at(f, a, axes));
        }
    }
    out
}

/// The outline of the band: its four edges, `per_edge` points each, in order
/// around it (a closed polygon on the sphere).
pub fn band_outline(range_deg: &[[f64; 2]; 3], axes: JointAxes, per_edge: usize) -> Vec<[f64; 3]> {
    rect_outline(
        range_deg[axes.flexion],
        range_deg[axes.abduction],
        axes,
        per_edge,
    )
}

/// The outline of the region of flexion in `flex` and ab/adduction in `abd`
/// (degrees), `per_edge` points per edge, in order around it.
pub fn rect_outline(
    flex: [f64; 2],
    abd: [f64; 2],
    axes: JointAxes,
    per_edge: usize,
) -> Vec<[f64; 3]> {
    let [f0, f1] = flex;
    let [a0, a1] = abd;
    let n = per_edge.max(2);
    let lerp = |a: f64, b: f64, i: usize| a + (b - a) * i as f64 / (n - 1) as f64;
    let mut out = Vec::with_capacity(4 * n);
    out.extend((0..n).map(|i| direction_at(f0, lerp(a0, a1, i), axes)));
    out.extend((0..n).map(|i| direction_at(lerp(f0, f1, i), a1, axes)));
    out.extend((0..n).map(|i| direction_at(f1, lerp(a1, a0, i), axes)));
    out.extend((0..n).map(|i| direction_at(lerp(f1, f0, i), a0, axes)));
    out
}

/// Grid lines of the globe: curves of constant flexion and of constant
/// ab/adduction every `every_deg` degrees (flexion within [-90, 90] around the
/// view's centre), `per_line` points each.
pub fn grid_lines(axes: JointAxes, every_deg: f64, per_line: usize) -> Vec<Vec<[f64; 3]>> {
    let n = per_line.max(2);
    let mut lines = vec![];
    let count = (180.0 / every_deg).round() as i64;
    for k in -count..=count {
        let v = k as f64 * every_deg;
        // Constant flexion, ab/adduction all round.
        lines.push(
            (0..n)
                .map(|i| direction_at(v, -180.0 + 360.0 * i as f64 / (n - 1) as f64, axes))
                .collect(),
        );
        // Constant ab/adduction, flexion all round.
        lines.push(
            (0..n)
                .map(|i| direction_at(-180.0 + 360.0 * i as f64 / (n - 1) as f64, v, axes))
                .collect(),
        );
    }
    lines
}

/// The band of the flexion and ab/adduction limits filled on a raster of
/// `grid` (screen coordinates of `view`, key 0).
///
/// When the whole band lies on the visible hemisphere its projected outline
/// is a simple closed curve (the orthographic projection is one-to-one
/// there), so the band is filled row by row between the outline's crossings;
/// otherwise the band is sampled on a grid of angles finer than a dot.
pub fn band_raster(
    range_deg: &[[f64; 2]; 3],
    axes: JointAxes,
    view: &GlobeView,
    grid: Grid,
) -> Raster {
    let mut out = Raster::new(grid.w, grid.h);
    if grid.w < 2 || grid.h < 2 {
        return out;
    }
    let outline = band_outline(range_deg, axes, 96);
    let poly: Option<Vec<(f64, f64)>> = outline.iter().map(|d| view.visible(*d)).collect();
    let m = out.mapper(grid.bx, grid.by);
    let Some(poly) = poly else {
        // About 0.7 dot apart at the centre of the sphere (closer elsewhere).
        let step = (0.7 * (grid.bx[1] - grid.bx[0]) / (grid.w - 1) as f64)
            .to_degrees()
            .max(0.05);
        for d in band_points(range_deg, axes, step) {
            if let Some((x, y)) = view.visible(d) {
                out.plot_mapped(&m, x, y, 0);
            }
        }
        return out;
    };
    let (bx, by) = (grid.bx, grid.by);
    let col = |x: f64| ((x - bx[0]) / (bx[1] - bx[0]) * (grid.w - 1) as f64).round();
    let mut xs: Vec<f64> = vec![];
    for row in 0..grid.h {
        let y = by[1] - (by[1] - by[0]) * row as f64 / (grid.h - 1) as f64;
        xs.clear();
        for k in 0..poly.len() {
            let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
            if (a.1 <= y) != (b.1 <= y) {
                xs.push(a.0 + (y - a.1) / (b.1 - a.1) * (b.0 - a.0));
            }
        }
        xs.sort_by(f64::total_cmp);
        for pair in xs.chunks_exact(2) {
            let c0 = col(pair[0]).max(0.0);
            let c1 = col(pair[1]).min((grid.w - 1) as f64);
            let mut c = c0;
            while c <= c1 {
                out.put(c as usize, row, 0);
                c += 1.0;
            }
        }
    }
    // The outline itself, so that a band thinner than a dot row still shows.
    for p in &poly {
        out.plot_mapped(&m, p.0, p.1, 0);
    }
    out
}

/// Bin size of [`globe_raster`]'s reduction in angle space, degrees: a quarter
/// of a dot at 200 dots across the sphere.
pub const GLOBE_BIN_DEG: f64 = 0.25;

/// The samples' directions on the visible hemisphere of `view`, reduced to a
/// raster of `grid` in screen coordinates (keys by `colouring`).
///
/// The direction depends only on flexion and ab/adduction, so samples are
/// first binned by those two angles ([`GLOBE_BIN_DEG`]), keeping the highest
/// key per bin, and only the occupied bins are mapped onto the sphere: the
/// trigonometry runs once per bin, not once per sample. A bin's point is off
/// its samples' true points by at most half a bin diagonal (0.18 deg).
pub fn globe_raster(
    angles: &[[f64; 3]],
    range_deg: &[[f64; 2]; 3],
    axes: JointAxes,
    view: &GlobeView,
    colouring: Colouring,
    grid: Grid,
) -> Raster {
    let mut out = Raster::new(grid.w, grid.h);
    let n = angles.len();
    if n == 0 {
        return out;
    }
    let (fk, ak) = (axes.flexion, axes.abduction);
    let (mut f0, mut f1, mut a0, mut a1) = (
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
    );
    for a in angles {
        if a[fk].is_finite() && a[ak].is_finite() {
            f0 = f0.min(a[fk]);
            f1 = f1.max(a[fk]);
            a0 = a0.min(a[ak]);
            a1 = a1.max(a[ak]);
        }
    }
    if !f0.is_finite() {
        return out;
    }
    let nf = ((f1 - f0) / GLOBE_BIN_DEG) as usize + 1;
    let na = ((a1 - a0) / GLOBE_BIN_DEG) as usize + 1;
    let mut bins = vec![0u8; nf * na];
    let inv = 1.0 / GLOBE_BIN_DEG;
    for (i, a) in angles.iter().enumerate() {
        if !(a[fk].is_finite() && a[ak].is_finite()) {
            continue;
        }
        let bf = (((a[fk] - f0) * inv) as usize).min(nf - 1);
        let ba = (((a[ak] - a0) * inv) as usize).min(na - 1);
        let cell = &mut bins[bf * na + ba];
        *cell = (*cell).max(colouring.key(i, n, *a, range_deg) + 1);
    }
    // Bin centres on a grid: their sines and cosines once per row and column.
    let centre_sc = |lo: f64, k: usize| {
        (lo + (k as f64 + 0.5) * GLOBE_BIN_DEG)
            .to_radians()
            .sin_cos()
    };
    let rows: Vec<(f64, f64)> = (0..nf).map(|k| centre_sc(f0, k)).collect();
    let cols: Vec<(f64, f64)> = (0..na).map(|k| centre_sc(a0, k)).collect();
    let m = out.mapper(grid.bx, grid.by);
    for (k, &key) in bins.iter().enumerate() {
        if key == 0 {
            continue;
        }
        let mut sc = [(0.0, 1.0); 3];
        sc[fk] = rows[k / na];
        sc[ak] = cols[k % na];
        if let Some((x, y)) = view.visible(direction_sc(sc, axes.rotation)) {
            out.plot_mapped(&m, x, y, key - 1);
        }
    }
    out
}

/// The edge of a swing-twist region ([`crate::limits::swing_twist`]) on the
/// sphere: the directions of the twist axis (the segment's long axis) turned
/// by the swings on the region's edge, `per` points (closed: the first
/// repeated last). Unit vectors in the table's axes, as [`direction`]'s; for
/// a twist about X they are the segment's true directions, like the points.
pub fn swing_outline(
    st: &crate::limits::swing_twist::SwingTwistLimits,
    per: usize,
) -> Vec<[f64; 3]> {
    let per = per.max(4);
    if st.zyx_box {
        return zyx_box_outline(st, per);
    }
    let [a1, a2] = crate::limits::swing_twist::swing_axes(st.twist_axis);
    let [h1, h2] = st.half_deg;
    (0..=per)
        .map(|k| {
            let th = k as f64 * std::f64::consts::TAU / per as f64;
            let (s, c) = th.sin_cos();
            let (u, v) = match st.corner_deg {
                None => (h1 * c, h2 * s),
                // Along the ray from the centre at angle th, the edge of the
                // (convex) rounded box, by bisection.
                Some(r) => {
                    let inside = |t: f64| {
                        let qu = ((t * c).abs() - (h1 - r)).max(0.0);
                        let qv = ((t * s).abs() - (h2 - r)).max(0.0);
                        (qu * qu + qv * qv).sqrt() <= r
                    };
                    let (mut lo, mut hi) = (0.0, h1 + h2);
                    for _ in 0..60 {
                        let mid = 0.5 * (lo + hi);
                        if inside(mid) {
                            lo = mid;
                        } else {
                            hi = mid;
                        }
                    }
                    (lo * c, lo * s)
                }
            };
            let mut rv = nalgebra::Vector3::zeros();
            rv[a1] = (st.centre_deg[0] + u).to_radians();
            rv[a2] = (st.centre_deg[1] + v).to_radians();
            let mut e = nalgebra::Vector3::zeros();
            e[st.twist_axis] = 1.0;
            let d = crate::rotation::Quat::from_scaled_axis(rv) * e;
            [d[0], d[1], d[2]]
        })
        .collect()
}

/// The edge of a Z-Y-X box region ([`crate::limits::swing_twist::SwingTwistLimits::zyx_box`]):
/// the directions `Rz(z) Ry(y) e_x` around its latitude-longitude rectangle
/// (Y and Z ranges, degrees), `per` points and the first repeated last.
fn zyx_box_outline(st: &crate::limits::swing_twist::SwingTwistLimits, per: usize) -> Vec<[f64; 3]> {
    let [_, [y0, y1], [z0, z1]] = st.zyx_ranges();
    let corners = [[y0, z0], [y0, z1], [y1, z1], [y1, z0]];
    (0..=per)
        .map(|k| {
            // Four sides, each a quarter of the points.
            let t = 4.0 * (k % per) as f64 / per as f64;
            let side = (t.floor() as usize).min(3);
            let f = t - side as f64;
            let [a, b] = [corners[side], corners[(side + 1) % 4]];
            let y = (a[0] + (b[0] - a[0]) * f).to_radians();
            let z = (a[1] + (b[1] - a[1]) * f).to_radians();
            direction_sc([(0.0, 1.0), y.sin_cos(), z.sin_cos()], 0)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::scatter::{classify, Grid, LimitClass};
    use crate::rotation::{euler_zyx_deg, quat_from_euler_zyx_deg, quat_from_wxyz, Quat};
    use nalgebra::Vector3;

    const KNEE: [[f64; 2]; 3] = [[-5.0, 5.0], [0.0, 130.0], [-5.0, 5.0]];
    const SHOULDER: [[f64; 2]; 3] = [[-10.0, 100.0], [-40.0, 60.0], [-70.0, 70.0]];

    fn rotate(q: &Quat, k: usize) -> [f64; 3] {
        let mut e = Vector3::zeros();
        e[k] = 1.0;
        let v = q * e;
        [v[0], v[1], v[2]]
    }

    /// Deterministic pseudo-random unit quaternions.
    fn quats(n: usize) -> Vec<Quat> {
        let mut s = 0x2545_f491_4f6c_dd1du64;
        let mut r = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        (0..n)
            .map(|_| quat_from_wxyz([r(), r(), r(), r()]))
            .collect()
    }

    #[test]
    fn axes_from_the_shipped_table() {
        let t = LimitTable::default_table();
        assert_eq!(JointAxes::of(&t, "l_knee", "knee"), JointAxes::default());
        assert_eq!(JointAxes::of(&t, "l_hip", "hip"), JointAxes::default());
        assert_eq!(JointAxes::of(&t, "back", "back"), JointAxes::default());
        assert_eq!(JointAxes::of(&t, "l_ankle", "ankle"), JointAxes::default());
        assert_eq!(
            JointAxes::of(&t, "l_shoulder", "shoulder"),
            JointAxes {
                rotation: 1,
                flexion: 0,
                abduction: 2
            }
        );
        assert_eq!(
            JointAxes::of(&t, "l_elbow", "elbow"),
            JointAxes {
                rotation: 2,
                flexion: 0,
                abduction: 1
            }
        );
        assert_eq!(JointAxes::of(&t, "nowhere", "none"), JointAxes::default());
    }

    #[test]
    fn direction_is_the_segment_axis_rotated_by_the_joint() {
        // Rotation about X (knee, hip, ...): the direction is R e_x computed
        // directly by rotating the unit vector with the joint's quaternion,
        // whatever the rotation angle; R' e_rot for the other joints.
        for q in quats(500) {
            let e = euler_zyx_deg(&q);
            let d = direction(e, JointAxes::default());
            let want = rotate(&q, 0);
            for k in 0..3 {
                assert!((d[k] - want[k]).abs() < 1e-9, "{d:?} {want:?}");
            }
            for axes in [
                JointAxes {
                    rotation: 1,
                    flexion: 0,
                    abduction: 2,
                },
                JointAxes {
                    rotation: 2,
                    flexion: 0,
                    abduction: 1,
                },
            ] {
                let mut no_rot = e;
                no_rot[axes.rotation] = 0.0;
                let want = rotate(&quat_from_euler_zyx_deg(no_rot), axes.rotation);
                let d = direction(e, axes);
                for k in 0..3 {
                    assert!((d[k] - want[k]).abs() < 1e-9, "{axes:?} {d:?} {want:?}");
                }
                // Unit length, and the two angles come back.
                assert!((dot(d, d) - 1.0).abs() < 1e-12);
                let [f, a] = globographic_angles(d, axes);
                // The inverse is unique while the latitude angle (the inner
                // one of the two left) is inside (-90, 90).
                let lat = if axes.rotation == 0 { 1 } else { 0 };
                if e[lat].abs() < 89.0 {
                    assert!((f - e[axes.flexion]).abs() < 1e-6, "{e:?} {f}");
                    assert!((a - e[axes.abduction]).abs() < 1e-6, "{e:?} {a}");
                }
            }
        }
        // The knee at 90 deg flexion points its calf along -Z of the thigh frame.
        let d = direction([30.0, 90.0, 0.0], JointAxes::default());
        assert!((d[2] + 1.0).abs() < 1e-12);
    }

    #[test]
    fn band_membership_equals_the_limit_test() {
        let axes = JointAxes::default();
        for q in quats(2000) {
            let e = euler_zyx_deg(&q);
            let d = direction(e, axes);
            let [f, a] = globographic_angles(d, axes);
            let inside = f >= KNEE[1][0] && f <= KNEE[1][1] && a >= KNEE[2][0] && a <= KNEE[2][1];
            assert_eq!(in_band(e, &KNEE, axes), inside, "{e:?}");
            // Within the limits implies inside the band; not the reverse (rotation).
            if classify(e, &KNEE) == LimitClass::Within {
                assert!(inside);
            }
        }
        // Band points lie inside the limits and reach their edges.
        let pts = band_points(&KNEE, axes, 1.0);
        assert_eq!(pts.len(), 131 * 11);
        let inside = |f: f64, a: f64| f > -1e-9 && f < 130.0 + 1e-9 && a.abs() < 5.0 + 1e-9;
        for p in &pts {
            // Past 90 deg of flexion the inverse answers in the other chart:
            // (f, a) and (180 - f, a + 180) are one direction.
            let [f, a] = globographic_angles(*p, axes);
            let a2 = crate::rotation::wrap180(a + 180.0);
            assert!(inside(f, a) || inside(180.0 - f, a2), "{f} {a}");
        }
        assert_eq!(band_outline(&KNEE, axes, 10).len(), 40);
    }

    #[test]
    fn view_centres_the_band_with_flexion_up_and_abduction_right() {
        for (range, axes) in [
            (KNEE, JointAxes::default()),
            (
                SHOULDER,
                JointAxes {
                    rotation: 1,
                    flexion: 0,
                    abduction: 2,
                },
            ),
        ] {
            let v = GlobeView::for_limits(&range, axes);
            let mid = |k: usize| 0.5 * (range[k][0] + range[k][1]);
            let (fm, am) = (mid(axes.flexion), mid(axes.abduction));
            let (x, y, z) = v.project(direction_at(fm, am, axes));
            assert!(x.abs() < 1e-12 && y.abs() < 1e-12 && (z - 1.0).abs() < 1e-12);
            let (_, y_up, _) = v.project(direction_at(fm + 10.0, am, axes));
            assert!(y_up > 0.03);
            let (x_r, _, _) = v.project(direction_at(fm, am + 10.0, axes));
            assert!(x_r > 0.03);
            // Fitting the band: it fills the rectangle, inside the disc.
            let (bx, by) = v.fit(&[band_outline(&range, axes, 20)], 0.0);
            assert!(bx[0] >= -1.05 && bx[1] <= 1.05 && by[0] < 0.0 && by[1] > 0.0);
            // Orthonormal screen basis.
            assert!(dot(v.right, v.up).abs() < 1e-9 && dot(v.right, v.centre).abs() < 1e-9);
        }
    }

    #[test]
    fn band_fill_matches_dense_sampling() {
        let grid = Grid {
            w: 160,
            h: 160,
            bx: [-1.0, 1.0],
            by: [-1.0, 1.0],
        };
        let near = |r: &Raster, c: usize, row: usize| {
            (c.saturating_sub(1)..=c + 1)
                .any(|cc| (row.saturating_sub(1)..=row + 1).any(|rr| r.get(cc, rr).is_some()))
        };
        for (range, axes) in [
            (KNEE, JointAxes::default()),
            (
                SHOULDER,
                JointAxes {
                    rotation: 1,
                    flexion: 0,
                    abduction: 2,
                },
            ),
        ] {
            let view = GlobeView::for_limits(&range, axes);
            let fill = band_raster(&range, axes, &view, grid);
            // Every densely sampled band direction lands on (or next to) a
            // filled dot, and every filled dot is next to a sampled one.
            let mut dense = Raster::new(grid.w, grid.h);
            for d in band_points(&range, axes, 0.2) {
                let (x, y) = view.visible(d).unwrap();
                dense.plot(x, y, grid.bx, grid.by, 0);
                let (c, r) = dense.dot(x, y, grid.bx, grid.by).unwrap();
                assert!(near(&fill, c, r), "{range:?} {c} {r}");
            }
            for (c, r, _) in fill.dots() {
                assert!(near(&dense, c, r), "{range:?} {c} {r}");
            }
            assert!(fill.count() > 100);
        }
    }

    #[test]
    fn globe_raster_places_samples_at_their_projected_direction() {
        let axes = JointAxes::default();
        let view = GlobeView::for_limits(&KNEE, axes);
        // Three samples: inside, near, beyond; on distinct dots.
        let angles = [[0.0, 65.0, 0.0], [8.0, 40.0, 0.0], [0.0, 90.0, 30.0]];
        let grid = |n| Grid {
            w: n,
            h: n,
            bx: [-1.0, 1.0],
            by: [-1.0, 1.0],
        };
        let r = globe_raster(&angles, &KNEE, axes, &view, Colouring::Limits, grid(400));
        assert_eq!(r.count(), 3);
        for a in angles {
            let (x, y) = view.visible(direction(a, axes)).unwrap();
            let (c, row) = r.dot(x, y, [-1.0, 1.0], [-1.0, 1.0]).unwrap();
            // The bin centre is within 0.18 deg: the same dot or its neighbour.
            let found = (c.saturating_sub(1)..=c + 1)
                .flat_map(|cc| (row.saturating_sub(1)..=row + 1).map(move |rr| (cc, rr)))
                .filter_map(|(cc, rr)| r.get(cc, rr))
                .collect::<Vec<_>>();
            assert_eq!(found, [classify(a, &KNEE).key()], "{a:?}");
        }
        // The far side of the sphere is not drawn.
        let back = [[0.0, -100.0, 0.0]];
        assert_eq!(
            globe_raster(&back, &KNEE, axes, &view, Colouring::Limits, grid(50)).count(),
            0
        );
    }

    #[test]
    fn swing_outline_is_the_region_edge_turning_the_twist_axis() {
        use crate::limits::swing_twist::SwingTwistLimits;
        // A 30-deg cone about Z: every direction 30 deg from Z.
        let cone = SwingTwistLimits {
            twist_axis: 2,
            centre_deg: [0.0, 0.0],
            half_deg: [30.0, 30.0],
            corner_deg: None,
            twist_deg: [-5.0, 5.0],
            edge_twist_deg: [-5.0, 5.0],
            zyx_box: false,
        };
        let out = swing_outline(&cone, 64);
        assert_eq!(out.len(), 65);
        for d in &out {
            assert!((d[2].acos().to_degrees() - 30.0).abs() < 1e-9, "{d:?}");
        }
        // A knee-like box (flexion 0..80 about Y, +-5 about Z, twist about
        // X): each direction is X turned about the swing's axis by its angle,
        // and the swings lie on the box's edge.
        let knee = SwingTwistLimits {
            twist_axis: 0,
            centre_deg: [40.0, 0.0],
            half_deg: [40.0, 5.0],
            corner_deg: Some(0.0),
            ..cone
        };
        for d in swing_outline(&knee, 64) {
            let angle = d[0].clamp(-1.0, 1.0).acos().to_degrees();
            // x cross d = sin(angle) * (0, -s_z... ): the swing's axis (0, s_y, s_z)/|s|.
            let (sy, sz) = (-d[2], d[1]);
            let norm = (sy * sy + sz * sz).sqrt();
            // (The edge passes through the zero swing, X itself.)
            let k = if norm > 1e-12 { angle / norm } else { 0.0 };
            let (sy, sz) = (sy * k, sz * k);
            let on_edge = (sy.abs() < 1e-6 || (sy - 80.0).abs() < 1e-6 || sz.abs() > 5.0 - 1e-6)
                && (-1e-6..=80.0 + 1e-6).contains(&sy)
                && sz.abs() <= 5.0 + 1e-6;
            assert!(on_edge, "({sy}, {sz})");
        }
        // A Z-Y-X box: every point's Z-Y-X angles Y and Z on the rectangle's
        // edge, the excursion 0 there with the twist inside its range.
        let shoulder = SwingTwistLimits {
            twist_axis: 0,
            centre_deg: [10.0, 0.0],
            half_deg: [50.0, 70.0],
            corner_deg: None,
            zyx_box: true,
            ..cone
        };
        let out = swing_outline(&shoulder, 64);
        assert_eq!(out.len(), 65);
        assert_eq!(out[0], out[64]);
        for d in &out {
            let y = (-d[2]).asin().to_degrees();
            let z = d[1].atan2(d[0]).to_degrees();
            let on_edge = ((y + 40.0).abs() < 1e-9 || (y - 60.0).abs() < 1e-9)
                || ((z.abs() - 70.0).abs() < 1e-9 && (-40.0..=60.0).contains(&y));
            assert!(on_edge, "({y}, {z})");
            let q = crate::rotation::quat_from_euler_zyx_deg([0.0, y, z]);
            assert!(shoulder.excursion(crate::rotation::wxyz(&q)) < 1e-9);
        }
    }
}
