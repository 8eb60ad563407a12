//! The workbench's shared data: the trials folder and what became of each
//! trial, the limits in use and as edited, the selection every screen shares
//! (open trial, joint, time cursor, variant) and the status message. Screens
//! read and change it; none of them owns it. No I/O here.

pub use super::loaded::{AngleCache, JointAngles, LiveTrace, Loaded, SavedOutput};
use super::msg::{Effect, FollowJob, RunJob};
use crate::acm::{Correction, Variant};
use crate::limits::{LimitTable, Settings, SettingsFile};
use crate::metrics::JointFigures;
use crate::model::Model;
use crate::report::TrialReport;
use ratatui::crossterm::event::{KeyCode, KeyEvent, KeyModifiers};
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;

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
    /// The variant whose save is under way.
    pub saving: Option<Variant>,
    /// The generation of the newest follow of this trial while another
    /// program appends to it (None: not followed).
    pub following: Option<u64>,
    /// The correction of the rows read while followed.
    pub live: Option<LiveTrace>,
    /// Correct every variant once the trial is read whole (it stopped growing).
    pub correct_when_loaded: bool,
    /// Outputs written this session: variant -> path as shown (relative to
    /// the trial's folder).
    pub written: BTreeMap<Variant, String>,
    /// A save over an output of another correction of this trial, waiting
    /// for y (overwrite) or n.
    pub overwrite: Option<Variant>,
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
            saving: None,
            following: None,
            live: None,
            correct_when_loaded: false,
            written: BTreeMap::new(),
            overwrite: None,
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

    /// Status of one variant, as the trials and compare screens show it.
    pub fn variant_status(&self, v: Variant) -> String {
        let on_disk = self.loaded().is_some_and(|l| l.on_disk.contains_key(&v));
        match self.results.get(&v) {
            _ if self.saving == Some(v) => "saving".into(),
            _ if self.live.as_ref().is_some_and(|l| l.variant == v) => "live".into(),
            Some(r) if r.saved.is_some() => "saved".into(),
            None if on_disk && self.running.is_none() => "saved".into(),
            Some(_) if self.chosen == Some(v) => "chosen".into(),
            _ if self.running.is_some() => format!("{}%", self.running.unwrap_or(0)),
            Some(_) => "done".into(),
            None => "-".into(),
        }
    }

    /// What a finished variant left undone or did otherwise than its name
    /// says: joints it skipped (and why), joints a baseline variant corrected
    /// with drift-centroid because it has no method for them.
    pub fn variant_note(&self, v: Variant) -> Option<String> {
        if v == Variant::None {
            // Leaving the trial as read is what this variant is for.
            return None;
        }
        let c = &self.results.get(&v)?.correction;
        let corrected = if v == Variant::Ik {
            c.ik.is_some()
        } else {
            !c.joints.is_empty()
        };
        // Joints whose IMUs the trial does not have are not the variant's doing.
        let present: Vec<&str> = self
            .loaded()
            .map(|l| l.before.iter().map(|f| f.joint.as_str()).collect())
            .unwrap_or_default();
        let skipped: Vec<_> = c
            .skipped
            .iter()
            .filter(|s| present.contains(&s.joint.as_str()))
            .collect();
        if !corrected {
            let why = skipped
                .first()
                .map_or("no joint could be corrected", |s| &s.reason);
            return Some(format!("nothing corrected: {why}"));
        }
        let mut notes = vec![];
        if let Some(s) = skipped.first() {
            let more = skipped.len() - 1;
            let more = if more > 0 {
                format!(" +{more} more")
            } else {
                String::new()
            };
            notes.push(format!("skipped {} ({}){more}", s.joint, s.reason));
        }
        if matches!(v, Variant::Rivest | Variant::Mueller) {
            let by_acm: Vec<&str> = c
                .joints
                .iter()
                .filter(|j| j.baseline.is_none())
                .map(|j| j.joint.as_str())
                .collect();
            if !by_acm.is_empty() {
                notes.push(format!(
                    "{} joint(s) by drift-centroid (no {v} method for them)",
                    by_acm.len()
                ));
            }
        }
        (!notes.is_empty()).then(|| notes.join("; "))
    }

    /// [`TrialEntry::variant_note`] in a few characters, for a footer.
    pub fn variant_note_short(&self, v: Variant) -> Option<String> {
        let note = self.variant_note(v)?;
        Some(if note.starts_with("nothing") {
            format!("{v}: nothing done!")
        } else if note.starts_with("skipped") {
            format!("{v} done, skips!")
        } else {
            format!("{v} done, d+c!")
        })
    }

    /// Whether a chosen variant is not saved yet.
    pub fn unsaved_choice(&self) -> bool {
        self.chosen
            .is_some_and(|v| self.results.get(&v).is_none_or(|r| r.saved.is_none()))
    }
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
    /// A save of the table and settings is under way.
    pub saving: bool,
    /// Why the files on disk cannot be read (located); the table in use is
    /// the last good one.
    pub disk_error: Option<String>,
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
            saving: false,
            disk_error: None,
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
        if table.swing_twist.is_some() {
            // Its rows here are the boxes of its regions, not what it limits.
            return Err(
                "a swing-twist table is edited in its CSV file; the workbench edits Euler tables"
                    .into(),
            );
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
                if !(0.0..=LAMBDA2_MAX).contains(&v) {
                    return Err(format!(
                        "lambda2 must be within 0..{LAMBDA2_MAX} (the thesis uses 30)"
                    ));
                }
                let has_centroid = table
                    .rows
                    .iter()
                    .any(|r| r.joint == joint && r.centroid_deg.is_some());
                if v > 0.0 && !has_centroid {
                    return Err(format!(
                        "lambda2 weighs the centroid and {joint} has none: set its centroid first"
                    ));
                }
                // lambda2 is the same on a joint's three rows.
                for r in table.rows.iter_mut().filter(|r| r.joint == joint) {
                    r.lambda2 = v;
                }
            }
            _ => return Err("this column cannot be edited".into()),
        }
        let r = &table.rows[self.row];
        if let Some(c) = r.centroid_deg {
            if r.lower_deg < r.upper_deg && !(r.lower_deg..=r.upper_deg).contains(&c) {
                return Err(format!(
                    "centroid {c} must lie within the limits [{}, {}]",
                    r.lower_deg, r.upper_deg
                ));
            }
        }
        LimitTable::parse(&table.to_csv(), "edit").map_err(|e| e.message)?;
        Ok((table, settings))
    }
}

/// The largest lambda2 the limits editor takes: the thesis weighs the
/// centroid term with 30; a thousand already lets it outweigh any excursion
/// (the term is at most sqrt(2) per sample).
pub const LAMBDA2_MAX: f64 = 1000.0;

/// What every screen shares.
#[derive(Debug, Clone)]
pub struct Workbench {
    /// The trials folder as the user named it (shown; never made absolute).
    pub dir_label: String,
    pub dir: PathBuf,
    pub trials: Vec<TrialEntry>,
    /// Index into [`Workbench::visible`].
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
    pub limits: LimitsState,
    pub settings: Settings,
    /// A message in the status bar: (text, is_error).
    pub message: Option<(String, bool)>,
}

impl Workbench {
    /// A workbench over `dir` listing `files` (names) as not loaded yet.
    pub fn new(
        dir_label: String,
        dir: PathBuf,
        files: Vec<String>,
        limits: LimitsState,
    ) -> Workbench {
        let settings = limits.settings.settings();
        let mut wb = Workbench {
            dir_label,
            trials: vec![],
            dir,
            selected: 0,
            filter: String::new(),
            filter_editing: false,
            model: None,
            sort: SortKey::Name,
            variant: Variant::Drift,
            open: None,
            joint: 0,
            view: View::default(),
            limits,
            settings,
            message: None,
        };
        for f in files {
            let path = wb.dir.join(&f);
            wb.trials.push(TrialEntry::new(f, path));
        }
        wb.sort_trials();
        wb
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

    pub fn entry_mut(&mut self, file: &str) -> Option<&mut TrialEntry> {
        self.trials.iter_mut().find(|t| t.file == file)
    }

    /// The trial open on the trial screen.
    pub fn open_entry(&self) -> Option<&TrialEntry> {
        self.entry(self.open.as_deref()?)
    }

    /// Whether anything would be lost by quitting now: unsaved edits or
    /// choices, a correction still running, a save still being written.
    pub fn unsaved(&self) -> bool {
        self.limits.dirty()
            || self.limits.saving
            || self
                .trials
                .iter()
                .any(|t| t.unsaved_choice() || t.running.is_some() || t.saving.is_some())
    }

    /// Sorts the trials by the sort key, keeping the selection.
    pub fn sort_trials(&mut self) {
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

    /// Shows `text` in the status bar.
    pub fn info(&mut self, text: impl Into<String>) {
        self.message = Some((text.into(), false));
    }

    /// Shows `text` in the status bar as an error.
    pub fn error(&mut self, text: impl Into<String>) {
        self.message = Some((text.into(), true));
    }

    /// Joints of the open trial's model present in the trial (model order).
    pub fn open_joints(&self) -> Vec<String> {
        let Some(l) = self.open_entry().and_then(|e| e.loaded()) else {
            return vec![];
        };
        l.before.iter().map(|f| f.joint.clone()).collect()
    }

    /// The job correcting `file` afresh, or re-correcting `recorrect` joints.
    pub fn run_effect(&mut self, file: &str, recorrect: Option<Vec<String>>) -> Option<Effect> {
        let limits = self.limits.table.clone();
        let limits_source = self.limits.source.clone();
        let settings = self.settings;
        let e = self.entry_mut(file)?;
        if e.following.is_some() {
            self.info(format!(
                "{file} is growing: corrected as it grows; every variant runs once it stops"
            ));
            return None;
        }
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
            auto_override: None,
        })))
    }

    /// The job re-correcting `auto` of `file` with the user's `choice` for
    /// `joint` (None: auto's own); the other variants' results are kept.
    pub fn override_effect(
        &mut self,
        file: &str,
        joint: &str,
        choice: Option<Variant>,
    ) -> Option<Effect> {
        let mut effect = self.run_effect(file, Some(vec![joint.to_string()]))?;
        if let Effect::Run(job) = &mut effect {
            job.auto_override = Some((joint.to_string(), choice));
        }
        Some(effect)
    }

    /// Whether `file` is still growing (followed, or its final reading not
    /// yet in): then `w` is refused, with a status message saying that it
    /// waits for the final correction, since a half trial saved under the
    /// final output's name would pass for the whole one.
    pub fn refuse_save_while_growing(&mut self, file: &str) -> bool {
        let growing = self
            .entry(file)
            .is_some_and(|e| e.following.is_some() || e.live.is_some());
        if growing {
            self.error(format!(
                "{file} is still growing: w waits for the final correction (made once it stops growing)"
            ));
        }
        growing
    }

    /// The job following `file` as it grows, corrected with the variant
    /// shown (replacing any earlier follow of it).
    pub fn follow_effect(&mut self, file: &str) -> Option<Effect> {
        let limits = self.limits.table.clone();
        let limits_source = self.limits.source.clone();
        let (settings, variant, model) = (self.settings, self.variant, self.model.clone());
        let e = self.entry_mut(file)?;
        e.gen += 1;
        e.following = Some(e.gen);
        e.running = None;
        Some(Effect::Follow(Box::new(FollowJob {
            file: file.to_string(),
            path: e.path.clone(),
            gen: e.gen,
            model,
            limits,
            limits_source,
            settings,
            variant,
        })))
    }

    /// Shows the next variant.
    pub fn next_variant(&mut self) {
        let k = Variant::ALL
            .iter()
            .position(|v| *v == self.variant)
            .unwrap_or(0);
        self.variant = Variant::ALL[(k + 1) % Variant::ALL.len()];
    }
}
