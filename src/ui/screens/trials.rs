//! The trials screen: every trial file of the folder, its status and figures.

use crate::acm::Variant;
use crate::ui::cells::{abbreviate, counter, fit, list_move, num, sel};
use crate::ui::keymap::Action;
use crate::ui::msg::{Nav, Reply};
use crate::ui::theme::Theme;
use crate::ui::workbench::{LoadState, SortKey, Workbench};
use ratatui::crossterm::event::{KeyCode, KeyEvent};
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Paragraph, Wrap};
use ratatui::Frame;

/// A variant's name in a 7-character column.
fn short_name(v: Variant) -> &'static str {
    v.info().short
}

/// The variant columns' headers, the first marked `<` when columns are
/// scrolled out of view on the left.
fn variant_headers(variants: &[Variant], more_left: bool) -> String {
    let mut h: String = variants
        .iter()
        .map(|v| format!("{:>7}", short_name(*v)))
        .collect();
    if more_left {
        h.replace_range(0..1, "<");
    }
    h
}

/// The name column's header: the filter first while there is one, so it
/// stays in view however narrow the column.
fn name_header(filter: &str, sort: &str, position: &str) -> String {
    if filter.is_empty() {
        format!("trial {position} (sort: {sort})")
    } else {
        format!("{}  {position} (sort: {sort})", filter.trim_start())
    }
}

/// The list and the details below it.
fn areas(area: Rect) -> [Rect; 2] {
    let details_h = if area.height >= 16 { 5 } else { 0 };
    Layout::vertical([Constraint::Min(1), Constraint::Length(details_h)]).areas(area)
}

/// The first list row shown, for a list `rows` tall.
fn first_row(app: &Workbench, rows: usize) -> usize {
    app.selected.saturating_sub(rows.saturating_sub(1))
}

/// The trial (index into the visible list) drawn at row `y` of the screen,
/// `body` being the screen's area as last drawn.
pub fn row_at(app: &Workbench, body: Rect, y: u16) -> Option<usize> {
    let [list, _] = areas(body);
    let rows = list.height.saturating_sub(1) as usize;
    let k = y.checked_sub(list.y + 1)? as usize;
    let i = first_row(app, rows) + k;
    (k < rows && i < app.visible().len()).then_some(i)
}

pub fn render(app: &Workbench, theme: &Theme, f: &mut Frame, area: Rect) {
    let [list, details] = areas(area);
    let details_h = details.height;
    // Variant status columns: as many as fit beside a 20-character name;
    // when not all fit they scroll so that the variant shown (`v`) is in
    // view, `<` and `>` marking columns out of view.
    let base = 2 + 8 + 6 + 5 + 7 + 7;
    let all = Variant::ALL.len();
    let shown = (1..=all)
        .rev()
        .find(|k| list.width as usize >= base + k * 7 + 20)
        .unwrap_or(1);
    let cur = Variant::ALL
        .iter()
        .position(|v| *v == app.variant)
        .unwrap_or(0);
    let start = cur.saturating_sub(shown - 1).min(all - shown);
    let variants = &Variant::ALL[start..start + shown];
    let fixed = base + shown * 7;
    let nw = (list.width as usize).saturating_sub(fixed).max(8);
    let filter = if app.filter_editing || !app.filter.is_empty() {
        format!(
            "  filter /{}{}",
            app.filter,
            if app.filter_editing { "_" } else { "" }
        )
    } else {
        String::new()
    };
    let mut lines = vec![Line::from(Span::styled(
        format!(
            "  {}{:>8}{:>6}{:>5}{}{:>7}{:>7}",
            fit(
                &name_header(
                    &filter,
                    app.sort.name(),
                    &counter(app.selected, app.visible().len())
                ),
                nw
            ),
            "dur s",
            "Hz",
            "IMUs",
            variant_headers(variants, start > 0),
            if start + shown < all {
                ">   exc"
            } else {
                "exc"
            },
            short_name(app.variant),
        ),
        theme.header,
    ))];
    let visible = app.visible();
    let rows = list.height.saturating_sub(1) as usize;
    let first = first_row(app, rows);
    for (k, &i) in visible.iter().enumerate().skip(first).take(rows) {
        let e = &app.trials[i];
        let selected = k == app.selected;
        let marker = if selected { "> " } else { "  " };
        let line = match &e.load {
            LoadState::Pending => Line::from(vec![
                Span::raw(format!("{marker}{}", abbreviate(&e.file, nw))),
                Span::styled("  loading...", theme.dim),
            ]),
            LoadState::Failed(m) => Line::from(vec![
                Span::raw(format!("{marker}{}", abbreviate(&e.file, nw))),
                Span::styled(
                    format!("  ERR {}", fit(m, fixed.saturating_sub(6))),
                    theme.error,
                ),
            ]),
            LoadState::Loaded(l) => {
                let mut s = format!(
                    "{marker}{}{:>8.1}{:>6.0}{:>5}",
                    abbreviate(&e.file, nw),
                    l.trial.duration_s(),
                    l.trial.rate_hz(),
                    l.trial.imus.len()
                );
                for &v in variants {
                    s.push_str(&format!("{:>7}", e.variant_status(v)));
                }
                s.push_str(&num(e.mean_excursion(None), 7));
                s.push_str(&num(e.mean_excursion(Some(app.variant)), 7));
                Line::from(s)
            }
        };
        lines.push(line.style(sel(theme, selected)));
    }
    if visible.is_empty() {
        lines.push(Line::from(Span::styled(
            if app.trials.is_empty() {
                format!("  no trial files in {}", app.dir_label)
            } else {
                "  no trial matches the filter".to_string()
            },
            theme.dim,
        )));
    }
    f.render_widget(Paragraph::new(lines), list);
    if details_h > 0 {
        let mut text = vec![];
        if let Some(e) = app.selected_entry() {
            match &e.load {
                LoadState::Loaded(l) => {
                    let imus: Vec<&str> = l.trial.imus.iter().map(|i| i.name.as_str()).collect();
                    text.push(Line::from(format!(
                        "{} samples, model {}, IMUs: {}",
                        l.trial.len(),
                        l.model.name,
                        imus.join(" ")
                    )));
                    if l.truth.is_some() {
                        text.push(Line::from("truth beside the trial: RMS errors on compare"));
                    }
                    if let Some(m) = &l.truth_error {
                        text.push(Line::from(Span::styled(format!("truth: {m}"), theme.warn)));
                    }
                    if let Some(r) = &l.reference {
                        text.push(Line::from(format!(
                            "optical reference beside the trial (lag {:+.2} s): drawn on the trial screen",
                            r.lag_s
                        )));
                    }
                    if let Some(m) = &l.reference_error {
                        text.push(Line::from(Span::styled(m.clone(), theme.warn)));
                    }
                    for w in &l.trial.warnings {
                        text.push(Line::from(Span::styled(w.clone(), theme.warn)));
                    }
                }
                LoadState::Failed(m) => text.push(Line::from(Span::styled(m.clone(), theme.error))),
                LoadState::Pending => text.push(Line::from("loading...")),
            }
        }
        f.render_widget(
            Paragraph::new(text)
                .wrap(Wrap { trim: true })
                .block(Block::new().borders(Borders::TOP).title(" details ")),
            details,
        );
    }
}

/// What a key does on the trials screen.
pub fn action(app: &mut Workbench, a: Action) -> Reply {
    let n = app.visible().len();
    match a {
        a if a.moves_in_list() => {
            if let Some(i) = list_move(a, app.selected, n, 10) {
                app.selected = i;
            }
        }
        Action::Filter => app.filter_editing = true,
        Action::Back => app.filter.clear(),
        Action::Sort => {
            app.sort = match app.sort {
                SortKey::Name => SortKey::Duration,
                SortKey::Duration => SortKey::Excursion,
                SortKey::Excursion => SortKey::Name,
            };
            app.sort_trials();
        }
        Action::Variant => app.next_variant(),
        Action::Calibration => return Reply::nav(Nav::Calibration),
        Action::Enter | Action::Right => {
            let Some(e) = app.selected_entry() else {
                return Reply::default();
            };
            match &e.load {
                LoadState::Loaded(_) => {
                    return Reply::nav(Nav::OpenTrial(e.file.clone()));
                }
                LoadState::Pending => app.info(format!("{} is still loading", e.file)),
                LoadState::Failed(m) => {
                    let m = m.clone();
                    app.error(m)
                }
            }
        }
        Action::Run => {
            if let Some(f) = app.selected_entry().map(|e| e.file.clone()) {
                return app.run_effect(&f, None).into();
            }
        }
        _ => {}
    }
    Reply::default()
}

/// A key while the name filter is being typed.
pub fn filter_key(app: &mut Workbench, k: KeyEvent) {
    match k.code {
        KeyCode::Enter => app.filter_editing = false,
        KeyCode::Esc => {
            app.filter_editing = false;
            app.filter.clear();
        }
        KeyCode::Backspace => {
            app.filter.pop();
        }
        KeyCode::Char(c) => app.filter.push(c),
        _ => {}
    }
    app.selected = 0;
}
