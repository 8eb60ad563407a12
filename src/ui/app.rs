//! The router: which screen is in front, the questions over it, and
//! `update(&mut App, Msg) -> Vec<Effect>`. Messages about the shared data are
//! handled here; keys go to the screen in front, which answers with effects
//! and perhaps a navigation that this module carries out. No I/O here: the
//! runtime (or a test's synchronous runner) carries out the effects.

use super::keymap::{self, Action};
use super::msg::{Nav, Reply};
use super::screens::calibration::CalibState;
use super::screens::histogram::HistogramState;
use super::screens::views::ViewsState;
use super::screens::{calibration, compare, histogram, limits, trial, trials, views};
use super::workbench::{
    AngleCache, LimitsState, LoadState, TrialEntry, VariantResult, Workbench, FIRST_EDIT_COL,
    LAST_COL,
};
use crate::limits::{LimitTable, SettingsFile};
use ratatui::crossterm::event::{
    KeyCode, KeyEvent, KeyEventKind, KeyModifiers, MouseButton, MouseEvent, MouseEventKind,
};
use std::path::PathBuf;

pub use super::msg::{Effect, LiveEvent, Msg, RunJob, Screen};
pub use super::workbench::{JointAngles, Loaded, SortKey, View};

/// A question in front of every screen.
#[derive(Debug, Clone, PartialEq)]
pub enum Overlay {
    Help,
    QuitConfirm,
    /// The limits changed on disk while edits are unsaved.
    ReloadConflict,
}

/// Workbench state: the shared data (reached through `Deref`) and what
/// belongs to the screens.
#[derive(Debug, Clone)]
pub struct App {
    pub wb: Workbench,
    pub screen: Screen,
    pub overlay: Option<Overlay>,
    /// Column picked on the compare screen (index into `Variant::ALL`).
    pub compare_col: usize,
    /// The screen the limits editor returns to.
    pub limits_from: Screen,
    pub quit: bool,
    /// State of the analysis views.
    pub views: ViewsState,
    /// The calibration screen.
    pub calib: CalibState,
    /// The histogram screen, once opened.
    pub histogram: Option<HistogramState>,
    /// First line of the help shown, and the largest that still fills it at
    /// the size last drawn (kept by the drawing).
    pub help_scroll: usize,
    pub help_max: std::cell::Cell<usize>,
    /// The size of the last frame drawn (where a click landed).
    pub frame: std::cell::Cell<ratatui::layout::Rect>,
    /// Mouse capture is on; and the terminal reports the mouse at all.
    pub mouse: bool,
    pub mouse_possible: bool,
}

impl std::ops::Deref for App {
    type Target = Workbench;
    fn deref(&self) -> &Workbench {
        &self.wb
    }
}

impl std::ops::DerefMut for App {
    fn deref_mut(&mut self) -> &mut Workbench {
        &mut self.wb
    }
}

impl App {
    /// A workbench over `dir` listing `files` (names) as not loaded yet.
    pub fn new(dir_label: String, dir: PathBuf, files: Vec<String>, limits: LimitsState) -> App {
        App {
            wb: Workbench::new(dir_label, dir, files, limits),
            screen: Screen::Trials,
            overlay: None,
            compare_col: 1,
            limits_from: Screen::Trials,
            quit: false,
            views: Default::default(),
            calib: Default::default(),
            histogram: None,
            help_scroll: 0,
            help_max: Default::default(),
            frame: Default::default(),
            mouse: false,
            mouse_possible: true,
        }
    }
}

/// Applies a message; returns what the runtime must do.
pub fn update(app: &mut App, msg: Msg) -> Vec<Effect> {
    match msg {
        Msg::Key(k) => {
            if k.kind != KeyEventKind::Press {
                return vec![];
            }
            key(app, k)
        }
        Msg::Mouse(m) => mouse(app, m),
        Msg::Resize => vec![],
        Msg::FileChanged(file, path) => {
            if app.entry(&file).is_some_and(|e| e.following.is_some()) {
                // Its follow reads the change (and notices a rewrite).
                return vec![];
            }
            match app.entry_mut(&file) {
                Some(e) => {
                    let (chosen, gen) = (e.chosen, e.gen);
                    *e = TrialEntry::new(file.clone(), path.clone());
                    e.chosen = chosen.filter(|_| false);
                    // A job of the replaced entry still running answers no more.
                    e.gen = gen + 1;
                }
                None => {
                    app.trials.push(TrialEntry::new(file.clone(), path.clone()));
                    app.sort_trials();
                }
            }
            if crate::trial::format::is_followable(&path) {
                // A CSV trial or a folder of exports that changes may be
                // growing: followed as it grows, read whole once it stops.
                return app.follow_effect(&file).into_iter().collect();
            }
            vec![Effect::Load {
                files: vec![(file, path)],
                limits: app.limits.table.clone(),
                glitch_deg: app.limits.settings.glitch_deg,
                model: app.model.clone(),
            }]
        }
        Msg::Live { file, gen, event } => live(app, file, gen, event),
        Msg::FileRemoved(file) => {
            let keep = app.selected_entry().map(|e| e.file.clone());
            app.trials.retain(|t| t.file != file);
            if let Some(k) = keep {
                app.select_file(&k);
            }
            app.selected = app.selected.min(app.visible().len().saturating_sub(1));
            if app.open.as_deref() == Some(file.as_str()) {
                app.open = None;
                if matches!(app.screen, Screen::Trial | Screen::Compare) {
                    app.screen = Screen::Trials;
                }
                app.error(format!("{file} was removed"));
            }
            vec![]
        }
        Msg::Loaded(file, result) => {
            let mut effects = vec![];
            if let Some(e) = app.entry_mut(&file) {
                if e.following.is_some() {
                    // Read before it was seen growing: its follow has it.
                    return vec![];
                }
                // Read whole: its live correction gives way to the final one.
                e.live = None;
                let correct = std::mem::take(&mut e.correct_when_loaded) && result.is_ok();
                e.load = match result {
                    Ok(l) => LoadState::Loaded(l),
                    Err(m) => LoadState::Failed(m),
                };
                if correct {
                    // It stopped growing: the final, offline correction.
                    effects.extend(app.run_effect(&file, None));
                }
            }
            if app.sort != SortKey::Name {
                app.sort_trials();
            }
            effects
        }
        Msg::Progress { file, gen, pct } => {
            if let Some(e) = app.entry_mut(&file) {
                if e.gen == gen && e.running.is_some() {
                    e.running = Some(pct.min(99));
                }
            }
            vec![]
        }
        Msg::RunDone { file, gen, result } => {
            let limits_hash = app.limits.table.hash();
            let Some(e) = app.entry_mut(&file) else {
                return vec![];
            };
            if e.gen != gen {
                return vec![];
            }
            e.running = None;
            match result {
                Ok((corrections, report)) => {
                    let old = std::mem::take(&mut e.results);
                    let on_disk = e.loaded().map(|l| l.on_disk.clone()).unwrap_or_default();
                    for c in corrections {
                        // Saved this session, or by an earlier one with the
                        // same settings and table.
                        let saved = old
                            .get(&c.variant)
                            .filter(|r| r.correction == c)
                            .and_then(|r| r.saved.clone())
                            .or_else(|| {
                                on_disk
                                    .get(&c.variant)
                                    .filter(|s| {
                                        s.settings == c.settings && s.limits_hash == limits_hash
                                    })
                                    .map(|s| s.shown.clone())
                            });
                        e.results.insert(
                            c.variant,
                            VariantResult {
                                correction: c,
                                angles: AngleCache::default(),
                                saved,
                            },
                        );
                    }
                    e.report = Some(report);
                    let shown = app.variant;
                    match app.entry(&file).and_then(|e| e.variant_note(shown)) {
                        Some(note) => app.error(format!("{file} {shown}: {note}")),
                        None => app.info(format!("{file}: corrections done")),
                    }
                }
                Err(m) => app.error(format!("{file}: {m}")),
            }
            if app.sort == SortKey::Excursion {
                app.sort_trials();
            }
            vec![]
        }
        Msg::Saved {
            file,
            variant,
            result,
        } => {
            if let Some(e) = app.entry_mut(&file) {
                e.saving = None;
            }
            match result {
                Ok(out) => {
                    if let Some(e) = app.entry_mut(&file) {
                        e.written.insert(variant, out.clone());
                        if let Some(r) = e.results.get_mut(&variant) {
                            r.saved = Some(out.clone());
                        }
                    }
                    app.info(format!("saved {out}"));
                }
                Err(m) => app.error(format!("cannot save {file}: {m}")),
            }
            vec![]
        }
        Msg::LimitsSaved(result) => {
            app.limits.saving = false;
            match result {
                Ok(path) => app.info(format!("saved {path}")),
                Err(m) => {
                    // Not saved after all: the edits stay unsaved.
                    app.limits.saved_table = LimitTable {
                        preamble: vec![],
                        rows: vec![],
                        swing_twist: None,
                    };
                    app.error(format!("cannot save limits: {m}"));
                }
            }
            vec![]
        }
        Msg::LimitsInvalid(why) => {
            app.limits.disk_error = Some(why.clone());
            app.error(format!("{why} (still using the last good table)"));
            vec![]
        }
        Msg::LimitsOnDisk(table, settings) => {
            let l = &mut app.limits;
            l.disk_error = None;
            if table == l.saved_table && settings == l.saved_settings {
                return vec![];
            }
            if l.dirty() {
                l.disk = Some((table, settings));
                app.overlay = Some(Overlay::ReloadConflict);
                vec![]
            } else {
                take_limits(app, table, settings)
            }
        }
        Msg::RecorrectDue => recorrect_now(app),
        Msg::Tick => {
            let in_front = app.screen == Screen::Views;
            views::tick(&mut app.views, &app.wb, in_front);
            vec![]
        }
        Msg::Calibrations(entries, protocol) => {
            calibration::loaded(&mut app.calib, entries, protocol);
            vec![]
        }
        Msg::Histograms(c) => histogram::received(&mut app.histogram, &mut app.wb, *c),
        Msg::TableWritten(result) => {
            histogram::written(&mut app.wb, result);
            vec![]
        }
        Msg::PoseCalibrated(file, result) => super::pose::calibrated(&mut app.wb, &file, result),
    }
}

/// A mouse event: the wheel scrolls (zooms the trial screen's time axis), a
/// left click selects the row or column under it; a click on what is
/// already selected does what Enter does there.
fn mouse(app: &mut App, m: MouseEvent) -> Vec<Effect> {
    if app.overlay.is_some() {
        return match m.kind {
            MouseEventKind::ScrollUp => action(app, Action::Up),
            MouseEventKind::ScrollDown => action(app, Action::Down),
            _ => vec![],
        };
    }
    let body = body_of(app.frame.get());
    match m.kind {
        MouseEventKind::ScrollUp if app.screen == Screen::Trial => trial::zoom(&mut app.wb, true),
        MouseEventKind::ScrollDown if app.screen == Screen::Trial => {
            trial::zoom(&mut app.wb, false)
        }
        MouseEventKind::ScrollUp => return action(app, Action::Up),
        MouseEventKind::ScrollDown => return action(app, Action::Down),
        MouseEventKind::Down(MouseButton::Left) => match app.screen {
            Screen::Trials => {
                if let Some(i) = trials::row_at(&app.wb, body, m.row) {
                    if i == app.selected {
                        return action(app, Action::Enter);
                    }
                    app.selected = i;
                }
            }
            Screen::Trial => {
                if let Some(j) = trial::joint_at(&app.wb, body, m.column, m.row) {
                    app.joint = j;
                }
            }
            Screen::Compare => {
                match compare::hit(app.compare_col, &app.wb, body, m.column, m.row) {
                    Some(compare::Hit::Column(k)) => {
                        if k == app.compare_col {
                            return action(app, Action::Choose);
                        }
                        app.compare_col = k;
                    }
                    Some(compare::Hit::Joint(j)) => app.joint = j,
                    None => {}
                }
            }
            Screen::Limits if app.limits.edit.is_none() => {
                if let Some((r, c)) = limits::cell_at(&app.wb, body, m.column, m.row) {
                    let l = &mut app.limits;
                    let c = c.clamp(FIRST_EDIT_COL, LAST_COL);
                    if (r, c) == (l.row, l.col) {
                        return action(app, Action::Enter);
                    }
                    (l.row, l.col) = (r, c);
                }
            }
            _ => {}
        },
        _ => {}
    }
    vec![]
}

/// News of a trial followed as it grows.
fn live(app: &mut App, file: String, gen: u64, event: LiveEvent) -> Vec<Effect> {
    let open = app.open.as_deref() == Some(file.as_str());
    let Some(e) = app.entry_mut(&file) else {
        return vec![];
    };
    if e.following != Some(gen) {
        return vec![];
    }
    match event {
        LiveEvent::Snapshot(s) => {
            let before = e.loaded().map_or(0.0, |l| l.trial.duration_s());
            let after = s.loaded.trial.duration_s();
            e.load = LoadState::Loaded(s.loaded);
            e.live = Some(s.trace);
            if open {
                trial::grown(&mut app.wb, before, after);
            }
            vec![]
        }
        LiveEvent::Restarted(why) => {
            e.live = None;
            e.results.clear();
            e.report = None;
            app.error(why);
            vec![]
        }
        LiveEvent::Ended { result, grew } => {
            e.following = None;
            let path = e.path.clone();
            match result {
                Ok(()) => {
                    e.correct_when_loaded = grew;
                    if grew {
                        app.info(format!(
                            "{file} stopped growing: reading it whole for the final correction"
                        ));
                    }
                }
                // Read whole, the file tells what is wrong with it.
                Err(why) => app.error(format!("{file}: cannot follow: {why}")),
            }
            vec![Effect::Load {
                files: vec![(file, path)],
                limits: app.limits.table.clone(),
                glitch_deg: app.limits.settings.glitch_deg,
                model: app.model.clone(),
            }]
        }
    }
}

fn take_limits(app: &mut App, table: LimitTable, settings: SettingsFile) -> Vec<Effect> {
    let l = &mut app.limits;
    l.table = table.clone();
    l.settings = settings.clone();
    l.saved_table = table;
    l.saved_settings = settings;
    l.edit = None;
    l.disk = None;
    l.row = l.row.min(l.rows().saturating_sub(1));
    l.pending_all = true;
    app.settings = app.limits.settings.settings();
    app.info("limits reloaded from disk");
    recorrect_now(app)
}

/// Re-corrects the edited joints of the open trial.
fn recorrect_now(app: &mut App) -> Vec<Effect> {
    let all = std::mem::take(&mut app.limits.pending_all);
    let kinds = app.limits.pending.take().unwrap_or_default();
    let Some(file) = app.open.clone() else {
        return vec![];
    };
    let Some(loaded) = app.entry(&file).and_then(|e| e.loaded()).cloned() else {
        return vec![];
    };
    if all {
        return app
            .run_effect(&file, Some(vec![]))
            .map(|e| match e {
                Effect::Run(mut j) => {
                    j.recorrect = None;
                    Effect::Run(j)
                }
                other => other,
            })
            .into_iter()
            .collect();
    }
    let joints: Vec<String> = loaded
        .model
        .joints
        .iter()
        .filter(|j| kinds.iter().any(|k| *k == j.name || *k == j.kind))
        .map(|j| j.name.clone())
        .collect();
    if joints.is_empty() {
        return vec![];
    }
    app.run_effect(&file, Some(joints)).into_iter().collect()
}

fn key(app: &mut App, k: KeyEvent) -> Vec<Effect> {
    // Esc and the next key pressed at once arrive as one Alt-key (the
    // terminal sends ESC then the key): both are carried out.
    if k.modifiers.contains(KeyModifiers::ALT) && !k.modifiers.contains(KeyModifiers::CONTROL) {
        let mut effects = key(app, KeyEvent::from(KeyCode::Esc));
        let plain = KeyEvent::new(k.code, k.modifiers - KeyModifiers::ALT);
        effects.extend(key(app, plain));
        return effects;
    }
    // Text entry first: the filter and the cell editor take characters
    // (all but Ctrl-C, which quits from anywhere).
    let quit = k.modifiers.contains(KeyModifiers::CONTROL) && k.code == KeyCode::Char('c');
    if app.filter_editing && app.overlay.is_none() && !quit {
        trials::filter_key(&mut app.wb, k);
        return vec![];
    }
    if app.screen == Screen::Limits && app.overlay.is_none() && app.limits.edit.is_some() && !quit {
        let reply = limits::edit_key(&mut app.wb, k);
        return follow(app, reply);
    }
    match keymap::action(&k) {
        Some(a) => action(app, a),
        None => vec![],
    }
}

/// Carries out a screen's reply: its effects, then its navigation.
fn follow(app: &mut App, reply: Reply) -> Vec<Effect> {
    let mut effects = reply.effects;
    if let Some(nav) = reply.nav {
        effects.extend(navigate(app, nav));
    }
    effects
}

/// Opens another screen, as a screen asked (or `acmw render` does).
pub fn navigate(app: &mut App, nav: Nav) -> Vec<Effect> {
    match nav {
        Nav::To(s) => app.screen = s,
        Nav::OpenTrial(file) => {
            trial::open(&mut app.wb, file);
            app.screen = Screen::Trial;
        }
        Nav::Compare => {
            app.compare_col = crate::acm::Variant::ALL
                .iter()
                .position(|v| *v == app.variant)
                .unwrap_or(0);
            app.screen = Screen::Compare;
        }
        Nav::View(kind) => {
            let from_views = app.screen == Screen::Views;
            views::open(&mut app.views, &app.wb, kind, from_views);
            app.screen = Screen::Views;
        }
        Nav::Calibration => {
            app.screen = Screen::Calibration;
            return calibration::enter(&mut app.calib, &app.wb);
        }
        Nav::Histogram => {
            let from = app.screen;
            let effects = histogram::open(&mut app.histogram, &mut app.wb, from);
            if !effects.is_empty() {
                app.screen = Screen::Histogram;
            }
            return effects;
        }
    }
    vec![]
}

/// Does what `a` asks on the screen in front (as its key would).
pub fn act(app: &mut App, a: Action) -> Vec<Effect> {
    action(app, a)
}

/// Opens a trial on the trial screen.
pub fn open(app: &mut App, file: String) {
    navigate(app, Nav::OpenTrial(file));
}

/// Whether the runtime should send ticks.
pub fn wants_ticks(app: &App) -> bool {
    app.screen == Screen::Views && views::wants_ticks(&app.views)
}

fn action(app: &mut App, a: Action) -> Vec<Effect> {
    // Overlays answer first.
    match (&app.overlay, a) {
        (Some(Overlay::Help), a) if a.moves_in_list() => {
            // The help scrolls as a list of help_max + 1 first lines.
            let max = app.help_max.get();
            let at = app.help_scroll.min(max);
            if let Some(to) = crate::ui::cells::list_move(a, at, max + 1, 10) {
                app.help_scroll = to;
            }
            return vec![];
        }
        (Some(Overlay::Help), _) => {
            app.overlay = None;
            return vec![];
        }
        (Some(Overlay::QuitConfirm), Action::Yes) => {
            app.quit = true;
            return vec![];
        }
        (Some(Overlay::QuitConfirm), Action::No | Action::Back) => {
            app.overlay = None;
            return vec![];
        }
        (Some(Overlay::ReloadConflict), Action::KeepMine) => {
            app.overlay = None;
            if let Some((t, s)) = app.limits.disk.take() {
                // The file's version becomes the saved one; ours stays as edits.
                app.limits.saved_table = t;
                app.limits.saved_settings = s;
            }
            app.info("kept your edits (unsaved)");
            return vec![];
        }
        (Some(Overlay::ReloadConflict), Action::TakeFile) => {
            app.overlay = None;
            if let Some((t, s)) = app.limits.disk.take() {
                return take_limits(app, t, s);
            }
            return vec![];
        }
        (Some(_), _) => return vec![],
        (None, _) => {}
    }
    match a {
        Action::Help => {
            app.overlay = Some(Overlay::Help);
            app.help_scroll = 0;
            return vec![];
        }
        Action::Mouse => {
            if !app.mouse_possible {
                app.error("this terminal (TERM) reports no mouse");
                return vec![];
            }
            app.mouse = !app.mouse;
            let on = app.mouse;
            app.info(if on {
                "mouse on: click selects, the wheel scrolls (M turns it off)"
            } else {
                "mouse off: the terminal selects text (M turns it on)"
            });
            return vec![Effect::Mouse(app.mouse)];
        }
        Action::Quit => {
            if app.unsaved() {
                app.overlay = Some(Overlay::QuitConfirm);
            } else {
                app.quit = true;
            }
            return vec![];
        }
        Action::Limits if app.screen != Screen::Limits => {
            app.limits_from = app.screen;
            app.screen = Screen::Limits;
            return vec![];
        }
        Action::Histogram if matches!(app.screen, Screen::Trials | Screen::Trial) => {
            app.message = None;
            return navigate(app, Nav::Histogram);
        }
        _ => {}
    }
    app.message = None;
    let variant = app.variant;
    let reply = match app.screen {
        Screen::Trials => trials::action(&mut app.wb, a),
        Screen::Trial => trial::action(&mut app.wb, a),
        Screen::Compare => compare::action(&mut app.compare_col, &mut app.wb, a),
        Screen::Limits => limits::action(&mut app.wb, app.limits_from, a),
        Screen::Views => views::action(&mut app.views, &mut app.wb, a),
        Screen::Calibration => calibration::action(&mut app.calib, &mut app.wb, a),
        Screen::Histogram => histogram::action(&mut app.histogram, &mut app.wb, a),
    };
    let mut effects = follow(app, reply);
    if app.variant != variant {
        // Trials followed as they grow are followed again with the variant shown.
        let following: Vec<String> = app
            .trials
            .iter()
            .filter(|e| e.following.is_some())
            .map(|e| e.file.clone())
            .collect();
        for f in following {
            effects.extend(app.follow_effect(&f));
        }
    }
    effects
}

/// The screens' area of a frame: all but the title and status rows.
pub fn body_of(frame: ratatui::layout::Rect) -> ratatui::layout::Rect {
    ratatui::layout::Rect {
        y: frame.y + 1,
        height: frame.height.saturating_sub(2),
        ..frame
    }
}
