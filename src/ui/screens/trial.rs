//! The trial screen: joints, three angle charts with limits, figures.

use crate::limits::axis_name;
use crate::metrics::JointFigures;
use crate::ui::cells::{fit, num, sel};
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

pub fn render(app: &Workbench, theme: &Theme, f: &mut Frame, area: Rect) {
    let Some(e) = app.open_entry() else {
        f.render_widget(Paragraph::new("no trial open (Esc)"), area);
        return;
    };
    let Some(l) = e.loaded() else {
        f.render_widget(Paragraph::new("trial not loaded"), area);
        return;
    };
    let left_w = if area.width >= 100 { 32 } else { 26 }.min(area.width / 2);
    let [left, right] =
        Layout::horizontal([Constraint::Length(left_w), Constraint::Min(1)]).areas(area);
    let figs_h = 9.min(left.height / 2);
    let [jl, fl] = Layout::vertical([Constraint::Min(1), Constraint::Length(figs_h)]).areas(left);

    // Joint list.
    let joints: Vec<&JointFigures> = l.before.iter().collect();
    let after = e.figures(Some(app.variant));
    let iw = jl.width.saturating_sub(1) as usize;
    let mut lines = vec![Line::from(Span::styled(
        format!(
            "{}{:>6}{:>6}",
            fit("joint", iw.saturating_sub(12)),
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
    let cor = e
        .results
        .get(&app.variant)
        .and_then(|r| r.angles.get(&r.correction.corrected, joint));
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
    let [charts, foot] = Layout::vertical([Constraint::Min(1), Constraint::Length(1)]).areas(right);
    let parts = Layout::vertical([Constraint::Ratio(1, 3); 3]).split(charts);
    for axis in 0..3 {
        let range = lim.map(|l| l.range_deg[axis]);
        let centroid = lim.and_then(|l| l.centroid_deg).map(|c| c[axis]);
        let mut title = vec![Span::styled(format!(" {} ", axis_name(axis)), theme.header)];
        if let Some([lo, hi]) = range {
            title.push(Span::styled(format!("[{lo}, {hi}] "), theme.limit));
        }
        if let Some(c) = centroid {
            title.push(Span::styled(format!("c {c} "), theme.centroid));
        }
        title.push(Span::styled(
            format!("raw {} ", num(raw.get(ci).map(|a| a[axis]), 0)),
            theme.raw,
        ));
        if let Some(c) = &cor {
            title.push(Span::styled(
                format!("{} {} ", app.variant, num(c.get(ci).map(|a| a[axis]), 0)),
                theme.corrected,
            ));
        }
        let ref_axis = reference.and_then(|r| r[axis].as_deref());
        if let Some(r) = ref_axis {
            let v = r.get(ci).copied().filter(|v| v.is_finite());
            title.push(Span::styled(format!("ref {} ", num(v, 0)), theme.ok));
        }
        chart(
            f,
            parts[axis],
            theme,
            Line::from(title),
            ChartData {
                t,
                origin,
                axis,
                raw: &raw,
                cor: cor.as_deref().map(Vec::as_slice),
                reference: ref_axis,
                range,
                centroid,
                span: (s0, s1),
                cursor: app.view.cursor_s,
                braille: app.view.braille,
                glitches: crate::ui::glitches::markers(&glitches, &raw, axis, (s0, s1)),
            },
        );
    }
    let note = e
        .variant_note_short(app.variant)
        .filter(|_| e.running.is_none());
    let status = if let Some(p) = e.running {
        format!("running {p}%")
    } else if note.is_some() {
        String::new()
    } else if e.results.contains_key(&app.variant) {
        format!("{} done", app.variant)
    } else {
        "not run: r runs all variants".to_string()
    };
    f.render_widget(
        Paragraph::new(Line::from(vec![
            Span::raw(format!(
                " t {s0:.1}-{s1:.1} s  x{}  cursor {:.2} s  ",
                1u32 << app.view.zoom.min(16),
                app.view.cursor_s
            )),
            Span::styled(
                crate::ui::glitches::footer(&glitches, app.view.cursor_s).unwrap_or_default(),
                theme.warn,
            ),
            Span::styled(status, theme.dim),
            Span::styled(
                l.reference
                    .as_ref()
                    .map(|r| format!("  ref lag {:+.2} s", r.lag_s))
                    .unwrap_or_default(),
                theme.ok,
            ),
            Span::styled(note.unwrap_or_default(), theme.warn),
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
    /// The optical reference's angle of this axis per sample (NaN: none).
    reference: Option<&'a [f64]>,
    range: Option<[f64; 2]>,
    centroid: Option<f64>,
    span: (f64, f64),
    cursor: f64,
    braille: bool,
    /// Glitch markers `(time, angle)` of the joint's IMUs in view.
    glitches: Vec<(f64, f64)>,
}

fn chart(f: &mut Frame, area: Rect, theme: &Theme, title: Line, d: ChartData) {
    if area.height < 2 || area.width < 10 {
        return;
    }
    let (s0, s1) = d.span;
    let label_w = 5u16;
    let cols = area.width.saturating_sub(label_w + 1).max(1) as usize;
    let per_col = if d.braille { 2 } else { 1 };
    let raw = envelope(d.t, d.origin, |i| d.raw[i][d.axis], s0, s1, cols * per_col);
    let cor = d
        .cor
        .map(|c| envelope(d.t, d.origin, |i| c[i][d.axis], s0, s1, cols * per_col))
        .unwrap_or_default();
    let reference: Vec<(f64, f64)> = d
        .reference
        .map(|r| envelope(d.t, d.origin, |i| r[i], s0, s1, cols * per_col))
        .unwrap_or_default()
        .into_iter()
        .filter(|(_, y)| y.is_finite())
        .collect();
    // Bounds: the data in view and the limits.
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for &(_, y) in raw.iter().chain(cor.iter()).chain(reference.iter()) {
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
    let lower: Vec<(f64, f64)>;
    let upper: Vec<(f64, f64)>;
    let centre: Vec<(f64, f64)>;
    let cursor = vec![(d.cursor, lo), (d.cursor, hi)];
    let marker = if d.braille {
        Marker::Braille
    } else {
        Marker::Dot
    };
    // Limit lines first: a later dataset overwrites whole cells.
    let mut sets = vec![];
    if let Some([a, b]) = d.range {
        lower = vec![(s0, a), (s1, a)];
        upper = vec![(s0, b), (s1, b)];
        sets.push(line(&lower, theme.limit, marker));
        sets.push(line(&upper, theme.limit, marker));
    }
    if let Some(c) = d.centroid {
        centre = vec![(s0, c), (s1, c)];
        sets.push(line(&centre, theme.centroid, marker));
    }
    if d.cursor >= s0 && d.cursor <= s1 {
        sets.push(line(&cursor, theme.cursor, marker));
    }
    sets.push(line(&raw, theme.raw, marker));
    if !cor.is_empty() {
        sets.push(line(&cor, theme.corrected, marker));
    }
    // The reference as points of the other marker (named `ref` in the title),
    // so it reads apart from raw and corrected without colour.
    if !reference.is_empty() {
        let other = if d.braille {
            Marker::Dot
        } else {
            Marker::Braille
        };
        sets.push(
            Dataset::default()
                .data(&reference)
                .graph_type(GraphType::Scatter)
                .marker(other)
                .style(theme.ok),
        );
    }
    // Glitches last, as full blocks: a glyph of their own, not colour alone.
    if !d.glitches.is_empty() {
        sets.push(
            Dataset::default()
                .data(&d.glitches)
                .graph_type(GraphType::Scatter)
                .marker(Marker::Block)
                .style(theme.warn),
        );
    }
    let y_labels = if area.height >= 7 {
        vec![
            format!("{lo:.0}"),
            format!("{:.0}", (lo + hi) / 2.0),
            format!("{hi:.0}"),
        ]
    } else {
        vec![format!("{lo:.0}"), format!("{hi:.0}")]
    };
    let chart = Chart::new(sets)
        .block(Block::new().borders(Borders::TOP).title(title))
        .x_axis(Axis::default().bounds([s0, s1]))
        .y_axis(
            Axis::default()
                .bounds([lo, hi])
                .labels(y_labels)
                .style(theme.dim),
        )
        .legend_position(None);
    f.render_widget(chart, area);
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
    let row = |label: &str, v: Option<[f64; 3]>| {
        let mut s = format!("{label:<6}");
        for k in 0..3 {
            s.push_str(&num(v.map(|v| v[k]), 6));
        }
        Line::from(s)
    };
    let mut lines = vec![
        Line::from(Span::styled(
            format!("{:<6}{:>6}{:>6}{:>6}", "deg", "X", "Y", "Z"),
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
        num(
            after
                .and_then(|f| f.shift.as_ref())
                .map(|s| s.mean_correction_angle_deg),
            6
        )
    )));
    f.render_widget(
        Paragraph::new(lines).block(
            Block::new()
                .borders(Borders::TOP | Borders::RIGHT)
                .title(" figures "),
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
    app.select_file(&file);
    app.open = Some(file);
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
        Action::Up => app.joint = app.joint.saturating_sub(1),
        Action::Down => app.joint = (app.joint + 1).min(joints.saturating_sub(1)),
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
    if let Some(t) = crate::ui::glitches::next_after(&found, app.view.cursor_s) {
        app.view.cursor_s = t;
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
            // Named in each chart's title, drawn with the other marker.
            let named = text.matches(" ref ").count() - text.matches(" ref lag").count();
            assert_eq!(named, 3, "{text}");
            assert!(text.contains('•'), "{text}");
            insta::assert_snapshot!(format!("trial_reference_{w}x{h}"), text);
        }
    }
}
