//! The heading-drift view (key `D` on the trial screen): the heading drift a
//! heading-drift variant estimated for every IMU over time, in degrees about
//! the global vertical, and its rates in degrees per second.

use super::Ctx;
use crate::acm::{ImuHeading, Variant};
use crate::ui::axis;
use crate::ui::cells::fit;
use crate::ui::glyphs::SERIES;
use crate::ui::theme::Theme;
use crate::ui::workbench::{TrialEntry, Workbench};
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::Style;
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Block, Borders, Chart, Dataset, GraphType, Paragraph};
use ratatui::Frame;

/// An IMU counts as drifting when some window's heading exceeds this, degrees.
pub const SHOWN_DEG: f64 = 0.05;

/// The heading-drift run the view shows: the current variant when it is one,
/// else the first heading variant that has a result.
pub fn shown_variant(app: &Workbench, e: &TrialEntry) -> Option<Variant> {
    let candidates = [
        app.variant,
        Variant::DriftHeadingCentroid,
        Variant::DriftHeading,
    ];
    candidates
        .into_iter()
        .find(|v| v.fits_headings() && e.results.contains_key(v))
}

/// The marker of the `k`-th drifting IMU: its label character (`1`, `2`, ...,
/// then letters), which the table shows beside its name, so that colour is
/// never the only cue.
fn marker_of(k: usize) -> Marker {
    Marker::Custom(char::from(SERIES[k % SERIES.len()]))
}

/// Line styles of the drifting IMUs, in turn.
fn styles(theme: &Theme) -> [Style; 5] {
    [
        theme.corrected,
        theme.raw,
        theme.warn,
        theme.centroid,
        theme.ok,
    ]
}

/// Draws the view.
pub fn render(app: &Ctx, e: &TrialEntry, theme: &Theme, f: &mut Frame, area: Rect) {
    let Some(v) = shown_variant(app, e) else {
        let text = vec![
            Line::from(Span::styled(
                "heading drift per IMU (drift-heading, drift-heading-centroid)",
                theme.header,
            )),
            Line::from(Span::styled(
                "  not run yet: Esc, then r runs all variants",
                theme.warn,
            )),
        ];
        f.render_widget(Paragraph::new(text), area);
        return;
    };
    let c = &e.results[&v].correction;
    let drifting: Vec<&ImuHeading> = c
        .headings
        .iter()
        .filter(|h| h.max_abs_heading_deg() > SHOWN_DEG)
        .collect();
    let table_h = (drifting.len() as u16 + 3).min(area.height / 2);
    let [head, plot, table] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Min(0),
        Constraint::Length(table_h),
    ])
    .areas(area);
    let vertical = c.settings.vertical.name();
    f.render_widget(
        Paragraph::new(Line::from(Span::styled(
            fit(
                &format!(
                    "heading drift of {v}, deg about the vertical ({vertical}), per window centre"
                ),
                head.width as usize,
            ),
            theme.dim,
        ))),
        head,
    );
    let duration = e.loaded().map_or(1.0, |l| l.trial.duration_s());
    if drifting.is_empty() {
        let text = format!("  no heading drift found (no window's heading beyond {SHOWN_DEG} deg)");
        f.render_widget(Paragraph::new(Span::styled(text, theme.ok)), plot);
    }
    chart(&drifting, duration, theme, f, plot);
    rows(c, &drifting, theme, f, table);
}

fn chart(hs: &[&ImuHeading], duration: f64, theme: &Theme, f: &mut Frame, area: Rect) {
    if area.height < 3 || area.width < 12 || hs.is_empty() {
        return;
    }
    let series: Vec<Vec<(f64, f64)>> = hs
        .iter()
        .map(|h| {
            h.windows
                .iter()
                .map(|w| (w.centre_s, w.heading_deg))
                .collect()
        })
        .collect();
    let (mut lo, mut hi) = (0.0f64, 0.0f64);
    for &(_, y) in series.iter().flatten() {
        lo = lo.min(y);
        hi = hi.max(y);
    }
    let pad = ((hi - lo) * 0.05).max(0.5);
    let (lo, hi) = (lo - pad, hi + pad);
    let zero = vec![(0.0, 0.0), (duration, 0.0)];
    let mut sets = vec![Dataset::default()
        .data(&zero)
        .graph_type(GraphType::Line)
        .marker(theme.glyphs(true).centroid)
        .style(theme.dim)];
    let st = styles(theme);
    for (k, s) in series.iter().enumerate() {
        sets.push(
            Dataset::default()
                .data(s)
                .graph_type(GraphType::Line)
                .marker(marker_of(k))
                .style(st[k % st.len()]),
        );
    }
    let unit = if theme.ascii { "" } else { "°" };
    let plot = axis::plot_rows(area, true);
    let labels = axis::y_labels(lo, hi, plot.1, unit);
    let w = axis::width(&labels).min(area.width / 3);
    let chart = Chart::new(sets)
        .block(Block::new().borders(Borders::TOP).title("deg"))
        .x_axis(
            Axis::default()
                .bounds([0.0, duration])
                .labels(vec!["0 s".to_string(), format!("{duration:.0} s")])
                .style(theme.dim),
        )
        .y_axis(
            Axis::default()
                .bounds([lo, hi])
                .labels(axis::blank(w))
                .style(theme.dim),
        )
        .legend_position(None);
    f.render_widget(chart, area);
    axis::draw_labels(
        f.buffer_mut(),
        area.x,
        plot,
        w,
        (lo, hi),
        &labels,
        theme.dim,
    );
}

/// The largest window-to-window rate of an IMU (deg/s) and the centre it ends at.
fn steepest(h: &ImuHeading) -> Option<(f64, f64)> {
    h.windows
        .iter()
        .filter_map(|w| w.rate_deg_s.map(|r| (r, w.centre_s)))
        .max_by(|a, b| a.0.abs().total_cmp(&b.0.abs()))
}

fn rows(c: &crate::acm::Correction, hs: &[&ImuHeading], theme: &Theme, f: &mut Frame, area: Rect) {
    let mut lines = vec![Line::from(Span::styled(
        format!(
            "  {:<14}{:>9}{:>10}{:>10}{:>8}",
            "imu", "last deg", "mean d/s", "max d/s", "at s"
        ),
        theme.header,
    ))];
    let st = styles(theme);
    for (k, h) in hs.iter().enumerate() {
        let last = h.windows.last().map_or(0.0, |w| w.heading_deg);
        let (rate, at) = steepest(h).unwrap_or((0.0, 0.0));
        lines.push(Line::from(vec![
            Span::styled(
                format!("{} ", char::from(SERIES[k % SERIES.len()])),
                st[k % st.len()],
            ),
            Span::raw(format!(
                "{:<14}{last:>9.2}{:>10.4}{rate:>10.4}{at:>8.0}",
                fit(&h.imu, 13),
                h.mean_rate_deg_s()
            )),
        ]));
    }
    let still: Vec<&str> = c
        .headings
        .iter()
        .filter(|h| h.max_abs_heading_deg() <= SHOWN_DEG)
        .map(|h| h.imu.as_str())
        .collect();
    if !still.is_empty() {
        lines.push(Line::from(Span::styled(
            format!("  no heading drift found: {}", still.join(", ")),
            theme.dim,
        )));
    }
    f.render_widget(Paragraph::new(lines), area);
}

#[cfg(test)]
mod tests {
    use crate::simulate::{preset, simulate, HeadingDrift};
    use crate::trial::{write_trial, TrialFormat};
    use crate::ui::headless::{buffer_text, draw, load_app, show, Show};
    use crate::ui::theme::Theme;

    #[test]
    fn heading_view_of_a_drifting_calf() {
        // 150 s of the full body, the left calf drifting 0.2 deg/s from 20 s.
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("trials");
        std::fs::create_dir_all(&dir).unwrap();
        let mut cfg = preset("full_body_clean").unwrap();
        cfg.duration_s = 150.0;
        cfg.drifts = vec![HeadingDrift {
            imu: "l_calf".into(),
            start_s: 20.0,
            rate_deg_s: 0.2,
        }];
        let sim = simulate(&cfg).unwrap();
        write_trial(&sim.trial, &dir.join("drift.csv"), TrialFormat::QuatCsv).unwrap();
        let mut app = load_app("trials", &dir, &tmp.path().join("joint_limits")).unwrap();
        show(
            &mut app,
            &Show {
                screen: "heading".into(),
                trial: Some("drift.csv".into()),
                ..Show::default()
            },
        )
        .unwrap();
        let e = app.open_entry().unwrap();
        let v = super::shown_variant(&app, e).unwrap();
        let h = e.results[&v].correction.heading("l_calf").unwrap().clone();
        // The calf's heading grows at about the simulated rate (window means
        // of a drift that starts inside the first window; 20% as in
        // tests/heading_drift.rs).
        let rate = h.mean_rate_deg_s();
        assert!((rate - 0.2).abs() < 0.04, "{rate}");
        for (w, hgt) in [(80, 24), (120, 40)] {
            let text = buffer_text(&draw(&app, &Theme::default(), w, hgt));
            assert!(text.contains("l_calf"), "{text}");
            insta::assert_snapshot!(format!("heading_drift_{w}x{hgt}"), text);
        }
        // Esc goes back to the trial screen.
        let esc =
            ratatui::crossterm::event::KeyEvent::from(ratatui::crossterm::event::KeyCode::Esc);
        crate::ui::jobs::SyncRunner::send(&mut app, crate::ui::app::Msg::Key(esc));
        assert_eq!(app.screen, crate::ui::msg::Screen::Trial);
    }
}
