//! Limit classes of joint angles and the 3-D scatter of a joint's Z-Y-X angles
//! as three projections (thesis appendix B).
//!
//! Angles are the joint's Z-Y-X Euler angles `[x, y, z]` in degrees (see
//! [`crate::metrics::joint_angles`]). A long trial has more samples than a
//! screen or page has dots, so the views reduce samples to a [`Raster`] of the
//! output's resolution: every sample lands in a dot, and a dot keeps the
//! highest key (the worst limit class, or the latest time) plotted into it, so
//! no sample beyond a limit is hidden by the reduction.

use crate::acm::cost::excursion;

/// Excess beyond a limit up to which a sample is "near" the limits (thesis 4.1:
/// purple points), degrees.
pub const NEAR_DEG: f64 = 10.0;

/// Number of time bands of the time-coded colouring.
pub const TIME_BINS: u8 = 6;

/// Where a sample lies against the joint's limits (the thesis' colours: blue,
/// purple, red).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum LimitClass {
    /// Inside the limits on all three axes.
    Within,
    /// Beyond a limit by at most [`NEAR_DEG`] on every axis.
    Near,
    /// Beyond a limit by more than [`NEAR_DEG`] on some axis.
    Beyond,
}

impl LimitClass {
    /// The classes, least severe first.
    pub const ALL: [LimitClass; 3] = [LimitClass::Within, LimitClass::Near, LimitClass::Beyond];

    /// A short label for legends.
    pub fn label(self) -> &'static str {
        match self {
            LimitClass::Within => "within",
            LimitClass::Near => "<=10 deg out",
            LimitClass::Beyond => ">10 out",
        }
    }

    /// The raster key of the class (its index in [`LimitClass::ALL`]).
    pub fn key(self) -> u8 {
        self as u8
    }
}

/// The class of one sample: by the largest excursion over the three axes
/// (0: within; up to [`NEAR_DEG`]: near; more: beyond). `range_deg` is
/// `[lower, upper]` per axis X, Y, Z in degrees. The angles are read in the
/// box first ([`crate::rotation::read_in_box`]: of the rotation's two Z-Y-X
/// triplets, the one the box reads).
pub fn classify(angles_deg: [f64; 3], range_deg: &[[f64; 2]; 3]) -> LimitClass {
    let worst = excursion(
        crate::rotation::read_in_box(angles_deg, range_deg),
        range_deg,
    )
    .into_iter()
    .fold(0.0, f64::max);
    if worst <= 0.0 {
        LimitClass::Within
    } else if worst <= NEAR_DEG {
        LimitClass::Near
    } else {
        LimitClass::Beyond
    }
}

/// Samples per class.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ClassCounts {
    /// Indexed by [`LimitClass::key`].
    pub counts: [usize; 3],
}

impl ClassCounts {
    /// Counts the classes of `angles` (degrees) against `range_deg`.
    pub fn of(angles: &[[f64; 3]], range_deg: &[[f64; 2]; 3]) -> ClassCounts {
        let mut counts = [0; 3];
        for a in angles {
            counts[classify(*a, range_deg) as usize] += 1;
        }
        ClassCounts { counts }
    }

    /// All samples counted.
    pub fn total(&self) -> usize {
        self.counts.iter().sum()
    }

    /// Percentage of the samples in `class` (0 when there are none).
    pub fn pct(&self, class: LimitClass) -> f64 {
        100.0 * self.counts[class as usize] as f64 / self.total().max(1) as f64
    }
}

/// How points are coloured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Colouring {
    /// By [`LimitClass`] (key = class key).
    #[default]
    Limits,
    /// By time: key = band `0 .. TIME_BINS` of the trial, earliest first.
    Time,
}

impl Colouring {
    /// The key of sample `i` of `n` with angles `a`.
    pub fn key(self, i: usize, n: usize, a: [f64; 3], range_deg: &[[f64; 2]; 3]) -> u8 {
        match self {
            Colouring::Limits => classify(a, range_deg).key(),
            Colouring::Time => time_bin(i, n),
        }
    }

    /// The number of distinct keys.
    pub fn keys(self) -> u8 {
        match self {
            Colouring::Limits => 3,
            Colouring::Time => TIME_BINS,
        }
    }
}

/// The time band of sample `i` of `n`: `0 .. TIME_BINS`, in equal parts of the samples.
pub fn time_bin(i: usize, n: usize) -> u8 {
    ((i * TIME_BINS as usize) / n.max(1)).min(TIME_BINS as usize - 1) as u8
}

/// The three projections of the scatter: (horizontal, vertical) axis indices
/// into `[x, y, z]`: X-Y, X-Z and Y-Z.
pub const PROJECTIONS: [(usize, usize); 3] = [(0, 1), (0, 2), (1, 2)];

/// A raster's size in dots and the rectangle of coordinates it covers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    pub w: usize,
    pub h: usize,
    /// Horizontal bounds `[left, right]`.
    pub bx: [f64; 2],
    /// Vertical bounds `[bottom, top]`.
    pub by: [f64; 2],
}

/// A grid of `w` x `h` dots, row 0 at the top; each dot holds the highest key
/// plotted into it. Points map to the nearest dot as ratatui's canvas maps
/// them, so a raster of the canvas' resolution draws exactly what plotting
/// every point would.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Raster {
    pub w: usize,
    pub h: usize,
    /// 0 = empty, `k + 1` = key `k`; row-major.
    cells: Vec<u8>,
}

impl Raster {
    /// An empty raster.
    pub fn new(w: usize, h: usize) -> Raster {
        Raster {
            w,
            h,
            cells: vec![0; w * h],
        }
    }

    /// The dot of `(x, y)` inside bounds `bx` x `by`, if inside.
    pub fn dot(&self, x: f64, y: f64, bx: [f64; 2], by: [f64; 2]) -> Option<(usize, usize)> {
        if self.w == 0 || self.h == 0 || !(x >= bx[0] && x <= bx[1] && y >= by[0] && y <= by[1]) {
            return None;
        }
        let (sw, sh) = (bx[1] - bx[0], by[1] - by[0]);
        if sw <= 0.0 || sh <= 0.0 {
            return None;
        }
        let c = ((x - bx[0]) * (self.w - 1) as f64 / sw).round() as usize;
        let r = ((by[1] - y) * (self.h - 1) as f64 / sh).round() as usize;
        Some((c.min(self.w - 1), r.min(self.h - 1)))
    }

    /// Plots `key` at `(x, y)` (ignored outside the bounds).
    pub fn plot(&mut self, x: f64, y: f64, bx: [f64; 2], by: [f64; 2], key: u8) {
        if let Some((c, r)) = self.dot(x, y, bx, by) {
            self.put(c, r, key);
        }
    }

    /// Keeps `key` at a dot if it is higher than the one there.
    pub fn put(&mut self, col: usize, row: usize, key: u8) {
        let cell = &mut self.cells[row * self.w + col];
        *cell = (*cell).max(key + 1);
    }

    /// A precomputed [`Raster::dot`] for many points in the same bounds.
    pub fn mapper(&self, bx: [f64; 2], by: [f64; 2]) -> Mapper {
        let (sw, sh) = (bx[1] - bx[0], by[1] - by[0]);
        let ok = self.w > 0 && self.h > 0 && sw > 0.0 && sh > 0.0;
        Mapper {
            bx,
            by,
            kx: if ok { (self.w - 1) as f64 / sw } else { 0.0 },
            ky: if ok { (self.h - 1) as f64 / sh } else { 0.0 },
            ok,
        }
    }

    /// Plots `key` at `(x, y)` through a mapper of this raster.
    pub fn plot_mapped(&mut self, m: &Mapper, x: f64, y: f64, key: u8) {
        if let Some((c, r)) = m.dot(x, y) {
            self.put(c.min(self.w - 1), r.min(self.h - 1), key);
        }
    }

    /// The key at a dot, if any.
    pub fn get(&self, col: usize, row: usize) -> Option<u8> {
        match self.cells.get(row * self.w + col) {
            Some(&k) if k > 0 && col < self.w => Some(k - 1),
            _ => None,
        }
    }

    /// The occupied dots: `(col, row, key)`, row by row.
    pub fn dots(&self) -> impl Iterator<Item = (usize, usize, u8)> + '_ {
        self.cells
            .iter()
            .enumerate()
            .filter(|(_, &k)| k > 0)
            .map(|(i, &k)| (i % self.w, i / self.w, k - 1))
    }

    /// Number of occupied dots.
    pub fn count(&self) -> usize {
        self.cells.iter().filter(|&&k| k > 0).count()
    }

    /// The centre of a dot in the coordinates of bounds `bx` x `by`.
    pub fn centre(&self, col: usize, row: usize, bx: [f64; 2], by: [f64; 2]) -> (f64, f64) {
        let fx = col as f64 / (self.w.max(2) - 1) as f64;
        let fy = row as f64 / (self.h.max(2) - 1) as f64;
        (bx[0] + fx * (bx[1] - bx[0]), by[1] - fy * (by[1] - by[0]))
    }
}

/// The dot of a point in fixed bounds, with the divisions done once. Rounds
/// half-way points up as [`Raster::dot`] does (the coordinates are never
/// negative here).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mapper {
    bx: [f64; 2],
    by: [f64; 2],
    kx: f64,
    ky: f64,
    ok: bool,
}

impl Mapper {
    /// `(col, row)` of a point inside the bounds.
    #[inline]
    pub fn dot(&self, x: f64, y: f64) -> Option<(usize, usize)> {
        if !(self.ok && x >= self.bx[0] && x <= self.bx[1] && y >= self.by[0] && y <= self.by[1]) {
            return None;
        }
        Some((
            ((x - self.bx[0]) * self.kx + 0.5) as usize,
            ((self.by[1] - y) * self.ky + 0.5) as usize,
        ))
    }
}

/// Axis bounds `[lo, hi]` per axis X, Y, Z (degrees) holding every sample of
/// `sets` and the limits, padded by 5% (at least 1 degree) each side.
pub fn axis_bounds(sets: &[&[[f64; 3]]], range_deg: Option<&[[f64; 2]; 3]>) -> [[f64; 2]; 3] {
    std::array::from_fn(|k| {
        let mut lo = f64::INFINITY;
        let mut hi = f64::NEG_INFINITY;
        for a in sets.iter().flat_map(|s| s.iter()) {
            if a[k].is_finite() {
                lo = lo.min(a[k]);
                hi = hi.max(a[k]);
            }
        }
        if let Some(r) = range_deg {
            lo = lo.min(r[k][0]);
            hi = hi.max(r[k][1]);
        }
        if !(lo.is_finite() && hi.is_finite()) {
            return [-1.0, 1.0];
        }
        let pad = ((hi - lo) * 0.05).max(1.0);
        [lo - pad, hi + pad]
    })
}

/// The three projections of `angles` (degrees), one raster each of `w` x `h`
/// dots over `bounds`, keyed by `colouring`. One pass over the samples.
pub fn scatter_rasters(
    angles: &[[f64; 3]],
    range_deg: &[[f64; 2]; 3],
    bounds: &[[f64; 2]; 3],
    colouring: Colouring,
    w: usize,
    h: usize,
) -> [Raster; 3] {
    let mut out = [Raster::new(w, h), Raster::new(w, h), Raster::new(w, h)];
    let maps: [Mapper; 3] =
        std::array::from_fn(|p| out[p].mapper(bounds[PROJECTIONS[p].0], bounds[PROJECTIONS[p].1]));
    let n = angles.len();
    for (i, a) in angles.iter().enumerate() {
        let key = colouring.key(i, n, *a, range_deg);
        for ((r, m), &(hx, vy)) in out.iter_mut().zip(&maps).zip(PROJECTIONS.iter()) {
            r.plot_mapped(m, a[hx], a[vy], key);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const KNEE: [[f64; 2]; 3] = [[-5.0, 5.0], [0.0, 130.0], [-5.0, 5.0]];

    /// The class computed the direct way, written independently of `classify`:
    /// the largest distance of any angle outside its `[lo, hi]`.
    fn direct_class(a: [f64; 3], r: &[[f64; 2]; 3]) -> LimitClass {
        let mut worst: f64 = 0.0;
        for k in 0..3 {
            if a[k] > r[k][1] {
                worst = worst.max(a[k] - r[k][1]);
            }
            if a[k] < r[k][0] {
                worst = worst.max(r[k][0] - a[k]);
            }
        }
        if worst == 0.0 {
            LimitClass::Within
        } else if worst <= 10.0 {
            LimitClass::Near
        } else {
            LimitClass::Beyond
        }
    }

    #[test]
    fn classes_match_direct_computation_and_boundaries() {
        // Exactly on a limit is within; exactly 10 deg out is near; just past, beyond.
        assert_eq!(classify([5.0, 130.0, -5.0], &KNEE), LimitClass::Within);
        assert_eq!(classify([0.0, 140.0, 0.0], &KNEE), LimitClass::Near);
        assert_eq!(
            classify([0.0, 140.0 + 1e-9, 0.0], &KNEE),
            LimitClass::Beyond
        );
        assert_eq!(classify([-15.0, 60.0, 0.0], &KNEE), LimitClass::Near);
        // The worst axis decides: near on X, beyond on Z.
        assert_eq!(classify([7.0, 60.0, 16.0], &KNEE), LimitClass::Beyond);
        // A sweep over a grid against the direct computation.
        let mut seen = [0usize; 3];
        for x in (-40..=40).step_by(3) {
            for y in (-30..=170).step_by(7) {
                for z in (-25..=25).step_by(2) {
                    let a = [x as f64 * 0.5, y as f64, z as f64 * 0.75];
                    let c = classify(a, &KNEE);
                    assert_eq!(c, direct_class(a, &KNEE), "{a:?}");
                    seen[c as usize] += 1;
                }
            }
        }
        assert!(seen.iter().all(|&s| s > 100), "{seen:?}");
        let angles = [
            [0.0, 10.0, 0.0],
            [0.0, -3.0, 0.0],
            [0.0, 10.0, 30.0],
            [1.0, 1.0, 1.0],
        ];
        let c = ClassCounts::of(&angles, &KNEE);
        assert_eq!(c.counts, [2, 1, 1]);
        assert_eq!(c.pct(LimitClass::Within), 50.0);
    }

    #[test]
    fn raster_keeps_the_worst_key_and_maps_like_the_canvas() {
        let mut r = Raster::new(11, 5);
        let (bx, by) = ([0.0, 10.0], [0.0, 4.0]);
        r.plot(3.0, 1.0, bx, by, 0);
        r.plot(3.2, 1.1, bx, by, 2); // same dot: the higher key stays
        r.plot(3.1, 0.9, bx, by, 1);
        r.plot(11.0, 0.0, bx, by, 2); // outside: ignored
        assert_eq!(r.count(), 1);
        assert_eq!(r.get(3, 3), Some(2));
        // Corners: (x0, y1) is the top-left dot, (x1, y0) the bottom-right.
        r.plot(0.0, 4.0, bx, by, 0);
        r.plot(10.0, 0.0, bx, by, 1);
        assert_eq!(r.get(0, 0), Some(0));
        assert_eq!(r.get(10, 4), Some(1));
        assert_eq!(r.centre(10, 4, bx, by), (10.0, 0.0));
        // The mapper agrees with `dot` everywhere inside.
        let m = r.mapper(bx, by);
        for k in 0..=400 {
            let (x, y) = (k as f64 * 0.025, (k % 17) as f64 * 0.25);
            assert_eq!(m.dot(x, y), r.dot(x, y, bx, by), "{x} {y}");
        }
        assert_eq!(m.dot(-0.1, 1.0), None);
        let dots: Vec<_> = r.dots().collect();
        assert_eq!(dots, [(0, 0, 0), (3, 3, 2), (10, 4, 1)]);
    }

    #[test]
    fn scatter_projections_hold_every_sample_once_per_dot() {
        // Samples on distinct dots: each projection holds all of them.
        let angles: Vec<[f64; 3]> = (0..20)
            .map(|i| [i as f64, 2.0 * i as f64, -(i as f64)])
            .collect();
        let b = axis_bounds(&[&angles], None);
        let rs = scatter_rasters(&angles, &KNEE, &b, Colouring::Limits, 200, 200);
        for r in &rs {
            assert_eq!(r.count(), 20);
        }
        // Classes reach the dots: the last sample (19, 38, -19) is beyond.
        let worst = rs[0].dots().map(|d| d.2).max();
        assert_eq!(worst, Some(LimitClass::Beyond.key()));
        // Time colouring: keys ascend with time.
        let rs = scatter_rasters(&angles, &KNEE, &b, Colouring::Time, 200, 200);
        let mut keys: Vec<u8> = rs[0].dots().map(|d| d.2).collect();
        keys.sort();
        assert_eq!(keys.first(), Some(&0));
        assert_eq!(keys.last(), Some(&(TIME_BINS - 1)));
        assert_eq!(time_bin(0, 20), 0);
        assert_eq!(time_bin(19, 20), TIME_BINS - 1);
        // Bounds hold the data and the limits.
        let b = axis_bounds(&[&angles], Some(&KNEE));
        assert!(b[1][0] < 0.0 && b[1][1] > 130.0);
    }
}
