//! The limits editor: the joint x axis table and the settings, edited in place.

use super::app::{App, SETTING_NAMES};
use super::render::fit;
use super::theme::Theme;
use crate::limits::HEADER;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::Style;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Paragraph, Wrap};
use ratatui::Frame;

/// Column widths: joint, axis, movement, lower, upper, centroid, lambda2.
fn widths(total: usize) -> [usize; 7] {
    let fixed = 11 + 5 + 8 + 8 + 9 + 8;
    [
        11,
        5,
        total.saturating_sub(fixed + 3).clamp(8, 28),
        8,
        8,
        9,
        8,
    ]
}

pub fn render(app: &App, theme: &Theme, f: &mut Frame, area: Rect) {
    let l = &app.limits;
    let [head, table, foot] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Min(1),
        Constraint::Length(3),
    ])
    .areas(area);
    let dirty = if l.dirty() {
        "  * unsaved changes (w saves)"
    } else {
        ""
    };
    f.render_widget(
        Paragraph::new(Line::from(vec![
            Span::raw(format!(" {} ", l.source)),
            Span::styled(dirty, theme.edited),
        ])),
        head,
    );
    let w = widths(table.width as usize);
    let mut lines = vec![];
    let mut h = String::from("  ");
    for (k, name) in HEADER.iter().enumerate() {
        let name = name.trim_end_matches("_deg");
        if k >= 3 {
            h.push_str(&format!("{name:>w$}", w = w[k]));
        } else {
            h.push_str(&fit(name, w[k]));
        }
    }
    lines.push(Line::from(Span::styled(h, theme.header)));
    let rows = table.height.saturating_sub(1) as usize;
    let first = l.row.saturating_sub(rows.saturating_sub(1));
    for r in (0..l.rows()).skip(first).take(rows) {
        let selected = r == l.row;
        let mut spans = vec![Span::raw(if selected { "> " } else { "  " })];
        if let Some(s) = r.checked_sub(l.table.rows.len()) {
            let name = SETTING_NAMES[s];
            spans.push(Span::styled(fit(name, w[0] + w[1] + w[2]), theme.header));
            spans.push(cell_span(app, theme, r, 3, w[3] + w[4]));
        } else {
            for (c, &cw) in w.iter().enumerate() {
                spans.push(cell_span(app, theme, r, c, cw));
            }
        }
        let mut line = Line::from(spans);
        if selected && l.edit.is_none() {
            line = line.style(Style::default());
        }
        lines.push(line);
    }
    f.render_widget(Paragraph::new(lines), table);
    let mut msg = vec![];
    match &l.edit {
        Some(e) => match &e.error {
            Some(m) => msg.push(Line::from(Span::styled(
                format!("x invalid: {m}"),
                theme.invalid,
            ))),
            None => msg.push(Line::from(Span::styled("ok: Enter commits", theme.ok))),
        },
        None => msg.push(Line::from(Span::styled(
            "Enter edits the cell; edits re-run the open trial's joints",
            theme.dim,
        ))),
    }
    f.render_widget(
        Paragraph::new(msg)
            .wrap(Wrap { trim: true })
            .block(Block::new().borders(Borders::TOP)),
        foot,
    );
}

fn cell_span(app: &App, theme: &Theme, row: usize, col: usize, w: usize) -> Span<'static> {
    let l = &app.limits;
    let on_setting = row >= l.table.rows.len();
    let selected = row == l.row && (on_setting || col == l.col);
    if selected {
        if let Some(e) = &l.edit {
            let (mark, style) = if e.error.is_some() {
                ("x", theme.invalid)
            } else {
                (">", theme.edited)
            };
            let text = format!("{mark}{}_", e.text);
            return Span::styled(format!("{:>w$}", fit_right(&text, w)), style);
        }
    }
    let text = l.cell_text(row, col);
    let changed = l.cell_changed(row, col);
    let text = if changed { format!("{text}*") } else { text };
    let body = if col >= 3 {
        format!("{:>w$}", fit_right(&text, w))
    } else {
        fit(&text, w)
    };
    let mut style = if changed {
        theme.edited
    } else {
        Style::default()
    };
    if selected {
        style = style.patch(theme.selected);
    }
    Span::styled(body, style)
}

fn fit_right(s: &str, w: usize) -> String {
    let n = s.chars().count();
    if n < w {
        s.to_string()
    } else {
        s.chars().skip(n + 1 - w.max(1)).collect()
    }
}
