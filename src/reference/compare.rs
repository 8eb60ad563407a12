//! Scoring joint angles against an optical reference.
//!
//! The reference is read at `t + lag` for each trial time `t`, both times as
//! their files give them (a C3D's count from 0 at its first frame), by
//! linear interpolation (across +-180 deg the short way); trial samples
//! outside the reference or beside a gap in it are left out. The lag is the
//! whole number of trial samples within `+-max_lag_s` that maximises the mean
//! absolute correlation of all reference channels with the first series'
//! angles (the uncorrected trial), unless it is given.
//!
//! Per series (uncorrected, then each variant), joint and axis: the RMS of the
//! angle difference (wrapped to +-180 deg), the mean difference (offset), the
//! RMS after removing that offset, and the correlation.

use super::Reference;
use crate::metrics::joint_angles;
use crate::model::Model;
use crate::rotation::wrap180;
use crate::trial::{median_dt, Trial};
use serde::{Deserialize, Serialize};

/// How to align and what span to score.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompareOptions {
    /// The lag is searched within +-this, seconds.
    pub max_lag_s: f64,
    /// A lag to use instead of searching, seconds.
    pub lag_s: Option<f64>,
    /// Scored span, seconds from the trial's first sample (whole trial when `None`).
    pub from_s: Option<f64>,
    pub to_s: Option<f64>,
}

impl Default for CompareOptions {
    fn default() -> Self {
        CompareOptions {
            max_lag_s: 2.0,
            lag_s: None,
            from_s: None,
            to_s: None,
        }
    }
}

/// The scores of one joint axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AxisScore {
    pub joint: String,
    /// `x`, `y` or `z`.
    pub axis: String,
    /// Samples scored (both sides present).
    pub samples: usize,
    pub rms_deg: f64,
    pub rms_without_offset_deg: f64,
    /// Mean of trial minus reference, degrees.
    pub offset_deg: f64,
    /// Pearson correlation (NaN, shown as null, when either side is constant).
    pub correlation: Option<f64>,
}

/// One series' scores (`uncorrected` or a variant's name).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct VariantScores {
    pub variant: String,
    pub axes: Vec<AxisScore>,
}

/// What `report --reference` found.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReferenceReport {
    pub reference: String,
    /// The reference is read at trial time + lag, seconds.
    pub lag_s: f64,
    /// Whether the lag was searched (else given).
    pub lag_searched: bool,
    pub max_lag_s: f64,
    /// Mean absolute correlation at the lag (uncorrected angles).
    pub lag_correlation: f64,
    /// Scored span, seconds from the trial's first sample.
    pub from_s: f64,
    pub to_s: f64,
    /// `source -> joint.axis` for every channel read.
    pub channels: Vec<String>,
    /// Reference columns that map to no joint axis.
    pub ignored: Vec<String>,
    pub variants: Vec<VariantScores>,
}

/// Values of `(time, value)` at `queries` (both increasing), linear, across
/// +-180 the short way; NaN outside or beside a gap.
fn resample(time: &[f64], values: &[f64], queries: impl Iterator<Item = f64>) -> Vec<f64> {
    let mut i = 0usize;
    queries
        .map(|q| {
            if time.is_empty() || q < time[0] || q > time[time.len() - 1] {
                return f64::NAN;
            }
            while i + 1 < time.len() && time[i + 1] < q {
                i += 1;
            }
            if i + 1 >= time.len() || time[i] == q {
                return if time[i] == q { values[i] } else { f64::NAN };
            }
            if time[i + 1] == q {
                return values[i + 1];
            }
            let f = (q - time[i]) / (time[i + 1] - time[i]);
            let (a, b) = (values[i], values[i + 1]);
            a + wrap180(b - a) * f
        })
        .collect()
}

/// Sums over the pairs where both are numbers.
struct Pairs {
    n: usize,
    diff: f64,
    diff2: f64,
    a: f64,
    b: f64,
    aa: f64,
    bb: f64,
    ab: f64,
}

fn pairs(a: &[f64], b: &[f64]) -> Pairs {
    let mut p = Pairs {
        n: 0,
        diff: 0.0,
        diff2: 0.0,
        a: 0.0,
        b: 0.0,
        aa: 0.0,
        bb: 0.0,
        ab: 0.0,
    };
    for (&x, &y) in a.iter().zip(b) {
        if x.is_nan() || y.is_nan() {
            continue;
        }
        let d = wrap180(x - y);
        p.n += 1;
        p.diff += d;
        p.diff2 += d * d;
        p.a += x;
        p.b += y;
        p.aa += x * x;
        p.bb += y * y;
        p.ab += x * y;
    }
    p
}

impl Pairs {
    fn correlation(&self) -> Option<f64> {
        let n = self.n as f64;
        let cov = self.ab - self.a * self.b / n;
        let va = self.aa - self.a * self.a / n;
        let vb = self.bb - self.b * self.b / n;
        let r = cov / (va * vb).sqrt();
        (self.n > 2 && r.is_finite()).then_some(r)
    }
}

/// Indices of the trial samples in the scored span.
fn span(trial: &Trial, opts: &CompareOptions) -> (std::ops::Range<usize>, f64, f64) {
    let t0 = trial.time_s.first().copied().unwrap_or(0.0);
    let end = trial.time_s.last().copied().unwrap_or(0.0) - t0;
    let from = opts.from_s.unwrap_or(0.0).max(0.0);
    let to = opts.to_s.unwrap_or(end).min(end);
    let a = trial.time_s.partition_point(|&t| t - t0 < from);
    let b = trial.time_s.partition_point(|&t| t - t0 <= to);
    (a..b.max(a), from, to)
}

/// The reference channels at trial times `time_s` plus `lag`.
fn channels_at(reference: &Reference, time_s: &[f64], lag: f64) -> Vec<Vec<f64>> {
    reference
        .channels
        .iter()
        .map(|c| {
            resample(
                &reference.time_s,
                &c.values_deg,
                time_s.iter().map(|t| t + lag),
            )
        })
        .collect()
}

/// Per channel, the trial's angle of that joint axis (NaN where the joint is
/// missing).
fn trial_channels(trial: &Trial, model: &Model, reference: &Reference) -> Vec<Vec<f64>> {
    reference
        .channels
        .iter()
        .map(|c| {
            let angles = model
                .joint(&c.joint)
                .and_then(|j| joint_angles(trial, j))
                .unwrap_or_default();
            if angles.is_empty() {
                vec![f64::NAN; trial.len()]
            } else {
                angles.iter().map(|a| a[c.axis.index()]).collect()
            }
        })
        .collect()
}

/// Mean absolute correlation of the channels over `range` at `lag`.
fn mean_abs_correlation(trial: &[Vec<f64>], reference: &Reference, time: &[f64], lag: f64) -> f64 {
    let resampled = channels_at(reference, time, lag);
    let rs: Vec<f64> = trial
        .iter()
        .zip(&resampled)
        .filter_map(|(a, b)| pairs(a, b).correlation())
        .map(f64::abs)
        .collect();
    if rs.is_empty() {
        0.0
    } else {
        rs.iter().sum::<f64>() / rs.len() as f64
    }
}

/// Why a trial cannot be scored against a reference ([`compare`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum CompareError {
    /// No series were given.
    #[error("nothing to compare")]
    Nothing,
    /// The scored span (seconds of the trial) holds fewer than 3 samples.
    #[error("the scored span {from_s}..{to_s} s holds {samples} samples; expected at least 3")]
    ShortSpan {
        from_s: f64,
        to_s: f64,
        samples: usize,
    },
}

/// Scores `series` (`(name, trial)`, the first the uncorrected one, all on
/// the same times) against `reference`.
pub fn compare(
    series: &[(String, &Trial)],
    model: &Model,
    reference: &Reference,
    opts: &CompareOptions,
) -> Result<ReferenceReport, CompareError> {
    let (_, first) = series.first().ok_or(CompareError::Nothing)?;
    let (range, from_s, to_s) = span(first, opts);
    if range.len() < 3 {
        return Err(CompareError::ShortSpan {
            from_s,
            to_s,
            samples: range.len(),
        });
    }
    let time = &first.time_s[range.clone()];
    let cut = |v: Vec<Vec<f64>>| -> Vec<Vec<f64>> {
        v.into_iter().map(|c| c[range.clone()].to_vec()).collect()
    };
    let uncorrected = cut(trial_channels(first, model, reference));
    let (lag_s, lag_searched) = match opts.lag_s {
        Some(l) => (l, false),
        None => {
            let dt = median_dt(&first.time_s);
            let steps = if dt > 0.0 {
                (opts.max_lag_s / dt).floor() as i64
            } else {
                0
            };
            let mut best = (f64::MIN, 0i64);
            for k in -steps..=steps {
                let r = mean_abs_correlation(&uncorrected, reference, time, k as f64 * dt);
                // Ties go to the smaller lag.
                if r > best.0 + 1e-12 || ((r - best.0).abs() <= 1e-12 && k.abs() < best.1.abs()) {
                    best = (r, k);
                }
            }
            (best.1 as f64 * dt, true)
        }
    };
    let lag_correlation = mean_abs_correlation(&uncorrected, reference, time, lag_s);
    let resampled = channels_at(reference, time, lag_s);
    let variants = series
        .iter()
        .map(|(name, trial)| {
            let angles = cut(trial_channels(trial, model, reference));
            let axes = reference
                .channels
                .iter()
                .zip(&angles)
                .zip(&resampled)
                .map(|((c, a), r)| score(&c.joint, c.axis.name(), a, r))
                .collect();
            VariantScores {
                variant: name.clone(),
                axes,
            }
        })
        .collect();
    Ok(ReferenceReport {
        reference: reference.origin.clone(),
        lag_s,
        lag_searched,
        max_lag_s: opts.max_lag_s,
        lag_correlation,
        from_s,
        to_s,
        channels: reference
            .channels
            .iter()
            .map(|c| format!("{} -> {}.{}", c.source, c.joint, c.axis.name()))
            .collect(),
        ignored: reference.ignored.clone(),
        variants,
    })
}

/// A reference as the trial screen draws it: per joint and axis the
/// reference's angle (degrees) at each trial sample's time plus the lag, NaN
/// where it has none.
#[derive(Debug, Clone, PartialEq)]
pub struct ReferenceTrace {
    /// The reference file as named.
    pub origin: String,
    /// The reference is read at trial time + lag, seconds (found as `report
    /// --reference` finds it, within +-`max_lag_s`).
    pub lag_s: f64,
    /// Per joint: per axis X, Y, Z the values at the trial's samples, or None
    /// when the reference has no channel for that axis.
    pub joints: std::collections::BTreeMap<String, [Option<Vec<f64>>; 3]>,
}

/// Aligns `reference` with `trial` (the lag of [`compare`] against the
/// trial's own angles) and resamples it onto the trial's times.
pub fn trace(
    trial: &Trial,
    model: &Model,
    reference: &Reference,
    opts: &CompareOptions,
) -> Result<ReferenceTrace, CompareError> {
    let report = compare(&[(String::new(), trial)], model, reference, opts)?;
    let values = channels_at(reference, &trial.time_s, report.lag_s);
    let mut joints: std::collections::BTreeMap<String, [Option<Vec<f64>>; 3]> = Default::default();
    for (c, v) in reference.channels.iter().zip(values) {
        joints.entry(c.joint.clone()).or_default()[c.axis.index()] = Some(v);
    }
    Ok(ReferenceTrace {
        origin: reference.origin.clone(),
        lag_s: report.lag_s,
        joints,
    })
}

fn score(joint: &str, axis: &str, trial: &[f64], reference: &[f64]) -> AxisScore {
    let p = pairs(trial, reference);
    let n = p.n.max(1) as f64;
    let offset = p.diff / n;
    AxisScore {
        joint: joint.to_string(),
        axis: axis.to_string(),
        samples: p.n,
        rms_deg: (p.diff2 / n).sqrt(),
        rms_without_offset_deg: (p.diff2 / n - offset * offset).max(0.0).sqrt(),
        offset_deg: offset,
        correlation: p.correlation(),
    }
}

/// The report as aligned text: per joint axis, each series' RMS, RMS
/// without offset, offset (degrees) and correlation.
pub fn format_text(r: &ReferenceReport) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let how = if r.lag_searched {
        format!("found within +-{} s", r.max_lag_s)
    } else {
        "given".to_string()
    };
    let _ = writeln!(
        out,
        "Reference {}: lag {:+.3} s ({how}; mean |r| {:.3}), scored {:.2}..{:.2} s",
        r.reference, r.lag_s, r.lag_correlation, r.from_s, r.to_s
    );
    if !r.ignored.is_empty() {
        let _ = writeln!(out, "not mapped to a joint axis: {}", r.ignored.join(", "));
    }
    let _ = writeln!(
        out,
        "RMS, RMS without offset, offset (deg) and correlation against the reference"
    );
    let _ = write!(out, "{:<13} {:>5}", "joint", "n");
    for v in &r.variants {
        let _ = write!(out, "  {:>27}", v.variant);
    }
    out.push('\n');
    let axes = r.variants.first().map_or(0, |v| v.axes.len());
    for k in 0..axes {
        let a = &r.variants[0].axes[k];
        let _ = write!(
            out,
            "{:<13} {:>5}",
            format!("{} {}", a.joint, a.axis),
            a.samples
        );
        for v in &r.variants {
            let s = &v.axes[k];
            let corr = s
                .correlation
                .map_or("    -".to_string(), |c| format!("{c:>5.2}"));
            let _ = write!(
                out,
                "  {:>6.2} {:>6.2} {:>7.2} {corr}",
                s.rms_deg, s.rms_without_offset_deg, s.offset_deg
            );
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resampling_is_linear_and_wraps_the_short_way() {
        let t = [0.0, 1.0, 2.0];
        let v = [170.0, -170.0, f64::NAN];
        let r = resample(&t, &v, [0.0, 0.5, 1.0, 1.5, 2.5, -0.1].into_iter());
        assert_eq!(r[0], 170.0);
        assert!((wrap180(r[1]) - 180.0).abs() < 1e-12 || (wrap180(r[1]) + 180.0).abs() < 1e-12);
        assert_eq!(r[2], -170.0);
        assert!(r[3].is_nan() && r[4].is_nan() && r[5].is_nan());
    }

    #[test]
    fn scores_of_an_offset_copy() {
        let a: Vec<f64> = (0..100).map(|i| (i as f64 * 0.1).sin() * 30.0).collect();
        let b: Vec<f64> = a.iter().map(|x| x - 2.0).collect();
        let s = score("r_knee", "y", &a, &b);
        assert!((s.rms_deg - 2.0).abs() < 1e-12);
        assert!(s.rms_without_offset_deg < 1e-6);
        assert!((s.offset_deg - 2.0).abs() < 1e-12);
        assert!((s.correlation.unwrap() - 1.0).abs() < 1e-12);
    }
}
