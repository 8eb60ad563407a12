//! The work behind effects: reading trials, correcting, saving. Each function
//! returns the message that reports its outcome; the runtime calls them on
//! worker threads, tests call them in line (see [`SyncRunner`]).

pub mod calibration;
pub mod histogram;
pub mod live;
pub mod pose;

use super::app::{update, App};
use super::msg::{Effect, Msg, RunJob};
use super::workbench::{LimitsState, Loaded, SavedOutput};
use crate::acm::{Correction, RunControl, Variant};
use crate::correct::pipeline::{self, Recorrect, Setup, Source};
use crate::limits::{LimitTable, LimitsDir, SettingsFile};
use crate::metrics::trial_figures;
use crate::model::Model;
use crate::sidecar::default_output;
use crate::simulate::truth::load_truth_beside;
use crate::trial::glitch::glitches;
use crate::trial::TrialError;
use std::collections::VecDeque;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// Trial names in `dir` (non-recursive), sorted: trial files, OpenSense
/// mapping XMLs, and folders of Xsens exports that no listed mapping reads.
pub fn list_trials(dir: &Path) -> Result<Vec<String>, String> {
    let paths = crate::trial::folder_trials(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut names: Vec<String> = paths
        .iter()
        .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
        .collect();
    names.sort();
    Ok(names)
}

/// The limits the workbench edits: `dir/settings.toml` and the table it names,
/// or the built-in ones when `dir` (normally `./joint_limits`) does not have them;
/// saving creates them there. Resolved as the command-line tools do.
pub fn load_limits(dir: &Path) -> Result<LimitsState, String> {
    let d = LimitsDir::load(dir).map_err(|e| e.to_string())?;
    Ok(limits_state(dir, d))
}

/// The limits editor's state of the folder `dir`, read as `d`.
pub fn limits_state(dir: &Path, d: LimitsDir) -> LimitsState {
    LimitsState::new(
        dir.to_path_buf(),
        d.settings.table.clone(),
        d.table_source,
        d.table,
        d.settings,
    )
}

/// Reads the limit files in `dir` as they are on disk now (None if absent or bad).
pub fn read_limits_on_disk(dir: &Path, table_name: &str) -> Option<Msg> {
    let s = crate::input::read_text(&dir.join("settings.toml")).ok()?;
    let settings = match SettingsFile::parse(&s, "settings.toml") {
        Ok(s) => s,
        Err(e) => return Some(Msg::LimitsInvalid(e.to_string())),
    };
    let name = if settings.table.is_empty() {
        table_name
    } else {
        &settings.table
    };
    Some(match LimitTable::load(&dir.join(name)) {
        Ok(table) => Msg::LimitsOnDisk(table, settings),
        Err(e) => Msg::LimitsInvalid(e.to_string()),
    })
}

/// Reads one trial: the trial, its model, its truth and its uncorrected figures.
/// Orientation jumps over `glitch_deg` (degrees) are flagged. `model` is the
/// body model to read it with; None detects it from the trial's IMU names.
pub fn load_trial(
    file: &str,
    path: &Path,
    limits: &LimitTable,
    glitch_deg: f64,
    model: Option<&Model>,
) -> Msg {
    let shown = |e: TrialError| {
        TrialError {
            file: file.to_string(),
            ..e
        }
        .to_string()
    };
    let result = (|| {
        let input = pipeline::read(path).map_err(shown)?;
        let model = model.cloned().unwrap_or_else(|| input.detect_model());
        let pipeline::LoadedTrial { source, mut trial } =
            pipeline::load_file(&input, &model).map_err(shown)?;
        drop(input);
        trial.name = file.to_string();
        let centroids = crate::pose::centroid_check::check_centroids(&trial, &model, limits);
        trial.warnings.extend(centroids);
        let (truth, truth_error) = match load_truth_beside(path, &model) {
            None => (None, None),
            Some(Ok(t)) => match t.check_against(&trial) {
                Ok(()) => (Some(t.segments), None),
                Err(m) => (None, Some(m.to_string())),
            },
            Some(Err(e)) => (None, Some(shown(e))),
        };
        let before = trial_figures(&trial, None, truth.as_ref(), &model, limits);
        let (reference, reference_error) = reference_beside(path, &trial, &model);
        let glitches = glitches(&trial, glitch_deg);
        let on_disk = saved_outputs(&source);
        Ok(Arc::new(Loaded {
            on_disk,
            glitches,
            trial,
            model,
            source,
            truth,
            truth_error,
            reference,
            reference_error,
            before,
            angles: Default::default(),
            pose: None,
            uncalibrated: None,
        }))
    })();
    Msg::Loaded(file.to_string(), result)
}

/// The optical reference beside the trial at `path`, aligned and resampled
/// onto `trial` (None, None when there is none; the reason when it is unusable).
fn reference_beside(
    path: &Path,
    trial: &crate::trial::Trial,
    model: &Model,
) -> (
    Option<Arc<crate::reference::ReferenceTrace>>,
    Option<String>,
) {
    use crate::reference::{read_reference, trace, CompareOptions};
    let Some(file) = crate::reference::reference_beside(path) else {
        return (None, None);
    };
    let traced = read_reference(&file, model)
        .map_err(|e| e.to_string())
        .and_then(|r| {
            trace(trial, model, &r, &CompareOptions::default()).map_err(|e| e.to_string())
        });
    match traced {
        Ok(t) => (Some(Arc::new(t)), None),
        Err(e) => (None, Some(format!("reference: {e}"))),
    }
}

/// The corrected outputs of the trial read from `source` on disk whose
/// sidecars record this very input (by its hash), by variant: what an
/// earlier session saved.
pub fn saved_outputs(source: &Source) -> std::collections::BTreeMap<Variant, SavedOutput> {
    let mut found = std::collections::BTreeMap::new();
    let input = &source.path;
    for v in Variant::ALL {
        let output = default_output(input, v, source.format.output_default(), source.gzip);
        let side = crate::sidecar::sidecar_path(&output);
        if !output.is_file() || !side.is_file() {
            continue;
        }
        let Ok(record) = crate::sidecar::Sidecar::load(&side) else {
            continue;
        };
        if record.variant != v || record.input.sha256 != source.sha256 {
            continue;
        }
        let shown = input
            .parent()
            .and_then(|d| output.strip_prefix(d).ok())
            .unwrap_or(&output)
            .display()
            .to_string();
        found.insert(
            v,
            SavedOutput {
                shown,
                settings: record.settings,
                limits_hash: record.limits.sha256,
            },
        );
    }
    found
}

/// Corrects a trial with every variant (or re-corrects the edited joints).
pub fn run_job(job: &RunJob, cancel: &AtomicBool, progress: &(dyn Fn(u8) + Sync)) -> Msg {
    let l = &job.loaded;
    let result = (|| {
        let setup = Setup {
            model: &l.model,
            limits: &job.limits,
            limits_source: &job.limits_source,
            settings: &job.settings,
        };
        let s = &job.settings;
        crate::acm::window::check_layout(&l.trial.time_s, s.window_s, s.hop_s)
            .map_err(|e| e.to_string())?;
        let report = |done: usize, total: usize| progress((done * 100 / total.max(1)) as u8);
        let control = RunControl {
            cancel: Some(cancel),
            progress: Some(&report),
        };
        let previous: Vec<&Correction>;
        let joints: Vec<&str>;
        let recorrect = match &job.recorrect {
            Some((p, j)) => {
                previous = p.iter().map(|c| &**c).collect();
                joints = j.iter().map(String::as_str).collect();
                Some(Recorrect {
                    previous: &previous,
                    joints: &joints,
                })
            }
            None => None,
        };
        let out: Vec<Arc<Correction>> = match (&job.auto_override, &job.recorrect) {
            (Some((joint, choice)), Some((all, _))) => {
                let others: Vec<&Correction> = all.iter().map(|c| &**c).collect();
                all.iter()
                    .map(|c| match c.variant {
                        Variant::Auto => pipeline::override_auto(
                            &l.trial,
                            setup,
                            (c, &others),
                            joint,
                            *choice,
                            &control,
                        )
                        .map(Arc::new),
                        _ => Ok(c.clone()),
                    })
                    .collect::<Result<_, _>>()
                    .map_err(|e| e.to_string())?
            }
            _ => pipeline::correct_many(&l.trial, setup, &Variant::ALL, recorrect, &control)
                .map_err(|e| e.to_string())?
                .into_iter()
                .map(Arc::new)
                .collect(),
        };
        let report = pipeline::report_input(&l.trial, setup, l.truth.as_ref())
            .report(out.iter().map(|c| &**c));
        Ok((out, report))
    })();
    Msg::RunDone {
        file: job.file.clone(),
        gen: job.gen,
        result,
    }
}

pub fn save_variant(
    dir: &Path,
    file: &str,
    loaded: &Loaded,
    correction: &Correction,
    limits: &LimitTable,
    limits_source: &str,
) -> Msg {
    let source = &loaded.source;
    let output = source.default_output(correction.variant, None);
    let settings = correction.settings;
    let setup = Setup {
        model: &loaded.model,
        limits,
        limits_source,
        settings: &settings,
    };
    let shown = output
        .path
        .strip_prefix(dir)
        .map(Path::to_path_buf)
        .unwrap_or_else(|_| output.path.clone());
    let saved = pipeline::save_trial(
        source,
        &loaded.trial,
        loaded.pose.as_ref(),
        correction,
        setup,
        &output,
        None,
    );
    Msg::Saved {
        file: file.to_string(),
        variant: correction.variant,
        result: saved
            .map(|_| shown.display().to_string())
            .map_err(|e| format!("{e:#}")),
    }
}

pub fn save_limits(dir: &Path, table_name: &str, table_csv: &str, settings_toml: &str) -> Msg {
    let result = (|| {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let table: PathBuf = dir.join(table_name);
        let settings = dir.join("settings.toml");
        // One commit: the table and the settings naming it change together.
        crate::save::atomic_write_all(&[
            (&table, table_csv.as_bytes()),
            (&settings, settings_toml.as_bytes()),
        ])
        .map_err(|e| format!("{}: cannot write: {e}", table.display()))?;
        Ok(table.display().to_string())
    })();
    Msg::LimitsSaved(result)
}

/// Carries out one effect in line; the messages it produces.
pub fn execute(app_dir: &Path, effect: Effect) -> Vec<Msg> {
    match effect {
        Effect::Load {
            files,
            limits,
            glitch_deg,
            model,
        } => files
            .iter()
            .map(|(f, p)| load_trial(f, p, &limits, glitch_deg, model.as_deref()))
            .collect(),
        Effect::Run(job) => {
            let cancel = AtomicBool::new(false);
            vec![run_job(&job, &cancel, &|_| {})]
        }
        Effect::SaveVariant {
            file,
            loaded,
            correction,
            limits,
            limits_source,
        } => vec![save_variant(
            app_dir,
            &file,
            &loaded,
            &correction,
            &limits,
            &limits_source,
        )],
        Effect::SaveLimits {
            dir,
            table_name,
            table_csv,
            settings_toml,
        } => vec![save_limits(&dir, &table_name, &table_csv, &settings_toml)],
        Effect::Debounce => vec![Msg::RecorrectDue],
        Effect::Mouse(_) => vec![],
        Effect::Calibrations { dir } => vec![calibration::scan(&dir)],
        Effect::Histograms {
            trials,
            span,
            table,
        } => vec![histogram::compute_job(&trials, span, &table)],
        Effect::WriteTable {
            path,
            original,
            csv,
        } => vec![histogram::write_job(&path, original.as_deref(), &csv)],
        Effect::PoseCalibrate {
            file,
            loaded,
            calibration,
            limits,
        } => vec![pose::calibrate_job(&file, &loaded, &calibration, &limits)],
        Effect::Follow(job) => live::follow_once(*job),
    }
}

/// Runs effects synchronously until none are left (tests and `acmw render`).
pub struct SyncRunner;

impl SyncRunner {
    /// Applies `msg`, then carries out every resulting effect to completion.
    pub fn send(app: &mut App, msg: Msg) {
        let effects = update(app, msg);
        SyncRunner::run(app, effects);
    }

    /// Carries out `effects` and everything they lead to.
    pub fn run(app: &mut App, effects: Vec<Effect>) {
        let mut queue: VecDeque<Effect> = effects.into();
        while let Some(e) = queue.pop_front() {
            let dir = app.dir.clone();
            for m in execute(&dir, e) {
                queue.extend(update(app, m));
            }
        }
    }
}
