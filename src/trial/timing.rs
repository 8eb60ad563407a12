//! Sample times as they really come: irregular intervals and gaps.
//!
//! Times are seconds. The nominal interval is the median one (docs/method.md
//! section 7); an interval longer than [`GAP_FACTOR`] times it is a gap: data
//! are missing there (dropped packets, a paused stream), and the report says so.

use serde::{Deserialize, Serialize};

/// An interval longer than this many median intervals is a gap. Three: one or
/// two dropped samples (an interval of 2 or 3) already count in jittery
/// streams' normal spread, more is missing data.
pub const GAP_FACTOR: f64 = 3.0;

/// Intervals that differ from the median by more than this fraction make the
/// stream irregular (printing times with 3 decimals at 100 Hz stays within it).
pub const IRREGULAR_FRACTION: f64 = 0.01;

/// Largest magnitude of a sample time, seconds (about 317 years): absolute
/// clocks in seconds since 1970 fit, nanosecond counters do not (at 1e18 an
/// f64 cannot tell neighbouring samples apart).
pub const MAX_ABS_TIME_S: f64 = 1e10;

/// Longest trial span (last time minus first), seconds: 115 days.
pub const MAX_SPAN_S: f64 = 1e7;

/// Shortest median sample interval, seconds (a 100 kHz stream).
pub const MIN_MEDIAN_DT_S: f64 = 1e-5;

/// Longest median sample interval, seconds (one sample an hour).
pub const MAX_MEDIAN_DT_S: f64 = 3600.0;

/// Why a time axis cannot be a trial's, if it cannot: every time finite and
/// within [`MAX_ABS_TIME_S`], strictly increasing, a span of at most
/// [`MAX_SPAN_S`] and a median interval in
/// [[`MIN_MEDIAN_DT_S`], [`MAX_MEDIAN_DT_S`]]. Returns the index of the
/// offending sample (0 for the axis as a whole) and what was expected.
pub fn check_time_axis(time_s: &[f64]) -> Result<(), (usize, String)> {
    let Some(&t0) = time_s.first() else {
        return Ok(());
    };
    for (i, &t) in time_s.iter().enumerate() {
        if !(t.is_finite() && t.abs() <= MAX_ABS_TIME_S) {
            return Err((
                i,
                format!("expected a time within +-{MAX_ABS_TIME_S:e} s, found {t}"),
            ));
        }
        if i > 0 && t <= time_s[i - 1] {
            return Err((
                i,
                format!(
                    "time {t} does not follow the previous time {}; expected times to strictly increase",
                    time_s[i - 1]
                ),
            ));
        }
        if t - t0 > MAX_SPAN_S {
            return Err((
                i,
                format!(
                    "time {t} is {:e} s after the first sample ({t0}); expected a trial of at most {MAX_SPAN_S:e} s",
                    t - t0
                ),
            ));
        }
    }
    if time_s.len() >= 2 {
        let dt = super::median_dt(time_s);
        if !(MIN_MEDIAN_DT_S..=MAX_MEDIAN_DT_S).contains(&dt) {
            return Err((
                0,
                format!(
                    "median sample interval {dt:e} s (rate {:e} Hz): expected a rate between {:e} Hz and {:e} Hz",
                    1.0 / dt,
                    1.0 / MAX_MEDIAN_DT_S,
                    1.0 / MIN_MEDIAN_DT_S
                ),
            ));
        }
    }
    Ok(())
}

/// A stretch without samples.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Gap {
    /// Index of the first sample after the gap.
    pub index: usize,
    /// Time of the sample before the gap, seconds from the first sample.
    pub from_s: f64,
    /// Time of the sample after the gap, seconds from the first sample.
    pub to_s: f64,
}

impl Gap {
    /// Length of the gap, seconds (the interval between its two samples).
    pub fn length_s(&self) -> f64 {
        self.to_s - self.from_s
    }
}

/// How a trial's samples are spaced in time.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Timing {
    /// Median interval, seconds.
    pub median_dt_s: f64,
    /// Shortest and longest interval that is not a gap, seconds.
    pub min_dt_s: f64,
    pub max_dt_s: f64,
    /// True when intervals (gaps aside) differ from the median by more than
    /// [`IRREGULAR_FRACTION`].
    pub irregular: bool,
    pub gaps: Vec<Gap>,
    /// Trial length, seconds ([`trial_length_s`]).
    pub length_s: f64,
}

/// The trial length `T` windows are laid out on, seconds. The source's rule
/// is `n * dt` with dt the median interval, which is exact for a regular
/// stream; it is computed here as the span of the times times `n / (n - 1)`
/// (the same for a regular stream, up to rounding), which stays right for a
/// jittery stream, where n times a median of jittered intervals can be off by
/// seconds. With gaps (intervals over [`GAP_FACTOR`] dt) it is the span plus one
/// median interval: windows stay in seconds of the recording, not in samples.
pub fn trial_length_s(time_s: &[f64]) -> f64 {
    let n = time_s.len();
    if n < 2 {
        return 0.0;
    }
    let dt = super::median_dt(time_s);
    let span = time_s[n - 1] - time_s[0];
    let gappy = time_s.windows(2).any(|w| w[1] - w[0] > GAP_FACTOR * dt);
    if gappy {
        span + dt
    } else {
        span * n as f64 / (n - 1) as f64
    }
}

/// Gaps and spacing of `time_s` (strictly increasing, seconds).
pub fn timing(time_s: &[f64]) -> Timing {
    let dt = super::median_dt(time_s);
    let t0 = time_s.first().copied().unwrap_or(0.0);
    let mut gaps = Vec::new();
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for (i, w) in time_s.windows(2).enumerate() {
        let d = w[1] - w[0];
        if d > GAP_FACTOR * dt {
            gaps.push(Gap {
                index: i + 1,
                from_s: w[0] - t0,
                to_s: w[1] - t0,
            });
        } else {
            lo = lo.min(d);
            hi = hi.max(d);
        }
    }
    if !lo.is_finite() {
        lo = dt;
        hi = dt;
    }
    Timing {
        median_dt_s: dt,
        min_dt_s: lo,
        max_dt_s: hi,
        irregular: dt > 0.0 && (hi - dt).max(dt - lo) > IRREGULAR_FRACTION * dt,
        gaps,
        length_s: trial_length_s(time_s),
    }
}

impl Timing {
    /// One line per finding, for reports (empty for a regular stream without gaps).
    pub fn notes(&self) -> Vec<String> {
        let mut out = Vec::new();
        if self.irregular {
            out.push(format!(
                "irregular sample times: intervals {:.1}-{:.1} ms (median {:.1} ms); windows are laid out in seconds",
                self.min_dt_s * 1e3,
                self.max_dt_s * 1e3,
                self.median_dt_s * 1e3
            ));
        }
        if !self.gaps.is_empty() {
            let missing: f64 = self.gaps.iter().map(Gap::length_s).sum();
            let list: Vec<String> = self
                .gaps
                .iter()
                .take(4)
                .map(|g| format!("{:.2}-{:.2} s", g.from_s, g.to_s))
                .collect();
            let more = if self.gaps.len() > 4 { ", ..." } else { "" };
            out.push(format!(
                "{} gap{} without samples (longer than {GAP_FACTOR} intervals), {missing:.2} s in all: {}{more}",
                self.gaps.len(),
                if self.gaps.len() == 1 { "" } else { "s" },
                list.join(", ")
            ));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_jittery_and_gappy_streams() {
        let regular: Vec<f64> = (0..100).map(|i| i as f64 * 0.01).collect();
        let t = timing(&regular);
        assert!(!t.irregular && t.gaps.is_empty(), "{t:?}");
        assert!((t.length_s - 1.0).abs() < 1e-12);
        assert!(t.notes().is_empty());
        // Random jitter of up to +-2 ms: irregular, no gaps, length n * dt with
        // dt the median interval (within 1 ms of the nominal 10 ms).
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let jitter: Vec<f64> = (0..100)
            .map(|i| i as f64 * 0.01 + rng.random_range(-0.002..0.002))
            .collect();
        let t = timing(&jitter);
        assert!(t.irregular && t.gaps.is_empty(), "{t:?}");
        assert!((t.length_s - 1.0).abs() < 0.005, "{}", t.length_s);
        // 0.5 s missing after sample 49: one gap, length from the span.
        let gappy: Vec<f64> = regular
            .iter()
            .map(|&x| if x >= 0.495 { x + 0.5 } else { x })
            .collect();
        let t = timing(&gappy);
        assert_eq!(t.gaps.len(), 1);
        assert_eq!(t.gaps[0].index, 50);
        assert!((t.gaps[0].length_s() - 0.51).abs() < 1e-9);
        assert!(!t.irregular);
        assert!((t.length_s - 1.5).abs() < 1e-9, "{}", t.length_s);
        assert!(
            t.notes()[0].contains("1 gap without samples"),
            "{:?}",
            t.notes()
        );
    }
}
