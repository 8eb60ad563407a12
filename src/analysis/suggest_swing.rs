//! Swing-twist limit tables ([`crate::limits::swing_twist`]) suggested from
//! clean trials, as [`super::suggest`] does for Euler tables: per row of a
//! swing-twist table (the current one, or the shipped `swing_twist.csv` when
//! the current table is an Euler one), the interval holding 90% of the
//! samples around the mean of each swing component and of the twist, pooled
//! over the joints that read the row, rounded outwards. The swing region is
//! centred on the middle of the two swing intervals with their half widths as
//! half-angles (the row's shape kept; a corner radius no larger than the new
//! smaller half-angle); the twist range is the twist interval, at the centre
//! and on the edge alike. Rows without samples keep their limits; movement,
//! centroid and lambda2 are kept. Degrees throughout.

use super::histogram::interval_around_mean;
use super::suggest::{limits_of, SuggestOptions};
use super::{TimeSpan, TrialRef};
use crate::limits::swing_twist::{SwingTwistLimits, SwingTwistRow};
use crate::limits::{LimitTable, BUILTIN_TABLES};
use crate::rotation::wxyz;

/// What happens to one row.
#[derive(Debug, Clone, PartialEq)]
pub struct SwingRowSuggestion {
    /// The row's `joint` column.
    pub joint: String,
    /// The row's limits now and as suggested (the same without samples).
    pub current: SwingTwistLimits,
    pub suggested: SwingTwistLimits,
    /// Samples behind the suggestion.
    pub samples: usize,
}

/// A suggested swing-twist table and the account of each row.
#[derive(Debug, Clone, PartialEq)]
pub struct SwingSuggestion {
    pub table: LimitTable,
    pub rows: Vec<SwingRowSuggestion>,
}

/// The swing-twist table suggestions start from: `current` when it is one,
/// else the shipped `swing_twist.csv`.
pub fn template(current: &LimitTable) -> LimitTable {
    if current.swing_twist.is_some() {
        return current.clone();
    }
    let (name, text) = BUILTIN_TABLES
        .iter()
        .find(|(n, _)| *n == "swing_twist.csv")
        .expect("the swing-twist table is built in");
    LimitTable::parse(text, name).expect("built-in table is valid")
}

/// The swing-twist coordinates `[swing_1, swing_2, twist]` (degrees, the
/// table's convention) of every sample of `span` of the joints whose row in
/// `table` is `key`, over `trials`.
fn pooled_coordinates(
    trials: &[TrialRef],
    span: TimeSpan,
    table: &LimitTable,
    key: &str,
) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for t in trials {
        let range = span.indices(&t.trial.time_s);
        for j in &t.model.joints {
            if super::row_key(table, &j.name, &j.kind) != key {
                continue;
            }
            let Some(lim) = table.joint_limits(&j.name, &j.kind, false) else {
                continue;
            };
            let Some(st) = lim.swing_twist else {
                continue;
            };
            let (Some(p), Some(d)) = (t.trial.imu(&j.proximal), t.trial.imu(&j.distal)) else {
                continue;
            };
            let (p, d) = (&p.orientation, &d.orientation);
            let axes = j.table_axes();
            let det = axes.map_or(1.0, |a| a.det);
            let end = range.end.min(p.len()).min(d.len());
            for i in range.start.min(end)..end {
                let r = p[i].inverse() * d[i];
                let r = axes.map_or(r, |a| a.to_table(&r));
                let c = st.decompose(wxyz(&r));
                out.push([
                    det * c.swing_deg[0],
                    det * c.swing_deg[1],
                    det * c.twist_deg,
                ]);
            }
        }
    }
    out
}

/// Suggests swing-twist limits for every row of [`template`]`(current)` from
/// the samples of `span` of `trials`.
pub fn suggest_swing_twist(
    current: &LimitTable,
    trials: &[TrialRef],
    span: TimeSpan,
    opts: SuggestOptions,
) -> SwingSuggestion {
    let base = template(current);
    let mut rows_out = Vec::new();
    let mut st_rows: Vec<SwingTwistRow> = base.swing_twist.clone().unwrap_or_default();
    for row in &mut st_rows {
        let coords = pooled_coordinates(trials, span, &base, &row.joint);
        let cur = row.limits;
        let mut new = cur;
        if !coords.is_empty() {
            let interval = |k: usize| {
                let mut v: Vec<f64> = coords.iter().map(|c| c[k]).collect();
                let mean = v.iter().sum::<f64>() / v.len() as f64;
                limits_of(interval_around_mean(&mut v, mean, 0.9), opts)
            };
            let (s1, s2, tw) = (interval(0), interval(1), interval(2));
            new.centre_deg = [0.5 * (s1[0] + s1[1]), 0.5 * (s2[0] + s2[1])];
            new.half_deg = [0.5 * (s1[1] - s1[0]), 0.5 * (s2[1] - s2[0])];
            new.corner_deg = cur
                .corner_deg
                .map(|r| r.min(new.half_deg[0].min(new.half_deg[1])));
            new.twist_deg = tw;
            new.edge_twist_deg = tw;
        }
        row.limits = new;
        rows_out.push(SwingRowSuggestion {
            joint: row.joint.clone(),
            current: cur,
            suggested: new,
            samples: coords.len(),
        });
    }
    let trials_n = trials.len();
    let mut preamble = base.preamble.clone();
    preamble.push(format!(
        "# Swing-twist limits suggested by acmw from {trials_n} trial(s), {}: per swing component and the twist, the interval holding 90% of the samples around the mean, rounded outwards.",
        span.label()
    ));
    let table = LimitTable {
        preamble,
        rows: st_rows.iter().flat_map(|r| r.euler_rows()).collect(),
        swing_twist: Some(st_rows),
    };
    SwingSuggestion {
        table,
        rows: rows_out,
    }
}

impl SwingSuggestion {
    /// The diff as text lines: a header, then one line per row (`old -> new`
    /// where it changed, and the samples behind it).
    pub fn diff_lines(&self) -> Vec<String> {
        let mut out = vec![format!(
            "{:<10} {:<26} {:<26} {:<22} {:>8}",
            "joint", "swing centre deg", "swing half deg", "twist deg", "samples"
        )];
        let pair = |a: [f64; 2]| format!("{} {}", a[0], a[1]);
        let arrow = |a: [f64; 2], b: [f64; 2]| {
            if a == b {
                pair(a)
            } else {
                format!("{} -> {}", pair(a), pair(b))
            }
        };
        for r in &self.rows {
            out.push(format!(
                "{:<10} {:<26} {:<26} {:<22} {:>8}",
                r.joint,
                arrow(r.current.centre_deg, r.suggested.centre_deg),
                arrow(r.current.half_deg, r.suggested.half_deg),
                arrow(r.current.twist_deg, r.suggested.twist_deg),
                r.samples
            ));
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::Model;
    use crate::simulate::{simulate, SimConfig};

    /// On a clean simulated full-body trial, each suggested region holds the
    /// trial's own samples (90% of each coordinate within its interval), and
    /// the table reads back as swing-twist.
    #[test]
    fn suggested_regions_hold_the_samples() {
        let model = Model::infant13();
        let mut cfg = SimConfig::full_body(1);
        cfg.duration_s = 40.0;
        let sim = simulate(&cfg).unwrap();
        let trials = [sim.truth.segments.clone()];
        let refs = super::super::trial_refs(&trials, &model);
        let s = suggest_swing_twist(
            &LimitTable::default_table(),
            &refs,
            TimeSpan::WHOLE,
            SuggestOptions::default(),
        );
        let back = LimitTable::parse(&s.table.to_csv(), "s.csv").unwrap();
        assert_eq!(back.model_name(), "swing-twist");
        assert_eq!(back.swing_twist, s.table.swing_twist);
        let mut with_samples = 0;
        for r in &s.rows {
            if r.samples == 0 {
                assert_eq!(r.current, r.suggested);
                continue;
            }
            with_samples += 1;
            let coords = pooled_coordinates(&refs, TimeSpan::WHOLE, &template(&back), &r.joint);
            let l = r.suggested;
            let inside = |k: usize, lo: f64, hi: f64| {
                coords.iter().filter(|c| c[k] >= lo && c[k] <= hi).count() as f64
                    / coords.len() as f64
            };
            for k in 0..2 {
                let (lo, hi) = (
                    l.centre_deg[k] - l.half_deg[k],
                    l.centre_deg[k] + l.half_deg[k],
                );
                assert!(inside(k, lo, hi) >= 0.9, "{} swing {k}", r.joint);
            }
            assert!(
                inside(2, l.twist_deg[0], l.twist_deg[1]) >= 0.9,
                "{} twist",
                r.joint
            );
        }
        assert!(with_samples >= 5, "{with_samples}");
    }
}
