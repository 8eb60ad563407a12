//! Limit tables suggested from the 90% intervals of clean trials (thesis
//! 3.1.2: the source adjusted Table 3-1 into Table 3-2 this way), shown as a
//! diff against the current table and saved beside it, never over it.
//!
//! Each row of the current table takes the interval of the samples of every
//! joint that reads that row (`hip` pools `l_hip` and `r_hip`), rounded
//! outwards to whole degrees; rows without samples keep their limits. The
//! movement, centroid and lambda2 columns are kept. Degrees throughout.

use super::histogram::JointHistogram;
use super::TimeSpan;
use crate::limits::{axis_name, LimitTable};
use std::path::{Path, PathBuf};

/// How intervals become limits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SuggestOptions {
    /// Limits are rounded outwards to multiples of this, degrees (0 = exact).
    pub round_deg: f64,
    /// Narrowest range suggested, degrees: an axis that hardly moves (a hinge's
    /// ab/adduction) gets at least this, centred on its interval.
    pub min_width_deg: f64,
}

impl Default for SuggestOptions {
    fn default() -> Self {
        SuggestOptions {
            round_deg: 1.0,
            min_width_deg: 2.0,
        }
    }
}

/// What happens to one row of the table.
#[derive(Debug, Clone, PartialEq)]
pub struct RowSuggestion {
    /// The row's `joint` column (a joint kind or a single joint).
    pub joint: String,
    /// 0 = X, 1 = Y, 2 = Z.
    pub axis: usize,
    pub movement: String,
    /// `[lower, upper]` in the current table, degrees.
    pub current: [f64; 2],
    /// The 90% interval of the samples, degrees, when there are samples.
    pub interval: Option<[f64; 2]>,
    /// `[lower, upper]` suggested (the current limits without samples), degrees.
    pub suggested: [f64; 2],
    /// Samples and trials behind the interval.
    pub samples: usize,
    pub trials: usize,
}

impl RowSuggestion {
    /// Whether the suggestion differs from the current limits.
    pub fn changed(&self) -> bool {
        self.suggested != self.current
    }
}

/// A suggested table and the row by row account of it.
#[derive(Debug, Clone, PartialEq)]
pub struct Suggestion {
    pub table: LimitTable,
    /// One per row of the table, in its order.
    pub rows: Vec<RowSuggestion>,
}

/// Suggests limits for every row of `current` from histograms pooled by
/// table row (see [`super::pool_by_table_row`]); `span` and the number of
/// trials go into the new table's comment lines.
pub fn suggest_limits(
    current: &LimitTable,
    hists: &[JointHistogram],
    span: TimeSpan,
    opts: SuggestOptions,
) -> Suggestion {
    let mut table = current.clone();
    let mut rows = Vec::with_capacity(current.rows.len());
    for r in &mut table.rows {
        let h = hists
            .iter()
            .find(|h| h.name == r.joint)
            .and_then(|h| h.axes[r.axis].as_ref().map(|a| (a, h.trials)));
        let current = [r.lower_deg, r.upper_deg];
        let suggested = h.map_or(current, |(a, _)| limits_of(a.interval_deg, opts));
        r.lower_deg = suggested[0];
        r.upper_deg = suggested[1];
        rows.push(RowSuggestion {
            joint: r.joint.clone(),
            axis: r.axis,
            movement: r.movement.clone(),
            current,
            interval: h.map(|(a, _)| a.interval_deg),
            suggested,
            samples: h.map_or(0, |(a, _)| a.count),
            trials: h.map_or(0, |(_, t)| t),
        });
    }
    let trials = rows.iter().map(|r| r.trials).max().unwrap_or(0);
    table.preamble.push(format!(
        "# Limits suggested by acmw from {trials} trial(s), {}: the interval holding 90% of the samples around the mean (thesis 3.1.2), rounded outwards.",
        span.label()
    ));
    Suggestion { table, rows }
}

/// An interval rounded outwards, at least `min_width_deg` wide, within -180..180.
pub fn limits_of(interval: [f64; 2], opts: SuggestOptions) -> [f64; 2] {
    let [mut lo, mut hi] = interval;
    if hi - lo < opts.min_width_deg {
        let c = 0.5 * (lo + hi);
        lo = c - 0.5 * opts.min_width_deg;
        hi = c + 0.5 * opts.min_width_deg;
    }
    if opts.round_deg > 0.0 {
        lo = (lo / opts.round_deg).floor() * opts.round_deg;
        hi = (hi / opts.round_deg).ceil() * opts.round_deg;
    }
    // Never a degenerate or out-of-range row (the table format forbids them).
    let lo = lo.clamp(-180.0, 179.0);
    [lo, hi.clamp(lo + 1.0, 180.0)]
}

impl Suggestion {
    /// The diff against the current table as text lines: a header, one line
    /// per changed row (`old -> new` and the samples behind it), then the
    /// unchanged rows and the rows without samples by name.
    pub fn diff_lines(&self) -> Vec<String> {
        let mut out = vec![format!(
            "{:<12} {:<4} {:<16} {:<16} {:>8}",
            "joint", "axis", "lower deg", "upper deg", "samples"
        )];
        let arrow = |a: f64, b: f64| {
            if a == b {
                format!("{a:>6}")
            } else {
                format!("{a:>6} -> {b}")
            }
        };
        for r in self.rows.iter().filter(|r| r.changed()) {
            out.push(format!(
                "{:<12} {:<4} {:<16} {:<16} {:>8}",
                r.joint,
                axis_name(r.axis),
                arrow(r.current[0], r.suggested[0]),
                arrow(r.current[1], r.suggested[1]),
                r.samples
            ));
        }
        let names = |f: &dyn Fn(&RowSuggestion) -> bool| {
            self.rows
                .iter()
                .filter(|r| f(r))
                .map(|r| format!("{} {}", r.joint, axis_name(r.axis)))
                .collect::<Vec<_>>()
        };
        let same = names(&|r| !r.changed() && r.samples > 0);
        let none = names(&|r| r.samples == 0);
        let changed = self.rows.iter().filter(|r| r.changed()).count();
        out.push(format!(
            "{changed} of {} rows change; {} unchanged{}",
            self.rows.len(),
            same.len(),
            if same.is_empty() {
                String::new()
            } else {
                format!(" ({})", same.join(", "))
            }
        ));
        if !none.is_empty() {
            out.push(format!("no samples, limits kept: {}", none.join(", ")));
        }
        out
    }
}

/// Why a table could not be written.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    #[error(
        "{0}: this is the current table; a suggestion is never written over it (name another file)"
    )]
    Original(PathBuf),
    #[error("{path}: cannot write: {source}")]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// Writes `table` to `out` atomically (an existing file is kept as `.bak`),
/// refusing when `out` is the current table `original`.
pub fn write_table(
    table: &LimitTable,
    out: &Path,
    original: Option<&Path>,
) -> Result<(), WriteError> {
    if let Some(orig) = original {
        if same_file(out, orig) {
            return Err(WriteError::Original(out.to_path_buf()));
        }
    }
    crate::save::atomic_write(out, table.to_csv().as_bytes()).map_err(|source| WriteError::Io {
        path: out.to_path_buf(),
        source,
    })
}

/// Whether two paths name the same file (resolving links and `..`; a path
/// that does not exist yet is compared as written, beside its resolved folder).
pub fn same_file(a: &Path, b: &Path) -> bool {
    let resolve = |p: &Path| -> PathBuf {
        if let Ok(c) = p.canonicalize() {
            return c;
        }
        let dir = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        let dir = dir.canonicalize().unwrap_or(dir);
        dir.join(p.file_name().unwrap_or_default())
    };
    resolve(a) == resolve(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_round_outwards_and_keep_a_width() {
        let o = SuggestOptions::default();
        assert_eq!(limits_of([-24.3, 29.6], o), [-25.0, 30.0]);
        assert_eq!(limits_of([0.2, 0.3], o), [-1.0, 2.0]);
        assert_eq!(limits_of([-179.9, 179.9], o), [-180.0, 180.0]);
        let exact = SuggestOptions {
            round_deg: 0.0,
            min_width_deg: 0.0,
        };
        assert_eq!(limits_of([3.25, 7.5], exact), [3.25, 7.5]);
        assert_eq!(limits_of([5.0, 5.0], exact), [5.0, 6.0]);
    }

    #[test]
    fn refuses_to_write_over_the_original() {
        let dir = tempfile::tempdir().unwrap();
        let orig = dir.path().join("t.csv");
        let t = LimitTable::default_table();
        std::fs::write(&orig, t.to_csv()).unwrap();
        let via_dots = dir.path().join("sub/../t.csv");
        std::fs::create_dir(dir.path().join("sub")).unwrap();
        let e = write_table(&t, &via_dots, Some(&orig)).unwrap_err();
        assert!(matches!(e, WriteError::Original(_)), "{e}");
        let out = dir.path().join("new.csv");
        write_table(&t, &out, Some(&orig)).unwrap();
        write_table(&t, &out, Some(&orig)).unwrap();
        assert!(dir.path().join("new.csv.bak").exists());
        assert_eq!(LimitTable::load(&out).unwrap().rows, t.rows);
        let e = write_table(&t, &dir.path().join("no/such/dir.csv"), None).unwrap_err();
        assert!(e.to_string().contains("cannot write"), "{e}");
    }
}
