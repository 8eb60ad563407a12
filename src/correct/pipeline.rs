//! One pipeline from a trial to saved corrections, as plain data in and out:
//!
//! ```text
//! load (a path)  ->  prepare (functional calibration, pose calibration,
//!                    convention checks)  ->  correct (one or many variants,
//!                    progress and cancellation)  ->  report  ->  save
//! ```
//!
//! Each step is a function of what the step before returned, so a caller
//! may enter anywhere: `acmw correct` and `acmw report` start from a path, the
//! workbench loads once and corrects again as the settings change, and a
//! live or batch caller may hand [`prepare`] a [`Trial`] it built in memory.
//! Nothing here prints, reads the command line or draws: warnings come back
//! in the values ([`Prepared::calibration_warnings`], `Trial::warnings`).
//!
//! ```no_run
//! use acm_workbench::correct::pipeline::{self, Preparation, Setup};
//! use acm_workbench::acm::{RunControl, Variant};
//! use acm_workbench::limits::{LimitTable, Settings};
//! use acm_workbench::model::Model;
//! use std::path::Path;
//!
//! let model = Model::infant13();
//! let limits = LimitTable::default_table();
//! let settings = Settings::default();
//! let setup = Setup { model: &model, limits: &limits, limits_source: "<built-in>", settings: &settings };
//! let path = Path::new("sample_trials/knee_calf_z15.csv.gz");
//! let loaded = pipeline::load(path, &model)?;
//! let prepared = pipeline::prepare(loaded.trial, setup, &Preparation::default())?;
//! let corrections = pipeline::correct_many(
//!     &prepared.trial, setup, &Variant::ALL, None, &RunControl::default())?;
//! let report = pipeline::report(&prepared, setup, None, &corrections);
//! println!("{}", acm_workbench::report::format_text(&report));
//! let output = loaded.source.default_output(corrections[2].variant, None);
//! pipeline::save(&loaded.source, &prepared, &corrections[2], setup, &output)?;
//! # Ok::<(), anyhow::Error>(())
//! ```

use crate::acm::window::LayoutError;
use crate::acm::{Cancelled, Correction, RunControl, Variant};
use crate::calibration::AppliedCalibration;
use crate::correct::{correct_trial, recorrect};
use crate::limits::{LimitTable, Settings};
use crate::model::Model;
use crate::pose::convention::check_conventions_of;
use crate::pose::{calibrate, PoseCalibration, PoseError, PoseRecord};
use crate::report::{ReportInput, TrialReport};
use crate::sidecar::{default_output, SaveRequest};
use crate::trial::{Trial, TrialError, TrialFile, TrialFormat};
use std::path::{Path, PathBuf};

/// What every step reads: the body model, the limit table and the engine's
/// settings (all borrowed; the caller owns them).
#[derive(Clone, Copy)]
pub struct Setup<'a> {
    pub model: &'a Model,
    pub limits: &'a LimitTable,
    /// Where the table came from (a path or `<built-in NAME>`), for reports
    /// and sidecars.
    pub limits_source: &'a str,
    pub settings: &'a Settings,
}

/// Where a trial was read from, and how.
#[derive(Debug, Clone, PartialEq)]
pub struct Source {
    pub path: PathBuf,
    pub format: TrialFormat,
    /// Whether the file was gzip-compressed (outputs follow it by default).
    pub gzip: bool,
    /// SHA-256 (hex) of the input's bytes as read ([`TrialFile::sha256`]),
    /// recorded in the sidecars of its corrections.
    pub sha256: String,
}

impl Source {
    /// Where `file` was read from.
    pub fn of(file: &TrialFile) -> Source {
        Source {
            path: file.path.clone(),
            format: file.format,
            gzip: file.gzip,
            sha256: file.sha256.clone(),
        }
    }

    /// `corrected/<name>.<variant>.<ext>` beside the input, in `format` or
    /// the input format's default output.
    pub fn default_output(&self, variant: Variant, format: Option<TrialFormat>) -> Output {
        let format = format.unwrap_or(self.format.output_default());
        Output {
            path: default_output(&self.path, variant, format, self.gzip),
            format,
            sidecar: None,
        }
    }
}

/// A trial read from a file.
#[derive(Debug, Clone)]
pub struct LoadedTrial {
    pub source: Source,
    pub trial: Trial,
}

/// Reads the trial at `path` (any format the program reads) with `model`'s
/// IMUs: [`read`], then [`load_file`].
pub fn load(path: &Path, model: &Model) -> Result<LoadedTrial, TrialError> {
    load_file(&read(path)?, model)
}

/// Reads the input at `path` once (whole, hashed as read): the caller may
/// detect its model ([`TrialFile::detect_model`]) or look at its hash
/// before [`load_file`] parses it.
pub fn read(path: &Path) -> Result<TrialFile, TrialError> {
    TrialFile::read(path)
}

/// The trial in `file` with `model`'s IMUs. A trial file that a sidecar
/// beside it describes as another version of it gets a warning.
pub fn load_file(file: &TrialFile, model: &Model) -> Result<LoadedTrial, TrialError> {
    let mut trial = file.trial(model)?;
    if file.format != TrialFormat::Xsens {
        trial
            .warnings
            .extend(crate::sidecar::mismatch_warning(&file.path, &file.sha256));
    }
    Ok(LoadedTrial {
        source: Source::of(file),
        trial,
    })
}

/// What to do to a trial before correcting it.
#[derive(Debug, Clone, Default)]
pub struct Preparation {
    /// A functional calibration (`acmw calibrate`) applied first.
    pub calibration: Option<AppliedCalibration>,
    /// A pose calibration with heading correction, applied next.
    pub pose: Option<PoseCalibration>,
}

/// A trial ready to correct, with what preparing it did.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The trial the corrections see; its `warnings` include the convention
    /// checks (mirrored or offset angles against the table).
    pub trial: Trial,
    /// The functional calibration applied, for the sidecar.
    pub calibration: Option<AppliedCalibration>,
    /// IMUs of the calibration the trial or model lacks.
    pub calibration_warnings: Vec<String>,
    /// What the pose calibration found.
    pub pose: Option<PoseRecord>,
}

/// Why a trial cannot be prepared.
#[derive(Debug, thiserror::Error)]
pub enum PrepareError {
    /// The drift windows do not suit the trial's length or sampling.
    #[error(transparent)]
    Windows(#[from] LayoutError),
    #[error(transparent)]
    Pose(#[from] PoseError),
}

/// Checks the drift windows suit `trial`, applies the functional and pose
/// calibrations `preparation` names, and adds the convention checks to the
/// trial's warnings.
pub fn prepare(
    mut trial: Trial,
    setup: Setup,
    preparation: &Preparation,
) -> Result<Prepared, PrepareError> {
    let s = setup.settings;
    crate::acm::window::check_layout(&trial.time_s, s.window_s, s.hop_s)?;
    let calibration_warnings = match &preparation.calibration {
        Some(c) => c.apply(&mut trial, setup.model),
        None => Vec::new(),
    };
    let (mut trial, pose) = match &preparation.pose {
        Some(p) => {
            let (t, r) = calibrate(&trial, setup.model, p)?;
            (t, Some(r))
        }
        None => (trial, None),
    };
    // Both checks read the same joint angles: computed once.
    let angles = crate::metrics::model_joint_angles(&trial, setup.model);
    let checks = check_conventions_of(&angles, setup.model, setup.limits, pose.is_some());
    trial.warnings.extend(checks);
    let centroids =
        crate::pose::centroid_check::check_centroids_of(&angles, setup.model, setup.limits);
    trial.warnings.extend(centroids);
    Ok(Prepared {
        trial,
        calibration: preparation.calibration.clone(),
        calibration_warnings,
        pose,
    })
}

/// Corrects `trial` with one variant; `control` sees (windows done, windows
/// in all) and may cancel.
pub fn correct(
    trial: &Trial,
    setup: Setup,
    variant: Variant,
    control: &RunControl,
) -> Result<Correction, Cancelled> {
    correct_trial(
        trial,
        setup.model,
        setup.limits,
        setup.settings,
        variant,
        control,
    )
}

/// Earlier corrections to re-solve only some joints of, after the limits of
/// those joints changed (the other joints' results are kept).
#[derive(Clone, Copy)]
pub struct Recorrect<'a> {
    /// One earlier correction per variant asked for, in the same order.
    pub previous: &'a [&'a Correction],
    /// The joints to solve again.
    pub joints: &'a [&'a str],
}

/// Progress of a run over several variants, as parts per thousand of the whole.
pub const MANY_TOTAL: usize = 1000;

/// Corrects `trial` with each of `variants` in turn (or re-solves the joints
/// `recorrect` names in earlier corrections). `control.progress` sees the
/// whole run as (done, [`MANY_TOTAL`]); cancelling stops before the next window.
pub fn correct_many(
    trial: &Trial,
    setup: Setup,
    variants: &[Variant],
    recorrect_from: Option<Recorrect>,
    control: &RunControl,
) -> Result<Vec<Correction>, Cancelled> {
    let n = variants.len();
    let mut out = Vec::with_capacity(n);
    for (k, &variant) in variants.iter().enumerate() {
        let report = move |done: usize, total: usize| {
            if let Some(p) = control.progress {
                let frac = if total == 0 {
                    1.0
                } else {
                    done as f64 / total as f64
                };
                p(
                    ((k as f64 + frac) * MANY_TOTAL as f64 / n as f64) as usize,
                    MANY_TOTAL,
                );
            }
        };
        let one = RunControl {
            cancel: control.cancel,
            progress: Some(&report),
        };
        if variant == Variant::Auto {
            // Composed from its candidates when they were corrected first.
            let forced = recorrect_from.map_or_else(Default::default, |r| {
                crate::acm::auto_run::overrides(r.previous[k])
            });
            let made: Vec<&Correction> = out.iter().collect();
            let parts = (setup.model, setup.limits, setup.settings);
            if let Some(c) = crate::acm::auto_run::compose_from(trial, parts, &made, &forced) {
                report(1, 1);
                out.push(c);
                continue;
            }
        }
        let c = match recorrect_from {
            Some(r) => recorrect(
                trial,
                setup.model,
                setup.limits,
                setup.settings,
                r.previous[k],
                r.joints,
                &one,
            )?,
            None => correct(trial, setup, variant, &one)?,
        };
        out.push(c);
    }
    Ok(out)
}

/// `auto`'s correction `previous` with the user's choice `choice` for
/// `joint` (`None`, or `auto`'s own choice: no override), the joint and the
/// joints below it solved again. The override is recorded in the joint's
/// `auto` record (and so in the sidecar) and kept by later re-corrections.
/// A joint `auto` did not choose for (or a variant that is not one of its
/// candidates) leaves `previous` as it was. When `others` holds every
/// candidate's correction of the trial with the same setup, `auto` is
/// composed from them without solving anything.
pub fn override_auto(
    trial: &Trial,
    setup: Setup,
    (previous, others): (&Correction, &[&Correction]),
    joint: &str,
    choice: Option<Variant>,
    control: &RunControl,
) -> Result<Correction, Cancelled> {
    let mut edited = previous.clone();
    let Some(a) = edited
        .joints
        .iter_mut()
        .find(|j| j.joint == joint)
        .and_then(|j| j.auto.as_mut())
    else {
        return Ok(previous.clone());
    };
    let own = a.overridden.unwrap_or(a.chosen);
    match choice.filter(|&v| v != own && crate::acm::auto::CANDIDATES.contains(&v)) {
        Some(v) => {
            a.chosen = v;
            a.overridden = Some(own);
        }
        None => {
            a.chosen = own;
            a.overridden = None;
        }
    }
    let forced = crate::acm::auto_run::overrides(&edited);
    let parts = (setup.model, setup.limits, setup.settings);
    if let Some(c) = crate::acm::auto_run::compose_from(trial, parts, others, &forced) {
        return Ok(c);
    }
    recorrect(
        trial,
        setup.model,
        setup.limits,
        setup.settings,
        &edited,
        &[joint],
        control,
    )
}

/// The figures of the prepared trial before and after each correction
/// (`truth`: the true segment orientations, when known).
pub fn report<'c>(
    prepared: &Prepared,
    setup: Setup,
    truth: Option<&Trial>,
    corrections: impl IntoIterator<Item = &'c Correction>,
) -> TrialReport {
    let mut r = report_input(&prepared.trial, setup, truth).report(corrections);
    r.pose_calibration = prepared.pose.clone();
    r
}

/// The report's inputs for a trial (callers holding the trial outside a
/// [`Prepared`], such as the workbench, report through this).
pub fn report_input<'a>(
    trial: &'a Trial,
    setup: Setup<'a>,
    truth: Option<&'a Trial>,
) -> ReportInput<'a> {
    ReportInput {
        trial,
        model: setup.model,
        limits: setup.limits,
        limits_source: setup.limits_source,
        settings: setup.settings,
        truth,
    }
}

/// Where to write a corrected trial.
#[derive(Debug, Clone, PartialEq)]
pub struct Output {
    pub path: PathBuf,
    pub format: TrialFormat,
    /// The sidecar's path; `None` for `<path>.acmw.json`.
    pub sidecar: Option<PathBuf>,
}

/// Writes `correction` of the trial read from `source` and prepared as
/// `prepared`, with its sidecar, each atomically. Returns the sidecar's path.
pub fn save(
    source: &Source,
    prepared: &Prepared,
    correction: &Correction,
    setup: Setup,
    output: &Output,
) -> anyhow::Result<PathBuf> {
    save_trial(
        source,
        &prepared.trial,
        prepared.pose.as_ref(),
        correction,
        setup,
        output,
        prepared.calibration.as_ref(),
    )
}

/// As [`save`], for a caller that keeps the corrected trial's parts apart.
pub fn save_trial(
    source: &Source,
    trial: &Trial,
    pose: Option<&PoseRecord>,
    correction: &Correction,
    setup: Setup,
    output: &Output,
    calibration: Option<&AppliedCalibration>,
) -> anyhow::Result<PathBuf> {
    let request = SaveRequest {
        input: &source.path,
        input_format: source.format,
        input_sha256: &source.sha256,
        trial,
        pose,
        correction,
        model: setup.model,
        limits: setup.limits,
        limits_source: setup.limits_source,
        output: &output.path,
        output_format: output.format,
        sidecar: output.sidecar.as_deref(),
    };
    request.save_building(|| {
        let mut sidecar = request.sidecar();
        sidecar.calibration = calibration.cloned();
        sidecar
    })
}
