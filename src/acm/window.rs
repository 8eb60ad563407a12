//! Drift windows and the time-dependent correction between them (METHOD.md section 4).
//!
//! Times are seconds. Window bounds are relative to the first sample; sample
//! indices are into the trial's time vector.

use crate::rotation::{slerp, Quat};
use crate::trial::median_dt;

/// Tolerance (seconds) for comparing window bounds with sample times.
const EPS: f64 = 1e-9;

/// One window: `[start_s, end_s)` relative to the first sample, and its samples.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    /// Start, seconds from the first sample.
    pub start_s: f64,
    /// End (exclusive), seconds from the first sample.
    pub end_s: f64,
    /// Centre, seconds from the first sample (`start + win / 2`).
    pub centre_s: f64,
    /// Index of the first sample inside.
    pub first: usize,
    /// One past the index of the last sample inside.
    pub end: usize,
}

impl Window {
    /// Number of samples inside.
    pub fn len(&self) -> usize {
        self.end - self.first
    }

    /// True when no sample falls inside.
    pub fn is_empty(&self) -> bool {
        self.end == self.first
    }
}

/// Lays out the windows of a trial: length `win_s`, hop `hop_s` (seconds).
///
/// `T = n * dt` with dt the median interval; window k starts at
/// `min(k * hop, T - win)` for `k = 0 ..= ceil((T - win) / hop)`; a trial no longer
/// than one window gets one window covering all of it.
pub fn layout(time_s: &[f64], win_s: f64, hop_s: f64) -> Vec<Window> {
    let n = time_s.len();
    if n == 0 {
        return Vec::new();
    }
    let t0 = time_s[0];
    let total = n as f64 * median_dt(time_s);
    let index_of = |s: f64| time_s.partition_point(|&t| t - t0 < s - EPS);
    if total <= win_s + EPS {
        return vec![Window {
            start_s: 0.0,
            end_s: total,
            centre_s: total / 2.0,
            first: 0,
            end: n,
        }];
    }
    let count = ((total - win_s) / hop_s - EPS).ceil() as usize + 1;
    (0..count)
        .map(|k| {
            let start = (k as f64 * hop_s).min(total - win_s);
            let last = k + 1 == count;
            Window {
                start_s: start,
                end_s: start + win_s,
                centre_s: start + win_s / 2.0,
                first: index_of(start),
                end: if last { n } else { index_of(start + win_s) },
            }
        })
        .collect()
}

/// The single window of the whole trial (the `basic` variant).
pub fn whole_trial(time_s: &[f64]) -> Vec<Window> {
    let n = time_s.len();
    let total = n as f64 * median_dt(time_s);
    vec![Window {
        start_s: 0.0,
        end_s: total,
        centre_s: total / 2.0,
        first: 0,
        end: n,
    }]
}

/// The correction at each sample (eq. 3.14-3.15): `q_1` before the first centre,
/// `q_N` from the last centre on, shorter-arc slerp between neighbouring centres.
///
/// `centres_s` are relative to the first sample, like the windows.
pub fn correction_series(time_s: &[f64], centres_s: &[f64], qs: &[Quat]) -> Vec<Quat> {
    between_centres(time_s, centres_s, qs, slerp)
}

/// Per-sample values from one value per window centre: the first before the
/// first centre, the last from the last centre on, `mix(v_k, v_k+1, f)` between
/// neighbouring centres with `f` the fraction of time elapsed (0..1).
///
/// `centres_s` are seconds from the first sample, like the windows.
pub fn between_centres<T: Copy>(
    time_s: &[f64],
    centres_s: &[f64],
    values: &[T],
    mix: impl Fn(&T, &T, f64) -> T,
) -> Vec<T> {
    assert_eq!(centres_s.len(), values.len());
    let Some(&t0) = time_s.first() else {
        return Vec::new();
    };
    let mut k = 0;
    time_s
        .iter()
        .map(|&t| {
            let rel = t - t0;
            if rel < centres_s[0] {
                return values[0];
            }
            while k + 1 < centres_s.len() && rel >= centres_s[k + 1] {
                k += 1;
            }
            if k + 1 == centres_s.len() {
                return values[k];
            }
            let f = (rel - centres_s[k]) / (centres_s[k + 1] - centres_s[k]);
            mix(&values[k], &values[k + 1], f)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{angle_between_deg, angle_deg, quat_axis_angle_deg};

    fn times(seconds: f64, rate: f64) -> Vec<f64> {
        (0..(seconds * rate).round() as usize)
            .map(|i| i as f64 / rate)
            .collect()
    }

    fn starts(seconds: f64) -> Vec<f64> {
        layout(&times(seconds, 50.0), 60.0, 30.0)
            .iter()
            .map(|w| (w.start_s * 1e6).round() / 1e6)
            .collect()
    }

    #[test]
    fn layouts_for_method_lengths() {
        assert_eq!(starts(30.0), [0.0]);
        assert_eq!(starts(60.0), [0.0]);
        assert_eq!(starts(61.0), [0.0, 1.0]);
        assert_eq!(starts(300.0).len(), 9);
        assert_eq!(starts(300.0).last(), Some(&240.0));
        let s301 = starts(301.0);
        assert_eq!(s301.len(), 10);
        assert_eq!(&s301[8..], [240.0, 241.0]);
        assert_eq!(starts(1800.0).len(), 59);
    }

    #[test]
    fn windows_are_half_open_and_cover_the_trial() {
        let t = times(301.0, 50.0);
        let w = layout(&t, 60.0, 30.0);
        assert_eq!((w[0].first, w[0].end), (0, 3000));
        assert_eq!((w[1].first, w[1].end), (1500, 4500));
        assert_eq!(w.last().unwrap().end, t.len());
        assert_eq!(w.last().unwrap().len(), 3000);
        let short = layout(&times(30.0, 50.0), 60.0, 30.0);
        assert_eq!((short[0].first, short[0].end), (0, 1500));
        assert!((short[0].centre_s - 15.0).abs() < 1e-9);
        assert_eq!(whole_trial(&t)[0].len(), t.len());
    }

    #[test]
    fn series_holds_ends_and_slerps_between_centres() {
        let t = times(120.0, 10.0);
        let qa = quat_axis_angle_deg([0.0, 0.0, 1.0], 10.0);
        let qb = quat_axis_angle_deg([0.0, 0.0, 1.0], 30.0);
        let s = correction_series(&t, &[30.0, 90.0], &[qa, qb]);
        assert!(angle_between_deg(&s[0], &qa) < 1e-12);
        assert!(angle_between_deg(&s[299], &qa) < 1e-9);
        assert!((angle_deg(&s[600]) - 20.0).abs() < 1e-9);
        assert!(angle_between_deg(&s[900], &qb) < 1e-12);
        assert!(angle_between_deg(&s[1199], &qb) < 1e-12);
    }
}
