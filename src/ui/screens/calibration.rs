//! The calibration screen (key `C` on the trials screen): the folder's
//! calibration recordings (`*.calib.csv[.gz]`), and for the selected one the
//! reliability rho of every movement and IMU (Ricci et al. 2014, Table 1), the
//! residual angle of each axis at the identity start and after the LM fit
//! (its Figure 5), and the fit per IMU.
//!
//! State, keys and drawing of the screen live here; reading and calibrating
//! run as a background job, never in `update`.

use crate::calibration::Calibration;
use crate::rotation::angle_deg;
use crate::ui::cells::{counter, fit, sel};
use crate::ui::keymap::Action;
use crate::ui::msg::{CalibEntry, Effect, Nav, Reply, Screen};
use crate::ui::theme::Theme;
use crate::ui::workbench::Workbench;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Paragraph};
use ratatui::Frame;

/// What the calibration screen shows.
#[derive(Debug, Clone, Default)]
pub struct CalibState {
    /// Recordings in name order (empty until the first scan ends).
    pub entries: Vec<CalibEntry>,
    pub selected: usize,
    /// A scan is under way.
    pub loading: bool,
    /// The protocol used: `<built-in ricci2014>` or the folder's file.
    pub protocol: String,
}

/// Starts reading the folder's recordings (the screen is opening or `r`).
pub fn enter(c: &mut CalibState, app: &Workbench) -> Vec<Effect> {
    c.loading = true;
    vec![Effect::Calibrations {
        dir: app.dir.clone(),
    }]
}

/// A key on the calibration screen.
pub fn action(c: &mut CalibState, app: &mut Workbench, a: Action) -> Reply {
    let n = c.entries.len();
    match a {
        Action::Back => return Reply::nav(Nav::To(Screen::Trials)),
        a if a.moves_in_list() => {
            if let Some(i) = crate::ui::cells::list_move(a, c.selected, n, 10) {
                c.selected = i;
            }
        }
        Action::Run => return enter(c, app).into(),
        _ => {}
    }
    Reply::default()
}

/// The end of a scan.
pub fn loaded(c: &mut CalibState, entries: Vec<CalibEntry>, protocol: String) {
    let keep = c.entries.get(c.selected).map(|e| e.file.clone());
    c.entries = entries;
    c.protocol = protocol;
    c.loading = false;
    // Keep the selected file; else the first one that could be read.
    c.selected = keep
        .and_then(|f| c.entries.iter().position(|e| e.file == f))
        .or_else(|| c.entries.iter().position(|e| e.result.is_ok()))
        .unwrap_or(0)
        .min(c.entries.len().saturating_sub(1));
}

/// Draws the screen.
pub fn render(c: &CalibState, theme: &Theme, f: &mut Frame, area: Rect) {
    let list_h = (c.entries.len().max(1) as u16 + 1)
        .min(area.height / 4)
        .max(2);
    let [list, body] =
        Layout::vertical([Constraint::Length(list_h), Constraint::Min(0)]).areas(area);
    render_list(c, theme, f, list);
    let Some(entry) = c.entries.get(c.selected) else {
        return;
    };
    match &entry.result {
        Ok(cal) => render_calibration(cal, theme, f, body),
        Err(m) => f.render_widget(
            Paragraph::new(Line::from(Span::styled(m.clone(), theme.error)))
                .wrap(ratatui::widgets::Wrap { trim: true }),
            body,
        ),
    }
}

fn render_list(c: &CalibState, theme: &Theme, f: &mut Frame, area: Rect) {
    let nw = (area.width as usize).saturating_sub(2 + 30).max(12);
    let mut lines = vec![Line::from(Span::styled(
        format!(
            "  {}{:>8}{:>6}{:>7}{:>9}",
            fit(
                &format!(
                    "recording {} (protocol {})",
                    counter(c.selected, c.entries.len()),
                    c.protocol
                ),
                nw
            ),
            "dur s",
            "IMUs",
            "moves",
            "rho mean"
        ),
        theme.header,
    ))];
    if c.entries.is_empty() {
        let text = if c.loading {
            "  reading calibration recordings...".to_string()
        } else {
            "  no calibration recordings (*.calib.csv) in this folder".to_string()
        };
        lines.push(Line::from(Span::styled(text, theme.dim)));
    }
    let rows = area.height.saturating_sub(1) as usize;
    let first = c.selected.saturating_sub(rows.saturating_sub(1));
    for (k, e) in c.entries.iter().enumerate().skip(first).take(rows) {
        let marker = if k == c.selected { "> " } else { "  " };
        let line = match &e.result {
            Ok(cal) => {
                let rhos: Vec<f64> = cal
                    .segments
                    .iter()
                    .flat_map(|s| s.axes.iter().map(|a| a.rho))
                    .collect();
                let mean = rhos.iter().sum::<f64>() / rhos.len().max(1) as f64;
                let moves = cal
                    .movements
                    .iter()
                    .filter(|m| cal.segments.iter().any(|s| s.axis(m).is_some()))
                    .count();
                Line::from(format!(
                    "{marker}{}{:>8.1}{:>6}{:>7}{:>9.3}",
                    fit(&e.file, nw),
                    cal.duration_s,
                    cal.segments.len(),
                    moves,
                    mean
                ))
            }
            Err(m) => {
                let m = m.strip_prefix(&format!("{}:", e.file)).unwrap_or(m);
                Line::from(vec![
                    Span::raw(format!("{marker}{}", fit(&e.file, nw))),
                    Span::styled(format!("  ERR {}", fit(m, 24)), theme.error),
                ])
            }
        };
        lines.push(line.style(sel(theme, k == c.selected)));
    }
    f.render_widget(Paragraph::new(lines), area);
}

fn render_calibration(cal: &Calibration, theme: &Theme, f: &mut Frame, area: Rect) {
    let fit_h = cal.segments.len() as u16 + 2 + u16::from(!cal.skipped.is_empty());
    let [table, fits] =
        Layout::vertical([Constraint::Min(0), Constraint::Length(fit_h)]).areas(area);
    // Cells: rho and the LM residual; with room, the residual at the start too.
    let mw = 8usize;
    let per = ((table.width as usize).saturating_sub(mw + 1) / cal.segments.len().max(1)).min(18);
    let wide = per >= 16;
    let mut lines = vec![Line::from(Span::styled(
        if wide {
            "rho (Table 1)  and axis residual, deg: identity start > LM fit (Figure 5)"
        } else {
            "rho (Table 1)  and axis residual after the LM fit, deg (Figure 5)"
        },
        theme.dim,
    ))];
    let mut head = format!("{:<mw$}", "movement");
    for s in &cal.segments {
        head.push_str(&format!("{:>per$}", fit_right(&s.imu, per - 1)));
    }
    lines.push(Line::from(Span::styled(head, theme.header)));
    for m in &cal.movements {
        let mut row = vec![Span::raw(fit(m, mw))];
        for s in &cal.segments {
            let cell = match s.axis(m) {
                Some(a) if wide => format!(
                    "{:.3} {:>5.1}>{:<4.1}",
                    a.rho, a.residual_before_deg, a.residual_lm_deg
                ),
                Some(a) => format!("{:.2} {:>4.1}", a.rho, a.residual_lm_deg),
                None if s.missing.contains(m) => "missing".into(),
                None => "//".into(),
            };
            let style = if s.missing.contains(m) {
                theme.warn
            } else {
                ratatui::style::Style::default()
            };
            row.push(Span::styled(format!("{cell:>per$}"), style));
        }
        lines.push(Line::from(row));
    }
    f.render_widget(Paragraph::new(lines), table);
    let mut lines = vec![Line::from(Span::styled(
        format!(
            "{:<12}{:>5}{:>11}{:>10}{:>8}{:>10}  {}",
            "imu", "iter", "cost start", "cost end", "angle", "LM-TRIAD", "TRIAD pair"
        ),
        theme.header,
    ))];
    for s in &cal.segments {
        lines.push(Line::from(format!(
            "{:<12}{:>5}{:>11.4}{:>10.4}{:>8.1}{:>10}  {}",
            fit(&s.imu, 11),
            s.iterations,
            s.cost_start,
            s.cost_end,
            angle_deg(&s.rotation()),
            s.lm_triad_deg
                .map_or("-".to_string(), |d| format!("{d:.2}")),
            s.triad_movements.join("+")
        )));
    }
    for s in &cal.skipped {
        lines.push(Line::from(Span::styled(
            format!("skipped {}: {}", s.imu, s.reason),
            theme.warn,
        )));
    }
    f.render_widget(
        Paragraph::new(lines).block(
            Block::new()
                .borders(Borders::TOP)
                .title(" rotation sensor -> functional frame (LM), deg "),
        ),
        fits,
    );
}

/// `s` cut to `w` characters from the left (names differ at their ends).
fn fit_right(s: &str, w: usize) -> String {
    let n = s.chars().count();
    if n <= w {
        s.to_string()
    } else {
        s.chars().skip(n - w).collect()
    }
}

#[cfg(test)]
mod tests {
    use crate::ui::app::{App, Msg, Screen};
    use crate::ui::headless::{load_app, write_demo_folder};
    use crate::ui::jobs::SyncRunner;
    use crate::ui::render::render;
    use crate::ui::tests::SIZES;
    use crate::ui::theme::Theme;
    use ratatui::backend::TestBackend;
    use ratatui::crossterm::event::{KeyCode, KeyEvent};
    use ratatui::Terminal;

    fn key(app: &mut App, c: KeyCode) {
        SyncRunner::send(app, Msg::Key(KeyEvent::from(c)));
    }

    fn snap(name: &str, app: &App) {
        for (w, h) in SIZES {
            let mut t = Terminal::new(TestBackend::new(w, h)).unwrap();
            t.draw(|f| render(app, &Theme::default(), f)).unwrap();
            insta::assert_snapshot!(format!("{name}_{w}x{h}"), t.backend());
        }
    }

    #[test]
    fn calibration_screen_flow() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("trials");
        write_demo_folder(&dir).unwrap();
        let mut app = load_app("trials", &dir, &tmp.path().join("joint_limits")).unwrap();
        // Recordings are not trials.
        assert!(app.trials.iter().all(|t| !t.file.contains(".calib.")));
        key(&mut app, KeyCode::Char('C'));
        assert_eq!(app.screen, Screen::Calibration);
        let c = &app.calib;
        assert!(!c.loading);
        assert_eq!(c.protocol, "<built-in ricci2014>");
        let files: Vec<&str> = c.entries.iter().map(|e| e.file.as_str()).collect();
        assert_eq!(files, ["bad.calib.csv", "cal.calib.csv"]);
        // The first readable recording is selected.
        assert_eq!(c.selected, 1);
        key(&mut app, KeyCode::Up);
        let c = &app.calib;
        // The malformed recording names file, line and column.
        let err = c.entries[0].result.as_ref().unwrap_err();
        assert!(err.starts_with("bad.calib.csv:3:7:"), "{err}");
        snap("calibration_error", &app);
        key(&mut app, KeyCode::Down);
        let cal = app.calib.entries[1].result.as_ref().unwrap();
        assert_eq!(cal.segments.len(), 5);
        // Table 1 shape: the thorax rows only where the thorax has movements.
        let thorax = cal.segment("upper_back").unwrap();
        assert!(thorax.axis("supine").unwrap().rho > 0.97);
        assert!(thorax.axis("TR").unwrap().rho < thorax.axis("TFE").unwrap().rho);
        // `r` reads again and keeps the selection; Esc goes back.
        key(&mut app, KeyCode::Char('r'));
        assert_eq!(app.calib.selected, 1);
        key(&mut app, KeyCode::Esc);
        assert_eq!(app.screen, Screen::Trials);
    }

    #[test]
    fn empty_folder_says_so_and_small_sizes_do_not_panic() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("trials");
        std::fs::create_dir_all(&dir).unwrap();
        let mut app = load_app("trials", &dir, &tmp.path().join("joint_limits")).unwrap();
        key(&mut app, KeyCode::Char('C'));
        assert!(app.calib.entries.is_empty());
        let mut t = Terminal::new(TestBackend::new(80, 24)).unwrap();
        t.draw(|f| render(&app, &Theme::default(), f)).unwrap();
        let text = crate::ui::headless::buffer_text(t.backend().buffer());
        assert!(text.contains("no calibration recordings"), "{text}");
        write_demo_folder(&dir).unwrap();
        key(&mut app, KeyCode::Char('r'));
        for (w, h) in [(0, 0), (1, 1), (2, 2), (20, 5), (40, 12)] {
            let mut t = Terminal::new(TestBackend::new(w, h)).unwrap();
            t.draw(|f| render(&app, &Theme::default(), f)).unwrap();
        }
    }
}
