//! What several commands share: model, limits and settings resolution, progress.

use acm_workbench::calibration::AppliedCalibration;
use acm_workbench::correct::pipeline::{self, Preparation, Prepared, Setup, Source};
use acm_workbench::limits::{LimitTable, LimitsDir, LimitsError, Settings, SettingsProblem};
use acm_workbench::model::{Model, SignedAxis};
use acm_workbench::names::Named;
use acm_workbench::pose::{PoseCalibration, PoseTime};
use acm_workbench::trial::precision::Precision;
use acm_workbench::trial::TrialFile;
use acm_workbench::variant::{Variant, VARIANTS};
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::Args;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

/// Options of the correction engine, shared by `correct` and `report`.
#[derive(Debug, Clone, Args, Default)]
pub struct EngineArgs {
    /// Body model: `infant13`, `opensim`, `opensense_lower`, `full_body16` or a
    /// model TOML file [default: the
    /// built-in model that knows most of the trial's IMUs].
    #[arg(long)]
    pub model: Option<String>,
    /// Limit table CSV [default: the table named in ./joint_limits/settings.toml,
    /// else the built-in Table 3-2].
    #[arg(long)]
    pub limits: Option<PathBuf>,
    /// Weight of the correction angle in the cost, per degree [default: 0.05].
    #[arg(long)]
    pub lambda1: Option<f64>,
    /// Drift window length, seconds [default: 60].
    #[arg(long)]
    pub window: Option<f64>,
    /// Hop between drift windows, seconds [default: 30].
    #[arg(long)]
    pub hop: Option<f64>,
    /// The global frame's up axis: `z-up`, or `z-down` for north-east-down
    /// recordings [default: from ./joint_limits/settings.toml, else z-up].
    #[arg(long, value_parser = named_parser::<acm_workbench::vertical::Vertical>())]
    pub vertical: Option<acm_workbench::vertical::Vertical>,
    /// Minimiser of the window costs: `gradient`, or `nelder-mead` (the
    /// previous solver, values only, slower) [default: gradient].
    #[arg(long, value_parser = named_parser::<acm_workbench::acm::minimise::Solver>())]
    pub solver: Option<acm_workbench::acm::minimise::Solver>,
    /// Worker threads [default: all cores]; results do not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
}

/// `--precision` of the commands that write corrected trials (`correct`,
/// `batch`, `follow`).
#[derive(Debug, Clone, Args, Default)]
pub struct PrecisionArgs {
    /// Decimal places of the orientation numbers written (quaternion
    /// components; Euler angles in degrees): `auto` as many as the input's
    /// had (full when it had 15 or more, fewer than 4 for quaternions or 2
    /// for degrees, or was of the other kind), `full` shortest round-trip
    /// digits (up to 17 significant), or N (0-17; 15 or more is full)
    /// [default: auto, or the sidecar's with --from-sidecar].
    #[arg(long, value_name = "auto|full|N", value_parser = Precision::parse)]
    pub precision: Option<Precision>,
}

impl PrecisionArgs {
    /// Puts the precision asked for, if any, into `settings`.
    pub fn apply(&self, settings: &mut Settings) {
        if let Some(p) = self.precision {
            settings.precision = p;
        }
    }
}

/// Pose calibration before the correction (shared by `correct` and `report`).
#[derive(Debug, Clone, Args, Default)]
pub struct PoseArgs {
    /// Pose calibration with heading correction before correcting: the
    /// subject holds the model's default pose at TIME, or over START..END
    /// (seconds from the first sample; orientations averaged).
    #[arg(long, value_name = "TIME|START..END")]
    pub pose_calibration: Option<PoseTime>,
    /// The base IMU's sensor axis that points forward in the calibration pose
    /// (+x, -x, +y, -y, +z, -z) [default: the model's `pose.base_forward`].
    #[arg(
        long,
        value_name = "AXIS",
        requires = "pose_calibration",
        allow_hyphen_values = true
    )]
    pub base_forward: Option<SignedAxis>,
}

impl PoseArgs {
    /// The calibration asked for, with the model's heading axes unless overridden.
    pub fn calibration(&self, model: &Model) -> Option<PoseCalibration> {
        let at = self.pose_calibration?;
        let mut setup = model.pose;
        if let Some(a) = self.base_forward {
            setup.base_forward = a;
        }
        Some(PoseCalibration { at, setup })
    }
}

/// The trial at `input`, read once ([`pipeline::read`]), and the run's
/// context, whose model is the one that fits the trial best unless
/// `--model` names one (the trial is read after the flags, the limit table
/// and the settings are checked).
pub fn context_and_file(args: &EngineArgs, input: &Path) -> anyhow::Result<(Context, TrialFile)> {
    let mut file = None;
    let ctx = load_context(args, || {
        let f = pipeline::read(input)?;
        let model = f.detect_model();
        file = Some(f);
        Ok(model)
    })?;
    let file = match file {
        Some(f) => f,
        None => pipeline::read(input)?,
    };
    Ok((ctx, file))
}

/// The pipeline's first two steps for the trial read as `file`: load it,
/// then prepare it as `preparation` asks, printing what the functional
/// calibration did unless `quiet` (`announce`: say that it was applied).
pub fn load_prepared(
    ctx: &Context,
    file: &TrialFile,
    preparation: &Preparation,
    announce: bool,
    quiet: bool,
) -> anyhow::Result<(Source, Prepared)> {
    let loaded = pipeline::load_file(file, &ctx.model)?;
    let prepared = pipeline::prepare(loaded.trial, ctx.setup(), preparation)
        .map_err(|e| anyhow::anyhow!("{}: {e}", file.path.display()))?;
    if let (Some(c), false) = (&prepared.calibration, quiet) {
        if announce {
            eprintln!(
                "{}: calibration {} applied to {} of its {} IMUs first",
                prepared.trial.name,
                c.file,
                c.imus.len() - prepared.calibration_warnings.len(),
                c.imus.len()
            );
        }
        for w in &prepared.calibration_warnings {
            eprintln!("warning: {w}");
        }
    }
    Ok((loaded.source, prepared))
}

/// The functional calibration file `path` names, if any.
pub fn load_calibration(path: Option<&Path>) -> anyhow::Result<Option<AppliedCalibration>> {
    Ok(path.map(AppliedCalibration::load).transpose()?)
}

/// Sizes the global worker pool (all cores when `None`). Results do not
/// depend on it; a pool that already exists is kept.
pub fn set_threads(threads: Option<usize>) {
    if let Some(n) = threads {
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global();
    }
}

/// Model, limits and settings for a run.
pub struct Context {
    pub model: Model,
    pub limits: LimitTable,
    /// Where the table came from (a path or `<built-in NAME>`).
    pub limits_source: String,
    pub settings: Settings,
    /// Glitch threshold from `settings.toml`, degrees.
    pub glitch_deg: f64,
}

impl Context {
    /// The pipeline's view of this context.
    pub fn setup(&self) -> Setup<'_> {
        Setup {
            model: &self.model,
            limits: &self.limits,
            limits_source: &self.limits_source,
            settings: &self.settings,
        }
    }

    /// Checks the drift windows suit `trial` (enough samples per window, not
    /// too many windows); `file` names the trial in the error.
    pub fn check_trial(
        &self,
        trial: &acm_workbench::trial::Trial,
        file: &Path,
    ) -> anyhow::Result<()> {
        let s = &self.settings;
        acm_workbench::acm::window::check_layout(&trial.time_s, s.window_s, s.hop_s)
            .map_err(|e| anyhow::anyhow!("{}: {e}", file.display()))
    }
}

/// The folder of limit tables the program uses when none is named: `./joint_limits`.
pub fn default_limits_dir() -> PathBuf {
    PathBuf::from("joint_limits")
}

/// Resolves model, limit table and settings from the arguments; without
/// `--model` the model is `detect()`'s, called once the table and the
/// settings are resolved.
pub fn load_context(
    args: &EngineArgs,
    detect: impl FnOnce() -> anyhow::Result<Model>,
) -> anyhow::Result<Context> {
    if let Some(n) = args.threads {
        // Ignore the error of a pool already built (tests call this twice).
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global();
    }
    let named = args.model.as_deref().map(Model::load).transpose()?;
    let dir = LimitsDir::load(&default_limits_dir())?;
    let (limits, limits_source) = match &args.limits {
        Some(p) => (LimitTable::load(p)?, p.display().to_string()),
        None => (dir.table, dir.table_source),
    };
    let defaults = dir.settings.settings();
    let settings = Settings {
        lambda1: args.lambda1.unwrap_or(defaults.lambda1),
        window_s: args.window.unwrap_or(defaults.window_s),
        hop_s: args.hop.unwrap_or(defaults.hop_s),
        vertical: args.vertical.unwrap_or(defaults.vertical),
        solver: args.solver.unwrap_or(defaults.solver),
        precision: defaults.precision,
    };
    if let Some(p) = settings.problem() {
        return Err(flag_error(args, &p).into());
    }
    let model = match named {
        Some(m) => m,
        None => detect()?,
    };
    limits.check_covers_in(
        &model,
        &limits_source,
        table_text(&limits_source).as_deref(),
    )?;
    Ok(Context {
        model,
        limits,
        limits_source,
        settings,
        glitch_deg: dir.settings.glitch_deg,
    })
}

/// The CSV text of a limit table by its source (a path, or `<built-in NAME>`),
/// for locating a coverage error; `None` when it cannot be read again.
fn table_text(source: &str) -> Option<String> {
    let builtin = acm_workbench::limits::BUILTIN_TABLES
        .iter()
        .find(|(n, _)| source == format!("<built-in {n}>"));
    match builtin {
        Some((_, text)) => Some(text.to_string()),
        None => acm_workbench::input::read_text(Path::new(source)).ok(),
    }
}

/// A settings problem after the flags were applied, as an error about the
/// flag that set the value (`--hop: expected ...`). A file's values were
/// checked when it was read, so the value at fault was set by a flag, or
/// the file's `hop_s` no longer suits the `--window` given.
fn flag_error(args: &EngineArgs, p: &SettingsProblem) -> LimitsError {
    let own = match p.key {
        "lambda1" => args.lambda1.map(|_| "--lambda1"),
        "window_s" => args.window.map(|_| "--window"),
        "hop_s" => args.hop.map(|_| "--hop"),
        _ => None,
    };
    match (own, args.window) {
        (Some(flag), _) => LimitsError {
            file: flag.into(),
            line: 0,
            column: 0,
            message: p.message.clone(),
        },
        (None, Some(_)) if p.key == "hop_s" => LimitsError {
            file: "--window".into(),
            line: 0,
            column: 0,
            message: format!(
                "the settings' hop_s does not suit it: {}; give --hop too",
                p.message
            ),
        },
        _ => p.at("command line", 0, 0),
    }
}

/// Progress on stderr: a line updated in place on a terminal, silent otherwise
/// or with `--quiet`.
pub struct Progress {
    label: String,
    enabled: bool,
    /// What the steps count (`windows`), or nothing to show percentages only.
    unit: &'static str,
    last: std::sync::atomic::AtomicUsize,
}

impl Progress {
    pub fn new(label: &str, quiet: bool) -> Progress {
        Progress {
            unit: "windows",
            ..Progress::overall(label, quiet)
        }
    }

    /// Progress shown as a percentage of the whole run only (a run over
    /// several variants counts parts of the whole, not windows).
    pub fn overall(label: &str, quiet: bool) -> Progress {
        Progress {
            unit: "",
            label: label.to_string(),
            enabled: !quiet && std::io::stderr().is_terminal(),
            last: std::sync::atomic::AtomicUsize::new(usize::MAX),
        }
    }

    /// Reports `done` of `total` steps.
    pub fn update(&self, done: usize, total: usize) {
        if !self.enabled || total == 0 {
            return;
        }
        let pct = 100 * done / total;
        if self.last.swap(pct, std::sync::atomic::Ordering::Relaxed) != pct {
            match self.unit {
                "" => eprint!("\r{}: {pct:3}%", self.label),
                unit => eprint!("\r{}: {pct:3}% ({done}/{total} {unit})", self.label),
            }
        }
    }

    /// Ends the progress line.
    pub fn finish(&self) {
        if self.enabled {
            eprintln!();
        }
    }
}

/// The parser of `--variant`: the variant table's names, each with its
/// description in `--help`.
/// A parser for a choice type of the library, offering its [`Named::CHOICES`]
/// with their help lines.
pub fn named_parser<T: Named + Send + Sync>() -> impl TypedValueParser<Value = T> {
    let names = T::CHOICES
        .iter()
        .map(|c| PossibleValue::new(c.name()).help(c.help()));
    PossibleValuesParser::new(names).map(|s| T::from_name(&s).expect("a name of the choices"))
}

pub fn variant_parser() -> impl TypedValueParser<Value = Variant> {
    let names = VARIANTS
        .iter()
        .map(|r| PossibleValue::new(r.name).help(r.description));
    PossibleValuesParser::new(names).map(|s| Variant::from_name(&s).expect("a name of the table"))
}
