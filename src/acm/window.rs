//! Drift windows and the time-dependent correction between them (docs/method.md section 7).
//!
//! Times are seconds. Window bounds are relative to the first sample; sample
//! indices are into the trial's time vector.

use crate::rotation::{slerp, Quat};
use crate::trial::median_dt;
use crate::trial::timing::trial_length_s;

/// Tolerance (seconds) for comparing window bounds with sample times.
const EPS: f64 = 1e-9;

/// A window whose samples cover less than this fraction of its length (samples
/// times the median interval) is solved on a wider span that borrows its
/// neighbours' samples, widened by one hop each side until it has enough.
pub const MIN_DATA_FRACTION: f64 = 0.5;

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
    /// Seconds of data in the window's own span: its samples times the median interval.
    pub data_s: f64,
    /// When the window's own span held too little data ([`MIN_DATA_FRACTION`]):
    /// the span `[from, to)` it is solved on instead, seconds from the first
    /// sample; `first..end` then index that span. The centre stays the window's.
    pub borrowed_s: Option<[f64; 2]>,
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
/// `T` is [`trial_length_s`] (`n * dt` with dt the median interval, or with
/// gaps the span of the times plus one interval); window k starts at
/// `min(k * hop, T - win)` for `k = 0 ..= ceil((T - win) / hop)`; a trial no longer
/// than one window gets one window covering all of it. Windows are in seconds:
/// an irregular stream gets the windows of a regular one of the same length. A
/// window left with too little data by gaps borrows its neighbours' samples
/// ([`Window::borrowed_s`]).
pub fn layout(time_s: &[f64], win_s: f64, hop_s: f64) -> Vec<Window> {
    let n = time_s.len();
    if n == 0 {
        return Vec::new();
    }
    let t0 = time_s[0];
    let dt = median_dt(time_s);
    let total = trial_length_s(time_s);
    let index_of = |s: f64| time_s.partition_point(|&t| t - t0 < s - EPS);
    if total <= win_s + EPS {
        return whole_trial(time_s);
    }
    let count = ((total - win_s) / hop_s - EPS).ceil() as usize + 1;
    let span = |a: f64, b: f64| {
        let first = index_of(a);
        let end = if b >= total - EPS { n } else { index_of(b) };
        (first, end)
    };
    (0..count)
        .map(|k| {
            let start = (k as f64 * hop_s).min(total - win_s);
            let last = k + 1 == count;
            let first = index_of(start);
            let end = if last { n } else { index_of(start + win_s) };
            let data_s = (end - first) as f64 * dt;
            let mut w = Window {
                start_s: start,
                end_s: start + win_s,
                centre_s: start + win_s / 2.0,
                first,
                end,
                data_s,
                borrowed_s: None,
            };
            if data_s < MIN_DATA_FRACTION * win_s {
                let (mut a, mut b) = (start, start + win_s);
                loop {
                    a = (a - hop_s).max(0.0);
                    b = (b + hop_s).min(total);
                    let (f, e) = span(a, b);
                    (w.first, w.end) = (f, e);
                    let whole = a <= 0.0 && b >= total - EPS;
                    if (e - f) as f64 * dt >= MIN_DATA_FRACTION * win_s || whole {
                        break;
                    }
                }
                w.borrowed_s = Some([a, b]);
            }
            w
        })
        .collect()
}

/// The single window of the whole trial (the `basic` variant).
pub fn whole_trial(time_s: &[f64]) -> Vec<Window> {
    let n = time_s.len();
    let total = trial_length_s(time_s);
    vec![Window {
        start_s: 0.0,
        end_s: total,
        centre_s: total / 2.0,
        first: 0,
        end: n,
        data_s: n as f64 * median_dt(time_s),
        borrowed_s: None,
    }]
}

/// One line per window that borrowed its neighbours' samples, for reports.
pub fn borrow_notes(windows: &[Window]) -> Vec<String> {
    windows
        .iter()
        .filter_map(|w| {
            let [a, b] = w.borrowed_s?;
            Some(format!(
                "window {:.1}-{:.1} s has {:.1} s of data (gaps): solved on {a:.1}-{b:.1} s, borrowing its neighbours' samples",
                w.start_s, w.end_s, w.data_s
            ))
        })
        .collect()
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
    fn irregular_times_get_the_windows_of_regular_ones() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        // 301 s at 50 Hz, each time jittered by up to +-8 ms.
        let regular = times(301.0, 50.0);
        let jittered: Vec<f64> = regular
            .iter()
            .map(|t| t + rng.random_range(-0.008..0.008))
            .collect();
        let a = layout(&regular, 60.0, 30.0);
        let b = layout(&jittered, 60.0, 30.0);
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(&b) {
            // The length is n * median dt; the median moves by well under 0.1 ms.
            assert!((x.start_s - y.start_s).abs() < 0.1 && (x.centre_s - y.centre_s).abs() < 0.1);
            assert!(x.first.abs_diff(y.first) <= 1 && x.end.abs_diff(y.end) <= 1);
            assert!(y.borrowed_s.is_none());
        }
    }

    #[test]
    fn gaps_keep_windows_in_seconds_and_thin_windows_borrow() {
        // 300 s at 50 Hz with no samples from 70 s to 125 s.
        let t: Vec<f64> = times(300.0, 50.0)
            .into_iter()
            .filter(|&x| !(70.0..125.0).contains(&x))
            .collect();
        let w = layout(&t, 60.0, 30.0);
        // The length comes from the span: 300 s, 9 windows as without the gap.
        assert_eq!(w.len(), 9);
        assert!((w[8].start_s - 240.0).abs() < 1e-9);
        // Window 60-120 s holds 10 s of data: it borrows 30-150 s (65 s of data).
        assert!((w[2].data_s - 10.0).abs() < 1e-9, "{}", w[2].data_s);
        assert_eq!(w[2].borrowed_s, Some([30.0, 150.0]));
        let at = |s: f64| t.partition_point(|&x| x < s - 1e-9);
        assert_eq!((w[2].first, w[2].end), (at(30.0), at(150.0)));
        assert_eq!(w[2].len(), 65 * 50);
        assert!((w[2].centre_s - 90.0).abs() < 1e-9);
        // Window 90-150 s has 25 s: borrows 60-180 s (65 s of data).
        assert_eq!(w[3].borrowed_s, Some([60.0, 180.0]));
        // Window 30-90 s has 40 s of data (two thirds): solved on its own.
        assert!(w[1].borrowed_s.is_none());
        let notes = borrow_notes(&w);
        assert_eq!(notes.len(), 2, "{notes:?}");
        assert!(
            notes[0].starts_with("window 60.0-120.0 s has 10.0 s of data"),
            "{}",
            notes[0]
        );
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
