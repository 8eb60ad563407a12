//! The 3-D scatter view (key `x`, thesis appendix B): a joint's Z-Y-X angles
//! as three projections (X-Y, X-Z, Y-Z), uncorrected beside corrected, points
//! coloured by limit class (or by time with `t`), the limits as rectangles.

use super::Ctx;
use super::{
    colour, draw_keys, joint_data, key_markers, marker, point_glyph, resolution, BAND_COLOUR,
    CLASS_COLOURS, TIME_COLOURS,
};
use crate::analysis::scatter::{
    axis_bounds, scatter_rasters, ClassCounts, Colouring, LimitClass, Raster, PROJECTIONS,
};
use crate::limits::axis_name;
use crate::ui::theme::Theme;
use crate::ui::workbench::TrialEntry;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::Style;
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::canvas::{Canvas, Rectangle};
use ratatui::widgets::{Block, Borders, Paragraph};
use ratatui::Frame;

/// The colouring the view is set to.
pub fn colouring(app: &Ctx) -> Colouring {
    if app.views.time_colour {
        Colouring::Time
    } else {
        Colouring::Limits
    }
}

/// The legend: the glyph and colour of each class, then each panel's share
/// of samples per class (within / near / beyond, percent), or the time bands.
pub fn legend(
    theme: &Theme,
    c: Colouring,
    markers: &[Marker],
    panels: &[(String, Option<ClassCounts>)],
) -> Line<'static> {
    let mut spans = vec![Span::raw(" ")];
    if c == Colouring::Time {
        spans.push(Span::raw("time: earliest "));
        for (col, m) in TIME_COLOURS.iter().zip(markers) {
            spans.push(Span::styled(
                point_glyph(*m),
                Style::default().fg(colour(theme, *col)),
            ));
        }
        spans.push(Span::raw(" latest (sixths of the trial)"));
        return Line::from(spans);
    }
    for (class, m) in LimitClass::ALL.into_iter().zip(markers) {
        spans.push(Span::styled(
            point_glyph(*m),
            Style::default().fg(colour(theme, CLASS_COLOURS[class as usize])),
        ));
        spans.push(Span::raw(format!(" {}  ", class.label())));
    }
    for (label, counts) in panels {
        spans.push(Span::styled(format!(" {label} "), theme.header));
        spans.push(Span::raw(match counts {
            Some(n) => format!(
                "{:.1}/{:.1}/{:.1}%",
                n.pct(LimitClass::Within),
                n.pct(LimitClass::Near),
                n.pct(LimitClass::Beyond)
            ),
            None => "not run".into(),
        }));
    }
    Line::from(spans)
}

/// The legend of the raw and corrected angles of a view.
pub fn legend_of(
    app: &Ctx,
    theme: &Theme,
    c: Colouring,
    range: &[[f64; 2]; 3],
    raw: &[[f64; 3]],
    cor: Option<&[[f64; 3]]>,
) -> Line<'static> {
    let panels = [
        ("raw".to_string(), Some(ClassCounts::of(raw, range))),
        (
            app.variant.to_string(),
            cor.map(|a| ClassCounts::of(a, range)),
        ),
    ];
    legend(
        theme,
        c,
        &key_markers(app, theme, c == Colouring::Time),
        &panels,
    )
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
    let c = colouring(app);
    let [head, grid, foot] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Min(3),
        Constraint::Length(1),
    ])
    .areas(area);
    f.render_widget(
        Paragraph::new(Line::from(vec![
            Span::styled(format!(" {} ", d.joint.name), theme.title),
            Span::raw("Z-Y-X angles, deg: three projections  "),
            Span::styled("t time colour  v variant  Up/Down joint", theme.dim),
        ])),
        head,
    );
    let mut sets: Vec<&[[f64; 3]]> = vec![&d.raw];
    if let Some(cor) = &d.cor {
        sets.push(cor);
    }
    let bounds = axis_bounds(&sets, limits.as_ref().map(|l| &l.range_deg));
    let [left, right] = Layout::horizontal([Constraint::Ratio(1, 2); 2]).areas(grid);
    let mk = marker(app, theme);
    let keys = key_markers(app, theme, c == Colouring::Time);
    let colours: Vec<_> = match c {
        Colouring::Limits => CLASS_COLOURS.iter().map(|&k| colour(theme, k)).collect(),
        Colouring::Time => TIME_COLOURS.iter().map(|&k| colour(theme, k)).collect(),
    };
    for (side, angles, label) in [
        (left, Some(&d.raw), "raw".to_string()),
        (right, d.cor.as_ref(), app.variant.to_string()),
    ] {
        let rows = Layout::vertical([Constraint::Ratio(1, 3); 3]).split(side);
        let (w, h) = resolution(rows[0], mk, true);
        let rasters: Option<[Raster; 3]> =
            angles.map(|a| scatter_rasters(a, &range, &bounds, c, w, h));
        for (p, &(hx, vy)) in PROJECTIONS.iter().enumerate() {
            let (bx, by) = (bounds[hx], bounds[vy]);
            let title = format!(
                " {label} {}[{:.0},{:.0}] {}[{:.0},{:.0}] ",
                axis_name(hx),
                bx[0],
                bx[1],
                axis_name(vy),
                by[0],
                by[1]
            );
            let block = Block::new()
                .borders(Borders::ALL)
                .border_style(theme.dim)
                .title(Span::styled(title, theme.header));
            let lim = limits.map(|l| (l.range_deg[hx], l.range_deg[vy]));
            // Yellow as the globe's band: red is the beyond class.
            let limit_colour = colour(theme, BAND_COLOUR);
            let raster = rasters.as_ref().map(|r| &r[p]);
            let canvas = Canvas::default()
                .block(block)
                .marker(mk)
                .x_bounds(bx)
                .y_bounds(by)
                .paint(|ctx| {
                    if let Some((rh, rv)) = lim {
                        ctx.draw(&Rectangle {
                            x: rh[0],
                            y: rv[0],
                            width: rh[1] - rh[0],
                            height: rv[1] - rv[0],
                            color: limit_colour,
                        });
                    }
                    ctx.layer();
                    if let Some(r) = raster {
                        draw_keys(ctx, r, &colours, &keys, mk);
                    }
                });
            f.render_widget(canvas, rows[p]);
            if raster.is_none() && p == 1 {
                let inner = Block::new().borders(Borders::ALL).inner(rows[p]);
                f.render_widget(
                    Paragraph::new(Span::styled(" not run: Esc, then r", theme.dim)),
                    inner,
                );
            }
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
