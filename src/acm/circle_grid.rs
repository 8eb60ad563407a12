//! The lowest point of a grid over the whole circle, of a 1-D cost of an
//! angle in degrees: the start of the heading fit's search
//! ([`super::heading`]) and of the turn about a hinge axis
//! ([`super::hinge::minimise_turn`]). Grids start at -180 deg; ties go to
//! the first point.

/// Points of the whole-circle grid `step` degrees apart (from -180).
fn grid_points(step: f64) -> usize {
    ((360.0 / step).round() as usize).max(1)
}

/// The grid's point `i` of `n`, degrees.
fn grid_at(i: usize, n: usize) -> f64 {
    -180.0 + i as f64 * 360.0 / n as f64
}

/// The lowest of every point of the grid `step` degrees apart, the first on
/// ties.
pub fn grid_minimum(eval: &mut impl FnMut(f64) -> f64, step: f64) -> Option<(f64, f64)> {
    let n = grid_points(step);
    lowest(n, (0..n).map(|i| (i, eval(grid_at(i, n)))))
}

/// Grid points between two of the coarse grid of [`refined_grid_minimum`].
const REFINE_BY: usize = 3;
/// The coarse grid's lowest local minima whose neighbourhoods are refined.
const REFINED_MINIMA: usize = 3;

/// The grid `step` degrees apart's lowest point, looked for coarse to fine:
/// every [`REFINE_BY`]-th point first, then every point between the coarse
/// neighbours of the coarse grid's [`REFINED_MINIMA`] lowest local minima
/// (the first on ties). About half the evaluations of the whole grid; the
/// same point as [`grid_minimum`] unless the grid's lowest point lies in a
/// dip narrower than the coarse grid, away from those minima (the descent
/// that follows then starts in another basin). Grids that are not a whole
/// number of coarse steps are scanned whole.
pub fn refined_grid_minimum(eval: &mut impl FnMut(f64) -> f64, step: f64) -> Option<(f64, f64)> {
    let n = grid_points(step);
    if !n.is_multiple_of(REFINE_BY) || n < 3 * REFINE_BY {
        return grid_minimum(eval, step);
    }
    let coarse: Vec<f64> = (0..n / REFINE_BY)
        .map(|c| eval(grid_at(c * REFINE_BY, n)))
        .collect();
    let m = coarse.len();
    let mut minima: Vec<usize> = (0..m)
        .filter(|&c| coarse[c] <= coarse[(c + m - 1) % m] && coarse[c] <= coarse[(c + 1) % m])
        .collect();
    minima.sort_by(|&a, &b| coarse[a].total_cmp(&coarse[b]));
    let mut seen: Vec<(usize, f64)> = (0..m).map(|c| (c * REFINE_BY, coarse[c])).collect();
    for &c in minima.iter().take(REFINED_MINIMA) {
        for d in 1..REFINE_BY {
            for i in [c * REFINE_BY + d, (c * REFINE_BY + n - d) % n] {
                if seen.iter().all(|&(j, _)| j != i) {
                    seen.push((i, eval(grid_at(i, n))));
                }
            }
        }
    }
    seen.sort_by_key(|&(i, _)| i);
    lowest(n, seen.into_iter())
}

/// The point of lowest cost (the first on ties) among `(index, cost)` of
/// a grid of `n` points, in index order, as (heading, cost).
fn lowest(n: usize, points: impl Iterator<Item = (usize, f64)>) -> Option<(f64, f64)> {
    let mut best: Option<(usize, f64)> = None;
    for (i, f) in points {
        if best.is_none_or(|(_, b)| f.total_cmp(&b).is_lt()) {
            best = Some((i, f));
        }
    }
    best.map(|(i, f)| (grid_at(i, n), f))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refined_scan_finds_the_whole_grids_lowest_point_with_half_the_evaluations() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for _ in 0..200 {
            // Smooth costs of the heading with up to four dips on the circle,
            // plus `lambda1 |h|` (a kink at 0).
            let terms: Vec<(f64, f64, f64)> = (0..4)
                .map(|k| {
                    let harmonic = (k + 1) as f64;
                    (
                        harmonic,
                        rng.random_range(0.0..5.0),
                        rng.random_range(-180.0..180.0),
                    )
                })
                .collect();
            let f = |x: f64| {
                0.05 * x.abs()
                    + terms
                        .iter()
                        .map(|&(k, a, p)| a * (1.0 - ((x - p) * k).to_radians().cos()))
                        .sum::<f64>()
            };
            let (mut full_evals, mut refined_evals) = (0, 0);
            let full = grid_minimum(
                &mut |x| {
                    full_evals += 1;
                    f(x)
                },
                4.0,
            );
            let refined = refined_grid_minimum(
                &mut |x| {
                    refined_evals += 1;
                    f(x)
                },
                4.0,
            );
            assert_eq!(full, refined, "{terms:?}");
            assert_eq!(full_evals, 90);
            assert!(refined_evals <= 30 + 4 * REFINED_MINIMA, "{refined_evals}");
        }
        // The whole grid is scanned when the coarse grid does not fit it.
        let mut evals = 0;
        let f = |x: f64| (x - 33.0).abs();
        let got = refined_grid_minimum(
            &mut |x| {
                evals += 1;
                f(x)
            },
            7.2,
        );
        assert_eq!((got, evals), (grid_minimum(&mut |x| f(x), 7.2), 50));
        assert_eq!(got, Some((36.0, 3.0)));
    }
}
