//! `acmw report`: the METHOD.md section 6 figures before and after each variant.

use super::common::{apply_pose, load_context, EngineArgs, PoseArgs, Progress};
use acm_workbench::acm::{RunControl, Variant};
use acm_workbench::report::{format_text, ReportInput};
use acm_workbench::trial::read_trial;
use acm_workbench::truth::load_truth_beside;
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct ReportArgs {
    /// The trial to report on (.csv, .sto, optionally .gz).
    pub input: PathBuf,
    /// Variants to run and compare (repeatable) [default: all].
    #[arg(long, value_enum)]
    pub variant: Vec<Variant>,
    /// Flag orientation jumps larger than this between neighbouring samples,
    /// degrees [default: `glitch_deg` in ./joint_limits/settings.toml, else 30].
    #[arg(long, value_parser = positive_deg)]
    pub glitch_deg: Option<f64>,
    /// Print JSON instead of text tables.
    #[arg(long)]
    pub json: bool,
    /// Apply this functional calibration (`acmw calibrate`) to the trial first.
    #[arg(long)]
    pub calibration: Option<PathBuf>,
    #[command(flatten)]
    pub engine: EngineArgs,
    #[command(flatten)]
    pub pose: PoseArgs,
    /// No progress output.
    #[arg(short, long)]
    pub quiet: bool,
}

/// A positive, finite angle in degrees.
fn positive_deg(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!(
            "expected a positive number of degrees, found '{s}'"
        )),
    }
}

/// Runs `acmw report`.
pub fn run(args: ReportArgs) -> anyhow::Result<i32> {
    let ctx = load_context(&args.engine, Some(&args.input))?;
    let mut trial = read_trial(&args.input, &ctx.model)?;
    ctx.check_trial(&trial, &args.input)?;
    super::calibrate::apply(
        args.calibration.as_deref(),
        &mut trial,
        &ctx.model,
        args.quiet,
    )?;
    let pose_calibration = args.pose.calibration(&ctx.model);
    let (trial, pose) = apply_pose(trial, &ctx.model, pose_calibration.as_ref(), &args.input)?;
    let truth = match load_truth_beside(&args.input, &ctx.model) {
        Some(t) => {
            let t = t?;
            t.check_against(&trial).map_err(|e| {
                anyhow::anyhow!(
                    "{}: truth does not fit the trial: {e}",
                    args.input.display()
                )
            })?;
            Some(t)
        }
        None => None,
    };
    let variants = if args.variant.is_empty() {
        Variant::ALL.to_vec()
    } else {
        args.variant.clone()
    };
    let progress = Progress::new(&trial.name, args.quiet);
    let report = |d: usize, t: usize| progress.update(d, t);
    let control = RunControl {
        cancel: None,
        progress: Some(&report),
    };
    let input = ReportInput {
        trial: &trial,
        model: &ctx.model,
        limits: &ctx.limits,
        limits_source: &ctx.limits_source,
        settings: &ctx.settings,
        truth: truth.as_ref().map(|t| &t.segments),
    };
    let mut r = input.run(&variants, &control)?;
    r.pose_calibration = pose;
    let glitch_deg = args.glitch_deg.unwrap_or(ctx.glitch_deg);
    if glitch_deg != r.glitch_deg {
        r.set_glitch_threshold(&trial, glitch_deg);
    }
    progress.finish();
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&r)?)?;
    } else {
        out!("{}", format_text(&r))?;
    }
    Ok(0)
}
