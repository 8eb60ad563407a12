//! The limits editor: the joint x axis table and the settings, edited in place.

use crate::limits::HEADER;
use crate::ui::cells::{counter, fit, list_move};
use crate::ui::keymap::Action;
use crate::ui::msg::{Effect, Nav, Reply, Screen};
use crate::ui::theme::Theme;
use crate::ui::workbench::{CellEdit, Workbench, FIRST_EDIT_COL, LAST_COL, SETTING_NAMES};
use ratatui::crossterm::event::{KeyCode, KeyEvent};
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Modifier, Style};
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

/// The heading, the table and the footer of the screen in `area`.
fn areas(app: &Workbench, area: Rect) -> [Rect; 3] {
    Layout::vertical([
        Constraint::Length(1 + u16::from(app.limits.disk_error.is_some())),
        Constraint::Min(1),
        Constraint::Length(3),
    ])
    .areas(area)
}

/// The (row, column) of the cell drawn at (`x`, `y`), `area` being the
/// screen's area (a settings row has its value in column 3).
pub fn cell_at(app: &Workbench, area: Rect, x: u16, y: u16) -> Option<(usize, usize)> {
    let l = &app.limits;
    let [_, table, _] = areas(app, area);
    let rows = table.height.saturating_sub(1) as usize;
    let k = y.checked_sub(table.y + 1)? as usize;
    let first = l.row.saturating_sub(rows.saturating_sub(1));
    let r = first + k;
    if k >= rows || r >= l.rows() {
        return None;
    }
    if r >= l.table.rows.len() {
        return Some((r, 3));
    }
    let w = widths(table.width as usize);
    let mut at = (x.checked_sub(table.x)? as usize).checked_sub(2)?;
    for (c, cw) in w.iter().enumerate() {
        if at < *cw {
            return Some((r, c));
        }
        at -= cw;
    }
    Some((r, l.col))
}

pub fn render(app: &Workbench, theme: &Theme, f: &mut Frame, area: Rect) {
    let l = &app.limits;
    let [head, table, foot] = areas(app, area);
    let dirty = if l.dirty() {
        "  * unsaved changes (w saves)"
    } else {
        ""
    };
    let mut heading = vec![Line::from(vec![
        Span::raw(format!(" {} {} ", l.source, counter(l.row, l.rows()))),
        Span::styled(dirty, theme.edited),
    ])];
    if let Some(why) = &l.disk_error {
        heading.push(Line::from(Span::styled(
            format!(" ! on disk: {why}; in use: the last good table"),
            theme.error,
        )));
    }
    f.render_widget(Paragraph::new(heading), head);
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
            spans.extend(cell_spans(app, theme, r, 3, w[3] + w[4]));
        } else {
            for (c, &cw) in w.iter().enumerate() {
                spans.extend(cell_spans(app, theme, r, c, cw));
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
    // An edit of lambda2 changes the joint's three rows: said before it is made.
    let whole_joint = joint_wide(app).map(|j| {
        Span::styled(
            format!("  lambda2 is one per joint: applies to {j}'s three rows (X, Y, Z)"),
            theme.warn,
        )
    });
    match &l.edit {
        Some(e) => match &e.error {
            Some(m) => msg.push(Line::from(Span::styled(
                format!("x invalid: {m}"),
                theme.invalid,
            ))),
            None => msg.push(Line::from(
                [Span::styled("ok: Enter commits", theme.ok)]
                    .into_iter()
                    .chain(whole_joint)
                    .collect::<Vec<_>>(),
            )),
        },
        None => msg.push(Line::from(
            [Span::styled(
                "Enter edits the cell; edits re-run the open trial's joints",
                theme.dim,
            )]
            .into_iter()
            .chain(whole_joint)
            .collect::<Vec<_>>(),
        )),
    }
    f.render_widget(
        Paragraph::new(msg)
            .wrap(Wrap { trim: true })
            .block(Block::new().borders(Borders::TOP)),
        foot,
    );
}

/// The joint whose three rows the selected cell's edit changes (the
/// lambda2 column), if it is such a cell.
fn joint_wide(app: &Workbench) -> Option<&str> {
    let l = &app.limits;
    if l.col != 6 {
        return None;
    }
    l.table.rows.get(l.row).map(|r| r.joint.as_str())
}

fn cell_spans(
    app: &Workbench,
    theme: &Theme,
    row: usize,
    col: usize,
    w: usize,
) -> Vec<Span<'static>> {
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
            return edit_spans(&e.text, e.cursor, mark, style, w);
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
    vec![Span::styled(body, style)]
}

/// A cell being edited, right-aligned in `w` columns (one kept as a gap, as
/// [`fit_right`] does): the mark (`>` valid, `x` invalid), the text, and the
/// cursor: `_` past the end, else the character under it shown reversed. Text
/// too long for the cell loses its left end, never the cursor.
fn edit_spans(text: &str, cursor: usize, mark: &str, style: Style, w: usize) -> Vec<Span<'static>> {
    let mut chars: Vec<char> = mark.chars().chain(text.chars()).collect();
    let at = cursor + mark.chars().count();
    let past_end = at >= chars.len();
    if past_end {
        chars.push('_');
    }
    let room = w.saturating_sub(1).max(1);
    let skip = chars.len().saturating_sub(room).min(at);
    let shown = &chars[skip..chars.len().min(skip + room)];
    let at = at - skip;
    let pad = " ".repeat(w.saturating_sub(shown.len()));
    let before: String = shown[..at].iter().collect();
    let cursor_style = if past_end {
        style
    } else {
        style.add_modifier(Modifier::REVERSED)
    };
    vec![
        Span::styled(format!("{pad}{before}"), style),
        Span::styled(shown[at].to_string(), cursor_style),
        Span::styled(shown[at + 1..].iter().collect::<String>(), style),
    ]
}

fn fit_right(s: &str, w: usize) -> String {
    let n = s.chars().count();
    if n < w {
        s.to_string()
    } else {
        s.chars().skip(n + 1 - w.max(1)).collect()
    }
}

/// What a key does on the limits editor; Esc returns to `from`.
pub fn action(app: &mut Workbench, from: Screen, a: Action) -> Reply {
    let l = &mut app.limits;
    let n = l.rows();
    match a {
        Action::Back => return Reply::nav(Nav::To(from)),
        a if a.moves_in_list() => {
            if let Some(i) = list_move(a, l.row, n, 10) {
                l.row = i;
            }
        }
        Action::Left => l.col = l.col.saturating_sub(1).max(FIRST_EDIT_COL),
        Action::Right => l.col = (l.col + 1).min(LAST_COL),
        Action::Enter => {
            let text = l.cell_text(l.row, l.col);
            l.edit = Some(CellEdit::new(text));
        }
        Action::Save => {
            let (table, settings) = (l.table.clone(), l.settings.clone());
            l.saved_table = table.clone();
            l.saved_settings = settings.clone();
            l.saving = true;
            let effect = Effect::SaveLimits {
                dir: l.dir.clone(),
                table_name: l.table_name.clone(),
                table_csv: table.to_csv(),
                settings_toml: settings.to_toml(),
            };
            app.info(format!("saving {}...", app.limits.table_name));
            return vec![effect].into();
        }
        _ => {}
    }
    Reply::default()
}
/// A key while a cell is being edited.
pub fn edit_key(app: &mut Workbench, k: KeyEvent) -> Reply {
    let l = &mut app.limits;
    let Some(edit) = l.edit.as_mut() else {
        return Reply::default();
    };
    match k.code {
        KeyCode::Esc => {
            l.edit = None;
            return Reply::default();
        }
        KeyCode::Enter => {
            let text = edit.text.clone();
            let applied = l.apply(&text);
            match applied {
                Ok((table, settings)) => {
                    let settings_changed = settings != l.settings;
                    let mut note = None;
                    if let Some(r) = l.table.rows.get(l.row) {
                        l.pending.get_or_insert_with(Vec::new).push(r.joint.clone());
                        if l.col == 6 {
                            note = Some(format!(
                                "lambda2 of {} set to {} on its three rows",
                                r.joint,
                                text.trim()
                            ));
                        }
                    }
                    l.pending_all |= settings_changed;
                    l.table = table;
                    l.settings = settings;
                    l.edit = None;
                    app.settings = app.limits.settings.settings();
                    if let Some(n) = note {
                        app.info(n);
                    }
                    return vec![Effect::Debounce].into();
                }
                Err(m) => {
                    if let Some(edit) = l.edit.as_mut() {
                        edit.error = Some(m);
                    }
                    return Reply::default();
                }
            }
        }
        _ => {
            if !edit.key(k) {
                return Reply::default();
            }
        }
    }
    let text = edit.text.clone();
    let err = l.apply(&text).err();
    if let Some(edit) = l.edit.as_mut() {
        edit.error = err;
    }
    Reply::default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ui::workbench::CellEdit;
    use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};

    fn press(e: &mut CellEdit, codes: &[KeyCode]) {
        for &c in codes {
            assert!(e.key(KeyEvent::from(c)), "{c:?} is an editing key");
        }
    }

    fn shown(spans: &[Span]) -> (String, String) {
        let all: String = spans.iter().map(|s| s.content.as_ref()).collect();
        (all, spans[1].content.to_string())
    }

    #[test]
    fn cell_editor_edits_anywhere_in_the_cell() {
        let mut e = CellEdit::new("150".into());
        assert_eq!(e.cursor, 3);
        // 150 -> 125: to the 5, delete it and the 0, type 25 before the end.
        press(&mut e, &[KeyCode::Left, KeyCode::Left, KeyCode::Delete]);
        assert_eq!((e.text.as_str(), e.cursor), ("10", 1));
        press(&mut e, &[KeyCode::Backspace, KeyCode::Char('2')]);
        assert_eq!((e.text.as_str(), e.cursor), ("20", 1));
        press(&mut e, &[KeyCode::Home, KeyCode::Char('-'), KeyCode::End]);
        assert_eq!((e.text.as_str(), e.cursor), ("-20", 3));
        // At the ends, Backspace and Delete do nothing and stay editing keys.
        press(
            &mut e,
            &[KeyCode::Delete, KeyCode::Home, KeyCode::Backspace],
        );
        assert_eq!((e.text.as_str(), e.cursor), ("-20", 0));
        let ctrl_u = KeyEvent::new(KeyCode::Char('u'), KeyModifiers::CONTROL);
        assert!(e.key(ctrl_u));
        assert_eq!((e.text.as_str(), e.cursor), ("", 0));
        // Keys that are not editing keys are left to the caller.
        assert!(!e.key(KeyEvent::from(KeyCode::Up)));
    }

    #[test]
    fn edited_cell_shows_its_cursor() {
        let st = Style::default();
        // At the end: an underscore, as before the cursor could move.
        let (all, under) = shown(&edit_spans("150", 3, ">", st, 8));
        assert_eq!((all.as_str(), under.as_str()), ("   >150_", "_"));
        // In the middle: the character under the cursor, reversed.
        let spans = edit_spans("150", 1, ">", st, 8);
        let (all, under) = shown(&spans);
        assert_eq!((all.as_str(), under.as_str()), ("    >150", "5"));
        assert!(spans[1].style.add_modifier.contains(Modifier::REVERSED));
        // Too long for the cell: the left end goes, the cursor stays in view.
        let (all, under) = shown(&edit_spans("123456789", 0, ">", st, 5));
        assert_eq!((all.as_str(), under.as_str()), (" 1234", "1"));
        let (all, under) = shown(&edit_spans("123456789", 9, ">", st, 5));
        assert_eq!((all.as_str(), under.as_str()), (" 789_", "_"));
    }
}
