//! The y axes of the workbench's charts: round tick values (1, 2 or 5 times
//! a power of ten) with their unit, written at the rows of their values.
//! Ratatui spreads its own labels evenly whatever their values; the charts
//! reserve the label column with blank labels and write these over it.

use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::Style;

/// Round tick values inside `[lo, hi]`: multiples of a step of 1, 2 or 5
/// times a power of ten, at most `max` of them (at least one step is tried
/// until few enough fit; none when the bounds are not finite).
pub fn ticks(lo: f64, hi: f64, max: usize) -> (f64, Vec<f64>) {
    let max = max.max(1);
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo {
        return (1.0, vec![]);
    }
    let mut decade = 10f64.powf(((hi - lo) / max as f64).log10().floor());
    loop {
        for m in [1.0, 2.0, 5.0] {
            let step = decade * m;
            let (first, last) = ((lo / step).ceil() as i64, (hi / step).floor() as i64);
            if last < first || ((last - first + 1) as usize) <= max {
                // `+ 0.0` turns -0 into 0.
                let vals = (first..=last).map(|k| k as f64 * step + 0.0).collect();
                return (step, vals);
            }
        }
        decade *= 10.0;
    }
}

/// A tick label: the value with as many decimals as the step needs, and
/// `unit` (`°` for degrees; ASCII charts name the unit in the title instead).
pub fn tick_label(v: f64, step: f64, unit: &str) -> String {
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    format!("{v:.decimals$}{unit}")
}

/// The row of `v` in a plot `height` rows tall over `[lo, hi]`, from the top
/// (as the chart's one-per-cell markers place it).
pub fn row_of(v: f64, lo: f64, hi: f64, height: u16) -> u16 {
    let h = f64::from(height.saturating_sub(1));
    ((hi - v) * h / (hi - lo)).round().clamp(0.0, h) as u16
}

/// Round ticks of `[lo, hi]` for a plot `plot_h` rows tall (at most one every
/// other row, and five), labelled with `unit`: `(value, label)`.
pub fn y_labels(lo: f64, hi: f64, plot_h: u16, unit: &str) -> Vec<(f64, String)> {
    let (step, vals) = ticks(lo, hi, usize::from(plot_h).div_ceil(2).clamp(1, 5));
    vals.into_iter()
        .map(|v| (v, tick_label(v, step, unit)))
        .collect()
}

/// The widest label's width, in characters.
pub fn width(labels: &[(f64, String)]) -> u16 {
    labels
        .iter()
        .map(|(_, s)| s.chars().count())
        .max()
        .unwrap_or(1) as u16
}

/// Two blank labels `w` wide: the chart keeps a label column that wide.
pub fn blank(w: u16) -> Vec<String> {
    vec![" ".repeat(w as usize); 2]
}

/// Writes `labels` right-aligned in the `w` columns from `x`, each at the row
/// of its value in a plot of rows `plot` (top row and height) over `[lo, hi]`;
/// a label wider than the column loses its left end.
pub fn draw_labels(
    buf: &mut Buffer,
    x: u16,
    plot: (u16, u16),
    w: u16,
    (lo, hi): (f64, f64),
    labels: &[(f64, String)],
    style: Style,
) {
    let (top, h) = plot;
    let area = buf.area;
    for (v, label) in labels {
        let y = top + row_of(*v, lo, hi, h);
        if y >= area.bottom() || x >= area.right() {
            continue;
        }
        let w = w as usize;
        let n = label.chars().count();
        let text: String = if n > w {
            label.chars().skip(n - w).collect()
        } else {
            format!("{label:>w$}")
        };
        buf.set_string(x, y, text, style);
    }
}

/// The rows of a chart's plot in `area`: below a one-row title, above the
/// x axis's labels and line when it has labels.
pub fn plot_rows(area: Rect, x_labels: bool) -> (u16, u16) {
    let below = if x_labels { 2 } else { 0 };
    (area.y + 1, area.height.saturating_sub(1 + below))
}
