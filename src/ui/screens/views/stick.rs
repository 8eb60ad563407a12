//! The stick-figure view (key `f`): the body's segments at one time, seen from
//! above and from the side (axes following the body's heading), uncorrected
//! beside corrected. Left/Right scrub by a second (PgUp/PgDn ten), Home/End
//! jump, Space or `p` plays.

use super::Ctx;
use super::{colour, marker, square_bounds};
use crate::analysis::stick::{BodyFrame, Segment, Skeleton};
use crate::ui::theme::Theme;
use crate::ui::workbench::TrialEntry;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::Color;
use ratatui::text::{Line, Span};
use ratatui::widgets::canvas::{Canvas, Line as CanvasLine};
use ratatui::widgets::{Block, Borders, Paragraph};
use ratatui::Frame;

/// Which side of the body an IMU is on, from its name (`l_...`, `..._l_...`).
fn side_colour(imu: &str) -> Color {
    let n = imu.to_ascii_lowercase();
    let has = |s: &str| {
        n.starts_with(&format!("{s}_"))
            || n.contains(&format!("_{s}_"))
            || n.ends_with(&format!("_{s}"))
    };
    if has("l") || n.starts_with("left") {
        Color::LightBlue
    } else if has("r") || n.starts_with("right") {
        Color::LightRed
    } else {
        Color::White
    }
}

/// The sample nearest to `t_s` seconds from the first sample.
fn index_at(time_s: &[f64], t_s: f64) -> usize {
    let t0 = time_s.first().copied().unwrap_or(0.0);
    let i = time_s.partition_point(|&t| t - t0 < t_s);
    match i {
        0 => 0,
        i if i >= time_s.len() => time_s.len().saturating_sub(1),
        i if t_s - (time_s[i - 1] - t0) <= time_s[i] - t0 - t_s => i - 1,
        i => i,
    }
}

/// One projection of one pose.
struct Panel<'a> {
    title: String,
    bones: &'a [(Segment, Color)],
    project: &'a dyn Fn([f64; 3]) -> (f64, f64),
    /// Half the side of the square shown, metres.
    reach: f64,
}

fn panel(f: &mut Frame, area: Rect, theme: &Theme, app: &Ctx, p: Panel) {
    let Panel {
        title,
        bones,
        project,
        reach,
    } = p;
    let mk = marker(app, theme);
    let (bx, by) = square_bounds(area, mk, true, reach, reach);
    let lines: Vec<(f64, f64, f64, f64, Color)> = bones
        .iter()
        .map(|([s, e], c)| {
            let (a, b) = (project(*s), project(*e));
            (a.0, a.1, b.0, b.1, *c)
        })
        .collect();
    let ground = colour(theme, theme.dim.fg.unwrap_or(Color::DarkGray));
    let canvas = Canvas::default()
        .block(
            Block::new()
                .borders(Borders::ALL)
                .border_style(theme.dim)
                .title(Span::styled(title, theme.header)),
        )
        .marker(mk)
        .x_bounds(bx)
        .y_bounds(by)
        .paint(move |ctx| {
            // The origin (the base segment's start) as a small cross.
            let k = reach * 0.03;
            ctx.draw(&CanvasLine::new(-k, 0.0, k, 0.0, ground));
            ctx.draw(&CanvasLine::new(0.0, -k, 0.0, k, ground));
            ctx.layer();
            for &(x1, y1, x2, y2, c) in &lines {
                ctx.draw(&CanvasLine::new(x1, y1, x2, y2, c));
            }
        });
    f.render_widget(canvas, area);
}

pub fn render(app: &Ctx, e: &TrialEntry, theme: &Theme, f: &mut Frame, area: Rect) {
    let Some(l) = e.loaded() else {
        return;
    };
    let [head, body, foot] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Min(3),
        Constraint::Length(1),
    ])
    .areas(area);
    let skel = match Skeleton::of(&l.model) {
        Ok(s) => s,
        Err(m) => {
            f.render_widget(
                Paragraph::new(format!("no stick figure: {m}"))
                    .wrap(ratatui::widgets::Wrap { trim: true }),
                body,
            );
            return;
        }
    };
    let d = l.trial.duration_s();
    let t = app.views.time_s.clamp(0.0, d);
    let i = index_at(&l.trial.time_s, t);
    let raw = skel.pose_at(&l.trial, i);
    let cor = e
        .results
        .get(&app.variant)
        .map(|r| skel.pose_at(&r.correction.corrected, i));
    let frame = BodyFrame::of(&raw);
    let reach = skel.reach_m() * 1.05;
    f.render_widget(
        Paragraph::new(Line::from(vec![
            Span::styled(format!(" {} ", l.model.name), theme.title),
            Span::raw(
                "stick figure, metres; top: forward right, left up; side: forward right, up up  ",
            ),
            Span::styled(
                "left",
                ratatui::style::Style::default().fg(colour(theme, Color::LightBlue)),
            ),
            Span::raw(" / "),
            Span::styled(
                "right",
                ratatui::style::Style::default().fg(colour(theme, Color::LightRed)),
            ),
        ])),
        head,
    );
    let [left, right] = Layout::horizontal([Constraint::Ratio(1, 2); 2]).areas(body);
    for (side, pose, label) in [
        (left, Some(&raw), "raw".to_string()),
        (right, cor.as_ref(), app.variant.to_string()),
    ] {
        let [top_a, side_a] = Layout::vertical([Constraint::Ratio(1, 2); 2]).areas(side);
        let Some(pose) = pose else {
            f.render_widget(
                Paragraph::new(Span::styled(
                    format!(" {label} not run: Esc, then r"),
                    theme.dim,
                ))
                .block(Block::new().borders(Borders::ALL).border_style(theme.dim)),
                side,
            );
            continue;
        };
        let bones: Vec<(Segment, Color)> = skel
            .bones
            .iter()
            .zip(pose.iter())
            .filter_map(|(b, s)| s.map(|s| (s, colour(theme, side_colour(&b.imu)))))
            .collect();
        let top = |p| frame.top(p);
        let side_view = |p| frame.side(p);
        for (a, name, project) in [
            (top_a, "top", &top as &dyn Fn([f64; 3]) -> (f64, f64)),
            (side_a, "side", &side_view),
        ] {
            let p = Panel {
                title: format!(" {label}: {name} "),
                bones: &bones,
                project,
                reach,
            };
            panel(f, a, theme, app, p);
        }
    }
    let state = if app.views.playing {
        "playing"
    } else {
        "paused"
    };
    f.render_widget(
        Paragraph::new(Line::from(vec![
            Span::raw(format!(" t {t:.2} / {d:.1} s (sample {i})  {state}  ")),
            Span::styled(
                "<- -> scrub  PgUp/PgDn 10 s  Space/p play  v variant",
                theme.dim,
            ),
        ])),
        foot,
    );
}
