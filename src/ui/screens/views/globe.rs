//! The globographic view (key `o`, thesis Figure 4-5 and appendix C): the
//! distal segment's direction on a sphere around the joint, seen from the
//! middle of the limits; the flexion and ab/adduction limits as a yellow band;
//! points coloured by limit class over all three axes (rotation, which cannot
//! move a point, shows only in its colour), or by time with `t`. With a
//! swing-twist table the region's edge is drawn over the band (its box), as
//! `acmw plot globe` draws it, and each panel's title names it.

use super::scatter::{colouring, legend_of};
use super::Ctx;
use super::{
    colour, draw_keys, joint_data, key_markers, marker, resolution, square_around, RasterShape,
    BAND_COLOUR, CLASS_COLOURS, SWING_COLOUR, TIME_COLOURS,
};
use crate::analysis::globe::{
    band_outline, band_raster, extent, globe_raster, grid_lines, rect_outline, swing_outline,
    GlobeView, JointAxes,
};
use crate::analysis::scatter::{Colouring, Grid};
use crate::ui::theme::Theme;
use crate::ui::workbench::TrialEntry;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::Color;
use ratatui::text::{Line, Span};
use ratatui::widgets::canvas::{Canvas, Circle, Context, Line as CanvasLine};
use ratatui::widgets::{Block, Borders, Paragraph};
use ratatui::Frame;

/// Visible polylines on the view's screen: runs of consecutive visible points.
fn visible_runs(view: &GlobeView, line: &[[f64; 3]]) -> Vec<Vec<(f64, f64)>> {
    let mut runs = vec![];
    let mut run: Vec<(f64, f64)> = vec![];
    for d in line {
        match view.visible(*d) {
            Some(p) => run.push(p),
            None if !run.is_empty() => runs.push(std::mem::take(&mut run)),
            None => {}
        }
    }
    if !run.is_empty() {
        runs.push(run);
    }
    runs
}

fn draw_runs(ctx: &mut Context, runs: &[Vec<(f64, f64)>], color: Color) {
    for run in runs {
        if run.len() == 1 {
            ctx.draw(&CanvasLine::new(
                run[0].0, run[0].1, run[0].0, run[0].1, color,
            ));
        }
        for w in run.windows(2) {
            ctx.draw(&CanvasLine::new(w[0].0, w[0].1, w[1].0, w[1].1, color));
        }
    }
}

pub fn render(app: &Ctx, e: &TrialEntry, theme: &Theme, f: &mut Frame, area: Rect) {
    let Some(d) = joint_data(app, e) else {
        f.render_widget(
            Paragraph::new("no joint with both IMUs in this trial"),
            area,
        );
        return;
    };
    let limits = app
        .limits
        .table
        .joint_limits(&d.joint.name, &d.joint.kind, false);
    let range = limits.map(|l| l.range_deg).unwrap_or([[-180.0, 180.0]; 3]);
    let axes = JointAxes::of(&app.limits.table, &d.joint.name, &d.joint.kind);
    let view = GlobeView::for_limits(&range, axes);
    let c = colouring(app);
    let [head, panels, foot] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Min(3),
        Constraint::Length(1),
    ])
    .areas(area);
    let [left, right] = Layout::horizontal([Constraint::Ratio(1, 2); 2]).areas(panels);
    let mk = marker(app, theme);
    let outline = theme.glyphs(app.view.braille).outline;
    let keys = key_markers(app, theme, c == Colouring::Time);
    // A swing-twist table's region: its edge (unit directions, table axes).
    let swing = limits
        .and_then(|l| l.swing_twist)
        .map(|st| swing_outline(&st, 128));
    // Zoom to the band, the region and the samples (the thesis' plots show
    // that region).
    let mut outlines = vec![band_outline(&range, axes, 24)];
    outlines.extend(swing.clone());
    for a in std::iter::once(&d.raw).chain(d.cor.as_ref()) {
        if let Some([fl, ab]) = extent(a, axes) {
            outlines.push(rect_outline(fl, ab, axes, 24));
        }
    }
    let (fx, fy) = view.fit(&outlines, 0.06);
    let (bx, by) = square_around(left, mk, true, fx, fy);
    let (w, h) = resolution(left, mk, true);
    let dots = Grid { w, h, bx, by };
    let band = band_raster(&range, axes, &view, dots);
    // Grid lines every 30, 10 or 5 degrees as the view zooms in.
    let span = (bx[1] - bx[0]).max(by[1] - by[0]);
    let every = if span > 1.2 {
        30.0
    } else if span > 0.5 {
        10.0
    } else {
        5.0
    };
    let grid: Vec<Vec<(f64, f64)>> = grid_lines(axes, every, 73)
        .iter()
        .flat_map(|l| visible_runs(&view, l))
        .collect();
    let swing_runs = swing
        .as_ref()
        .map_or_else(Vec::new, |line| visible_runs(&view, line));
    let name = |k: usize| crate::limits::axis_name(k);
    f.render_widget(
        Paragraph::new(Line::from(vec![
            Span::styled(format!(" {} ", d.joint.name), theme.title),
            // A swing-twist table's axes are its swing components and its
            // twist (for the shipped table, Y, Z and X whatever the joint).
            Span::raw(format!(
                "{} direction; {} ({}) up, {} ({}) right, {} ({}) in colour  ",
                d.joint.distal,
                if swing.is_some() {
                    "swing_1"
                } else {
                    "flexion"
                },
                name(axes.flexion),
                if swing.is_some() {
                    "swing_2"
                } else {
                    "ab/adduction"
                },
                name(axes.abduction),
                if swing.is_some() { "twist" } else { "rotation" },
                name(axes.rotation)
            )),
            Span::styled(format!("grid {every:.0} deg  t time colour"), theme.dim),
        ])),
        head,
    );
    let colours: Vec<Color> = match c {
        Colouring::Limits => CLASS_COLOURS.iter().map(|&k| colour(theme, k)).collect(),
        Colouring::Time => TIME_COLOURS.iter().map(|&k| colour(theme, k)).collect(),
    };
    let dim = colour(theme, theme.dim.fg.unwrap_or(Color::DarkGray));
    let band_colour = colour(theme, BAND_COLOUR);
    let swing_colour = colour(theme, SWING_COLOUR);
    for (side, angles, label) in [
        (left, Some(&d.raw), "raw".to_string()),
        (right, d.cor.as_ref(), app.variant.to_string()),
    ] {
        let raster = angles.map(|a| globe_raster(a, &range, axes, &view, c, dots));
        let title = format!(" {label}: {} around {} ", d.joint.distal, d.joint.name);
        let canvas = Canvas::default()
            .block(
                Block::new()
                    .borders(Borders::ALL)
                    .border_style(theme.dim)
                    .title(Line::from(vec![
                        Span::styled(title, theme.header),
                        // Names the edge drawn in its colour.
                        Span::styled(
                            if swing.is_some() {
                                "swing-twist edge "
                            } else {
                                ""
                            },
                            theme.header.fg(swing_colour),
                        ),
                    ])),
            )
            .marker(mk)
            .x_bounds(bx)
            .y_bounds(by)
            .paint(|ctx| {
                if outline != mk {
                    ctx.marker(outline);
                }
                ctx.draw(&Circle {
                    x: 0.0,
                    y: 0.0,
                    radius: 1.0,
                    color: dim,
                });
                draw_runs(ctx, &grid, dim);
                ctx.layer();
                ctx.draw(&RasterShape {
                    raster: &band,
                    colours: &[band_colour],
                });
                ctx.layer();
                if !swing_runs.is_empty() {
                    draw_runs(ctx, &swing_runs, swing_colour);
                    ctx.layer();
                }
                if outline != mk {
                    ctx.marker(mk);
                }
                if let Some(r) = &raster {
                    draw_keys(ctx, r, &colours, &keys, mk);
                }
            });
        f.render_widget(canvas, side);
        if raster.is_none() {
            let inner = Block::new().borders(Borders::ALL).inner(side);
            f.render_widget(
                Paragraph::new(Span::styled(" not run: Esc, then r", theme.dim)),
                inner,
            );
        }
    }
    f.render_widget(
        Paragraph::new(legend_of(
            app,
            theme,
            c,
            &range,
            &d.raw,
            d.cor.as_deref().map(Vec::as_slice),
        )),
        foot,
    );
}
