//! The histogram screen (key `H` from the trials or trial screen): per joint
//! and axis, the histogram of the chosen trials' angles over a span (the
//! first 30 s unless moved), with the current limits, the mean and the
//! interval holding 90% of the samples (thesis 3.1.2); Enter suggests a limit
//! table from those intervals and shows its diff before saving it beside the
//! current table; `w` saves the centroid table (thesis 3.3). Everything is
//! computed in a background job; a suggestion or centroid save asked for while
//! it runs is carried out when it arrives.
//!
//! The trials are the open one (from the trial screen) or every loaded trial
//! the trials screen shows (filter with `/` first to choose).

use crate::analysis::histogram::{AxisHistogram, JointHistogram};
use crate::analysis::suggest::{suggest_limits, SuggestOptions, Suggestion};
use crate::analysis::TimeSpan;
use crate::limits::axis_name;
use crate::ui::cells::{centred, counter, fit, sel};
use crate::ui::keymap::Action;
use crate::ui::msg::{Computed, Effect, Nav, Reply, RowAnalysis, Screen};
use crate::ui::theme::Theme;
use crate::ui::workbench::Workbench;
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::symbols::Marker;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Axis, Block, Borders, Chart, Clear, Dataset, GraphType, Paragraph};
use ratatui::Frame;
use std::path::PathBuf;
use std::sync::Arc;

/// Shortest span the `-` key narrows to, seconds.
const MIN_SPAN_S: f64 = 5.0;

/// State of the histogram screen.
#[derive(Debug, Clone)]
pub struct HistogramState {
    /// The screen Esc returns to.
    pub from: Screen,
    /// Trial files the histograms pool.
    pub files: Vec<String>,
    pub span: TimeSpan,
    /// One per joint, in model order, of the span last computed.
    pub hists: Vec<JointHistogram>,
    /// Still computing `span` in the background: `hists` are of an earlier
    /// span (or empty) until it arrives.
    pub computing: bool,
    /// The span's samples pooled per limit-table row, for the suggestion and
    /// the centroids (of the span and table last computed).
    pub rows: Option<Arc<RowAnalysis>>,
    /// Enter or `w` pressed while computing: done when the job answers.
    pub pending: Option<Action>,
    /// Selected joint (index into `hists`).
    pub joint: usize,
    /// A suggested table waiting for y (save) or n (cancel), and the diff's scroll.
    pub suggestion: Option<Arc<Suggestion>>,
    pub scroll: usize,
    /// A write over an existing file waiting for y (overwrite) or n: the
    /// file and the CSV it would get.
    pub overwrite: Option<(PathBuf, String)>,
}

/// Opens the screen over the trials the current screen has chosen.
pub fn open(hist: &mut Option<HistogramState>, app: &mut Workbench, from: Screen) -> Vec<Effect> {
    let files: Vec<String> = match from {
        Screen::Trial | Screen::Compare => app.open.clone().into_iter().collect(),
        _ => app
            .visible()
            .into_iter()
            .filter(|&i| app.trials[i].loaded().is_some())
            .map(|i| app.trials[i].file.clone())
            .collect(),
    };
    if files.is_empty() {
        app.message = Some(("no loaded trial to take histograms of".into(), true));
        return vec![];
    }
    let effect = request(app, &files, TimeSpan::FIRST_30_S);
    *hist = Some(HistogramState {
        from,
        files,
        span: TimeSpan::FIRST_30_S,
        hists: vec![],
        computing: true,
        rows: None,
        pending: None,
        joint: 0,
        suggestion: None,
        scroll: 0,
        overwrite: None,
    });
    vec![effect]
}

/// The background job computing the histograms of `files` over `span`.
fn request(app: &Workbench, files: &[String], span: TimeSpan) -> Effect {
    Effect::Histograms {
        trials: files
            .iter()
            .filter_map(|f| app.entry(f)?.loaded().cloned())
            .collect(),
        span,
        table: app.limits.table.clone(),
    }
}

/// Takes the results of the span the screen last asked for (dropping those of
/// spans it has moved past), then does a suggestion or save asked for meanwhile.
pub fn received(
    hist: &mut Option<HistogramState>,
    app: &mut Workbench,
    c: Computed,
) -> Vec<Effect> {
    let Some(st) = hist.as_mut().filter(|st| st.span == c.span) else {
        return vec![];
    };
    st.hists = c.joints;
    st.rows = Some(c.rows);
    st.computing = false;
    st.joint = st.joint.min(st.hists.len().saturating_sub(1));
    match st.pending.take() {
        Some(Action::Enter) => suggest(hist, app),
        Some(Action::Save) => save_centroids(hist, app),
        _ => vec![],
    }
}

/// The row analysis of the current span against the current table; else
/// `then` is remembered for when it arrives (asking for it if the table changed).
fn ready_rows(
    hist: &mut Option<HistogramState>,
    app: &mut Workbench,
    then: Action,
) -> Result<Arc<RowAnalysis>, Vec<Effect>> {
    let table = &app.limits.table;
    let Some(st) = hist.as_mut() else {
        return Err(vec![]);
    };
    match &st.rows {
        Some(r) if !st.computing && r.table == *table => Ok(r.clone()),
        _ => {
            st.pending = Some(then);
            app.message = Some(("computing; done when the histograms arrive".into(), false));
            if st.computing {
                return Err(vec![]);
            }
            st.computing = true;
            let (files, span) = (st.files.clone(), st.span);
            Err(vec![request(app, &files, span)])
        }
    }
}

/// The suggested table's file: `<table stem>.suggested.csv` beside the table.
pub fn suggested_path(app: &Workbench) -> PathBuf {
    let name = &app.limits.table_name;
    let stem = name.strip_suffix(".csv").unwrap_or(name);
    app.limits.dir.join(format!("{stem}.suggested.csv"))
}

/// The centroid table's file, beside the limit tables.
pub fn centroids_path(app: &Workbench) -> PathBuf {
    app.limits.dir.join("centroids.csv")
}

/// Applies a key on the histogram screen.
pub fn action(hist: &mut Option<HistogramState>, app: &mut Workbench, a: Action) -> Reply {
    let Some(st) = hist.as_mut() else {
        return Reply::nav(Nav::To(Screen::Trials));
    };
    if st.overwrite.is_some() {
        return overwrite(st, app, a).into();
    }
    if let Some(s) = st.suggestion.clone() {
        return confirm(hist, app, &s, a).into();
    }
    let mut span = st.span;
    let len = if span.end_s.is_finite() {
        span.end_s - span.start_s
    } else {
        f64::INFINITY
    };
    match a {
        Action::Back => return Reply::nav(Nav::To(st.from)),
        Action::Up | Action::Down | Action::PageUp | Action::PageDown => {
            if let Some(i) = crate::ui::cells::list_move(a, st.joint, st.hists.len(), 10) {
                st.joint = i;
            }
        }
        Action::Left if len.is_finite() => {
            span.start_s = (span.start_s - len).max(0.0);
            span.end_s = span.start_s + len;
        }
        Action::Right if len.is_finite() => {
            span.start_s += len;
            span.end_s += len;
        }
        Action::ZoomIn if len.is_finite() => {
            span.end_s = span.start_s + (len / 2.0).max(MIN_SPAN_S)
        }
        Action::ZoomOut if len.is_finite() => span.end_s = span.start_s + 2.0 * len,
        Action::Home => span = TimeSpan::FIRST_30_S,
        Action::End => span = TimeSpan::WHOLE,
        Action::Enter => return suggest(hist, app).into(),
        Action::Save => return save_centroids(hist, app).into(),
        _ => {}
    }
    if span != st.span {
        st.span = span;
        st.computing = true;
        let files = st.files.clone();
        return vec![request(app, &files, span)].into();
    }
    Reply::default()
}

/// The suggestion from the chosen trials' intervals, pooled per table row.
fn suggest(hist: &mut Option<HistogramState>, app: &mut Workbench) -> Vec<Effect> {
    let rows = match ready_rows(hist, app, Action::Enter) {
        Ok(r) => r,
        Err(fx) => return fx,
    };
    let Some(st) = hist.as_mut() else {
        return vec![];
    };
    let s = suggest_limits(&rows.table, &rows.hists, st.span, SuggestOptions::default());
    {
        st.suggestion = Some(Arc::new(s));
        st.scroll = 0;
    }
    vec![]
}

/// Keys while the diff is shown: y saves, n or Esc cancels, arrows scroll.
fn confirm(
    hist: &mut Option<HistogramState>,
    app: &Workbench,
    s: &Suggestion,
    a: Action,
) -> Vec<Effect> {
    let path = suggested_path(app);
    let original = app.limits.dir.join(&app.limits.table_name);
    let Some(st) = hist.as_mut() else {
        return vec![];
    };
    match a {
        Action::Yes | Action::Save => {
            st.suggestion = None;
            return vec![Effect::WriteTable {
                path,
                original: Some(original),
                csv: s.table.to_csv(),
            }];
        }
        Action::No | Action::Back => st.suggestion = None,
        Action::Up => st.scroll = st.scroll.saturating_sub(1),
        Action::Down => st.scroll = (st.scroll + 1).min(s.rows.len()),
        _ => {}
    }
    vec![]
}

fn save_centroids(hist: &mut Option<HistogramState>, app: &mut Workbench) -> Vec<Effect> {
    let rows = match ready_rows(hist, app, Action::Save) {
        Ok(r) => r,
        Err(fx) => return fx,
    };
    let path = centroids_path(app);
    let csv = rows.centroids.to_csv();
    // An existing file is not overwritten without asking (the only look at
    // the disk on this screen: whether the file is there).
    if path.exists() {
        if let Some(st) = hist.as_mut() {
            st.overwrite = Some((path, csv));
        }
        return vec![];
    }
    vec![Effect::WriteTable {
        path,
        original: None,
        csv,
    }]
}

/// Keys while an overwrite is asked: y (or `w` again) writes, n or Esc keeps
/// the file as it is.
fn overwrite(st: &mut HistogramState, app: &mut Workbench, a: Action) -> Vec<Effect> {
    match a {
        Action::Yes | Action::Save => {
            if let Some((path, csv)) = st.overwrite.take() {
                return vec![Effect::WriteTable {
                    path,
                    original: None,
                    csv,
                }];
            }
        }
        Action::No | Action::Back => {
            if let Some((path, _)) = st.overwrite.take() {
                app.info(format!("{} left as it was", path.display()));
            }
        }
        _ => {}
    }
    vec![]
}

/// Reports a finished write in the status bar.
pub fn written(app: &mut Workbench, result: Result<String, String>) {
    app.message = Some(match result {
        Ok(p) => (format!("saved {p}"), false),
        Err(m) => (format!("cannot save: {m}"), true),
    });
}

/// Draws the screen.
pub fn render(
    hist: &Option<HistogramState>,
    app: &Workbench,
    theme: &Theme,
    f: &mut Frame,
    area: Rect,
) {
    let Some(st) = hist.as_ref() else {
        f.render_widget(Paragraph::new("no histograms (Esc)"), area);
        return;
    };
    let left_w = if area.width >= 100 { 30 } else { 24 }.min(area.width / 2);
    let [left, right] =
        Layout::horizontal([Constraint::Length(left_w), Constraint::Min(1)]).areas(area);
    joint_list(st, theme, f, left);
    let [head, charts] = Layout::vertical([Constraint::Length(1), Constraint::Min(1)]).areas(right);
    let samples = st
        .hists
        .get(st.joint)
        .and_then(|h| h.axes[0].as_ref())
        .map_or(0, |a| a.count);
    f.render_widget(
        Paragraph::new(Line::from(vec![
            Span::styled(format!(" {} ", st.span.label()), theme.header),
            Span::raw(format!(
                "{} trial(s), {samples} samples  ",
                st.hists.get(st.joint).map_or(0, |h| h.trials)
            )),
            Span::styled("lim", theme.limit),
            Span::raw(" "),
            Span::styled("mean", theme.centroid),
            Span::raw(" "),
            Span::styled("90%", theme.corrected),
            Span::styled(if st.computing { "  computing..." } else { "" }, theme.warn),
        ])),
        head,
    );
    if let Some(h) = st.hists.get(st.joint) {
        let parts = Layout::vertical([Constraint::Ratio(1, 3); 3]).split(charts);
        for axis in 0..3 {
            let range = h.limits.map(|l| l.range_deg[axis]);
            if let Some(a) = &h.axes[axis] {
                axis_chart(f, parts[axis], theme, axis, a, range);
            }
        }
    } else if st.computing {
        f.render_widget(Paragraph::new(" computing the histograms..."), charts);
    } else {
        f.render_widget(Paragraph::new(" no samples in this span"), charts);
    }
    if let Some(s) = &st.suggestion {
        diff_popup(app, s, st.scroll, theme, f, area);
    }
    if let Some((path, _)) = &st.overwrite {
        let name = path
            .file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned());
        let lines = vec![
            Line::from(format!("{name} exists in {}.", app.limits.dir.display())),
            Line::from("Overwrite it with these centroids?"),
            Line::from(""),
            Line::from(vec![
                Span::styled("y", theme.title),
                Span::raw(" overwrite   "),
                Span::styled("n", theme.title),
                Span::raw(" keep the file"),
            ]),
        ];
        let r = centred(area, 56, 6);
        f.render_widget(Clear, r);
        f.render_widget(
            Paragraph::new(lines)
                .wrap(ratatui::widgets::Wrap { trim: false })
                .block(
                    Block::new()
                        .borders(Borders::ALL)
                        .title(Span::styled(" Overwrite? ", theme.title)),
                ),
            r,
        );
    }
}

fn joint_list(st: &HistogramState, theme: &Theme, f: &mut Frame, area: Rect) {
    let w = area.width.saturating_sub(1) as usize;
    let mut lines = vec![Line::from(Span::styled(
        fit(
            &format!(
                "joint {}, {} trial(s)",
                counter(st.joint, st.hists.len()),
                st.files.len()
            ),
            w,
        ),
        theme.header,
    ))];
    let rows = area.height.saturating_sub(1) as usize;
    let first = st.joint.saturating_sub(rows.saturating_sub(1));
    for (k, h) in st.hists.iter().enumerate().skip(first).take(rows) {
        let n = h.axes[0].as_ref().map_or(0, |a| a.count);
        let mark = if k == st.joint { ">" } else { " " };
        let name = fit(&format!("{mark}{}", h.name), w.saturating_sub(7));
        lines.push(Line::from(format!("{name}{n:>7}")).style(sel(theme, k == st.joint)));
    }
    f.render_widget(
        Paragraph::new(lines).block(Block::new().borders(Borders::RIGHT)),
        area,
    );
}

/// One axis: the bars, the limit lines, the mean and the 90% interval.
fn axis_chart(
    f: &mut Frame,
    area: Rect,
    theme: &Theme,
    axis: usize,
    h: &AxisHistogram,
    range: Option<[f64; 2]>,
) {
    if area.height < 3 || area.width < 12 {
        return;
    }
    let last = h.first_edge_deg + h.counts.len() as f64 * h.bin_deg;
    let (mut x0, mut x1) = (h.first_edge_deg, last);
    if let Some([l, u]) = range {
        x0 = x0.min(l);
        x1 = x1.max(u);
    }
    let pad = ((x1 - x0) * 0.03).max(1.0);
    let (x0, x1) = (x0 - pad, x1 + pad);
    let top = f64::from(h.peak()).max(1.0) * 1.05;
    let bars: Vec<(f64, f64)> = h
        .counts
        .iter()
        .enumerate()
        .filter(|(_, &c)| c > 0)
        .map(|(k, &c)| (h.bin_centre(k), f64::from(c)))
        .collect();
    let vline = |x: f64| vec![(x, 0.0), (x, top)];
    let [lo90, hi90] = h.interval_deg;
    let lines: Vec<(Vec<(f64, f64)>, ratatui::style::Style)> = range
        .into_iter()
        .flatten()
        .map(|x| (vline(x), theme.limit))
        .chain([
            (vline(lo90), theme.corrected),
            (vline(hi90), theme.corrected),
            (vline(h.mean_deg), theme.centroid),
        ])
        .collect();
    // Lines first: a later dataset overwrites whole cells, and the bars
    // must stay readable where they cross a line.
    let mut sets: Vec<Dataset> = lines
        .iter()
        .map(|(pts, style)| {
            Dataset::default()
                .data(pts)
                .graph_type(GraphType::Line)
                .marker(Marker::Braille)
                .style(*style)
        })
        .collect();
    sets.push(
        Dataset::default()
            .data(&bars)
            .graph_type(GraphType::Bar)
            .marker(Marker::Braille)
            .style(theme.raw),
    );
    let mut title = vec![
        Span::styled(format!(" {} ", axis_name(axis)), theme.header),
        Span::raw(format!("m {:.1} sd {:.1} ", h.mean_deg, h.sd_deg)),
        Span::styled(format!("90% [{lo90:.1}, {hi90:.1}] "), theme.corrected),
    ];
    if let Some([l, u]) = range {
        title.push(Span::styled(format!("lim [{l}, {u}] "), theme.limit));
    }
    let chart = Chart::new(sets)
        .block(Block::new().borders(Borders::TOP).title(Line::from(title)))
        .x_axis(
            Axis::default()
                .bounds([x0, x1])
                .labels([format!("{x0:.0}"), format!("{x1:.0}")])
                .style(theme.dim),
        )
        .y_axis(
            Axis::default()
                .bounds([0.0, top])
                .labels(["0".to_string(), format!("{}", h.peak())])
                .style(theme.dim),
        )
        .legend_position(None);
    f.render_widget(chart, area);
}

fn diff_popup(
    app: &Workbench,
    s: &Suggestion,
    scroll: usize,
    theme: &Theme,
    f: &mut Frame,
    body: Rect,
) {
    let diff = s.diff_lines();
    let w = (diff.iter().map(|l| l.len()).max().unwrap_or(40) + 4).max(50) as u16;
    let area = centred(body, w, body.height);
    f.render_widget(Clear, area);
    let block = Block::new().borders(Borders::ALL).title(Span::styled(
        " Suggested limits (90% intervals) ",
        theme.title,
    ));
    let inner = block.inner(area);
    f.render_widget(block, area);
    let [head, rows, foot] = Layout::vertical([
        Constraint::Length(1),
        Constraint::Min(1),
        Constraint::Length(2),
    ])
    .areas(inner);
    f.render_widget(
        Paragraph::new(Span::styled(diff[0].clone(), theme.header)),
        head,
    );
    let body_lines: Vec<Line> = diff[1..]
        .iter()
        .skip(scroll)
        .map(|l| Line::from(l.as_str()))
        .collect();
    f.render_widget(Paragraph::new(body_lines), rows);
    let file = suggested_path(app);
    let name = file.file_name().map(|n| n.to_string_lossy().into_owned());
    f.render_widget(
        Paragraph::new(vec![
            Line::from(format!(
                "against {}; saves {} beside it",
                app.limits.table_name,
                name.unwrap_or_default()
            )),
            Line::from(vec![
                Span::styled("y", theme.title),
                Span::raw(" save   "),
                Span::styled("n", theme.title),
                Span::raw(" cancel   "),
                Span::styled("Up/Down", theme.title),
                Span::raw(" scroll"),
            ]),
        ]),
        foot,
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::limits::LimitTable;
    use crate::ui::app::{open as open_trial, update, App, Msg};
    use crate::ui::headless::{buffer_text, draw, load_app, write_demo_folder};
    use crate::ui::jobs::histogram::{compute_job, write_job};
    use crate::ui::jobs::SyncRunner;
    use ratatui::crossterm::event::{KeyCode, KeyEvent};

    fn key(app: &mut App, c: KeyCode) {
        SyncRunner::send(app, Msg::Key(KeyEvent::from(c)));
    }

    fn snap(name: &str, app: &App) {
        for (w, h) in crate::ui::tests::SIZES {
            let text = buffer_text(&draw(app, &Theme::default(), w, h));
            insta::assert_snapshot!(format!("{name}_{w}x{h}"), text);
        }
    }

    #[test]
    fn suggest_shows_the_diff_and_saves_beside_the_table() {
        let tmp = tempfile::tempdir().unwrap();
        let root = tmp.path();
        write_demo_folder(&root.join("trials")).unwrap();
        let mut app = load_app("trials", &root.join("trials"), &root.join("joint_limits")).unwrap();
        open_trial(&mut app, "fb.csv.gz".into());
        key(&mut app, KeyCode::Char('H'));
        assert_eq!(app.screen, Screen::Histogram);
        let st = app.histogram.as_ref().unwrap();
        assert_eq!((st.files.len(), st.hists.len()), (1, 12));
        assert_eq!(st.span, TimeSpan::FIRST_30_S);
        // 30 s at 50 Hz.
        assert_eq!(st.hists[0].axes[0].as_ref().unwrap().count, 1500);
        key(&mut app, KeyCode::Down);
        key(&mut app, KeyCode::Enter);
        assert!(app.histogram.as_ref().unwrap().suggestion.is_some());
        snap("histogram_diff", &app);
        // n cancels; Enter again and y saves beside the (built-in) table.
        key(&mut app, KeyCode::Char('n'));
        assert!(app.histogram.as_ref().unwrap().suggestion.is_none());
        key(&mut app, KeyCode::Enter);
        key(&mut app, KeyCode::Char('y'));
        let saved = root.join("joint_limits/table_3_2.suggested.csv");
        let t = LimitTable::load(&saved).unwrap();
        assert_eq!(t.rows.len(), app.limits.table.rows.len());
        assert!(!root.join("joint_limits/table_3_2.csv").exists());
        assert!(
            app.message.as_ref().unwrap().0.starts_with("saved "),
            "{:?}",
            app.message
        );
        // w saves the centroid table.
        key(&mut app, KeyCode::Char('w'));
        let c = std::fs::read_to_string(root.join("joint_limits/centroids.csv")).unwrap();
        assert!(
            c.contains("\njoint,axis,centroid_deg,sd_deg,samples,trials\nback,X,"),
            "{c}"
        );
        // w again: the file exists, so it asks; n keeps it, y overwrites.
        let path = root.join("joint_limits/centroids.csv");
        std::fs::write(&path, "mine\n").unwrap();
        key(&mut app, KeyCode::Char('w'));
        assert!(app.histogram.as_ref().unwrap().overwrite.is_some());
        let text = buffer_text(&draw(&app, &Theme::default(), 80, 24));
        assert!(
            text.contains("centroids.csv exists") && text.contains("y overwrite"),
            "{text}"
        );
        key(&mut app, KeyCode::Char('n'));
        assert!(app.histogram.as_ref().unwrap().overwrite.is_none());
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "mine\n");
        key(&mut app, KeyCode::Char('w'));
        key(&mut app, KeyCode::Char('y'));
        assert_eq!(std::fs::read_to_string(&path).unwrap(), c);
        // The next 30 s of a 30 s trial hold nothing; Home comes back.
        key(&mut app, KeyCode::Right);
        assert!(app.histogram.as_ref().unwrap().hists.is_empty());
        snap("histogram_empty", &app);
        key(&mut app, KeyCode::Home);
        assert_eq!(app.histogram.as_ref().unwrap().hists.len(), 12);
        key(&mut app, KeyCode::End);
        assert_eq!(app.histogram.as_ref().unwrap().span, TimeSpan::WHOLE);
        key(&mut app, KeyCode::Esc);
        assert_eq!(app.screen, Screen::Trial);
        // From the trials screen: every loaded trial the list shows.
        key(&mut app, KeyCode::Esc);
        let fx = update(&mut app, Msg::Key(KeyEvent::from(KeyCode::Char('H'))));
        // The histograms come from a background job; the screen says so meanwhile.
        assert!(matches!(fx[..], [Effect::Histograms { .. }]), "{fx:?}");
        let st = app.histogram.as_ref().unwrap();
        assert_eq!(st.files, ["fb.csv.gz", "knee.csv"]);
        assert!(st.computing && st.hists.is_empty());
        let text = buffer_text(&draw(&app, &Theme::default(), 120, 40));
        assert!(text.contains("computing the histograms"), "{text}");
        // A late answer for a span the screen has left is dropped.
        let Effect::Histograms { trials, table, .. } = &fx[0] else {
            unreachable!()
        };
        let Msg::Histograms(stale) = compute_job(trials, TimeSpan::WHOLE, table) else {
            unreachable!()
        };
        assert!(received(&mut app.histogram, &mut app.wb, *stale).is_empty());
        assert!(app.histogram.as_ref().unwrap().computing);
        // Enter while computing waits for the job instead of blocking.
        let waits = update(&mut app, Msg::Key(KeyEvent::from(KeyCode::Enter)));
        assert!(waits.is_empty(), "{waits:?}");
        assert_eq!(app.histogram.as_ref().unwrap().pending, Some(Action::Enter));
        SyncRunner::run(&mut app, fx);
        let st = app.histogram.as_ref().unwrap();
        assert!(!st.computing && st.pending.is_none());
        assert!(st.suggestion.is_some(), "the waiting suggestion is made");
        key(&mut app, KeyCode::Char('n'));
        // A limits edit since the job: `w` asks for the rows anew, then saves.
        app.limits.table.rows[0].upper_deg += 1.0;
        let fx = update(&mut app, Msg::Key(KeyEvent::from(KeyCode::Char('w'))));
        assert!(matches!(fx[..], [Effect::Histograms { .. }]), "{fx:?}");
        std::fs::remove_file(root.join("joint_limits/centroids.csv")).unwrap();
        SyncRunner::run(&mut app, fx);
        assert!(root.join("joint_limits/centroids.csv").exists());
        let st = app.histogram.as_ref().unwrap();
        assert!(!st.computing);
        // Both trials pooled: the knee trial adds its l_knee samples.
        assert_eq!(st.hists.len(), 12);
        let knee = st.hists.iter().find(|h| h.name == "l_knee").unwrap();
        assert_eq!(knee.trials, 2);
    }

    #[test]
    fn a_table_is_never_written_over_the_original() {
        let tmp = tempfile::tempdir().unwrap();
        let p = tmp.path().join("t.csv");
        std::fs::write(&p, "x").unwrap();
        let Msg::TableWritten(r) = write_job(&p, Some(&p), "y") else {
            panic!()
        };
        assert!(r.unwrap_err().contains("never written over"));
        assert_eq!(std::fs::read_to_string(&p).unwrap(), "x");
        let Msg::TableWritten(r) = write_job(&tmp.path().join("new/c.csv"), Some(&p), "y") else {
            panic!()
        };
        assert!(r.unwrap().ends_with("c.csv"));
    }
}
