//! Drawing: a pure function of the state. One module per screen; this one
//! draws the frame around them (title, status bar) and the overlays.

use super::app::{App, Overlay};
use super::cells::{centred, fit};
use super::keymap::{help_lines, hint_line, Scope, FIGURE_LEGEND};
use super::msg::Screen;
use super::screens::{calibration, compare, histogram, limits, trial, trials, views};
use super::theme::Theme;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Clear, Paragraph, Wrap};
use ratatui::Frame;

/// Draws the whole workbench.
pub fn render(app: &App, theme: &Theme, f: &mut Frame) {
    let area = f.area();
    app.frame.set(area);
    if area.width < 20 || area.height < 5 {
        f.render_widget(
            Paragraph::new("acmw: window too small").wrap(Wrap { trim: true }),
            area,
        );
        return;
    }
    let [top, body, bottom] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Min(1),
        Constraint::Length(1),
    ])
    .areas(area);
    title_bar(app, theme, f, top);
    match app.screen {
        Screen::Trials => trials::render(&app.wb, theme, f, body),
        Screen::Trial => trial::render(&app.wb, theme, f, body),
        Screen::Compare => compare::render(app.compare_col, &app.wb, theme, f, body),
        Screen::Limits => limits::render(&app.wb, theme, f, body),
        Screen::Views => views::render(&app.views, &app.wb, theme, f, body),
        Screen::Calibration => calibration::render(&app.calib, theme, f, body),
        Screen::Histogram => histogram::render(&app.histogram, &app.wb, theme, f, body),
    }
    status_bar(app, theme, f, bottom);
    match &app.overlay {
        Some(Overlay::Help) => help(app, theme, f, body),
        Some(Overlay::QuitConfirm) => quit_confirm(app, theme, f, body),
        Some(Overlay::ReloadConflict) => reload_conflict(app, theme, f, body),
        None => {}
    }
}

fn title_bar(app: &App, theme: &Theme, f: &mut Frame, area: Rect) {
    let screen = match app.screen {
        Screen::Trials => "Trials".to_string(),
        Screen::Trial => format!("Trial {}", app.open.as_deref().unwrap_or("")),
        Screen::Compare => format!("Compare {}", app.open.as_deref().unwrap_or("")),
        Screen::Limits => "Limits".to_string(),
        Screen::Views => format!(
            "{} {}",
            app.views.kind.name(),
            app.open.as_deref().unwrap_or("")
        ),
        Screen::Calibration => "Calibration".to_string(),
        Screen::Histogram => "Histograms".to_string(),
    };
    let right = format!(
        "variant {}{} ",
        app.variant,
        if app.limits.disk_error.is_some() {
            "  limits!"
        } else if app.limits.dirty() {
            "  limits*"
        } else {
            ""
        }
    );
    // The folder and the screen's name give way (cut with `~`) before the
    // right-hand part runs into them.
    let w = area.width as usize;
    let room = w.saturating_sub(6 + right.chars().count() + 2);
    let dir_w = app.dir_label.chars().count().min(room / 3).max(4).min(room);
    let screen_w = room.saturating_sub(dir_w + 2);
    let mut spans = vec![
        Span::styled(" acmw ", theme.title),
        Span::raw(format!("{}  ", fit(&app.dir_label, dir_w).trim_end())),
        Span::styled(fit(&screen, screen_w).trim_end().to_string(), theme.header),
    ];
    let used: usize = spans.iter().map(|s| s.width()).sum();
    let pad = w.saturating_sub(used + right.chars().count());
    spans.push(Span::raw(" ".repeat(pad)));
    spans.push(Span::styled(right, theme.dim));
    f.render_widget(Paragraph::new(Line::from(spans)), area);
}

/// The keys of each screen, as its help and hints list them.
pub fn scope_of(screen: Screen) -> Scope {
    match screen {
        Screen::Trials => Scope::Trials,
        Screen::Trial => Scope::Trial,
        Screen::Compare => Scope::Compare,
        Screen::Limits => Scope::Limits,
        Screen::Views => Scope::Views,
        Screen::Calibration => Scope::Calibration,
        Screen::Histogram => Scope::Histogram,
    }
}

/// Key hints of the screen in front (from the keymap's hints).
pub fn hints(app: &App) -> String {
    if app.filter_editing {
        return "type to filter  Enter done  Esc clear".into();
    }
    if app.screen == Screen::Limits && app.limits.edit.is_some() {
        return "type a value  <- -> Home End move  Enter commit  Esc cancel".into();
    }
    hint_line(scope_of(app.screen))
}

/// The hints that fit in `w` columns, whole (the first ones: most used),
/// never one cut in half; `? help` stays whatever else goes.
pub fn fit_hints(line: &str, w: usize) -> String {
    const HELP: &str = "? help";
    let keep_help = line.split("  ").any(|h| h == HELP);
    let room = if keep_help {
        w.saturating_sub(HELP.len() + 2)
    } else {
        w
    };
    let mut out = String::new();
    for h in line.split("  ").filter(|h| !keep_help || *h != HELP) {
        let next = if out.is_empty() {
            h.to_string()
        } else {
            format!("{out}  {h}")
        };
        if next.chars().count() > room {
            break;
        }
        out = next;
    }
    if keep_help && w >= HELP.len() {
        out = if out.is_empty() {
            HELP.to_string()
        } else {
            format!("{out}  {HELP}")
        };
    }
    out
}

fn status_bar(app: &App, theme: &Theme, f: &mut Frame, area: Rect) {
    let line = match &app.message {
        Some((m, true)) => Line::from(vec![
            Span::styled(" ! ", theme.error),
            Span::styled(m.clone(), theme.error),
        ]),
        Some((m, false)) => Line::from(vec![Span::raw(" "), Span::styled(m.clone(), theme.ok)]),
        None => Line::from(Span::raw(format!(
            " {}",
            fit_hints(&hints(app), area.width.saturating_sub(1) as usize)
        ))),
    };
    f.render_widget(Paragraph::new(line).style(theme.status), area);
}

fn popup(f: &mut Frame, theme: &Theme, area: Rect, title: &str, lines: Vec<Line>) {
    f.render_widget(Clear, area);
    f.render_widget(
        Paragraph::new(lines).wrap(Wrap { trim: false }).block(
            Block::new()
                .borders(Borders::ALL)
                .title(Span::styled(format!(" {title} "), theme.title)),
        ),
        area,
    );
}

/// The help's sections for the screen in front: the keys that work
/// everywhere, the screen's own, and (trial screen) what its figures mean.
pub fn help_items(screen: Screen, theme: &Theme) -> Vec<Line<'static>> {
    let own = scope_of(screen);
    let mut items: Vec<Line> = vec![];
    for scope in [own, Scope::Everywhere] {
        let entries: Vec<_> = help_lines().into_iter().filter(|l| l.2 == scope).collect();
        if entries.is_empty() {
            continue;
        }
        items.push(Line::from(Span::styled(scope.title(), theme.header)));
        for (keys, text, _) in entries {
            items.push(Line::from(vec![
                Span::styled(format!(" {keys:<15}"), theme.title),
                Span::raw(text),
            ]));
        }
    }
    if matches!(screen, Screen::Trials | Screen::Compare) {
        items.push(Line::from(Span::styled("variant columns", theme.header)));
        for v in crate::acm::Variant::ALL {
            let info = v.info();
            items.push(Line::from(vec![
                Span::styled(format!(" {:<15}", info.short), theme.title),
                Span::raw(info.name),
            ]));
        }
        items.push(Line::from(vec![
            Span::styled(format!(" {:<15}", "exc / variant"), theme.title),
            Span::raw("mean excursion, deg: before / after"),
        ]));
    }
    if screen == Screen::Trial {
        items.push(Line::from(Span::styled("figures", theme.header)));
        for (label, text) in FIGURE_LEGEND {
            items.push(Line::from(vec![
                Span::styled(format!(" {label:<15}"), theme.title),
                Span::raw(*text),
            ]));
        }
    }
    items
}

fn help(app: &App, theme: &Theme, f: &mut Frame, body: Rect) {
    let items = help_items(app.screen, theme);
    let n = items.len();
    let area = centred(body, 62, n as u16 + 2);
    let inner_h = area.height.saturating_sub(2) as usize;
    let max = n.saturating_sub(inner_h);
    app.help_max.set(max);
    let first = app.help_scroll.min(max);
    let title = if max == 0 {
        " Keys (any key closes) ".to_string()
    } else {
        format!(
            " Keys {}-{} of {n}: Up/Down PgUp/PgDn scroll, others close ",
            first + 1,
            (first + inner_h).min(n)
        )
    };
    f.render_widget(Clear, area);
    f.render_widget(
        Paragraph::new(items.into_iter().skip(first).collect::<Vec<_>>()).block(
            Block::new()
                .borders(Borders::ALL)
                .title(Span::styled(title, theme.title)),
        ),
        area,
    );
}

fn quit_confirm(app: &App, theme: &Theme, f: &mut Frame, body: Rect) {
    let mut lines = vec![Line::from("Not saved yet:")];
    if app.limits.dirty() {
        lines.push(Line::from(format!(
            "  limit edits ({})",
            app.limits.table_name
        )));
    }
    if app.limits.saving {
        lines.push(Line::from(format!(
            "  limits being saved ({})",
            app.limits.table_name
        )));
    }
    for t in &app.trials {
        if let Some(v) = t.saving {
            lines.push(Line::from(format!("  {} {v} being saved", t.file)));
        } else if t.unsaved_choice() {
            lines.push(Line::from(format!(
                "  {} chosen variant {}",
                t.file,
                t.chosen.map(|v| v.name()).unwrap_or("")
            )));
        }
        if let Some(pct) = t.running {
            lines.push(Line::from(format!("  {} correcting, {pct}%", t.file)));
        }
    }
    lines.push(Line::from(""));
    lines.push(Line::from(vec![
        Span::raw("Quit anyway?  "),
        Span::styled("y", theme.title),
        Span::raw(" quit   "),
        Span::styled("n", theme.title),
        Span::raw(" stay"),
    ]));
    let h = lines.len() as u16 + 2;
    popup(f, theme, centred(body, 50, h), "Quit?", lines);
}

fn reload_conflict(app: &App, theme: &Theme, f: &mut Frame, body: Rect) {
    let lines = vec![
        Line::from(format!(
            "{} changed on disk, and you have unsaved edits.",
            app.limits.table_name
        )),
        Line::from(""),
        Line::from(vec![
            Span::styled("K", theme.title),
            Span::raw(" keep mine (still unsaved)   "),
            Span::styled("T", theme.title),
            Span::raw(" take the file's"),
        ]),
    ];
    popup(
        f,
        theme,
        centred(body, 56, 6),
        "Limits changed on disk",
        lines,
    );
}
