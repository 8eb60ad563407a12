//! The compare screen: every variant side by side; choose one and save it.

use crate::acm::Variant;
use crate::metrics::JointFigures;
use crate::ui::cells::{fit, num};
use crate::ui::keymap::Action;
use crate::ui::msg::{Effect, Nav, Reply, Screen};
use crate::ui::theme::Theme;
use crate::ui::workbench::Workbench;
use ratatui::layout::Rect;
use ratatui::style::Style;
use ratatui::text::{Line, Span};
use ratatui::widgets::Paragraph;
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

/// Where the compare screen puts things in an area: the variant columns in
/// view and their place, the joint rows in view, the status list's columns.
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
    /// Columns of the status list (several when the rows are few).
    status_cols: usize,
}

fn geometry(col: usize, app: &Workbench, area: Rect) -> Option<Geometry> {
    let e = app.open_entry()?;
    let truth = e.loaded().is_some_and(|l| l.truth.is_some());
    let cw = if truth { 14 } else { 8 };
    let col_w = cw.max(15);
    let fixed = 2 + NAME_W + cw;
    let cols = visible_columns(area.width as usize, fixed, col_w, col);
    let joints = e.figures(None).map_or(0, <[JointFigures]>::len);
    // Title, header, mean, a blank line, and the notes below the status list.
    let notes = usize::from(e.results.is_empty() && e.running.is_none())
        + usize::from(e.loaded().is_some_and(|l| l.truth_error.is_some()));
    let fixed_rows = 4 + notes;
    let h = area.height as usize;
    let n = Variant::ALL.len();
    // The status list runs in as many columns as it needs to leave the
    // joints room (up to what the width holds), then the joints scroll.
    let most = (area.width as usize / STATUS_W).max(1);
    // In columns the saved outputs' paths get a line each below the list.
    let saved = saved_lines(e).len();
    let status_rows = |cols: usize| n.div_ceil(cols) + if cols > 1 { saved } else { 0 };
    let mut status_cols = 1;
    while status_cols < most && fixed_rows + joints + status_rows(status_cols) > h {
        status_cols += 1;
    }
    let joint_rows = h
        .saturating_sub(fixed_rows + status_rows(status_cols))
        .clamp(1, joints.max(1));
    let first_joint = app.joint.saturating_sub(joint_rows - 1);
    Some(Geometry {
        cw,
        col_w,
        fixed,
        cols,
        first_joint,
        joint_rows,
        status_cols,
    })
}

/// `variant -> path` of each saved variant of `e`.
fn saved_lines(e: &crate::ui::workbench::TrialEntry) -> Vec<String> {
    Variant::ALL
        .iter()
        .filter_map(|v| {
            let p = e.results.get(v)?.saved.as_ref()?;
            Some(format!("  {v} -> {p}"))
        })
        .collect()
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
        title.push_str(&format!(
            " [{}-{} of {}]",
            cols.start + 1,
            cols.end,
            Variant::ALL.len()
        ));
    }
    let mut lines = vec![Line::from(Span::styled(title, theme.dim))];
    let mut head = vec![Span::styled(
        format!("  {}{:>w$}", fit("joint", nw), "raw", w = cw),
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
    let before = e.figures(None).unwrap_or(&[]);
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
    lines.push(Line::from(""));
    if g.status_cols == 1 {
        for v in Variant::ALL {
            let s = e.variant_status(v);
            let saved = e
                .results
                .get(&v)
                .and_then(|r| r.saved.clone())
                .map(|p| format!(" -> {p}"))
                .unwrap_or_default();
            lines.push(Line::from(format!("  {:<24}{s}{saved}", v.name())));
        }
    } else {
        // Short of rows: the list runs down then across, each name cut to
        // leave its status whole.
        let per = Variant::ALL.len().div_ceil(g.status_cols);
        let w = (area.width as usize / g.status_cols).max(STATUS_W);
        for r in 0..per {
            let mut text = String::new();
            for c in 0..g.status_cols {
                let Some(v) = Variant::ALL.get(c * per + r) else {
                    continue;
                };
                let s = e.variant_status(*v);
                let name_w = w.saturating_sub(3 + s.chars().count().max(6));
                text.push_str(&format!("  {} {s:<6}", fit(v.name(), name_w)));
                let pad = (c + 1) * w;
                while text.chars().count() < pad {
                    text.push(' ');
                }
            }
            lines.push(Line::from(text.trim_end().to_string()));
        }
        lines.extend(saved_lines(e).into_iter().map(Line::from));
    }
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

/// What a key does on the compare screen; `col` is the picked column.
pub fn action(col: &mut usize, app: &mut Workbench, a: Action) -> Reply {
    let Some(file) = app.open.clone() else {
        return Reply::nav(Nav::To(Screen::Trials));
    };
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
            let limits = app.limits.table.clone();
            let limits_source = app.limits.source.clone();
            let Some(e) = app.entry_mut(&file) else {
                return Reply::default();
            };
            let (Some(loaded), Some(r)) = (e.loaded().cloned(), e.results.get(&v)) else {
                app.error(format!("run the corrections first (r): {v} is not done"));
                return Reply::default();
            };
            e.chosen = Some(v);
            e.saving = Some(v);
            let effect = Effect::SaveVariant {
                file: file.clone(),
                loaded,
                correction: r.correction.clone(),
                limits,
                limits_source,
            };
            app.info(format!("saving {file} {v}..."));
            return vec![effect].into();
        }
        _ => {}
    }
    Reply::default()
}
