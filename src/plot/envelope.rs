//! Long series reduced for drawing: per column of the figure (or terminal),
//! the minimum and maximum sample, so that spikes stay visible. The
//! workbench's charts and `acmw plot` share it.

/// Reduces the samples `y(i)` at times `t[i] - origin` (ascending) inside
/// `[t0, t1]` to at most two points per column of `columns`: the minimum and the
/// maximum of the column, so that spikes stay visible. Fewer samples than
/// columns are returned as they are (plus one neighbour each side, so lines
/// reach the edges). Reads the samples in place: only the visible ones are
/// touched, and nothing of the trial's length is allocated.
pub fn envelope(
    t: &[f64],
    origin: f64,
    y: impl Fn(usize) -> f64,
    t0: f64,
    t1: f64,
    columns: usize,
) -> Vec<(f64, f64)> {
    let n = t.len();
    if n == 0 || columns == 0 || t1 <= t0 {
        return vec![];
    }
    let a = t.partition_point(|&x| x - origin < t0).saturating_sub(1);
    let b = (t.partition_point(|&x| x - origin <= t1) + 1).min(n);
    if b - a <= 2 * columns {
        return (a..b).map(|i| (t[i] - origin, y(i))).collect();
    }
    let w = (t1 - t0) / columns as f64;
    let mut out = Vec::with_capacity(2 * columns);
    // Times ascend, so each column is a run of samples found by binary search;
    // the first column also takes the neighbour before t0, the last the one after t1.
    let mut start = a;
    for col in 0..columns {
        let end = if col + 1 == columns {
            b
        } else {
            let edge = t0 + (col + 1) as f64 * w;
            start + t[start..b].partition_point(|&x| x - origin < edge)
        };
        if end > start {
            let (lo, hi) = (start..end).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), k| {
                let v = y(k);
                (lo.min(v), hi.max(v))
            });
            let tc = t0 + (col as f64 + 0.5) * w;
            out.push((tc, lo));
            if hi != lo {
                out.push((tc, hi));
            }
        }
        start = end;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn envelope_keeps_spikes_and_bounds_points() {
        let t: Vec<f64> = (0..1000).map(|i| i as f64 / 100.0).collect();
        let mut y = vec![0.0; 1000];
        y[503] = 50.0; // one-sample spike
        y[700] = -20.0;
        let e = envelope(&t, 0.0, |i| y[i], 0.0, 10.0, 40);
        assert!(e.len() <= 80, "{}", e.len());
        assert!(e.iter().any(|&(_, v)| v == 50.0));
        assert!(e.iter().any(|&(_, v)| v == -20.0));
        assert!(e.windows(2).all(|w| w[0].0 <= w[1].0));
        // Few samples: kept as they are, with a neighbour each side.
        let e = envelope(&t, 0.0, |i| y[i], 1.0, 1.05, 40);
        assert_eq!(e.first().unwrap().0, 0.99);
        assert_eq!(e.last().unwrap().0, 1.06);
        assert!(envelope(&t, 0.0, |i| y[i], 0.0, 10.0, 0).is_empty());
        assert!(envelope(&[], 0.0, |_| 0.0, 0.0, 1.0, 10).is_empty());
        // Times recorded from 100 s, drawn from the origin: the same envelope.
        let late: Vec<f64> = t.iter().map(|x| x + 100.0).collect();
        let shifted = envelope(&late, 100.0, |i| y[i], 0.0, 10.0, 40);
        let plain = envelope(&t, 0.0, |i| y[i], 0.0, 10.0, 40);
        assert_eq!(shifted.len(), plain.len());
        for (a, b) in shifted.iter().zip(&plain) {
            assert!((a.0 - b.0).abs() < 1e-9 && a.1 == b.1);
        }
    }
}
