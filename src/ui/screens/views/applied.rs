//! The applied-correction view (key `a`): the rotation the variant applied to
//! the joint's distal IMU over time, its angle and its rotation-vector
//! components in the sensor frame, with the window centres it was slerped
//! between marked.

use super::Ctx;
use super::{colour, marker};
use crate::analysis::applied::AppliedCorrection;
use crate::ui::axis;
use crate::ui::theme::Theme;
use crate::ui::workbench::TrialEntry;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::{Color, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Block, Borders, Chart, Dataset, GraphType, Paragraph};
use ratatui::Frame;

fn bounds(ys: impl Iterator<Item = f64>) -> [f64; 2] {
    let (lo, hi) = ys.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), y| {
        (a.min(y), b.max(y))
    });
    if !lo.is_finite() {
        return [-1.0, 1.0];
    }
    let pad = ((hi - lo) * 0.1).max(0.5);
    [lo - pad, hi + pad]
}

/// A chart in `area` whose y axis over `b` has round ticks in degrees.
fn chart_with_ticks(f: &mut Frame, chart: Chart, area: Rect, b: [f64; 2], theme: &Theme) {
    let unit = if theme.ascii { "" } else { "°" };
    let plot = axis::plot_rows(area, false);
    let labels = axis::y_labels(b[0], b[1], plot.1, unit);
    let w = axis::width(&labels).min(area.width / 3);
    let chart = chart.y_axis(
        Axis::default()
            .bounds(b)
            .labels(axis::blank(w))
            .style(theme.dim),
    );
    f.render_widget(chart, area);
    axis::draw_labels(
        f.buffer_mut(),
        area.x,
        plot,
        w,
        (b[0], b[1]),
        &labels,
        theme.dim,
    );
}

pub fn render(app: &Ctx, e: &TrialEntry, theme: &Theme, f: &mut Frame, area: Rect) {
    let Some(l) = e.loaded() else {
        return;
    };
    let Some(joint) = l.before.get(app.joint).map(|j| j.joint.clone()) else {
        f.render_widget(
            Paragraph::new("no joint with both IMUs in this trial"),
            area,
        );
        return;
    };
    let [head, top, bottom, foot] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Ratio(1, 3),
        Constraint::Ratio(2, 3),
        Constraint::Length(1),
    ])
    .areas(area);
    let distal = l.model.joint(&joint).map_or("", |j| j.distal.as_str());
    f.render_widget(
        Paragraph::new(Line::from(vec![
            Span::styled(format!(" {joint} "), theme.title),
            Span::raw(format!(
                "correction C(t) of {distal} ({}), sensor frame  ",
                app.variant
            )),
            Span::styled("v variant  Up/Down joint", theme.dim),
        ])),
        head,
    );
    let result = e
        .results
        .get(&app.variant)
        .and_then(|r| r.correction.joint(&joint));
    let Some(result) = result else {
        let why = if e.results.contains_key(&app.variant) {
            format!("{joint} was not corrected by {}", app.variant)
        } else {
            format!("{} not run: Esc, then r", app.variant)
        };
        f.render_widget(Paragraph::new(Span::styled(why, theme.dim)), top);
        return;
    };
    let applied = AppliedCorrection::of(result);
    let d = l.trial.duration_s();
    let cols = area.width.saturating_sub(8).max(2) as usize;
    let per_col = if app.view.braille { 2 } else { 1 };
    let s = applied.sampled(0.0, d, cols * per_col);
    let mk = marker(app, theme);
    let angle: Vec<(f64, f64)> = s.iter().map(|(t, c)| (*t, c.angle_deg)).collect();
    let centres: Vec<(f64, f64)> = applied
        .centres_s
        .iter()
        .filter_map(|c| {
            s.iter()
                .find(|(t, _)| t == c)
                .map(|(t, x)| (*t, x.angle_deg))
        })
        .collect();
    let comp: [Vec<(f64, f64)>; 3] =
        std::array::from_fn(|k| s.iter().map(|(t, c)| (*t, c.axis_deg[k])).collect());
    let centre_style = theme.cursor;
    let x_axis = Axis::default().bounds([0.0, d.max(1e-6)]);
    // Angle.
    let ba = bounds(angle.iter().map(|p| p.1));
    let sets = vec![
        Dataset::default()
            .data(&angle)
            .graph_type(GraphType::Line)
            .marker(mk)
            .style(theme.corrected),
        Dataset::default()
            .data(&centres)
            .graph_type(GraphType::Scatter)
            .marker(ratatui::symbols::Marker::Dot)
            .style(centre_style),
    ];
    let title = Line::from(vec![
        Span::styled(" angle, deg ", theme.header),
        Span::styled(format!("• {} window centres ", centres.len()), centre_style),
    ]);
    chart_with_ticks(
        f,
        Chart::new(sets)
            .block(Block::new().borders(Borders::TOP).title(title))
            .x_axis(x_axis.clone())
            .legend_position(None),
        top,
        ba,
        theme,
    );
    // Components.
    let axis_colours = [Color::LightRed, Color::LightGreen, Color::LightBlue];
    let bc = bounds(comp.iter().flat_map(|c| c.iter().map(|p| p.1)));
    let mut sets: Vec<Dataset> = comp
        .iter()
        .zip(axis_colours)
        .map(|(c, col)| {
            Dataset::default()
                .data(c)
                .graph_type(GraphType::Line)
                .marker(mk)
                .style(Style::default().fg(colour(theme, col)))
        })
        .collect();
    let centre_marks: Vec<Vec<(f64, f64)>> = (0..3)
        .map(|k| {
            applied
                .centres_s
                .iter()
                .filter_map(|c| {
                    s.iter()
                        .find(|(t, _)| t == c)
                        .map(|(t, x)| (*t, x.axis_deg[k]))
                })
                .collect()
        })
        .collect();
    for m in &centre_marks {
        sets.push(
            Dataset::default()
                .data(m)
                .graph_type(GraphType::Scatter)
                .marker(ratatui::symbols::Marker::Dot)
                .style(centre_style),
        );
    }
    let mut title = vec![Span::styled(" rotation vector, deg: ", theme.header)];
    for (k, col) in axis_colours.iter().enumerate() {
        title.push(Span::styled(
            format!("{} ", crate::limits::axis_name(k)),
            Style::default()
                .fg(colour(theme, *col))
                .add_modifier(ratatui::style::Modifier::BOLD),
        ));
    }
    chart_with_ticks(
        f,
        Chart::new(sets)
            .block(Block::new().borders(Borders::TOP).title(Line::from(title)))
            .x_axis(x_axis)
            .legend_position(None),
        bottom,
        bc,
        theme,
    );
    let (lo, hi) = angle
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), p| {
            (a.min(p.1), b.max(p.1))
        });
    f.render_widget(
        Paragraph::new(format!(
            " t 0-{d:.1} s  {} windows (centres at {})  angle {lo:.1}-{hi:.1} deg",
            result.windows.len(),
            centre_list(&applied.centres_s),
        )),
        foot,
    );
}

/// The first few window centres, seconds.
fn centre_list(c: &[f64]) -> String {
    let mut s: Vec<String> = c.iter().take(3).map(|x| format!("{x:.0}")).collect();
    if c.len() > 3 {
        s.push("...".into());
    }
    format!("{} s", s.join(", "))
}
