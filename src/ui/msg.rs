//! What passes between the parts of the workbench: messages in (keys, job
//! results, file events), effects out (jobs for the runtime), and the
//! navigation a screen asks the router for. A leaf: it names no screen.

use super::loaded::{LiveTrace, Loaded};
use crate::acm::{Correction, Variant};
use crate::analysis::centroid::CentroidTable;
use crate::analysis::histogram::JointHistogram;
use crate::analysis::TimeSpan;
use crate::calibration::Calibration;
use crate::limits::{LimitTable, Settings, SettingsFile};
use crate::model::Model;
use crate::report::TrialReport;
use ratatui::crossterm::event::{KeyEvent, MouseEvent};
use std::path::PathBuf;
use std::sync::Arc;

/// The screen in front.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Screen {
    Trials,
    Trial,
    Compare,
    Limits,
    /// The analysis views.
    Views,
    Calibration,
    Histogram,
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
    /// Turn mouse capture on or off (`M`).
    Mouse(bool),
    /// Follow a trial another program is appending to (answered by
    /// `Msg::Live` until it stops growing; a newer follow of the same trial
    /// replaces an older one).
    Follow(Box<FollowJob>),
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
    /// With `recorrect`: override `auto`'s choice for this joint with this
    /// variant (None: back to auto's own); the other variants are kept.
    pub auto_override: Option<(String, Option<Variant>)>,
}

/// A trial to follow while it grows, and how to correct it.
#[derive(Debug, Clone)]
pub struct FollowJob {
    pub file: String,
    pub path: PathBuf,
    /// Generation of the follow; messages of older ones are ignored.
    pub gen: u64,
    /// The model to read it with (None: detected from its header).
    pub model: Option<Arc<Model>>,
    pub limits: LimitTable,
    pub limits_source: String,
    pub settings: Settings,
    pub variant: Variant,
}

/// What following a growing trial reports.
#[derive(Debug, Clone)]
pub enum LiveEvent {
    /// The rows read so far and their correction.
    Snapshot(Box<LiveSnapshot>),
    /// The file was truncated, replaced or rewritten: read again from its
    /// start (why, for the status line).
    Restarted(String),
    /// Following ended: the file stopped growing (`Ok`), or cannot be
    /// followed (why, located). `grew`: it grew while followed.
    Ended {
        result: Result<(), String>,
        grew: bool,
    },
}

/// A growing trial as read so far.
#[derive(Debug, Clone)]
pub struct LiveSnapshot {
    /// The rows read so far (no truth, reference or glitches yet: those are
    /// read with the whole file once it stops growing).
    pub loaded: Arc<Loaded>,
    pub trace: LiveTrace,
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
    /// The limit files on disk cannot be read: why, located (file:line:col).
    LimitsInvalid(String),
    RecorrectDue,
    /// Time passes (only sent while something plays).
    Tick,
    /// The calibration recordings of the folder, read and calibrated (protocol label).
    Calibrations(Vec<CalibEntry>, String),
    /// The histograms and centroids of the histogram screen's trials over a span.
    Histograms(Box<Computed>),
    /// A suggested limit table or a centroid table was written (its path), or why not.
    TableWritten(Result<String, String>),
    /// News of a trial being followed as it grows.
    Live {
        file: String,
        gen: u64,
        event: LiveEvent,
    },
    /// A pose-calibrated version of a trial, or why there is none.
    PoseCalibrated(String, Result<Arc<Loaded>, String>),
}

/// Which analysis view is in front.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ViewKind {
    #[default]
    Scatter,
    Globe,
    Applied,
    Stick,
    /// The heading drift per IMU of a heading variant.
    Heading,
}

impl ViewKind {
    /// The view's name in titles and `acmw render`.
    pub fn name(self) -> &'static str {
        match self {
            ViewKind::Scatter => "scatter",
            ViewKind::Globe => "globe",
            ViewKind::Applied => "applied",
            ViewKind::Stick => "stick",
            ViewKind::Heading => "heading",
        }
    }

    /// The view of a name.
    pub fn from_name(name: &str) -> Option<ViewKind> {
        [
            ViewKind::Scatter,
            ViewKind::Globe,
            ViewKind::Applied,
            ViewKind::Stick,
            ViewKind::Heading,
        ]
        .into_iter()
        .find(|k| k.name() == name)
    }
}

/// Another screen a screen asks the router to open.
#[derive(Debug, Clone, PartialEq)]
pub enum Nav {
    /// Back to (or over to) a screen whose state is already in place.
    To(Screen),
    /// The trial screen on this trial (file name).
    OpenTrial(String),
    /// The compare screen of the open trial, on the variant shown.
    Compare,
    /// An analysis view of the open trial.
    View(ViewKind),
    /// The calibration screen (reads the folder's recordings afresh).
    Calibration,
    /// The histogram screen over the trials the current screen has chosen.
    Histogram,
}

/// What a screen's answer to a key holds: jobs for the runtime, and perhaps
/// another screen.
#[derive(Debug, Clone, Default)]
pub struct Reply {
    pub effects: Vec<Effect>,
    pub nav: Option<Nav>,
}

impl Reply {
    /// Only a navigation.
    pub fn nav(nav: Nav) -> Reply {
        Reply {
            effects: vec![],
            nav: Some(nav),
        }
    }
}

impl From<Vec<Effect>> for Reply {
    fn from(effects: Vec<Effect>) -> Reply {
        Reply { effects, nav: None }
    }
}

impl From<Option<Effect>> for Reply {
    fn from(effect: Option<Effect>) -> Reply {
        Reply {
            effects: effect.into_iter().collect(),
            nav: None,
        }
    }
}

/// One calibration recording of the folder and what became of it.
#[derive(Debug, Clone)]
pub struct CalibEntry {
    /// File name inside the folder.
    pub file: String,
    /// The calibration, or why the recording could not be read.
    pub result: Result<Arc<Calibration>, String>,
}

/// What the histogram job computes over one span.
#[derive(Debug, Clone)]
pub struct Computed {
    pub span: TimeSpan,
    /// One histogram per joint, in model order.
    pub joints: Vec<JointHistogram>,
    pub rows: Arc<RowAnalysis>,
}

/// The span's samples pooled per row of `table` (joints sharing a row pool
/// together): the histograms a suggestion is made from, and the centroids.
#[derive(Debug, Clone)]
pub struct RowAnalysis {
    /// The table the rows are of (a suggestion needs the same one).
    pub table: LimitTable,
    pub hists: Vec<JointHistogram>,
    pub centroids: CentroidTable,
}
