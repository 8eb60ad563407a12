//! `acmw correct`: correct a trial, write the corrected trial and its sidecar.

use super::common::{
    context_and_file, load_calibration, load_prepared, set_threads, variant_parser, Context,
    EngineArgs, PoseArgs, PrecisionArgs, Progress,
};
use acm_workbench::acm::{RunControl, Variant};
use acm_workbench::correct::pipeline::{self, Preparation};
use acm_workbench::ik::output::coordinates_path;
use acm_workbench::sidecar::Sidecar;
use acm_workbench::trial::TrialFormat;
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct CorrectArgs {
    /// The trial: a canonical CSV (`time,<imu>_qw,_qx,_qy,_qz,...`; `#`
    /// comment lines above the header), an Euler CSV (`time,<imu>_roll,_pitch,_yaw,...`,
    /// degrees), an OpenSim `.sto` (each optionally `.gz`); an Xsens MT Manager
    /// export (`.txt` or `.csv`, tab, comma or semicolon separated: a trial of
    /// one IMU); a folder of such exports; or an OpenSense mapping `.xml` naming them.
    pub input: PathBuf,
    /// Output trial [default: corrected/<name>.<variant>.<ext> beside the input].
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Correction variant.
    #[arg(long, value_parser = variant_parser(), default_value = "drift-centroid")]
    pub variant: Variant,
    /// Output format [default: the input's].
    #[arg(long, value_parser = super::common::named_parser::<TrialFormat>())]
    pub format: Option<TrialFormat>,
    /// Sidecar JSON path [default: <output>.acmw.json].
    #[arg(long)]
    pub sidecar: Option<PathBuf>,
    /// Take variant, settings, model and limit table from an earlier sidecar
    /// (reproduces that run exactly).
    #[arg(long, conflicts_with_all = ["variant", "model", "limits", "lambda1", "window", "hop", "pose_calibration"])]
    pub from_sidecar: Option<PathBuf>,
    /// With --from-sidecar: run even when the input's SHA-256 differs from the
    /// one the sidecar records (another trial, or an edited one); says so.
    #[arg(long, requires = "from_sidecar")]
    pub force: bool,
    /// Apply this functional calibration (`acmw calibrate`) to the trial first.
    #[arg(long, conflicts_with = "from_sidecar")]
    pub calibration: Option<PathBuf>,
    #[command(flatten)]
    pub engine: EngineArgs,
    #[command(flatten)]
    pub pose: PoseArgs,
    #[command(flatten)]
    pub output_precision: PrecisionArgs,
    /// No progress or summary output.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs `acmw correct`.
pub fn run(args: CorrectArgs) -> anyhow::Result<i32> {
    let mut recorded_calibration = None;
    let (mut ctx, variant, pose, file) = match &args.from_sidecar {
        Some(p) => {
            let s = Sidecar::load_checked(p)?;
            let origin = p.display().to_string();
            let file = pipeline::read(&args.input)?;
            if let Some(found) = s.check_input(&file.sha256) {
                let what = format!(
                    "{}: SHA-256 {found} differs from the {} that {origin} records for {}",
                    args.input.display(),
                    s.input.sha256,
                    s.input.file
                );
                anyhow::ensure!(
                    args.force,
                    "{what}; expected the trial the sidecar was made from (--force runs anyway)"
                );
                eprintln!("warning: {what}; running anyway (--force)");
            }
            recorded_calibration = s
                .calibration
                .as_ref()
                .map(|c| c.reread(&p.display().to_string()))
                .transpose()?;
            let limits = s.table(&p.display().to_string())?;
            set_threads(args.engine.threads);
            let ctx = Context {
                model: s.model.clone(),
                limits,
                limits_source: s.limits.source.clone(),
                settings: s.settings,
                // correct reports no glitches
                glitch_deg: acm_workbench::trial::glitch::DEFAULT_GLITCH_DEG,
            };
            let pose = s.pose_calibration.as_ref().map(|p| p.calibration);
            (ctx, s.variant, pose, file)
        }
        None => {
            let (ctx, file) = context_and_file(&args.engine, &args.input)?;
            let pose = args.pose.calibration(&ctx.model);
            (ctx, args.variant, pose, file)
        }
    };
    args.output_precision.apply(&mut ctx.settings);
    let calibration = match recorded_calibration {
        Some(c) => Some(c),
        None => load_calibration(args.calibration.as_deref())?,
    };
    let announce = args.from_sidecar.is_none();
    let preparation = Preparation { calibration, pose };
    let (source, prepared) = load_prepared(&ctx, &file, &preparation, announce, args.quiet)?;
    let trial = &prepared.trial;
    if !args.quiet {
        for w in &trial.warnings {
            eprintln!("warning: {w}");
        }
    }
    let mut output = source.default_output(variant, args.format);
    if let Some(o) = &args.output {
        output.path = o.clone();
    }
    output.sidecar = args.sidecar.clone();
    let progress = Progress::new(&format!("{} {variant}", trial.name), args.quiet);
    let report = |d: usize, t: usize| progress.update(d, t);
    let control = RunControl {
        cancel: None,
        progress: Some(&report),
    };
    let correction = pipeline::correct(trial, ctx.setup(), variant, &control)?;
    progress.finish();
    if output.format == TrialFormat::Sto && correction.corrected.has_gyros() {
        eprintln!(
            "warning: .sto has no gyroscope columns: the corrected trial's gyroscope readings are not written (--format quat-csv keeps them)"
        );
    }
    let sc_path = pipeline::save(&source, &prepared, &correction, ctx.setup(), &output)?;
    let output = output.path;
    let pose = &prepared.pose;
    if !args.quiet {
        for s in &correction.skipped {
            eprintln!("skipped {}: {}", s.joint, s.reason);
        }
        if let Some(p) = &pose {
            outln!(
                "{}: pose calibration at {} s ({} samples), heading correction {:.2} deg",
                trial.name,
                p.calibration.at,
                p.samples,
                p.heading_deg
            )?;
        }
        match &correction.ik {
            Some(run) => {
                let s = run.summary();
                outln!(
                    "{}: ik, {} coordinates, RMS orientation error {:.3} deg (max {:.3}), {:.1} steps per frame -> {} and {} (sidecar {})",
                    trial.name,
                    s.coordinates.len(),
                    s.mean_rms_error_deg,
                    s.max_rms_error_deg,
                    s.mean_iterations,
                    output.display(),
                    coordinates_path(&output).display(),
                    sc_path.display()
                )?;
            }
            None => outln!(
                "{}: {variant}, {} joints corrected -> {} (sidecar {})",
                trial.name,
                correction.joints.len(),
                output.display(),
                sc_path.display()
            )?,
        }
    }
    Ok(0)
}
