//! Histograms of joint angles with the mean and the interval holding 90% of
//! the samples (thesis 3.1.2, Figures 3-3 to 3-6).
//!
//! The interval is the source's: the lines that "enclose 90% of the samples on
//! either side of the mean with joint angles closest to the mean". Of the
//! samples below the mean, the 90% closest to it lie at or above the lower
//! line; of the samples at or above the mean, the 90% closest to it lie at or
//! below the upper line. The interval holds 90% of all samples, split around
//! the mean in the proportion the samples are; for a distribution with as many
//! samples below its mean as above, it is the 5th to 95th percentile.
//!
//! All values are degrees. Bins are 1 degree wide by default, as the source's.

use super::JointSamples;
use crate::limits::{JointLimits, LimitTable};
use crate::model::Model;

/// The share of samples the interval holds.
pub const INTERVAL_FRACTION: f64 = 0.9;
/// The source's bin width, degrees.
pub const DEFAULT_BIN_DEG: f64 = 1.0;

/// Statistics and histogram of one angle.
#[derive(Debug, Clone, PartialEq)]
pub struct AxisHistogram {
    /// Number of samples.
    pub count: usize,
    /// Arithmetic mean, degrees.
    pub mean_deg: f64,
    /// Standard deviation (population), degrees.
    pub sd_deg: f64,
    /// Smallest and largest sample, degrees.
    pub min_deg: f64,
    pub max_deg: f64,
    /// `[lower, upper]` holding [`INTERVAL_FRACTION`] of the samples around the
    /// mean (see the module docs), degrees.
    pub interval_deg: [f64; 2],
    /// Bin width, degrees.
    pub bin_deg: f64,
    /// Left edge of the first bin, degrees (a multiple of `bin_deg`).
    pub first_edge_deg: f64,
    /// Samples per bin; bin `k` is `[first + k * bin, first + (k + 1) * bin)`.
    pub counts: Vec<u32>,
}

impl AxisHistogram {
    /// Histogram and statistics of `values` (degrees) with bins `bin_deg`
    /// wide; None when there is no finite value. Non-finite values are ignored.
    pub fn new(values: impl IntoIterator<Item = f64>, bin_deg: f64) -> Option<AxisHistogram> {
        let mut v: Vec<f64> = values.into_iter().filter(|x| x.is_finite()).collect();
        if v.is_empty() || !(bin_deg.is_finite() && bin_deg > 0.0) {
            return None;
        }
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt();
        let (min, max) = v
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
                (a.min(x), b.max(x))
            });
        let first = (min / bin_deg).floor() * bin_deg;
        let bins = (((max - first) / bin_deg).floor() as usize + 1).max(1);
        let mut counts = vec![0u32; bins];
        for &x in &v {
            let k = (((x - first) / bin_deg).floor() as usize).min(bins - 1);
            counts[k] += 1;
        }
        let interval = interval_around_mean(&mut v, mean, INTERVAL_FRACTION);
        Some(AxisHistogram {
            count: v.len(),
            mean_deg: mean,
            sd_deg: sd,
            min_deg: min,
            max_deg: max,
            interval_deg: interval,
            bin_deg,
            first_edge_deg: first,
            counts,
        })
    }

    /// Centre of bin `k`, degrees.
    pub fn bin_centre(&self, k: usize) -> f64 {
        self.first_edge_deg + (k as f64 + 0.5) * self.bin_deg
    }

    /// The largest bin count.
    pub fn peak(&self) -> u32 {
        self.counts.iter().copied().max().unwrap_or(0)
    }
}

/// The interval holding `fraction` of `values` around `mean` (module docs):
/// `[lower, upper]`, each a sample value (the mean itself on a side without
/// samples). Reorders `values`.
pub fn interval_around_mean(values: &mut [f64], mean: f64, fraction: f64) -> [f64; 2] {
    // Below the mean first, then at or above it.
    let split = partition(values, |x| x < mean);
    let (below, above) = values.split_at_mut(split);
    let keep = |m: usize| ((fraction * m as f64).ceil() as usize).clamp(1, m.max(1));
    let lower = if below.is_empty() {
        mean
    } else {
        // The farthest of the `keep` samples closest to the mean: the
        // (m - keep)-th smallest below it.
        let k = below.len() - keep(below.len());
        *below.select_nth_unstable_by(k, f64::total_cmp).1
    };
    let upper = if above.is_empty() {
        mean
    } else {
        let k = keep(above.len()) - 1;
        *above.select_nth_unstable_by(k, f64::total_cmp).1
    };
    [lower, upper]
}

/// Moves the values for which `pred` holds to the front; returns their count.
fn partition(values: &mut [f64], pred: impl Fn(f64) -> bool) -> usize {
    let mut k = 0;
    for i in 0..values.len() {
        if pred(values[i]) {
            values.swap(i, k);
            k += 1;
        }
    }
    k
}

/// Histograms of one joint (or pooled group) on its three axes.
#[derive(Debug, Clone, PartialEq)]
pub struct JointHistogram {
    /// Joint or table row name (see [`JointSamples::name`]).
    pub name: String,
    /// Joints pooled.
    pub joints: Vec<String>,
    /// Trials that contributed.
    pub trials: usize,
    /// X, Y, Z (None when there are no samples).
    pub axes: [Option<AxisHistogram>; 3],
    /// The current limits of the group, if the table has them.
    pub limits: Option<JointLimits>,
}

/// Histograms of every group of `samples`, with the limits of `table` (the
/// group's own rows, else those of its first joint's kind in `model`).
pub fn histograms(
    samples: &[JointSamples],
    table: &LimitTable,
    model: &Model,
    bin_deg: f64,
) -> Vec<JointHistogram> {
    samples
        .iter()
        .map(|s| joint_histogram(s, table, model, bin_deg))
        .collect()
}

/// Histograms of one group (see [`histograms`]).
pub fn joint_histogram(
    s: &JointSamples,
    table: &LimitTable,
    model: &Model,
    bin_deg: f64,
) -> JointHistogram {
    let kind = s
        .joints
        .first()
        .and_then(|j| model.joint(j))
        .map_or(s.name.as_str(), |j| j.kind.as_str());
    JointHistogram {
        name: s.name.clone(),
        joints: s.joints.clone(),
        trials: s.trials,
        axes: std::array::from_fn(|axis| {
            AxisHistogram::new(s.angles.iter().map(|a| a[axis]), bin_deg)
        }),
        limits: table.joint_limits(&s.name, kind, true),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The interval by its definition, counted directly: the lowest sample
    /// below the mean with at least `fraction` of the below-mean samples in
    /// `[it, mean)`, and the same above. O(n^2), independent of the selection
    /// algorithm.
    fn direct_interval(values: &[f64], fraction: f64) -> ([f64; 2], f64) {
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        let below: Vec<f64> = values.iter().copied().filter(|&x| x < mean).collect();
        let above: Vec<f64> = values.iter().copied().filter(|&x| x >= mean).collect();
        let need = |m: usize| (fraction * m as f64).ceil() as usize;
        // The largest candidate that still has `need` samples between it and the mean.
        let lower = below
            .iter()
            .copied()
            .filter(|&c| below.iter().filter(|&&x| x >= c).count() >= need(below.len()))
            .fold(f64::NEG_INFINITY, f64::max);
        let upper = above
            .iter()
            .copied()
            .filter(|&c| above.iter().filter(|&&x| x <= c).count() >= need(above.len()))
            .fold(f64::INFINITY, f64::min);
        // A side without samples ends at the mean.
        let side = |v: f64| if v.is_finite() { v } else { mean };
        ([side(lower), side(upper)], mean)
    }

    #[test]
    fn interval_and_mean_match_a_direct_computation() {
        // Skewed, tied and noisy data from a fixed generator.
        use rand::{Rng, SeedableRng};
        let mut r = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        for n in [1usize, 2, 3, 10, 101, 1000] {
            let v: Vec<f64> = (0..n)
                .map(|_| {
                    let u: f64 = r.random_range(0.0..1.0);
                    (40.0 * u * u - 10.0).round() / 2.0 // skewed, many ties
                })
                .collect();
            let h = AxisHistogram::new(v.clone(), 1.0).unwrap();
            let (want, mean) = direct_interval(&v, 0.9);
            assert!((h.mean_deg - mean).abs() < 1e-12, "n={n}");
            assert_eq!(h.interval_deg, want, "n={n}");
            // It holds at least 90% of the samples, and not one sample more
            // than 90% of each side rounds up to.
            let inside = v.iter().filter(|&&x| x >= want[0] && x <= want[1]).count();
            assert!(inside as f64 >= 0.9 * n as f64, "n={n}: {inside}");
            assert_eq!(h.counts.iter().sum::<u32>() as usize, n);
        }
    }

    #[test]
    fn interval_of_1_to_100_by_hand() {
        // Mean 50.5; below it 1..=50, 45 kept closest: 6..=50; above 51..=100:
        // 51..=95. The interval [6, 95] holds 90 of 100.
        let v: Vec<f64> = (1..=100).map(f64::from).collect();
        let h = AxisHistogram::new(v, 1.0).unwrap();
        assert_eq!(h.mean_deg, 50.5);
        assert_eq!(h.interval_deg, [6.0, 95.0]);
        assert_eq!((h.min_deg, h.max_deg, h.first_edge_deg), (1.0, 100.0, 1.0));
        assert_eq!(h.counts, vec![1; 100]);
        // Population SD of 1..=100: sqrt((100^2 - 1) / 12).
        assert!((h.sd_deg - (9999.0f64 / 12.0).sqrt()).abs() < 1e-12);
    }

    #[test]
    fn interval_of_a_sinusoid_is_near_its_extremes() {
        // Samples of c + A sin(theta), theta uniform over whole cycles: 90% of
        // each half lies within A sin(0.9 * 90 deg) of the centre.
        let (c, a) = (20.0, 50.0);
        let n = 36_000;
        let v: Vec<f64> = (0..n)
            .map(|i| c + a * (std::f64::consts::TAU * i as f64 / n as f64 * 3.0).sin())
            .collect();
        let h = AxisHistogram::new(v, 1.0).unwrap();
        let half = a * (0.9f64 * 90.0).to_radians().sin();
        assert!((h.mean_deg - c).abs() < 1e-9);
        assert!((h.interval_deg[0] - (c - half)).abs() < 0.01, "{h:?}");
        assert!((h.interval_deg[1] - (c + half)).abs() < 0.01);
    }

    #[test]
    fn bins_cover_every_sample_and_bad_input_gives_none() {
        let h = AxisHistogram::new([-0.5, 0.0, 0.2, 0.99, 1.0, 2.5], 1.0).unwrap();
        assert_eq!(h.first_edge_deg, -1.0);
        assert_eq!(h.counts, vec![1, 3, 1, 1]);
        assert_eq!(h.bin_centre(0), -0.5);
        assert_eq!(h.peak(), 3);
        let h = AxisHistogram::new([5.0, f64::NAN, 5.0], 2.0).unwrap();
        assert_eq!((h.count, h.interval_deg), (2, [5.0, 5.0]));
        assert!(AxisHistogram::new([], 1.0).is_none());
        assert!(AxisHistogram::new([f64::NAN], 1.0).is_none());
        assert!(AxisHistogram::new([1.0], 0.0).is_none());
    }
}
