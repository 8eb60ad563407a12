//! Small text and layout helpers the screens share: fixed-width cells, the
//! selected-row style, a centred popup rectangle.

use super::theme::Theme;
use ratatui::layout::Rect;
use ratatui::style::Style;

/// A centred rectangle of at most `w` x `h` inside `area`.
pub fn centred(area: Rect, w: u16, h: u16) -> Rect {
    let w = w.min(area.width);
    let h = h.min(area.height);
    Rect {
        x: area.x + (area.width - w) / 2,
        y: area.y + (area.height - h) / 2,
        width: w,
        height: h,
    }
}

/// `value` with one decimal, or `-`.
pub fn num(v: Option<f64>, width: usize) -> String {
    match v {
        Some(v) if v.is_finite() => format!("{v:>width$.1}"),
        _ => format!("{:>width$}", "-"),
    }
}

/// Cuts `s` to `w` characters (with `~` when cut).
pub fn fit(s: &str, w: usize) -> String {
    let n = s.chars().count();
    if n <= w {
        format!("{s:<w$}")
    } else if w == 0 {
        String::new()
    } else {
        let mut t: String = s.chars().take(w - 1).collect();
        t.push('~');
        t
    }
}

/// A style for selected rows.
pub fn sel(theme: &Theme, selected: bool) -> Style {
    if selected {
        theme.selected
    } else {
        Style::default()
    }
}
