//! The compare screen: every variant side by side; choose one and save it.

use crate::acm::Variant;
use crate::metrics::JointFigures;
use crate::ui::cells::{abbreviate, centred, counter, fit, num, sel};
use crate::ui::keymap::Action;
use crate::ui::msg::{Effect, Nav, Reply, Screen};
use crate::ui::theme::Theme;
use crate::ui::workbench::Workbench;
use ratatui::layout::Rect;
use ratatui::style::Style;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Clear, Paragraph, Wrap};
use ratatui::Frame;

fn rms(f: &JointFigures) -> Option<f64> {
    f.truth
        .as_ref()
        .map(|t| (t.rms_error_deg.iter().map(|x| x * x).sum::<f64>() / 3.0).sqrt())
}

/// A variant's name in a 14-character column (the status list below the
/// table spells every name out).
fn column_label(v: Variant) -> &'static str {
    v.info().column
}

/// Width of the joint-name column.
const NAME_W: usize = 12;
/// Width of one entry of the status list when it runs in several columns.
const STATUS_W: usize = 30;
/// Joint rows kept in view (when the trial has that many) before the
/// status list scrolls.
const MIN_JOINTS: usize = 3;

/// Where the compare screen puts things in an area: the variant columns in
/// view and their place, the joint rows in view, the status list's columns
/// and the rows of it in view.
struct Geometry {
    /// Width of the raw column and of each variant column.
    cw: usize,
    col_w: usize,
    /// Columns before the first variant column.
    fixed: usize,
    cols: std::ops::Range<usize>,
    /// First joint row shown and how many are.
    first_joint: usize,
    joint_rows: usize,
    /// The status list: its columns (entries run down, then across), its
    /// rows, the first row shown and how many are.
    status: StatusGeometry,
}

/// Where the status list of the variants goes: in `cols` columns of `rows`
/// rows (down, then across), rows `first..first + shown` in view. In one
/// column each entry's line holds its saved path; in several, a line below
/// the list spells out the selected variant's status, path and note.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct StatusGeometry {
    cols: usize,
    rows: usize,
    first: usize,
    shown: usize,
}

impl StatusGeometry {
    /// Lines the list takes, the detail line under a multi-column list
    /// included.
    fn height(&self) -> usize {
        self.shown + usize::from(self.cols > 1)
    }

    fn scrolled(&self) -> bool {
        self.shown < self.rows
    }
}

/// Lays the status list out in `avail` rows (after the fixed rows) of a
/// screen `width` wide, leaving `joints` joint rows as many as it can,
/// scrolled to keep variant `selected` in view.
fn status_geometry(avail: usize, width: usize, joints: usize, selected: usize) -> StatusGeometry {
    let n = Variant::ALL.len();
    let most = (width / STATUS_W).max(1);
    let joints = joints.max(1);
    // One column while everything fits, else as few columns as leave every
    // joint room, else the most columns the width holds.
    let mut cols = 1;
    while cols < most && joints + n.div_ceil(cols) + usize::from(cols > 1) > avail {
        cols += 1;
    }
    let rows = n.div_ceil(cols);
    let detail = usize::from(cols > 1);
    let keep = joints.min(MIN_JOINTS);
    let shown = if keep + rows + detail <= avail {
        rows
    } else {
        avail.saturating_sub(keep + detail).clamp(1, rows)
    };
    let at = selected.min(n - 1) % rows;
    let first = at.saturating_sub(shown - 1).min(rows - shown);
    StatusGeometry {
        cols,
        rows,
        first,
        shown,
    }
}

fn geometry(col: usize, app: &Workbench, area: Rect) -> Option<Geometry> {
    let e = app.open_entry()?;
    let truth = e.loaded().is_some_and(|l| l.truth.is_some());
    let cw = if truth { 14 } else { 8 };
    let col_w = cw.max(15);
    let fixed = 2 + NAME_W + cw;
    let cols = visible_columns(area.width as usize, fixed, col_w, col);
    let joints = e.figures(None).map_or(0, <[JointFigures]>::len);
    // Title, header, mean, auto's lines, the line above the status list,
    // and the notes below it.
    let notes = usize::from(e.results.is_empty() && e.running.is_none())
        + usize::from(e.loaded().is_some_and(|l| l.truth_error.is_some()));
    let auto = auto_lines(app, e, &Theme::default(), area.width as usize).len();
    let fixed_rows = 4 + auto + notes;
    let avail = (area.height as usize).saturating_sub(fixed_rows);
    let status = status_geometry(avail, area.width as usize, joints, col);
    let joint_rows = avail
        .saturating_sub(status.height())
        .clamp(1, joints.max(1));
    let first_joint = app.joint.saturating_sub(joint_rows - 1);
    Some(Geometry {
        cw,
        col_w,
        fixed,
        cols,
        first_joint,
        joint_rows,
        status,
    })
}

/// Where variant `v`'s output of `e` was saved (this session, or found on
/// disk by its sidecar at start-up).
fn saved_path(e: &crate::ui::workbench::TrialEntry, v: Variant) -> Option<String> {
    match e.results.get(&v) {
        Some(r) => r.saved.clone(),
        None if e.running.is_none() => e.loaded()?.on_disk.get(&v).map(|s| s.shown.clone()),
        None => None,
    }
}

/// What a click at (`x`, `y`) of the screen lands on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Hit {
    /// A variant column (index into `Variant::ALL`).
    Column(usize),
    /// A joint row (index into the trial's joints).
    Joint(usize),
}

/// The column or joint row drawn at (`x`, `y`), `area` being the screen's area.
pub fn hit(col: usize, app: &Workbench, area: Rect, x: u16, y: u16) -> Option<Hit> {
    let g = geometry(col, app, area)?;
    let row = y.checked_sub(area.y)? as usize;
    let x = x.checked_sub(area.x)? as usize;
    // Row 1 is the header, the joints follow.
    let on_joint = (2..2 + g.joint_rows).contains(&row);
    if (row == 1 || on_joint) && x >= g.fixed {
        let k = g.cols.start + (x - g.fixed) / g.col_w;
        if k < g.cols.end {
            return Some(Hit::Column(k));
        }
    }
    if on_joint {
        let j = g.first_joint + row - 2;
        if j < app.open_joints().len() {
            return Some(Hit::Joint(j));
        }
    }
    None
}

pub fn render(col: usize, app: &Workbench, theme: &Theme, f: &mut Frame, area: Rect) {
    let (Some(e), Some(g)) = (app.open_entry(), geometry(col, app, area)) else {
        f.render_widget(Paragraph::new("no trial open"), area);
        return;
    };
    let truth = e.loaded().is_some_and(|l| l.truth.is_some());
    let cw = g.cw;
    let nw = NAME_W;
    let cols = g.cols.clone();
    let mut title = if truth {
        "joint mean excursion, deg  /  truth RMS error, deg (mean of X Y Z)".to_string()
    } else {
        "joint mean excursion, deg".to_string()
    };
    if cols.len() < Variant::ALL.len() {
        let shown = format!(
            " [{}-{} of {}]",
            cols.start + 1,
            cols.end,
            Variant::ALL.len()
        );
        if title.chars().count() + shown.chars().count() > area.width as usize {
            // Narrow: a shorter title keeps the columns' counter in view.
            title = if truth {
                "mean excursion / truth RMS error, deg".to_string()
            } else {
                "mean excursion, deg".to_string()
            };
        }
        title.push_str(&shown);
    }
    let mut lines = vec![Line::from(Span::styled(title, theme.dim))];
    let before = e.figures(None).unwrap_or(&[]);
    // The joints' position counter, as on the trial screen.
    let joint_label = format!("joint {}", counter(app.joint, before.len()));
    let mut head = vec![Span::styled(
        format!("  {}{:>w$}", fit(&joint_label, nw), "raw", w = cw),
        theme.header,
    )];
    for (k, v) in Variant::ALL
        .iter()
        .enumerate()
        .skip(cols.start)
        .take(cols.len())
    {
        let mut name = column_label(*v).to_string();
        if e.chosen == Some(*v) {
            name = format!("*{name}");
        }
        let name = fit(&name, cw.max(15) - 1).trim_end().to_string();
        let style = if k == col {
            theme.selected.patch(theme.header)
        } else {
            theme.header
        };
        head.push(Span::raw(" "));
        head.push(Span::styled(
            format!("{name:>w$}", w = cw.max(15) - 1),
            style,
        ));
    }
    lines.push(Line::from(head));
    let cell = |fig: Option<&JointFigures>| -> String {
        let exc = num(fig.map(|f| f.excursion.joint_mean_excursion_deg), 6);
        if truth {
            format!("{exc} /{}", num(fig.and_then(rms), 6))
        } else {
            exc
        }
    };
    let mut rows: Vec<(String, Vec<String>)> = vec![];
    for (k, j) in before.iter().enumerate() {
        let mut cells = vec![cell(Some(j))];
        for v in &Variant::ALL[cols.clone()] {
            let v = *v;
            let fig = e
                .figures(Some(v))
                .and_then(|fs| fs.iter().find(|f| f.joint == j.joint));
            cells.push(cell(fig));
        }
        let marker = if k == app.joint { "> " } else { "  " };
        rows.push((format!("{marker}{}", fit(&j.joint, nw)), cells));
    }
    // Mean over joints.
    let mut mean = vec![num(e.mean_excursion(None), 6)];
    for v in &Variant::ALL[cols.clone()] {
        let v = *v;
        mean.push(num(e.mean_excursion(Some(v)), 6));
    }
    for (k, (name, cells)) in rows
        .iter()
        .enumerate()
        .skip(g.first_joint)
        .take(g.joint_rows)
    {
        let mut spans = vec![Span::raw(format!("{name}{:>w$}", cells[0], w = cw))];
        for (c, text) in cells[1..].iter().enumerate() {
            let style = if cols.start + c == col {
                theme.corrected
            } else {
                Style::default()
            };
            spans.push(Span::raw(" "));
            spans.push(Span::styled(
                format!("{text:>w$}", w = cw.max(15) - 1),
                style,
            ));
        }
        let mut line = Line::from(spans);
        if k == app.joint {
            line = line.style(theme.selected);
        }
        lines.push(line);
    }
    let mut spans = vec![Span::styled(
        format!("  {}{:>w$}", fit("mean", nw), mean[0], w = cw),
        theme.header,
    )];
    for text in &mean[1..] {
        spans.push(Span::styled(
            format!(" {text:>w$}", w = cw.max(15) - 1),
            theme.header,
        ));
    }
    lines.push(Line::from(spans));
    lines.extend(auto_lines(app, e, theme, area.width as usize));
    lines.extend(status_lines(e, &g.status, col, theme, area.width as usize));
    if e.results.is_empty() && e.running.is_none() {
        lines.push(Line::from(Span::styled(
            "  not run yet: r runs all variants",
            theme.warn,
        )));
    }
    if let Some(m) = e.loaded().and_then(|l| l.truth_error.clone()) {
        lines.push(Line::from(Span::styled(
            format!("  truth: {m}"),
            theme.warn,
        )));
    }
    f.render_widget(Paragraph::new(lines), area);
    if let Some(v) = e.overwrite {
        overwrite_popup(e, v, theme, f, area);
    }
}

/// The question over the screen while a save would replace another
/// correction's output.
fn overwrite_popup(
    e: &crate::ui::workbench::TrialEntry,
    v: Variant,
    theme: &Theme,
    f: &mut Frame,
    area: Rect,
) {
    let path = output_on_disk(e, v).unwrap_or_default();
    let lines = vec![
        Line::from(format!("{path} exists.")),
        Line::from(format!("It holds {v} with other settings or limits.")),
        Line::from("Overwrite it with this correction?"),
        Line::from(vec![
            Span::styled("y", theme.title),
            Span::raw(" overwrite   "),
            Span::styled("n", theme.title),
            Span::raw(" keep the file"),
        ]),
    ];
    let r = centred(area, 60, 6);
    f.render_widget(Clear, r);
    f.render_widget(
        Paragraph::new(lines).wrap(Wrap { trim: false }).block(
            Block::new()
                .borders(Borders::ALL)
                .title(Span::styled(" Overwrite? ", theme.title)),
        ),
        r,
    );
}

/// The line above the status list (its position counter when it scrolls),
/// the rows of it in view, the selected variant's line under a multi-column
/// list. `col` is the selected variant (index into `Variant::ALL`).
fn status_lines(
    e: &crate::ui::workbench::TrialEntry,
    g: &StatusGeometry,
    col: usize,
    theme: &Theme,
    width: usize,
) -> Vec<Line<'static>> {
    let mut lines = vec![if g.scrolled() {
        Line::from(Span::styled(
            format!(
                "  status, variant {} (<- -> scroll)",
                counter(col, Variant::ALL.len())
            ),
            theme.dim,
        ))
    } else {
        Line::from("")
    }];
    let marker = |k: usize| if k == col { "> " } else { "  " };
    if g.cols == 1 {
        for (k, v) in Variant::ALL.iter().enumerate().skip(g.first).take(g.shown) {
            let mut text = format!("{}{:<24}{}", marker(k), v.name(), e.variant_status(*v));
            if let Some(p) = saved_path(e, *v) {
                text.push_str(&format!(" -> {p}"));
            }
            // The selected variant's line also says what it skipped.
            if let Some(note) = e.variant_note(*v).filter(|_| k == col) {
                text.push_str(&format!("; {note}"));
            }
            lines.push(
                Line::from(fit(&text, width).trim_end().to_string()).style(sel(theme, k == col)),
            );
        }
        return lines;
    }
    // Short of rows: the list runs down then across, each name cut to leave
    // its status whole; the selected variant's line follows in full.
    let w = (width / g.cols).max(STATUS_W);
    for r in g.first..g.first + g.shown {
        let mut spans = vec![];
        let mut used = 0;
        for c in 0..g.cols {
            let k = c * g.rows + r;
            let Some(v) = Variant::ALL.get(k) else {
                continue;
            };
            let s = e.variant_status(*v);
            let name_w = w.saturating_sub(4 + s.chars().count().max(6));
            let pad = (c * w).saturating_sub(used);
            let text = format!("{}{} {s:<6}", marker(k), fit(v.name(), name_w));
            used += pad + text.chars().count();
            spans.push(Span::raw(" ".repeat(pad)));
            spans.push(Span::styled(text, sel(theme, k == col)));
        }
        lines.push(Line::from(spans));
    }
    let v = Variant::ALL[col.min(Variant::ALL.len() - 1)];
    let mut text = format!("> {v}: {}", e.variant_status(v));
    if let Some(p) = saved_path(e, v) {
        // A long path keeps both its ends (folder and extension).
        let room = width.saturating_sub(text.chars().count() + 4).max(16);
        text.push_str(&format!(" -> {}", abbreviate(&p, room).trim_end()));
    }
    if let Some(note) = e.variant_note(v) {
        text.push_str(&format!("; {note}"));
    }
    lines.push(Line::from(Span::styled(
        fit(&text, width).trim_end().to_string(),
        theme.header,
    )));
    lines
}

/// `auto`'s choice for the selected joint: the variant, the runner-up, the
/// figures that decided and the flags (nothing before `auto` has run).
fn auto_lines(
    app: &Workbench,
    e: &crate::ui::workbench::TrialEntry,
    theme: &Theme,
    width: usize,
) -> Vec<Line<'static>> {
    let joints = app.open_joints();
    let Some(a) = (joints.get(app.joint))
        .and_then(|j| e.results.get(&Variant::Auto)?.correction.joint(j))
        .and_then(|r| r.auto.clone())
    else {
        return vec![];
    };
    let joint = &joints[app.joint];
    let who = match a.overridden {
        Some(own) => format!("yours, auto chose {own}"),
        None => format!(
            "runner-up {}",
            a.runner_up.map_or("-".into(), |v| v.to_string())
        ),
    };
    let mut lines = vec![Line::from(Span::styled(
        fit(
            &format!("  auto, {joint}: {} ({who}); o overrides", a.chosen),
            width,
        ),
        theme.header,
    ))];
    lines.push(Line::from(fit(&format!("    {}", a.reason), width)));
    for flag in &a.flags {
        lines.push(Line::from(Span::styled(
            fit(&format!("    ! {flag}"), width),
            theme.warn,
        )));
    }
    lines
}

/// The variant columns (indices into `Variant::ALL`) that fit in `width`
/// after `fixed` characters, `col_w` each, scrolled to show `selected`.
fn visible_columns(
    width: usize,
    fixed: usize,
    col_w: usize,
    selected: usize,
) -> std::ops::Range<usize> {
    let all = Variant::ALL.len();
    let fit = (width.saturating_sub(fixed) / col_w.max(1)).clamp(1, all);
    let start = selected.min(all - 1).saturating_sub(fit - 1);
    start..start + fit
}

/// Overrides `auto`'s choice for the selected joint with the next of its
/// candidates (back to auto's own after the last).
fn override_next(app: &mut Workbench, file: &str) -> Reply {
    let joints = app.open_joints();
    let Some(joint) = joints.get(app.joint).cloned() else {
        return Reply::default();
    };
    let record = app
        .entry(file)
        .and_then(|e| e.results.get(&Variant::Auto))
        .and_then(|r| r.correction.joint(&joint)?.auto.clone());
    let Some(a) = record else {
        app.error(format!(
            "run the corrections first (r): auto has not chosen for {joint}"
        ));
        return Reply::default();
    };
    let candidates = crate::acm::auto::CANDIDATES;
    let k = candidates.iter().position(|v| *v == a.chosen).unwrap_or(0);
    let next = candidates[(k + 1) % candidates.len()];
    let own = a.overridden.unwrap_or(a.chosen);
    let choice = (next != own).then_some(next);
    app.info(match choice {
        Some(v) => format!("{joint}: {v} instead of auto's {own}; correcting..."),
        None => format!("{joint}: back to auto's {own}; correcting..."),
    });
    app.override_effect(file, &joint, choice).into()
}

/// The output of variant `v` of `e` already on disk (found at start-up by
/// its sidecar, or written this session), as shown.
fn output_on_disk(e: &crate::ui::workbench::TrialEntry, v: Variant) -> Option<String> {
    e.written
        .get(&v)
        .cloned()
        .or_else(|| Some(e.loaded()?.on_disk.get(&v)?.shown.clone()))
}

/// Saves variant `v` of `file`: asks first (unless `overwrite`) when its
/// output on disk holds another correction (other settings or limits).
fn save(app: &mut Workbench, file: &str, v: Variant, overwrite: bool) -> Reply {
    let limits = app.limits.table.clone();
    let limits_source = app.limits.source.clone();
    let Some(e) = app.entry_mut(file) else {
        return Reply::default();
    };
    let (Some(loaded), Some(r)) = (e.loaded().cloned(), e.results.get(&v)) else {
        app.error(format!("run the corrections first (r): {v} is not done"));
        return Reply::default();
    };
    e.chosen = Some(v);
    if !overwrite && r.saved.is_none() {
        if let Some(path) = output_on_disk(e, v) {
            e.overwrite = Some(v);
            app.info(format!(
                "{path} exists (another correction): y overwrites, n keeps it"
            ));
            return Reply::default();
        }
    }
    let effect = Effect::SaveVariant {
        file: file.to_string(),
        loaded,
        correction: r.correction.clone(),
        limits,
        limits_source,
    };
    e.saving = Some(v);
    app.info(format!("saving {file} {v}..."));
    vec![effect].into()
}

/// What a key does on the compare screen; `col` is the picked column.
pub fn action(col: &mut usize, app: &mut Workbench, a: Action) -> Reply {
    let Some(file) = app.open.clone() else {
        return Reply::nav(Nav::To(Screen::Trials));
    };
    // A save over another correction's output waits for an answer: y (or
    // w again) overwrites, any other key keeps the file.
    if let Some(v) = app.entry_mut(&file).and_then(|e| e.overwrite.take()) {
        if matches!(a, Action::Yes | Action::Save) {
            return save(app, &file, v, true);
        }
        let path = app.entry(&file).and_then(|e| output_on_disk(e, v));
        app.info(format!("kept {}; not saved", path.unwrap_or_default()));
        return Reply::default();
    }
    match a {
        Action::Back => return Reply::nav(Nav::To(Screen::Trial)),
        Action::Left => *col = col.saturating_sub(1),
        Action::Right => *col = (*col + 1).min(Variant::ALL.len() - 1),
        a if a.moves_in_list() => {
            let n = app.open_joints().len();
            if let Some(j) = crate::ui::cells::list_move(a, app.joint, n, 10) {
                app.joint = j;
            }
        }
        Action::Run => return app.run_effect(&file, None).into(),
        // `o` here: the next of auto's candidates for the selected joint.
        Action::Globe => return override_next(app, &file),
        Action::Choose | Action::Enter => {
            // The choice is this trial's; the variant shown stays as it is.
            let v = Variant::ALL[*col];
            if let Some(e) = app.entry_mut(&file) {
                e.chosen = Some(v);
            }
            app.info(format!("chose {v}; w saves it"));
        }
        Action::Save => {
            if app.refuse_save_while_growing(&file) {
                return Reply::default();
            }
            let v = app
                .entry(&file)
                .and_then(|e| e.chosen)
                .unwrap_or(Variant::ALL[*col]);
            return save(app, &file, v, false);
        }
        _ => {}
    }
    Reply::default()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Whatever the room, the status list holds every variant (columns times
    /// rows), keeps the selected one in view, and shows every row whenever
    /// the joints can keep their minimum beside it.
    #[test]
    fn the_status_list_keeps_every_variant_reachable() {
        let n = Variant::ALL.len();
        for width in [40, 60, 80, 120] {
            for avail in 0..30 {
                for joints in [1, 12] {
                    for selected in 0..n {
                        let g = status_geometry(avail, width, joints, selected);
                        let what =
                            format!("{width} wide, {avail} rows, {joints} joints, {selected}");
                        assert!(g.cols * g.rows >= n, "{what}: {g:?}");
                        assert!(g.shown >= 1 && g.first + g.shown <= g.rows, "{what}: {g:?}");
                        let row = selected % g.rows;
                        assert!((g.first..g.first + g.shown).contains(&row), "{what}: {g:?}");
                        if joints.min(MIN_JOINTS) + g.rows + usize::from(g.cols > 1) <= avail {
                            assert!(!g.scrolled(), "{what}: {g:?}");
                        }
                    }
                }
            }
        }
        // 80x24 with twelve joints: two columns of six, every row shown.
        let g = status_geometry(22 - 7, 80, 12, 1);
        assert_eq!((g.cols, g.rows, g.shown), (2, 6, 6));
        // Too short even in two columns: rows scroll to the selection.
        let g = status_geometry(6, 60, 12, 5);
        assert_eq!((g.cols, g.rows, g.shown, g.first), (2, 6, 2, 4));
        assert!(g.scrolled());
    }
}
