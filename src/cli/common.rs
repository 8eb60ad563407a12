//! What several commands share: model, limits and settings resolution, progress.

use acm_workbench::limits::{LimitTable, Settings, SettingsFile, BUILTIN_SETTINGS, BUILTIN_TABLES};
use acm_workbench::model::{Model, BUILTIN_MODELS};
use acm_workbench::trial::read_trial_header;
use anyhow::Context as _;
use clap::Args;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

/// Options of the correction engine, shared by `correct` and `report`.
#[derive(Debug, Clone, Args, Default)]
pub struct EngineArgs {
    /// Body model: `infant13`, `opensim` or a model TOML file [default: the
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
    /// Worker threads [default: all cores]; results do not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
}

/// Model, limits and settings for a run.
pub struct Context {
    pub model: Model,
    pub limits: LimitTable,
    /// Where the table came from (a path or `<built-in NAME>`).
    pub limits_source: String,
    pub settings: Settings,
}

/// The folder of limit tables the program uses when none is named: `./joint_limits`.
pub fn default_limits_dir() -> PathBuf {
    PathBuf::from("joint_limits")
}

/// Picks the built-in model that recognises most IMUs of the trial.
pub fn detect_model(trial: &Path) -> Model {
    let mut best: Option<(usize, Model)> = None;
    for (name, _) in BUILTIN_MODELS {
        let model = Model::builtin(name).expect("built-in model is valid");
        let known = read_trial_header(trial, &model)
            .map(|h| h.imus.iter().filter(|i| model.imus.contains(i)).count())
            .unwrap_or(0);
        if best.as_ref().is_none_or(|(k, _)| known > *k) {
            best = Some((known, model));
        }
    }
    best.expect("there are built-in models").1
}

/// Resolves model, limit table and settings from the arguments.
pub fn load_context(args: &EngineArgs, trial: Option<&Path>) -> anyhow::Result<Context> {
    if let Some(n) = args.threads {
        // Ignore the error of a pool already built (tests call this twice).
        let _ = rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build_global();
    }
    let model = match (&args.model, trial) {
        (Some(m), _) => Model::load(m)?,
        (None, Some(t)) => detect_model(t),
        (None, None) => Model::infant13(),
    };
    let dir = default_limits_dir();
    let settings_path = dir.join("settings.toml");
    let file_settings = if settings_path.exists() {
        let text = std::fs::read_to_string(&settings_path)
            .with_context(|| format!("{}: cannot read", settings_path.display()))?;
        SettingsFile::parse(&text, &settings_path.display().to_string())?
    } else {
        SettingsFile::parse(BUILTIN_SETTINGS, "<built-in settings.toml>")?
    };
    let (limits, limits_source) = match &args.limits {
        Some(p) => (LimitTable::load(p)?, p.display().to_string()),
        None => {
            let p = dir.join(&file_settings.table);
            if p.exists() {
                (LimitTable::load(&p)?, p.display().to_string())
            } else {
                let (name, text) = BUILTIN_TABLES
                    .iter()
                    .find(|(n, _)| *n == file_settings.table)
                    .unwrap_or(&BUILTIN_TABLES[0]);
                let source = format!("<built-in {name}>");
                (LimitTable::parse(text, &source)?, source)
            }
        }
    };
    limits.check_covers(&model, &limits_source)?;
    let defaults = file_settings.settings();
    let settings = Settings {
        lambda1: args.lambda1.unwrap_or(defaults.lambda1),
        window_s: args.window.unwrap_or(defaults.window_s),
        hop_s: args.hop.unwrap_or(defaults.hop_s),
    };
    settings.validate("command line")?;
    Ok(Context {
        model,
        limits,
        limits_source,
        settings,
    })
}

/// Progress on stderr: a line updated in place on a terminal, silent otherwise
/// or with `--quiet`.
pub struct Progress {
    label: String,
    enabled: bool,
    last: std::sync::atomic::AtomicUsize,
}

impl Progress {
    pub fn new(label: &str, quiet: bool) -> Progress {
        Progress {
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
            eprint!("\r{}: {pct:3}% ({done}/{total} windows)", self.label);
        }
    }

    /// Ends the progress line.
    pub fn finish(&self) {
        if self.enabled {
            eprintln!();
        }
    }
}
