//! Small text and layout helpers the screens share: fixed-width cells, the
//! selected-row style, a centred popup rectangle.

use super::keymap::Action;
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

/// Fits a name to `w` characters keeping both its ends (`~` marks the
/// characters left out of its middle), so that names sharing a long start,
/// or a long end, still read apart: `2024-03-12_subject07_trial03.csv` in
/// 16 is `2024-03-~l03.csv`. Padded when short.
pub fn abbreviate(s: &str, w: usize) -> String {
    let n = s.chars().count();
    if n <= w {
        return format!("{s:<w$}");
    }
    if w < 5 {
        return fit(s, w);
    }
    let tail = (w - 1) / 2;
    let head = w - 1 - tail;
    let mut t: String = s.chars().take(head).collect();
    t.push('~');
    t.extend(s.chars().skip(n - tail));
    t
}

/// A style for selected rows.
pub fn sel(theme: &Theme, selected: bool) -> Style {
    if selected {
        theme.selected
    } else {
        Style::default()
    }
}

/// Where a list's selection goes on `a`: Up/Down one row, PgUp/PgDn
/// `page` rows, Home/End the first and last; None for other actions (and on
/// an empty list).
pub fn list_move(a: Action, at: usize, n: usize, page: usize) -> Option<usize> {
    let last = n.checked_sub(1)?;
    let page = page.max(1);
    Some(match a {
        Action::Up => at.saturating_sub(1),
        Action::Down => (at + 1).min(last),
        Action::PageUp => at.saturating_sub(page),
        Action::PageDown => (at + page).min(last),
        Action::Home => 0,
        Action::End => last,
        _ => return None,
    })
}

/// A list's position counter: `73/100` (the selection counted from 1).
pub fn counter(at: usize, n: usize) -> String {
    if n == 0 {
        "0/0".into()
    } else {
        format!("{}/{n}", at.min(n - 1) + 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_move_by_row_page_and_end() {
        assert_eq!(list_move(Action::Down, 98, 100, 10), Some(99));
        assert_eq!(list_move(Action::Down, 99, 100, 10), Some(99));
        assert_eq!(list_move(Action::PageDown, 95, 100, 10), Some(99));
        assert_eq!(list_move(Action::PageUp, 5, 100, 10), Some(0));
        assert_eq!(list_move(Action::End, 0, 100, 10), Some(99));
        assert_eq!(list_move(Action::Home, 50, 100, 10), Some(0));
        assert_eq!(list_move(Action::Enter, 50, 100, 10), None);
        assert_eq!(list_move(Action::Down, 0, 0, 10), None);
        assert_eq!(counter(72, 100), "73/100");
        assert_eq!(counter(0, 0), "0/0");
    }

    #[test]
    fn long_names_keep_both_ends() {
        let a = abbreviate("2024-03-12_subject07_trial03.csv", 16);
        let b = abbreviate("2024-03-12_subject07_trial04.csv", 16);
        assert_eq!(a, "2024-03-~l03.csv");
        assert_ne!(a, b);
        assert_eq!(abbreviate("knee.csv", 10), "knee.csv  ");
        assert_eq!(abbreviate("knee_calf.csv", 4), "kne~");
        for s in ["", "x", "long name here"] {
            for w in 0..20 {
                assert_eq!(abbreviate(s, w).chars().count(), w, "{s:?} in {w}");
            }
        }
    }
}
