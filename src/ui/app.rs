//! Workbench state and `update(&mut App, Msg) -> Vec<Effect>`: no I/O here; the
//! runtime (or a test's synchronous runner) carries out the effects.

use super::keymap::{self, Action};
use crate::acm::{Correction, Variant};
use crate::limits::{LimitTable, Settings, SettingsFile};
use crate::metrics::JointFigures;
use crate::model::Model;
use crate::report::TrialReport;
use crate::trial::{Trial, TrialFormat};
use ratatui::crossterm::event::{
    KeyCode, KeyEvent, KeyEventKind, KeyModifiers, MouseEvent, MouseEventKind,
};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;

/// Joint angles per joint of one trial (raw or corrected), computed the first
/// time a screen asks: a 30-minute trial has 90,000 samples per joint, too many
/// to convert on every frame.
#[derive(Debug, Clone, Default)]
pub struct AngleCache(Arc<std::sync::Mutex<BTreeMap<String, JointAngles>>>);

/// Z-Y-X angles `[x, y, z]` in degrees, one per sample, shared between frames.
pub type JointAngles = Arc<Vec<[f64; 3]>>;

impl AngleCache {
    /// Z-Y-X angles (degrees) of `joint` in `trial`, cached by joint name.
    pub fn get(&self, trial: &Trial, joint: &crate::model::Joint) -> Option<JointAngles> {
        let mut map = self.0.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(a) = map.get(&joint.name) {
            return Some(a.clone());
        }
        let a = Arc::new(crate::metrics::joint_angles(trial, joint)?);
        map.insert(joint.name.clone(), a.clone());
        Some(a)
    }
}

/// A trial read from disk, with what the screens need of it.
#[derive(Debug, Clone)]
pub struct Loaded {
    pub trial: Trial,
    pub model: Model,
    pub format: TrialFormat,
    pub gzip: bool,
    /// True segment orientations when a truth sits beside the trial.
    pub truth: Option<Trial>,
    /// Why the truth beside the trial could not be used.
    pub truth_error: Option<String>,
    /// Figures of the uncorrected trial.
    pub before: Vec<JointFigures>,
    /// Joint angles of the uncorrected trial, filled on demand.
    pub angles: AngleCache,
    /// The pose calibration `trial` went through (None: as read).
    pub pose: Option<crate::pose::PoseRecord>,
    /// The trial as read, while `trial` is pose-calibrated.
    pub uncalibrated: Option<Arc<Loaded>>,
    /// Orientation jumps over the default threshold, by time (key `G`).
    pub glitches: Vec<crate::trial::glitch::Glitch>,
}

/// Whether a trial is read yet.
#[derive(Debug, Clone)]
pub enum LoadState {
    Pending,
    Loaded(Arc<Loaded>),
    Failed(String),
}

/// One finished correction of a trial.
#[derive(Debug, Clone)]
pub struct VariantResult {
    pub correction: Arc<Correction>,
    /// Joint angles of the corrected trial, filled on demand.
    pub angles: AngleCache,
    /// Where it was saved, relative to the trials folder.
    pub saved: Option<String>,
}

/// One row of the trials screen.
#[derive(Debug, Clone)]
pub struct TrialEntry {
    /// File name inside the folder.
    pub file: String,
    pub path: PathBuf,
    pub load: LoadState,
    /// Percent done of the running job, if one runs.
    pub running: Option<u8>,
    /// Generation of the newest job; older completions are ignored.
    pub gen: u64,
    pub results: BTreeMap<Variant, VariantResult>,
    /// Figures of the uncorrected trial and of every finished variant.
    pub report: Option<TrialReport>,
    /// The variant picked on the compare screen.
    pub chosen: Option<Variant>,
}

impl TrialEntry {
    pub fn new(file: String, path: PathBuf) -> TrialEntry {
        TrialEntry {
            file,
            path,
            load: LoadState::Pending,
            running: None,
            gen: 0,
            results: BTreeMap::new(),
            report: None,
            chosen: None,
        }
    }

    pub fn loaded(&self) -> Option<&Arc<Loaded>> {
        match &self.load {
            LoadState::Loaded(l) => Some(l),
            _ => None,
        }
    }

    /// Figures of a variant (None = uncorrected), when known.
    pub fn figures(&self, variant: Option<Variant>) -> Option<&[JointFigures]> {
        match variant {
            None => match &self.report {
                Some(r) => Some(&r.uncorrected),
                None => self.loaded().map(|l| l.before.as_slice()),
            },
            Some(v) => self
                .report
                .as_ref()?
                .variants
                .iter()
                .find(|r| r.variant == v)
                .map(|r| r.joints.as_slice()),
        }
    }

    /// Mean over joints of the joint mean excursion, degrees.
    pub fn mean_excursion(&self, variant: Option<Variant>) -> Option<f64> {
        let f = self.figures(variant)?;
        if f.is_empty() {
            return None;
        }
        Some(
            f.iter()
                .map(|j| j.excursion.joint_mean_excursion_deg)
                .sum::<f64>()
                / f.len() as f64,
        )
    }

    /// Whether a chosen variant is not saved yet.
    pub fn unsaved_choice(&self) -> bool {
        self.chosen
            .is_some_and(|v| self.results.get(&v).is_none_or(|r| r.saved.is_none()))
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Screen {
    Trials,
    Trial,
    Compare,
    Limits,
    /// The analysis views (`super::views`).
    Views,
    Calibration,
    Histogram,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SortKey {
    Name,
    Duration,
    Excursion,
}

impl SortKey {
    pub fn name(self) -> &'static str {
        match self {
            SortKey::Name => "name",
            SortKey::Duration => "duration",
            SortKey::Excursion => "excursion",
        }
    }
}

/// A question in front of every screen.
#[derive(Debug, Clone, PartialEq)]
pub enum Overlay {
    Help,
    QuitConfirm,
    /// The limits changed on disk while edits are unsaved.
    ReloadConflict,
}

/// Visible time span and cursor of the trial screen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct View {
    /// Zoom level: the span is the trial duration / 2^zoom.
    pub zoom: u32,
    /// Left edge of the span, seconds from the first sample.
    pub start_s: f64,
    /// Cursor, seconds from the first sample.
    pub cursor_s: f64,
    /// Braille (true) or dot markers.
    pub braille: bool,
}

impl Default for View {
    fn default() -> Self {
        View {
            zoom: 0,
            start_s: 0.0,
            cursor_s: 0.0,
            braille: true,
        }
    }
}

impl View {
    /// `(start, end)` of the visible span for a trial of `duration` seconds.
    pub fn span(&self, duration: f64) -> (f64, f64) {
        let width = (duration / f64::from(1u32 << self.zoom.min(16))).max(1e-6);
        let start = self.start_s.clamp(0.0, (duration - width).max(0.0));
        (start, start + width)
    }
}

/// A cell being edited in the limits editor.
#[derive(Debug, Clone, PartialEq)]
pub struct CellEdit {
    pub text: String,
    /// Insertion point, in characters from the start of `text`.
    pub cursor: usize,
    /// Why the text cannot be committed, if it cannot.
    pub error: Option<String>,
}

impl CellEdit {
    /// Starts editing `text` with the cursor at its end.
    pub fn new(text: String) -> Self {
        let cursor = text.chars().count();
        CellEdit {
            text,
            cursor,
            error: None,
        }
    }

    /// Byte offset of the character at `char_index` (the end if past it).
    fn byte_at(&self, char_index: usize) -> usize {
        self.text
            .char_indices()
            .nth(char_index)
            .map_or(self.text.len(), |(b, _)| b)
    }

    /// Applies one editing key; returns whether the key was an editing key.
    /// Left/Right/Home/End move the cursor, Backspace and Delete remove the
    /// character before or under it, Ctrl-U clears the cell, characters insert.
    pub fn key(&mut self, k: KeyEvent) -> bool {
        let n = self.text.chars().count();
        match k.code {
            KeyCode::Left => self.cursor = self.cursor.saturating_sub(1),
            KeyCode::Right => self.cursor = (self.cursor + 1).min(n),
            KeyCode::Home => self.cursor = 0,
            KeyCode::End => self.cursor = n,
            KeyCode::Backspace if self.cursor > 0 => {
                self.cursor -= 1;
                self.text.remove(self.byte_at(self.cursor));
            }
            KeyCode::Delete if self.cursor < n => {
                self.text.remove(self.byte_at(self.cursor));
            }
            KeyCode::Char('u') if k.modifiers.contains(KeyModifiers::CONTROL) => {
                self.text.clear();
                self.cursor = 0;
            }
            KeyCode::Char(c) if !k.modifiers.contains(KeyModifiers::CONTROL) => {
                self.text.insert(self.byte_at(self.cursor), c);
                self.cursor += 1;
            }
            KeyCode::Backspace | KeyCode::Delete => {}
            _ => return false,
        }
        true
    }
}

/// The limits editor: the table and settings, as saved and as edited.
#[derive(Debug, Clone)]
pub struct LimitsState {
    /// The `joint_limits` folder (created on save if missing).
    pub dir: PathBuf,
    /// File name of the table inside `dir`.
    pub table_name: String,
    /// Where the table came from, for display.
    pub source: String,
    pub table: LimitTable,
    pub settings: SettingsFile,
    pub saved_table: LimitTable,
    pub saved_settings: SettingsFile,
    pub row: usize,
    pub col: usize,
    pub edit: Option<CellEdit>,
    /// The version found on disk while edits were unsaved.
    pub disk: Option<(LimitTable, SettingsFile)>,
    /// Joints edited since the last re-correction (None = settings changed: all).
    pub pending: Option<Vec<String>>,
    pub pending_all: bool,
}

/// First editable column of a table row (movement) and the last (lambda2).
pub const FIRST_EDIT_COL: usize = 2;
pub const LAST_COL: usize = 6;
/// Names of the settings rows below the table.
pub const SETTING_NAMES: [&str; 3] = ["lambda1", "window_s", "hop_s"];

impl LimitsState {
    pub fn new(
        dir: PathBuf,
        table_name: String,
        source: String,
        table: LimitTable,
        settings: SettingsFile,
    ) -> LimitsState {
        LimitsState {
            dir,
            table_name,
            source,
            saved_table: table.clone(),
            saved_settings: settings.clone(),
            table,
            settings,
            row: 0,
            col: FIRST_EDIT_COL + 1,
            edit: None,
            disk: None,
            pending: None,
            pending_all: false,
        }
    }

    pub fn dirty(&self) -> bool {
        self.table != self.saved_table || self.settings != self.saved_settings
    }

    pub fn rows(&self) -> usize {
        self.table.rows.len() + SETTING_NAMES.len()
    }

    /// The settings row index (0..3) when the selection is on one.
    pub fn setting_row(&self) -> Option<usize> {
        self.row.checked_sub(self.table.rows.len())
    }

    /// The text of a cell as shown and as edited.
    pub fn cell_text(&self, row: usize, col: usize) -> String {
        if let Some(s) = row.checked_sub(self.table.rows.len()) {
            return match s {
                0 => self.settings.lambda1.to_string(),
                1 => self.settings.window_s.to_string(),
                _ => self.settings.hop_s.to_string(),
            };
        }
        let r = &self.table.rows[row];
        match col {
            0 => r.joint.clone(),
            1 => crate::limits::axis_name(r.axis).to_string(),
            2 => r.movement.clone(),
            3 => r.lower_deg.to_string(),
            4 => r.upper_deg.to_string(),
            5 => r.centroid_deg.map(|c| c.to_string()).unwrap_or_default(),
            _ => r.lambda2.to_string(),
        }
    }

    /// Whether a saved value differs from the edited one.
    pub fn cell_changed(&self, row: usize, col: usize) -> bool {
        let saved = LimitsState {
            table: self.saved_table.clone(),
            settings: self.saved_settings.clone(),
            ..self.clone()
        };
        row < saved.rows()
            && saved.rows() == self.rows()
            && saved.cell_text(row, col) != self.cell_text(row, col)
    }

    /// Applies `text` to the selected cell of a copy; the copy, or why not.
    pub fn apply(&self, text: &str) -> Result<(LimitTable, SettingsFile), String> {
        let mut table = self.table.clone();
        let mut settings = self.settings.clone();
        let num = |t: &str| -> Result<f64, String> {
            let v: f64 = t
                .trim()
                .parse()
                .map_err(|_| format!("'{}' is not a number", t.trim()))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err("not a finite number".into())
            }
        };
        if let Some(s) = self.setting_row() {
            let v = num(text)?;
            match s {
                0 => settings.lambda1 = v,
                1 => settings.window_s = v,
                _ => settings.hop_s = v,
            }
            settings.settings().validate("").map_err(|e| e.message)?;
            return Ok((table, settings));
        }
        let joint = table.rows[self.row].joint.clone();
        match self.col {
            2 => {
                if text.trim().is_empty() {
                    return Err("movement must not be empty".into());
                }
                table.rows[self.row].movement = text.trim().to_string();
            }
            3 => table.rows[self.row].lower_deg = num(text)?,
            4 => table.rows[self.row].upper_deg = num(text)?,
            5 => {
                let c = if text.trim().is_empty() {
                    None
                } else {
                    Some(num(text)?)
                };
                table.rows[self.row].centroid_deg = c;
            }
            6 => {
                let v = num(text)?;
                // lambda2 is the same on a joint's three rows.
                for r in table.rows.iter_mut().filter(|r| r.joint == joint) {
                    r.lambda2 = v;
                }
            }
            _ => return Err("this column cannot be edited".into()),
        }
        LimitTable::parse(&table.to_csv(), "edit").map_err(|e| e.message)?;
        Ok((table, settings))
    }
}

/// Workbench state.
#[derive(Debug, Clone)]
pub struct App {
    /// The trials folder as the user named it (shown; never made absolute).
    pub dir_label: String,
    pub dir: PathBuf,
    pub screen: Screen,
    pub overlay: Option<Overlay>,
    pub trials: Vec<TrialEntry>,
    /// Index into [`App::visible`].
    pub selected: usize,
    pub filter: String,
    pub filter_editing: bool,
    /// The body model every trial is read with (`--model`); None: each
    /// trial's is detected from its IMU names among the built-in models.
    pub model: Option<Arc<Model>>,
    pub sort: SortKey,
    pub variant: Variant,
    /// The trial open on the trial and compare screens (file name).
    pub open: Option<String>,
    pub joint: usize,
    pub view: View,
    /// Column picked on the compare screen (index into `Variant::ALL`).
    pub compare_col: usize,
    pub limits: LimitsState,
    pub settings: Settings,
    /// The screen the limits editor returns to.
    pub limits_from: Screen,
    /// A message in the status bar: (text, is_error).
    pub message: Option<(String, bool)>,
    pub quit: bool,
    /// State of the analysis views.
    pub views: super::views::ViewsState,
    /// The calibration screen (`super::calibration`).
    pub calib: super::calibration::CalibState,
    /// The histogram screen, once opened.
    pub histogram: Option<super::histogram::HistogramState>,
}

/// What the runtime should do.
#[derive(Debug, Clone)]
pub enum Effect {
    /// Read these trials (file name, path), in the background, one message each;
    /// figures against `limits`.
    Load {
        files: Vec<(String, PathBuf)>,
        limits: LimitTable,
        /// Glitch threshold, degrees (`settings.toml`).
        glitch_deg: f64,
        /// The model to read them with (None: detected per trial).
        model: Option<Arc<Model>>,
    },
    /// Correct a trial with every variant (replacing any job of the same trial),
    /// or re-correct `joints` of the previous results.
    Run(Box<RunJob>),
    /// Save a variant of a trial.
    SaveVariant {
        file: String,
        path: PathBuf,
        loaded: Arc<Loaded>,
        correction: Arc<Correction>,
        limits: LimitTable,
        limits_source: String,
    },
    /// Save the limit table and settings (atomically, keeping `.bak`).
    SaveLimits {
        dir: PathBuf,
        table_name: String,
        table_csv: String,
        settings_toml: String,
    },
    /// Read and calibrate the calibration recordings of this folder.
    Calibrations { dir: PathBuf },
    /// Histograms of these loaded trials over `span` against `table`
    /// (answered by `Msg::Histograms`).
    Histograms {
        trials: Vec<Arc<Loaded>>,
        span: crate::analysis::TimeSpan,
        table: LimitTable,
    },
    /// Write a table (CSV text) atomically, never over `original`.
    WriteTable {
        path: PathBuf,
        original: Option<PathBuf>,
        csv: String,
    },
    /// Ask for `Msg::RecorrectDue` after the debounce delay (a newer request
    /// replaces an older one).
    Debounce,
    /// Pose-calibrate a loaded trial (answered by `Msg::PoseCalibrated`).
    PoseCalibrate {
        file: String,
        loaded: Arc<Loaded>,
        calibration: crate::pose::PoseCalibration,
        limits: LimitTable,
    },
}

/// A correction job.
#[derive(Debug, Clone)]
pub struct RunJob {
    pub file: String,
    pub gen: u64,
    pub loaded: Arc<Loaded>,
    pub limits: LimitTable,
    pub limits_source: String,
    pub settings: Settings,
    /// Re-correct these joints of the previous results (None: run afresh).
    pub recorrect: Option<(Vec<Arc<Correction>>, Vec<String>)>,
}

/// Everything that happens to the workbench.
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)] // transient; boxing buys nothing
pub enum Msg {
    Key(KeyEvent),
    Mouse(MouseEvent),
    Resize,
    /// A trial file appeared or changed on disk (file name, path).
    FileChanged(String, PathBuf),
    FileRemoved(String),
    Loaded(String, Result<Arc<Loaded>, String>),
    Progress {
        file: String,
        gen: u64,
        pct: u8,
    },
    RunDone {
        file: String,
        gen: u64,
        result: Result<(Vec<Arc<Correction>>, TrialReport), String>,
    },
    Saved {
        file: String,
        variant: Variant,
        result: Result<String, String>,
    },
    LimitsSaved(Result<String, String>),
    /// The limit files on disk differ from what the workbench last loaded or saved.
    LimitsOnDisk(LimitTable, SettingsFile),
    RecorrectDue,
    /// Time passes (only sent while something plays).
    Tick,
    /// The calibration recordings of the folder, read and calibrated (protocol label).
    Calibrations(Vec<super::calibration::CalibEntry>, String),
    /// The histograms and centroids of the histogram screen's trials over a span.
    Histograms(Box<super::histogram::Computed>),
    /// A suggested limit table or a centroid table was written (its path), or why not.
    TableWritten(Result<String, String>),
    /// A pose-calibrated version of a trial, or why there is none.
    PoseCalibrated(String, Result<Arc<Loaded>, String>),
}

impl App {
    /// A workbench over `dir` listing `files` (names) as not loaded yet.
    pub fn new(dir_label: String, dir: PathBuf, files: Vec<String>, limits: LimitsState) -> App {
        let settings = limits.settings.settings();
        let mut app = App {
            dir_label,
            trials: vec![],
            dir,
            screen: Screen::Trials,
            overlay: None,
            selected: 0,
            filter: String::new(),
            filter_editing: false,
            model: None,
            sort: SortKey::Name,
            variant: Variant::Drift,
            open: None,
            joint: 0,
            view: View::default(),
            compare_col: 1,
            limits,
            settings,
            limits_from: Screen::Trials,
            message: None,
            quit: false,
            views: Default::default(),
            calib: Default::default(),
            histogram: None,
        };
        for f in files {
            let path = app.dir.join(&f);
            app.trials.push(TrialEntry::new(f, path));
        }
        app.sort_trials();
        app
    }

    /// The effects that start the workbench: read every listed trial.
    pub fn start(&self) -> Vec<Effect> {
        vec![Effect::Load {
            files: self
                .trials
                .iter()
                .map(|t| (t.file.clone(), t.path.clone()))
                .collect(),
            limits: self.limits.table.clone(),
            glitch_deg: self.limits.settings.glitch_deg,
            model: self.model.clone(),
        }]
    }

    /// Indices into `trials` of the rows shown (filtered), in order.
    pub fn visible(&self) -> Vec<usize> {
        let f = self.filter.to_lowercase();
        (0..self.trials.len())
            .filter(|&i| f.is_empty() || self.trials[i].file.to_lowercase().contains(&f))
            .collect()
    }

    pub fn selected_entry(&self) -> Option<&TrialEntry> {
        self.visible().get(self.selected).map(|&i| &self.trials[i])
    }

    pub fn entry(&self, file: &str) -> Option<&TrialEntry> {
        self.trials.iter().find(|t| t.file == file)
    }

    pub(super) fn entry_mut(&mut self, file: &str) -> Option<&mut TrialEntry> {
        self.trials.iter_mut().find(|t| t.file == file)
    }

    /// The trial open on the trial screen.
    pub fn open_entry(&self) -> Option<&TrialEntry> {
        self.entry(self.open.as_deref()?)
    }

    /// Whether anything would be lost by quitting now.
    pub fn unsaved(&self) -> bool {
        self.limits.dirty() || self.trials.iter().any(TrialEntry::unsaved_choice)
    }

    fn sort_trials(&mut self) {
        let keep = self.selected_entry().map(|e| e.file.clone());
        let dur = |e: &TrialEntry| e.loaded().map_or(f64::INFINITY, |l| l.trial.duration_s());
        let v = self.variant;
        let exc = |e: &TrialEntry| {
            e.mean_excursion(Some(v))
                .or_else(|| e.mean_excursion(None))
                .unwrap_or(f64::NEG_INFINITY)
        };
        match self.sort {
            SortKey::Name => self.trials.sort_by(|a, b| a.file.cmp(&b.file)),
            SortKey::Duration => self
                .trials
                .sort_by(|a, b| dur(a).total_cmp(&dur(b)).then(a.file.cmp(&b.file))),
            SortKey::Excursion => self
                .trials
                .sort_by(|a, b| exc(b).total_cmp(&exc(a)).then(a.file.cmp(&b.file))),
        }
        if let Some(f) = keep {
            self.select_file(&f);
        }
    }

    /// Moves the selection to a file, if it is visible.
    pub fn select_file(&mut self, file: &str) {
        if let Some(k) = self
            .visible()
            .iter()
            .position(|&i| self.trials[i].file == file)
        {
            self.selected = k;
        }
    }

    pub(super) fn info(&mut self, text: impl Into<String>) {
        self.message = Some((text.into(), false));
    }

    pub(super) fn error(&mut self, text: impl Into<String>) {
        self.message = Some((text.into(), true));
    }

    /// Joints of the open trial's model present in the trial (model order).
    pub fn open_joints(&self) -> Vec<String> {
        let Some(l) = self.open_entry().and_then(|e| e.loaded()) else {
            return vec![];
        };
        l.before.iter().map(|f| f.joint.clone()).collect()
    }

    pub(super) fn run_effect(
        &mut self,
        file: &str,
        recorrect: Option<Vec<String>>,
    ) -> Option<Effect> {
        let limits = self.limits.table.clone();
        let limits_source = self.limits.source.clone();
        let settings = self.settings;
        let e = self.entry_mut(file)?;
        let loaded = e.loaded()?.clone();
        let recorrect = match recorrect {
            Some(joints) if e.results.len() == Variant::ALL.len() => Some((
                Variant::ALL
                    .iter()
                    .map(|v| e.results[v].correction.clone())
                    .collect(),
                joints,
            )),
            Some(_) if e.results.is_empty() => return None,
            _ => None,
        };
        e.gen += 1;
        e.running = Some(0);
        Some(Effect::Run(Box::new(RunJob {
            file: file.to_string(),
            gen: e.gen,
            loaded,
            limits,
            limits_source,
            settings,
            recorrect,
        })))
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
        Msg::Mouse(m) => {
            if app.screen == Screen::Trial && app.overlay.is_none() {
                match m.kind {
                    MouseEventKind::ScrollUp => zoom(app, true),
                    MouseEventKind::ScrollDown => zoom(app, false),
                    _ => {}
                }
            } else {
                match m.kind {
                    MouseEventKind::ScrollUp => return action(app, Action::Up),
                    MouseEventKind::ScrollDown => return action(app, Action::Down),
                    _ => {}
                }
            }
            vec![]
        }
        Msg::Resize => vec![],
        Msg::FileChanged(file, path) => {
            match app.entry_mut(&file) {
                Some(e) => {
                    let chosen = e.chosen;
                    *e = TrialEntry::new(file.clone(), path.clone());
                    e.chosen = chosen.filter(|_| false);
                }
                None => {
                    app.trials.push(TrialEntry::new(file.clone(), path.clone()));
                    app.sort_trials();
                }
            }
            vec![Effect::Load {
                files: vec![(file, path)],
                limits: app.limits.table.clone(),
                glitch_deg: app.limits.settings.glitch_deg,
                model: app.model.clone(),
            }]
        }
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
            if let Some(e) = app.entry_mut(&file) {
                e.load = match result {
                    Ok(l) => LoadState::Loaded(l),
                    Err(m) => LoadState::Failed(m),
                };
            }
            if app.sort != SortKey::Name {
                app.sort_trials();
            }
            vec![]
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
                    for c in corrections {
                        let saved = old
                            .get(&c.variant)
                            .filter(|r| r.correction == c)
                            .and_then(|r| r.saved.clone());
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
                    app.info(format!("{file}: corrections done"));
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
            match result {
                Ok(out) => {
                    if let Some(r) = app
                        .entry_mut(&file)
                        .and_then(|e| e.results.get_mut(&variant))
                    {
                        r.saved = Some(out.clone());
                    }
                    app.info(format!("saved {out}"));
                }
                Err(m) => app.error(format!("cannot save {file}: {m}")),
            }
            vec![]
        }
        Msg::LimitsSaved(result) => {
            match result {
                Ok(path) => app.info(format!("saved {path}")),
                Err(m) => {
                    // Not saved after all: the edits stay unsaved.
                    app.limits.saved_table = LimitTable {
                        preamble: vec![],
                        rows: vec![],
                    };
                    app.error(format!("cannot save limits: {m}"));
                }
            }
            vec![]
        }
        Msg::LimitsOnDisk(table, settings) => {
            let l = &mut app.limits;
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
            super::views::tick(app);
            vec![]
        }
        Msg::Calibrations(entries, protocol) => {
            super::calibration::loaded(app, entries, protocol);
            vec![]
        }
        Msg::Histograms(c) => super::histogram::received(app, *c),
        Msg::TableWritten(result) => {
            super::histogram::written(app, result);
            vec![]
        }
        Msg::PoseCalibrated(file, result) => super::pose::calibrated(app, &file, result),
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

fn zoom(app: &mut App, zoom_in: bool) {
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

fn key(app: &mut App, k: KeyEvent) -> Vec<Effect> {
    // Text entry first: the filter and the cell editor take characters.
    if app.filter_editing && app.overlay.is_none() {
        match k.code {
            KeyCode::Enter => app.filter_editing = false,
            KeyCode::Esc => {
                app.filter_editing = false;
                app.filter.clear();
            }
            KeyCode::Backspace => {
                app.filter.pop();
            }
            KeyCode::Char(c) => app.filter.push(c),
            _ => {}
        }
        app.selected = 0;
        return vec![];
    }
    if app.screen == Screen::Limits && app.overlay.is_none() && app.limits.edit.is_some() {
        return edit_key(app, k);
    }
    match keymap::action(&k) {
        Some(a) => action(app, a),
        None => vec![],
    }
}

fn edit_key(app: &mut App, k: KeyEvent) -> Vec<Effect> {
    let l = &mut app.limits;
    let Some(edit) = l.edit.as_mut() else {
        return vec![];
    };
    match k.code {
        KeyCode::Esc => {
            l.edit = None;
            return vec![];
        }
        KeyCode::Enter => {
            let text = edit.text.clone();
            let applied = l.apply(&text);
            match applied {
                Ok((table, settings)) => {
                    let settings_changed = settings != l.settings;
                    if let Some(r) = l.table.rows.get(l.row) {
                        l.pending.get_or_insert_with(Vec::new).push(r.joint.clone());
                    }
                    l.pending_all |= settings_changed;
                    l.table = table;
                    l.settings = settings;
                    l.edit = None;
                    app.settings = app.limits.settings.settings();
                    return vec![Effect::Debounce];
                }
                Err(m) => {
                    if let Some(edit) = l.edit.as_mut() {
                        edit.error = Some(m);
                    }
                    return vec![];
                }
            }
        }
        _ => {
            if !edit.key(k) {
                return vec![];
            }
        }
    }
    let text = edit.text.clone();
    let err = l.apply(&text).err();
    if let Some(edit) = l.edit.as_mut() {
        edit.error = err;
    }
    vec![]
}

fn action(app: &mut App, a: Action) -> Vec<Effect> {
    // Overlays answer first.
    match (&app.overlay, a) {
        (Some(Overlay::Help), Action::Quit) => {
            app.overlay = None;
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
            return vec![];
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
            return super::histogram::open(app);
        }
        _ => {}
    }
    app.message = None;
    match app.screen {
        Screen::Trials => trials_action(app, a),
        Screen::Trial => trial_action(app, a),
        Screen::Compare => compare_action(app, a),
        Screen::Limits => limits_action(app, a),
        Screen::Views => {
            super::views::action(app, a);
            vec![]
        }
        Screen::Calibration => super::calibration::action(app, a),
        Screen::Histogram => super::histogram::action(app, a),
    }
}

fn trials_action(app: &mut App, a: Action) -> Vec<Effect> {
    let n = app.visible().len();
    match a {
        Action::Up => app.selected = app.selected.saturating_sub(1),
        Action::Down => app.selected = (app.selected + 1).min(n.saturating_sub(1)),
        Action::PageUp => app.selected = app.selected.saturating_sub(10),
        Action::PageDown => app.selected = (app.selected + 10).min(n.saturating_sub(1)),
        Action::Filter => app.filter_editing = true,
        Action::Back => app.filter.clear(),
        Action::Sort => {
            app.sort = match app.sort {
                SortKey::Name => SortKey::Duration,
                SortKey::Duration => SortKey::Excursion,
                SortKey::Excursion => SortKey::Name,
            };
            app.sort_trials();
        }
        Action::Variant => next_variant(app),
        Action::Calibration => return super::calibration::enter(app),
        Action::Enter | Action::Right => {
            let Some(e) = app.selected_entry() else {
                return vec![];
            };
            match &e.load {
                LoadState::Loaded(_) => {
                    let f = e.file.clone();
                    open(app, f);
                }
                LoadState::Pending => app.info(format!("{} is still loading", e.file)),
                LoadState::Failed(m) => {
                    let m = m.clone();
                    app.error(m)
                }
            }
        }
        Action::Run => {
            if let Some(f) = app.selected_entry().map(|e| e.file.clone()) {
                return app.run_effect(&f, None).into_iter().collect();
            }
        }
        _ => {}
    }
    vec![]
}

/// Opens a trial on the trial screen.
pub fn open(app: &mut App, file: String) {
    if app.open.as_deref() != Some(file.as_str()) {
        app.joint = 0;
        app.view = View {
            braille: app.view.braille,
            ..View::default()
        };
    }
    app.select_file(&file);
    app.open = Some(file);
    app.screen = Screen::Trial;
}

pub(super) fn next_variant(app: &mut App) {
    let k = Variant::ALL
        .iter()
        .position(|v| *v == app.variant)
        .unwrap_or(0);
    app.variant = Variant::ALL[(k + 1) % Variant::ALL.len()];
}

fn trial_action(app: &mut App, a: Action) -> Vec<Effect> {
    let joints = app.open_joints().len();
    let d = app
        .open_entry()
        .and_then(|e| e.loaded())
        .map_or(0.0, |l| l.trial.duration_s());
    let (s0, s1) = app.view.span(d);
    let step = (s1 - s0) / 50.0;
    match a {
        Action::Back => app.screen = Screen::Trials,
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
        Action::Variant => next_variant(app),
        Action::Pose => return super::pose::toggle(app),
        Action::Scatter => super::views::open(app, super::views::ViewKind::Scatter),
        Action::Globe => super::views::open(app, super::views::ViewKind::Globe),
        Action::Applied => super::views::open(app, super::views::ViewKind::Applied),
        Action::Stick => super::views::open(app, super::views::ViewKind::Stick),
        Action::HeadingDrift => super::views::open(app, super::views::ViewKind::Heading),
        Action::Compare => {
            app.compare_col = Variant::ALL
                .iter()
                .position(|v| *v == app.variant)
                .unwrap_or(0);
            app.screen = Screen::Compare;
        }
        Action::Run => {
            if let Some(f) = app.open.clone() {
                return app.run_effect(&f, None).into_iter().collect();
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
    vec![]
}

/// Moves the cursor to the selected joint's next glitch (wrapping).
fn next_glitch(app: &mut App) {
    let Some(l) = app.open_entry().and_then(|e| e.loaded()) else {
        return;
    };
    let Some(joint) = l.before.get(app.joint).map(|f| f.joint.clone()) else {
        return;
    };
    let found = super::glitches::of_joint(l, &joint);
    if let Some(t) = super::glitches::next_after(&found, app.view.cursor_s) {
        app.view.cursor_s = t;
    }
}

fn compare_action(app: &mut App, a: Action) -> Vec<Effect> {
    let Some(file) = app.open.clone() else {
        app.screen = Screen::Trials;
        return vec![];
    };
    match a {
        Action::Back => app.screen = Screen::Trial,
        Action::Left => app.compare_col = app.compare_col.saturating_sub(1),
        Action::Right => app.compare_col = (app.compare_col + 1).min(Variant::ALL.len() - 1),
        Action::Up => app.joint = app.joint.saturating_sub(1),
        Action::Down => app.joint = (app.joint + 1).min(app.open_joints().len().saturating_sub(1)),
        Action::Run => return app.run_effect(&file, None).into_iter().collect(),
        Action::Choose | Action::Enter => {
            let v = Variant::ALL[app.compare_col];
            app.variant = v;
            if let Some(e) = app.entry_mut(&file) {
                e.chosen = Some(v);
            }
            app.info(format!("chose {v}; w saves it"));
        }
        Action::Save => {
            let v = app
                .entry(&file)
                .and_then(|e| e.chosen)
                .unwrap_or(Variant::ALL[app.compare_col]);
            let limits = app.limits.table.clone();
            let limits_source = app.limits.source.clone();
            let Some(e) = app.entry_mut(&file) else {
                return vec![];
            };
            let (Some(loaded), Some(r)) = (e.loaded().cloned(), e.results.get(&v)) else {
                app.error(format!("run the corrections first (r): {v} is not done"));
                return vec![];
            };
            e.chosen = Some(v);
            return vec![Effect::SaveVariant {
                file: file.clone(),
                path: e.path.clone(),
                loaded,
                correction: r.correction.clone(),
                limits,
                limits_source,
            }];
        }
        _ => {}
    }
    vec![]
}

fn limits_action(app: &mut App, a: Action) -> Vec<Effect> {
    let l = &mut app.limits;
    let n = l.rows();
    match a {
        Action::Back => app.screen = app.limits_from,
        Action::Up => l.row = l.row.saturating_sub(1),
        Action::Down => l.row = (l.row + 1).min(n.saturating_sub(1)),
        Action::PageUp => l.row = l.row.saturating_sub(10),
        Action::PageDown => l.row = (l.row + 10).min(n.saturating_sub(1)),
        Action::Left => l.col = l.col.saturating_sub(1).max(FIRST_EDIT_COL),
        Action::Right => l.col = (l.col + 1).min(LAST_COL),
        Action::Enter => {
            let text = l.cell_text(l.row, l.col);
            l.edit = Some(CellEdit::new(text));
        }
        Action::Save => {
            let (table, settings) = (l.table.clone(), l.settings.clone());
            l.saved_table = table.clone();
            l.saved_settings = settings.clone();
            return vec![Effect::SaveLimits {
                dir: l.dir.clone(),
                table_name: l.table_name.clone(),
                table_csv: table.to_csv(),
                settings_toml: settings.to_toml(),
            }];
        }
        _ => {}
    }
    vec![]
}
