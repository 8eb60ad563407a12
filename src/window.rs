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
    if !(total.is_finite() && win_s.is_finite() && win_s > 0.0) || total <= win_s + EPS {
        return whole_trial(time_s);
    }
    let hop_s = bounded_hop(total, win_s, hop_s);
    let count = window_count(total, win_s, hop_s);
    let span = |a: f64, b: f64| {
        let first = index_of(a);
        let end = if b >= total - EPS { n } else { index_of(b) };
        (first, end)
    };
    let enough = |(f, e): (usize, usize)| (e - f) as f64 * dt >= MIN_DATA_FRACTION * win_s;
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
                let [a, b] = borrow(start, win_s, hop_s, total, |a, b| enough(span(a, b)));
                (w.first, w.end) = span(a, b);
                w.borrowed_s = Some([a, b]);
            }
            w
        })
        .collect()
}

/// Most windows a trial is laid out in; a hop that would make more is widened.
pub const MAX_WINDOWS: usize = 100_000;

/// A window shorter than this many median sample intervals holds too few
/// samples to estimate a correction from.
pub const MIN_WINDOW_SAMPLES: f64 = 4.0;

/// Number of windows of length `win_s` and hop `hop_s` on a trial of `total` s.
fn window_count(total: f64, win_s: f64, hop_s: f64) -> usize {
    ((total - win_s) / hop_s - EPS).ceil().max(0.0) as usize + 1
}

/// `hop_s`, or the shortest hop that keeps the layout within [`MAX_WINDOWS`]
/// when it is not a positive number or would exceed them (callers check
/// settings with [`check_layout`] first; this only keeps the layout bounded).
fn bounded_hop(total: f64, win_s: f64, hop_s: f64) -> f64 {
    let hop = if hop_s.is_finite() && hop_s > 0.0 {
        hop_s
    } else {
        win_s
    };
    if window_count(total, win_s, hop) <= MAX_WINDOWS {
        hop
    } else {
        (total - win_s) / (MAX_WINDOWS - 1) as f64 * (1.0 + 1e-9)
    }
}

/// Why drift windows do not suit a trial ([`check_layout`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LayoutError {
    /// A window spans fewer than [`MIN_WINDOW_SAMPLES`] median intervals.
    #[error("window_s = {window_s} s holds fewer than {min} samples at this trial's median interval of {dt_s} s; expected a longer window", min = MIN_WINDOW_SAMPLES)]
    ShortWindow {
        /// Window length, seconds.
        window_s: f64,
        /// The trial's median sample interval, seconds.
        dt_s: f64,
    },
    /// The trial would need more than [`MAX_WINDOWS`] windows.
    #[error("window_s = {window_s} s and hop_s = {hop_s} s lay this {length_s:.1}-s trial out in {count:e} windows; expected at most {max} (a longer hop)", max = MAX_WINDOWS)]
    TooManyWindows {
        /// Window length and hop, seconds.
        window_s: f64,
        hop_s: f64,
        /// The trial's length, seconds.
        length_s: f64,
        /// Windows the layout would need.
        count: f64,
    },
}

/// Why windows of `win_s` and hop `hop_s` seconds do not suit the trial with
/// these sample times, if they do not: a window must hold at least
/// [`MIN_WINDOW_SAMPLES`] median intervals, and the trial must need no more
/// than [`MAX_WINDOWS`] windows.
pub fn check_layout(time_s: &[f64], win_s: f64, hop_s: f64) -> Result<(), LayoutError> {
    let total = trial_length_s(time_s);
    if time_s.len() < 2 || total <= win_s + EPS {
        return Ok(());
    }
    let dt = median_dt(time_s);
    if win_s < MIN_WINDOW_SAMPLES * dt {
        return Err(LayoutError::ShortWindow {
            window_s: win_s,
            dt_s: dt,
        });
    }
    let count = ((total - win_s) / hop_s).ceil() + 1.0;
    if !(hop_s > 0.0 && count <= MAX_WINDOWS as f64) {
        return Err(LayoutError::TooManyWindows {
            window_s: win_s,
            hop_s,
            length_s: total,
            count,
        });
    }
    Ok(())
}

/// The span `[a, b)` a thin window `[start, start + win)` is solved on: widened
/// by one hop each side (clamped to the trial) until `enough(a, b)` or the span
/// is the whole trial. The first steps are taken one by one; past them the
/// number of hops is found by bisection (data only grow as the span widens),
/// so a window in a long gap costs a logarithmic number of looks, not one per hop.
fn borrow(
    start: f64,
    win_s: f64,
    hop_s: f64,
    total: f64,
    enough: impl Fn(f64, f64) -> bool,
) -> [f64; 2] {
    const STEPS: usize = 16;
    let whole = |a: f64, b: f64| a <= 0.0 && b >= total - EPS;
    let (mut a, mut b) = (start, start + win_s);
    for _ in 0..STEPS {
        a = (a - hop_s).max(0.0);
        b = (b + hop_s).min(total);
        if enough(a, b) || whole(a, b) {
            return [a, b];
        }
    }
    // After `m` more hops each side: the span from `STEPS` hops on, widened.
    let (a0, b0) = (a, b);
    let at = |m: f64| [(a0 - m * hop_s).max(0.0), (b0 + m * hop_s).min(total)];
    let mut hi = (a0.max(total - b0) / hop_s).ceil() + 1.0;
    let mut lo = 0.0;
    // `lo` hops are too few; `hi` are enough (or reach the whole trial).
    while hi - lo > 1.0 {
        let mid = ((lo + hi) / 2.0).floor();
        let [x, y] = at(mid);
        if enough(x, y) || whole(x, y) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    at(hi)
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
    fn long_gaps_and_tiny_hops_stay_bounded() {
        // 4 s of data, a pause of 1e6 s, 4 s more: 33 333 windows, each in the
        // gap borrowing until it reaches data, found by bisection.
        let mut t = times(4.0, 100.0);
        t.extend(times(4.0, 100.0).iter().map(|x| x + 1e6));
        let w = layout(&t, 60.0, 30.0);
        assert_eq!(w.len(), 33_333);
        let mid = &w[w.len() / 2];
        // 8 s of data in all, less than half a window: the span grows to the whole trial.
        assert_eq!((mid.first, mid.end), (0, t.len()));
        assert_eq!(w[0].borrowed_s.unwrap()[0], 0.0);
        // Settings that would need billions of windows are refused by the check
        // and bounded by the layout itself.
        let t = times(100.0, 100.0);
        let e = check_layout(&t, 1e-6, 1e-6).unwrap_err();
        assert!(matches!(e, LayoutError::ShortWindow { .. }), "{e}");
        assert!(e.to_string().contains("fewer than 4 samples"), "{e}");
        let e = check_layout(&t, 1.0, 1e-6).unwrap_err();
        assert!(matches!(e, LayoutError::TooManyWindows { .. }), "{e}");
        assert!(
            e.to_string().contains("windows; expected at most 100000"),
            "{e}"
        );
        assert!(check_layout(&t, 60.0, 30.0).is_ok());
        assert!(layout(&t, 1.0, 1e-6).len() <= MAX_WINDOWS);
        assert!(layout(&t, 1.0, 0.0).len() <= MAX_WINDOWS);
        assert_eq!(layout(&t, f64::NAN, 1.0).len(), 1);
    }

    #[test]
    fn bisection_finds_the_span_stepping_would() {
        // A window deep in a gap needs many hops: stepping one hop at a time
        // and bisecting agree on the span.
        let mut t = times(40.0, 50.0);
        t.extend(times(40.0, 50.0).iter().map(|x| x + 3000.0));
        let w = layout(&t, 60.0, 10.0);
        let dt = median_dt(&t);
        for win in w.iter().filter(|w| w.borrowed_s.is_some()) {
            let (mut a, mut b) = (win.start_s, win.end_s);
            let total = trial_length_s(&t);
            let at = |s: f64| t.partition_point(|&x| x - t[0] < s - EPS);
            loop {
                a = (a - 10.0).max(0.0);
                b = (b + 10.0).min(total);
                let e = if b >= total - EPS { t.len() } else { at(b) };
                if (e - at(a)) as f64 * dt >= 30.0 || (a <= 0.0 && b >= total - EPS) {
                    break;
                }
            }
            let [x, y] = win.borrowed_s.unwrap();
            assert!(
                (x - a).abs() < 1e-6 && (y - b).abs() < 1e-6,
                "{win:?} vs {a} {b}"
            );
        }
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
