//! The trial screen: joints, three angle charts with limits, figures.

use crate::limits::axis_name;
use crate::metrics::JointFigures;
use crate::ui::cells::{counter, fit, list_move, num, sel};
use crate::ui::glyphs::{sample, Glyphs};
use crate::ui::keymap::Action;
use crate::ui::msg::{Nav, Reply, Screen, ViewKind};
use crate::ui::theme::Theme;
use crate::ui::workbench::{TrialEntry, View, Workbench};
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::style::Style;
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Block, Borders, Chart, Dataset, GraphType, Paragraph};
use ratatui::Frame;

pub use crate::plot::envelope::envelope;
use crate::ui::axis;

/// The sample index nearest to `ts` (times `t` already relative).
fn index_at(t: &[f64], ts: f64) -> usize {
    let i = t.partition_point(|&x| x < ts);
    if i == 0 {
        0
    } else if i >= t.len() {
        t.len().saturating_sub(1)
    } else if ts - t[i - 1] <= t[i] - ts {
        i - 1
    } else {
        i
    }
}

fn joint_row(name: &str, before: Option<f64>, after: Option<f64>, w: usize) -> String {
    format!(
        "{}{}{}",
        fit(name, w.saturating_sub(12)),
        num(before, 6),
        num(after, 6)
    )
}

fn figures_of<'a>(figs: Option<&'a [JointFigures]>, joint: &str) -> Option<&'a JointFigures> {
    figs?.iter().find(|f| f.joint == joint)
}

/// The joint list, the figures below it and the charts beside them.
fn panes(area: Rect) -> [Rect; 3] {
    let left_w = match area.width {
        100.. => 32,
        80.. => 26,
        _ => 22,
    }
    .min(area.width / 2);
    let [left, right] =
        Layout::horizontal([Constraint::Length(left_w), Constraint::Min(1)]).areas(area);
    let figs_h = 9.min(left.height / 2);
    let [jl, fl] = Layout::vertical([Constraint::Min(1), Constraint::Length(figs_h)]).areas(left);
    [jl, fl, right]
}

/// The joint (index into the open trial's joints) listed at (`x`, `y`),
/// `area` being the screen's area.
pub fn joint_at(app: &Workbench, area: Rect, x: u16, y: u16) -> Option<usize> {
    let [jl, _, _] = panes(area);
    if x < jl.x || x >= jl.right() {
        return None;
    }
    let rows = jl.height.saturating_sub(1) as usize;
    let k = y.checked_sub(jl.y + 1)? as usize;
    let j = app.joint.saturating_sub(rows.saturating_sub(1)) + k;
    (k < rows && j < app.open_joints().len()).then_some(j)
}

pub fn render(app: &Workbench, theme: &Theme, f: &mut Frame, area: Rect) {
    let Some(e) = app.open_entry() else {
        f.render_widget(Paragraph::new("no trial open (Esc)"), area);
        return;
    };
    let Some(l) = e.loaded() else {
        f.render_widget(Paragraph::new("trial not loaded"), area);
        return;
    };
    let [jl, fl, right] = panes(area);

    // Joint list.
    let joints: Vec<&JointFigures> = l.before.iter().collect();
    let after = e.figures(Some(app.variant));
    let iw = jl.width.saturating_sub(1) as usize;
    let mut lines = vec![Line::from(Span::styled(
        format!(
            "{}{:>6}{:>6}",
            fit(
                &format!("joint {}", counter(app.joint, joints.len())),
                iw.saturating_sub(12)
            ),
            "exc",
            "after"
        ),
        theme.header,
    ))];
    let rows = jl.height.saturating_sub(1) as usize;
    let first = app.joint.saturating_sub(rows.saturating_sub(1));
    for (k, j) in joints.iter().enumerate().skip(first).take(rows) {
        let a = figures_of(after, &j.joint).map(|x| x.excursion.joint_mean_excursion_deg);
        lines.push(
            Line::from(joint_row(
                &format!("{}{}", if k == app.joint { ">" } else { " " }, j.joint),
                Some(j.excursion.joint_mean_excursion_deg),
                a,
                iw,
            ))
            .style(sel(theme, k == app.joint)),
        );
    }
    f.render_widget(
        Paragraph::new(lines).block(Block::new().borders(Borders::RIGHT)),
        jl,
    );
    let Some(jf) = joints.get(app.joint) else {
        return;
    };
    let joint_name = jf.joint.clone();
    figures_panel(app, e, theme, f, fl, &joint_name);

    // Charts.
    let Some(joint) = l.model.joint(&joint_name) else {
        return;
    };
    let raw = l.angles.get(&l.trial, joint).unwrap_or_default();
    // A growing trial: its correction so far, solved then extrapolated.
    let live = e
        .live
        .as_ref()
        .filter(|v| v.corrected.len() == l.trial.len());
    let cor = match live {
        Some(v) => v.angles.get(&v.corrected, joint),
        None => e
            .results
            .get(&app.variant)
            .and_then(|r| r.angles.get(&r.correction.corrected, joint)),
    };
    let solved = live.map(|v| v.solved);
    let shown = live.map_or(app.variant, |v| v.variant);
    let lim = app
        .limits
        .table
        .joint_limits(&joint.name, &joint.kind, true);
    let t = &l.trial.time_s;
    let origin = t.first().copied().unwrap_or(0.0);
    let d = l.trial.duration_s();
    let (s0, s1) = app.view.span(d);
    let ci = index_at(t, app.view.cursor_s + origin);
    let glitches = crate::ui::glitches::of_joint(l, &joint.name);
    // The optical reference beside the trial, per axis where it has one.
    let reference = l.reference.as_ref().and_then(|r| r.joints.get(&joint.name));
    let glyphs = theme.glyphs(app.view.braille);
    let [charts, legend_row, foot] = Layout::vertical([
        Constraint::Min(1),
        Constraint::Length(1),
        Constraint::Length(1),
    ])
    .areas(right);
    let parts = Layout::vertical([Constraint::Ratio(1, 3); 3]).split(charts);
    let data: Vec<ChartData> = (0..3)
        .map(|axis| ChartData {
            t,
            origin,
            axis,
            raw: &raw,
            cor: cor.as_deref().map(Vec::as_slice),
            solved,
            reference: reference.and_then(|r| r[axis].as_deref()),
            range: lim.map(|l| l.range_deg[axis]),
            centroid: lim.and_then(|l| l.centroid_deg).map(|c| c[axis]),
            span: (s0, s1),
            cursor: app.view.cursor_s,
            glyphs,
            glitches: crate::ui::glitches::markers(&glitches, &raw, axis, (s0, s1)),
        })
        .collect();
    // One label width for the three charts: their time axes line up.
    let frames: Vec<Option<Frame_>> = data
        .iter()
        .zip(parts.iter())
        .map(|(d, a)| frame_of(d, *a, theme.ascii))
        .collect();
    let label_w = frames
        .iter()
        .flatten()
        .map(|fr| axis::width(&fr.labels))
        .max()
        .unwrap_or(1);
    for (axis, (d, fr)) in data.iter().zip(frames).enumerate() {
        let Some(fr) = fr else { continue };
        let mut title = vec![Span::styled(
            format!(
                " {}{} ",
                axis_name(axis),
                if theme.ascii { " deg" } else { "" }
            ),
            theme.header,
        )];
        if let Some([lo, hi]) = d.range {
            title.push(Span::styled(format!("[{lo}, {hi}] "), theme.limit));
        }
        if let Some(c) = d.centroid {
            title.push(Span::styled(format!("c {c} "), theme.centroid));
        }
        title.push(Span::styled("at cursor ", theme.dim));
        title.push(Span::styled(
            format!("raw {} ", num(raw.get(ci).map(|a| a[axis]), 0)),
            theme.raw,
        ));
        if let Some(c) = &cor {
            title.push(Span::styled(
                format!("{shown} {} ", num(c.get(ci).map(|a| a[axis]), 0)),
                theme.corrected,
            ));
        }
        let ref_axis = d.reference;
        if let Some(r) = ref_axis {
            let v = r.get(ci).copied().filter(|v| v.is_finite());
            title.push(Span::styled(format!("ref {} ", num(v, 0)), theme.ok));
        }
        chart(f, parts[axis], theme, Line::from(title), d, fr, label_w);
    }
    // (glyph, name, short name, style) of what the charts show.
    let mut legend = vec![(sample(glyphs.raw), "raw".to_string(), "", theme.raw)];
    if cor.is_some() && solved != Some(0) {
        let name = if live.is_some() {
            format!("{shown} solved")
        } else {
            shown.to_string()
        };
        legend.push((sample(glyphs.corrected), name, "", theme.corrected));
    }
    if live.is_some_and(|v| v.solved < v.corrected.len()) {
        legend.push((
            sample(glyphs.extrapolated),
            "extrapolated".into(),
            "ext",
            theme.corrected,
        ));
    }
    if reference.is_some() {
        legend.push((sample(glyphs.reference), "ref".into(), "", theme.ok));
    }
    if lim.is_some() {
        legend.push((sample(glyphs.limit), "limits".into(), "lim", theme.limit));
    }
    if lim.is_some_and(|l| l.centroid_deg.is_some()) {
        legend.push((
            sample(glyphs.centroid),
            "centroid".into(),
            "cen",
            theme.centroid,
        ));
    }
    // A vertical line: one of its glyph.
    let cursor: String = sample(glyphs.cursor).chars().take(1).collect();
    legend.push((cursor, "cursor".into(), "cur", theme.cursor));
    if !glitches.is_empty() {
        legend.push((sample(glyphs.glitch), "glitch".into(), "gl", theme.warn));
    }
    let full: usize = legend
        .iter()
        .map(|(g, n, _, _)| g.chars().count() + n.chars().count() + 3)
        .sum::<usize>()
        + 1;
    let mut spans = vec![Span::raw(" ")];
    for (glyph, name, short, style) in legend {
        if full <= legend_row.width as usize {
            spans.push(Span::styled(glyph, style));
            spans.push(Span::raw(format!(" {name}  ")));
        } else {
            // Narrow: one glyph and a short name each.
            spans.push(Span::styled(
                glyph.chars().take(1).collect::<String>(),
                style,
            ));
            let name = if short.is_empty() {
                name
            } else {
                short.to_string()
            };
            spans.push(Span::raw(format!("{name} ")));
        }
    }
    f.render_widget(Paragraph::new(Line::from(spans)), legend_row);
    let note = e
        .variant_note_short(app.variant)
        .filter(|_| e.running.is_none());
    let status = if let Some(v) = live {
        let n = l.trial.len();
        let solving = if v.solving { ", solving" } else { "" };
        if v.solved == 0 {
            format!("LIVE {n} rows, not solved yet{solving}")
        } else if foot.width >= 80 {
            format!(
                "LIVE {n} rows, solved 0-{:.1} s{solving}, extrapolated after",
                v.solved_s
            )
        } else {
            format!("LIVE {n} solved {:.0}s", v.solved_s)
        }
    } else if let Some(p) = e.running {
        format!("running {p}%")
    } else if note.is_some() {
        String::new()
    } else if e.results.contains_key(&app.variant) {
        format!("{} done", app.variant)
    } else {
        "not run: r runs all variants".to_string()
    };
    // A running correction first: it must not be cut at narrow widths; the
    // span and cursor shorter there.
    let zoom = 1u32 << app.view.zoom.min(16);
    let (running, done) = if e.running.is_some() || live.is_some() {
        (format!(" {status} "), String::new())
    } else {
        (String::new(), status)
    };
    let place = if foot.width >= 60 {
        format!(
            " t {s0:.1}-{s1:.1} s  x{zoom}  cursor {:.2} s  ",
            app.view.cursor_s
        )
    } else {
        format!(" {s0:.0}-{s1:.0}s x{zoom} @{:.2}s ", app.view.cursor_s)
    };
    f.render_widget(
        Paragraph::new(Line::from(vec![
            Span::styled(running, theme.warn),
            Span::raw(place),
            Span::styled(
                crate::ui::glitches::footer(&glitches, app.view.cursor_s).unwrap_or_default(),
                theme.warn,
            ),
            Span::styled(done, theme.dim),
            Span::styled(
                l.reference
                    .as_ref()
                    .map(|r| format!("  ref lag {:+.2} s", r.lag_s))
                    .unwrap_or_default(),
                theme.ok,
            ),
            Span::styled(note.unwrap_or_default(), theme.warn),
            Span::styled(
                live.and_then(|v| v.note.clone())
                    .map(|n| format!("  {n}"))
                    .unwrap_or_default(),
                theme.warn,
            ),
            Span::styled(
                crate::ui::pose::label(l)
                    .map(|p| format!("  {p}"))
                    .unwrap_or_default(),
                theme.header,
            ),
        ])),
        foot,
    );
}

fn line(pts: &[(f64, f64)], style: Style, marker: Marker) -> Dataset<'_> {
    Dataset::default()
        .data(pts)
        .graph_type(GraphType::Line)
        .marker(marker)
        .style(style)
}

struct ChartData<'a> {
    /// Sample times as recorded; the chart's time axis starts at `origin`.
    t: &'a [f64],
    origin: f64,
    /// Which angle of `raw` and `cor` to draw (0 = X).
    axis: usize,
    raw: &'a [[f64; 3]],
    cor: Option<&'a [[f64; 3]]>,
    /// A growing trial's first extrapolated sample of `cor` (None: all of
    /// `cor` is solved).
    solved: Option<usize>,
    /// The optical reference's angle of this axis per sample (NaN: none).
    reference: Option<&'a [f64]>,
    range: Option<[f64; 2]>,
    centroid: Option<f64>,
    span: (f64, f64),
    cursor: f64,
    glyphs: Glyphs,
    /// Glitch markers `(time, angle)` of the joint's IMUs in view.
    glitches: Vec<(f64, f64)>,
}

/// What a chart shows before it is drawn: the traces reduced to the columns
/// of its plot, the angle bounds and the y-axis tick labels.
struct Frame_ {
    /// The raw trace: one line, or the lower and upper lines of its
    /// envelope where the view holds more samples than the plot has dots.
    raw: Vec<Vec<(f64, f64)>>,
    /// The optical reference's points (finite ones only).
    reference: Vec<(f64, f64)>,
    /// The corrected trace, as `raw`.
    cor: Vec<Vec<(f64, f64)>>,
    /// The extrapolated part of the corrected trace (a growing trial's), as `raw`.
    ext: Vec<Vec<(f64, f64)>>,
    /// Angle bounds of the plot, degrees.
    lo: f64,
    hi: f64,
    /// (value, label) of the round ticks inside the bounds.
    labels: Vec<(f64, String)>,
}

/// The plot's content and axis for a chart in `area` (None when too small).
fn frame_of(d: &ChartData, area: Rect, ascii: bool) -> Option<Frame_> {
    if area.height < 2 || area.width < 10 {
        return None;
    }
    let (s0, s1) = d.span;
    // The plot is narrower by the labels and the axis: a few columns of
    // envelope more than needed cost nothing visible.
    let cols = area.width.saturating_sub(6).max(1) as usize;
    let raw_per_col = crate::ui::glyphs::dots_per_cell(d.glyphs.raw).0;
    let raw = envelope(
        d.t,
        d.origin,
        |i| d.raw[i][d.axis],
        s0,
        s1,
        cols * raw_per_col,
    );
    // A growing trial's correction in two parts: solved, then extrapolated.
    let k = d.solved.unwrap_or(d.t.len()).min(d.t.len());
    let (cor, ext) = match d.cor {
        Some(c) => (
            envelope(&d.t[..k], d.origin, |i| c[i][d.axis], s0, s1, cols),
            envelope(&d.t[k..], d.origin, |i| c[k + i][d.axis], s0, s1, cols),
        ),
        None => (vec![], vec![]),
    };
    let reference: Vec<(f64, f64)> = d
        .reference
        .map(|r| envelope(d.t, d.origin, |i| r[i], s0, s1, cols))
        .unwrap_or_default()
        .into_iter()
        .filter(|(_, y)| y.is_finite())
        .collect();
    // Bounds: the data in view and the limits.
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for &(_, y) in raw.iter().chain(&cor).chain(&ext).chain(&reference) {
        lo = lo.min(y);
        hi = hi.max(y);
    }
    if let Some([a, b]) = d.range {
        lo = lo.min(a);
        hi = hi.max(b);
    }
    if !lo.is_finite() || !hi.is_finite() {
        lo = -1.0;
        hi = 1.0;
    }
    let pad = ((hi - lo) * 0.05).max(0.5);
    let (lo, hi) = (lo - pad, hi + pad);
    let (_, plot_h) = axis::plot_rows(area, false);
    let labels = axis::y_labels(lo, hi, plot_h, if ascii { "" } else { "°" });
    Some(Frame_ {
        raw: outline(raw),
        reference,
        cor: outline(cor),
        ext: outline(ext),
        lo,
        hi,
        labels,
    })
}

/// An [`envelope`]'s points as lines to draw: as they are when it kept the
/// samples (each time once), else its lower and its upper line (one point
/// per column each). Joining a column's minimum to its maximum would fill
/// the plot solid wherever the angle swings faster than a column is wide
/// (a 300 s trace over 100 columns); the two lines keep it a trace, and
/// the band between them shows the swing.
fn outline(points: Vec<(f64, f64)>) -> Vec<Vec<(f64, f64)>> {
    if points.is_empty() {
        return vec![];
    }
    if points.windows(2).all(|w| w[0].0 != w[1].0) {
        return vec![points];
    }
    let mut lower: Vec<(f64, f64)> = vec![];
    let mut upper: Vec<(f64, f64)> = vec![];
    for p in points {
        match lower.last_mut() {
            Some(l) if l.0 == p.0 => {
                let u = upper.last_mut().expect("pushed together");
                l.1 = l.1.min(p.1);
                u.1 = u.1.max(p.1);
            }
            _ => {
                lower.push(p);
                upper.push(p);
            }
        }
    }
    vec![lower, upper]
}

fn chart(
    f: &mut Frame,
    area: Rect,
    theme: &Theme,
    title: Line,
    d: &ChartData,
    fr: Frame_,
    label_w: u16,
) {
    let (s0, s1) = d.span;
    let (lo, hi) = (fr.lo, fr.hi);
    let g = d.glyphs;
    let lower: Vec<(f64, f64)>;
    let upper: Vec<(f64, f64)>;
    let centre: Vec<(f64, f64)>;
    let cursor = vec![(d.cursor, lo), (d.cursor, hi)];
    // Limit lines first: a later dataset overwrites whole cells.
    let mut sets = vec![];
    if let Some([a, b]) = d.range {
        lower = vec![(s0, a), (s1, a)];
        upper = vec![(s0, b), (s1, b)];
        sets.push(line(&lower, theme.limit, g.limit));
        sets.push(line(&upper, theme.limit, g.limit));
    }
    if let Some(c) = d.centroid {
        centre = vec![(s0, c), (s1, c)];
        sets.push(line(&centre, theme.centroid, g.centroid));
    }
    if d.cursor >= s0 && d.cursor <= s1 {
        sets.push(line(&cursor, theme.cursor, g.cursor));
    }
    for l in &fr.raw {
        sets.push(line(l, theme.raw, g.raw));
    }
    for l in &fr.cor {
        sets.push(line(l, theme.corrected, g.corrected));
    }
    for l in &fr.ext {
        sets.push(line(l, theme.corrected, g.extrapolated));
    }
    // The reference as points of its own glyph (named `ref` in the title and
    // the legend), so it reads apart from raw and corrected without colour.
    if !fr.reference.is_empty() {
        sets.push(
            Dataset::default()
                .data(&fr.reference)
                .graph_type(GraphType::Scatter)
                .marker(g.reference)
                .style(theme.ok),
        );
    }
    // Glitches last: a glyph of their own, not colour alone.
    if !d.glitches.is_empty() {
        sets.push(
            Dataset::default()
                .data(&d.glitches)
                .graph_type(GraphType::Scatter)
                .marker(g.glitch)
                .style(theme.warn),
        );
    }
    // Blank labels of the common width keep the plot where the other charts
    // have theirs; the round ticks are written at their own rows below.
    let label_w = label_w.min(area.width / 3);
    let chart = Chart::new(sets)
        .block(Block::new().borders(Borders::TOP).title(title))
        .x_axis(Axis::default().bounds([s0, s1]))
        .y_axis(
            Axis::default()
                .bounds([lo, hi])
                .labels(axis::blank(label_w))
                .style(theme.dim),
        )
        .legend_position(None);
    f.render_widget(chart, area);
    axis::draw_labels(
        f.buffer_mut(),
        area.x,
        axis::plot_rows(area, false),
        label_w,
        (lo, hi),
        &fr.labels,
        theme.dim,
    );
}

fn figures_panel(
    app: &Workbench,
    e: &TrialEntry,
    theme: &Theme,
    f: &mut Frame,
    area: Rect,
    joint: &str,
) {
    let before = figures_of(e.figures(None), joint);
    let after = figures_of(e.figures(Some(app.variant)), joint);
    // Number columns as wide as the panel allows (6, or 5 when narrow).
    let nw = (area.width.saturating_sub(7) as usize / 3).clamp(4, 6);
    // One decimal while a space is left before the number, else none.
    let cell = |v: Option<f64>| match v {
        Some(v) if v.is_finite() && format!("{v:.1}").len() >= nw => format!("{v:>nw$.0}"),
        v => num(v, nw),
    };
    let row = |label: &str, v: Option<[f64; 3]>| {
        let mut s = format!("{label:<6}");
        for k in 0..3 {
            s.push_str(&cell(v.map(|v| v[k])));
        }
        Line::from(s)
    };
    let mut lines = vec![
        Line::from(Span::styled(
            format!("{:<6}{:>nw$}{:>nw$}{:>nw$}", "deg", "X", "Y", "Z"),
            theme.header,
        )),
        row("out%b", before.map(|f| f.excursion.pct_outside)),
        row("out%a", after.map(|f| f.excursion.pct_outside)),
        row("exc b", before.map(|f| f.excursion.mean_excursion_deg)),
        row("exc a", after.map(|f| f.excursion.mean_excursion_deg)),
        row(
            "shift",
            after
                .and_then(|f| f.shift.as_ref())
                .map(|s| s.mean_shift_deg),
        ),
    ];
    lines.push(Line::from(format!(
        "{:<6}{}",
        "corr",
        cell(
            after
                .and_then(|f| f.shift.as_ref())
                .map(|s| s.mean_correction_angle_deg)
        )
    )));
    f.render_widget(
        Paragraph::new(lines).block(
            Block::new()
                .borders(Borders::TOP | Borders::RIGHT)
                .title(" figures (? legend) "),
        ),
        area,
    );
}

/// Opens a trial on the trial screen.
pub fn open(app: &mut Workbench, file: String) {
    if app.open.as_deref() != Some(file.as_str()) {
        app.joint = 0;
        app.view = View {
            braille: app.view.braille,
            ..View::default()
        };
    }
    // A growing trial opens at its newest sample, and follows it.
    if let Some(l) = app
        .entry(&file)
        .filter(|e| e.live.is_some())
        .and_then(|e| e.loaded())
    {
        app.view.cursor_s = l.trial.duration_s();
    }
    app.select_file(&file);
    app.open = Some(file);
}

/// The open trial grew from `before` to `after` seconds: a view showing its
/// end keeps showing it (the time axis scrolls with the data), and a cursor
/// on its last sample stays on the last sample.
pub fn grown(app: &mut Workbench, before: f64, after: f64) {
    let eps = 1e-9;
    let (_, end) = app.view.span(before);
    if end >= before - eps {
        let (a, b) = app.view.span(after);
        app.view.start_s = (after - (b - a)).max(0.0);
    }
    if app.view.cursor_s >= before - eps {
        app.view.cursor_s = after;
    }
}

/// What a key does on the trial screen.
pub fn action(app: &mut Workbench, a: Action) -> Reply {
    let joints = app.open_joints().len();
    let d = app
        .open_entry()
        .and_then(|e| e.loaded())
        .map_or(0.0, |l| l.trial.duration_s());
    let (s0, s1) = app.view.span(d);
    let step = (s1 - s0) / 50.0;
    match a {
        Action::Back => return Reply::nav(Nav::To(Screen::Trials)),
        Action::Up | Action::Down | Action::PageUp | Action::PageDown => {
            if let Some(i) = list_move(a, app.joint, joints, 10) {
                app.joint = i;
            }
        }
        Action::ZoomIn => zoom(app, true),
        Action::ZoomOut => zoom(app, false),
        Action::Left => app.view.start_s = (s0 - (s1 - s0) / 4.0).max(0.0),
        Action::Right => app.view.start_s = (s0 + (s1 - s0) / 4.0).min((d - (s1 - s0)).max(0.0)),
        Action::CursorLeft => app.view.cursor_s = (app.view.cursor_s - step).clamp(0.0, d),
        Action::CursorRight => app.view.cursor_s = (app.view.cursor_s + step).clamp(0.0, d),
        Action::Home => app.view.cursor_s = 0.0,
        Action::End => app.view.cursor_s = d,
        Action::Marker => app.view.braille = !app.view.braille,
        Action::NextGlitch => next_glitch(app),
        Action::Variant => app.next_variant(),
        Action::Pose => return crate::ui::pose::toggle(app).into(),
        Action::Scatter => return Reply::nav(Nav::View(ViewKind::Scatter)),
        Action::Globe => return Reply::nav(Nav::View(ViewKind::Globe)),
        Action::Applied => return Reply::nav(Nav::View(ViewKind::Applied)),
        Action::Stick => return Reply::nav(Nav::View(ViewKind::Stick)),
        Action::HeadingDrift => return Reply::nav(Nav::View(ViewKind::Heading)),
        Action::Compare => return Reply::nav(Nav::Compare),
        // Saving is the compare screen's; a growing trial says why it waits.
        Action::Save => {
            if let Some(f) = app.open.clone() {
                app.refuse_save_while_growing(&f);
            }
        }
        Action::Run => {
            if let Some(f) = app.open.clone() {
                return app.run_effect(&f, None).into();
            }
        }
        _ => {}
    }
    // Keep the cursor in view when it moved.
    if matches!(
        a,
        Action::CursorLeft | Action::CursorRight | Action::Home | Action::End | Action::NextGlitch
    ) {
        let (s0, s1) = app.view.span(d);
        let w = s1 - s0;
        let c = app.view.cursor_s;
        if c < s0 || c > s1 {
            app.view.start_s = (c - w / 2.0).clamp(0.0, (d - w).max(0.0));
        }
    }
    Reply::default()
}

/// Moves the cursor to the selected joint's next glitch (wrapping).
fn next_glitch(app: &mut Workbench) {
    let Some(l) = app.open_entry().and_then(|e| e.loaded()) else {
        return;
    };
    let Some(joint) = l.before.get(app.joint).map(|f| f.joint.clone()) else {
        return;
    };
    let found = crate::ui::glitches::of_joint(l, &joint);
    match crate::ui::glitches::next_after(&found, app.view.cursor_s) {
        Some(t) => app.view.cursor_s = t,
        // Said, not silently ignored.
        None if found.is_empty() => app.info(format!("{joint}: no glitches")),
        None => app.info(format!("{joint}: no glitch after the cursor")),
    }
}

/// Zooms the time axis in or out about the cursor (or the centre when the
/// cursor is out of view).
pub fn zoom(app: &mut Workbench, zoom_in: bool) {
    let Some(d) = app
        .open_entry()
        .and_then(|e| e.loaded())
        .map(|l| l.trial.duration_s())
    else {
        return;
    };
    let (a, b) = app.view.span(d);
    let centre = if app.view.cursor_s >= a && app.view.cursor_s <= b {
        app.view.cursor_s
    } else {
        (a + b) / 2.0
    };
    if zoom_in {
        app.view.zoom = (app.view.zoom + 1).min(12);
    } else {
        app.view.zoom = app.view.zoom.saturating_sub(1);
    }
    let w = d / f64::from(1u32 << app.view.zoom);
    app.view.start_s = (centre - w / 2.0).clamp(0.0, (d - w).max(0.0));
}

#[cfg(test)]
mod tests {
    use crate::reference::write_csv;
    use crate::simulate::{preset, simulate};
    use crate::trial::{write_trial, TrialFormat};
    use crate::ui::headless::{buffer_text, draw, load_app, show, Show};
    use crate::ui::theme::Theme;

    /// A 20 s knee trial with its truth written beside it as an optical
    /// reference (`knee.reference.csv`) whose clock runs 0.4 s ahead: the
    /// trial screen draws it with its own marker, names it and its lag.
    #[test]
    fn the_reference_beside_a_trial_is_drawn_on_the_trial_screen() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("trials");
        std::fs::create_dir_all(&dir).unwrap();
        let mut cfg = preset("knee_calf_z15").unwrap();
        cfg.duration_s = 20.0;
        let sim = simulate(&cfg).unwrap();
        write_trial(&sim.trial, &dir.join("knee.csv"), TrialFormat::QuatCsv).unwrap();
        let knee = crate::model::Model::infant13();
        let knee = knee.joint("l_knee").unwrap();
        let truth = sim.truth.true_joint_angles(knee);
        let time: Vec<f64> = sim.trial.time_s.iter().map(|t| t + 0.4).collect();
        let columns: Vec<(String, Vec<f64>)> = ["x", "y", "z"]
            .iter()
            .enumerate()
            .map(|(k, a)| (format!("l_knee_{a}"), truth.iter().map(|v| v[k]).collect()))
            .collect();
        write_csv(&dir.join("knee.reference.csv"), &time, &columns).unwrap();
        let mut app = load_app("trials", &dir, &tmp.path().join("joint_limits")).unwrap();
        // The reference is not listed as a trial.
        assert_eq!(app.trials.len(), 1);
        show(
            &mut app,
            &Show {
                screen: "trial".into(),
                trial: Some("knee.csv".into()),
                ..Show::default()
            },
        )
        .unwrap();
        let l = app.trials[0].loaded().unwrap();
        let r = l.reference.as_ref().expect("reference read");
        assert!((r.lag_s - 0.4).abs() < 1e-9, "{}", r.lag_s);
        // At the cursor the reference reads the truth (the titles show it).
        app.wb.view.cursor_s = 5.0;
        for (w, h) in crate::ui::tests::SIZES {
            let text = buffer_text(&draw(&app, &Theme::default(), w, h));
            // The footer names the lag where it has room.
            assert!(w < 120 || text.contains("ref lag +0.40 s"), "{text}");
            // Named in the legend, drawn with its own glyph, and its value at
            // the cursor in each chart's title where the title has room.
            assert!(text.contains("∘ref") || text.contains("∘∘ ref"), "{text}");
            assert!(text.matches('∘').count() > 20, "{text}");
            let named = text
                .match_indices(" ref ")
                .filter(|(i, _)| {
                    text[i + 5..].starts_with(|c: char| c.is_ascii_digit() || c == '-')
                })
                .count();
            assert!(w < 80 || named == 3, "{text}");
            insta::assert_snapshot!(format!("trial_reference_{w}x{h}"), text);
        }
    }
}
