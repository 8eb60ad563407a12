//! `acmw report`: the figures of docs/method.md section 16 before and after each variant.

use super::common::{
    context_and_file, load_calibration, load_prepared, EngineArgs, PoseArgs, Progress,
};
use acm_workbench::acm::{RunControl, Variant};
use acm_workbench::correct::pipeline::{self, Preparation};
use acm_workbench::reference::{compare, read_reference, CompareOptions};
use acm_workbench::report::format_text;
use acm_workbench::simulate::truth::load_truth_beside;
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct ReportArgs {
    /// The trial: a canonical CSV (`time,<imu>_qw,_qx,_qy,_qz,...`; `#`
    /// comment lines above the header), an Euler CSV (`time,<imu>_roll,_pitch,_yaw,...`,
    /// degrees), an OpenSim `.sto` (each optionally `.gz`); an Xsens MT Manager
    /// export (`.txt` or `.csv`, tab, comma or semicolon separated: a trial of
    /// one IMU); a folder of such exports; or an OpenSense mapping `.xml` naming them.
    pub input: PathBuf,
    /// Variants to run and compare (repeatable) [default: all].
    #[arg(long, value_parser = super::common::variant_parser())]
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
    /// Score the angles against an optical reference: a CSV
    /// (`time,<joint>_x,<joint>_y,<joint>_z`, degrees, any subset), an OpenSim
    /// `.mot` (coordinates mapped to joint axes by the model's
    /// `[reference_coordinates]`) or a C3D (Plug-in Gait angle points such as
    /// `LKneeAngles`, mapped the same way).
    #[arg(long, value_name = "FILE")]
    pub reference: Option<PathBuf>,
    /// Start of the span scored against the reference, seconds from the first sample.
    #[arg(long, value_name = "S", requires = "reference")]
    pub from: Option<f64>,
    /// End of the span scored against the reference, seconds from the first sample.
    #[arg(long, value_name = "S", requires = "reference")]
    pub to: Option<f64>,
    /// Search the reference's time lag within +-S seconds [default: 2].
    #[arg(long, value_name = "S", requires = "reference", value_parser = non_negative_s)]
    pub max_lag: Option<f64>,
    /// Use this time lag instead of searching: the reference is read at the
    /// trial's time + S, both as their files give them (a C3D's from 0).
    #[arg(
        long,
        value_name = "S",
        requires = "reference",
        conflicts_with = "max_lag",
        allow_negative_numbers = true
    )]
    pub lag: Option<f64>,
    /// No progress output.
    #[arg(short, long)]
    pub quiet: bool,
}

/// A finite number of seconds, at least 0.
fn non_negative_s(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
        _ => Err(format!("expected seconds >= 0, found '{s}'")),
    }
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
    let (ctx, file) = context_and_file(&args.engine, &args.input)?;
    let preparation = Preparation {
        calibration: load_calibration(args.calibration.as_deref())?,
        pose: args.pose.calibration(&ctx.model),
    };
    let (_, prepared) = load_prepared(&ctx, &file, &preparation, true, args.quiet)?;
    let trial = &prepared.trial;
    let truth = match load_truth_beside(&args.input, &ctx.model) {
        Some(t) => {
            let t = t?;
            t.check_against(trial).map_err(|e| {
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
    let progress = Progress::overall(&trial.name, args.quiet);
    let report = |d: usize, t: usize| progress.update(d, t);
    let control = RunControl {
        cancel: None,
        progress: Some(&report),
    };
    let setup = ctx.setup();
    let corrections = pipeline::correct_many(trial, setup, &variants, None, &control)?;
    let mut r = pipeline::report(
        &prepared,
        setup,
        truth.as_ref().map(|t| &t.segments),
        &corrections,
    );
    if let Some(path) = &args.reference {
        let reference = read_reference(path, &ctx.model)?;
        let mut series = vec![("uncorrected".to_string(), trial)];
        series.extend(
            corrections
                .iter()
                .map(|c| (c.variant.name().to_string(), &c.corrected)),
        );
        let opts = CompareOptions {
            max_lag_s: args.max_lag.unwrap_or(CompareOptions::default().max_lag_s),
            lag_s: args.lag,
            from_s: args.from,
            to_s: args.to,
        };
        r.reference = Some(
            compare(&series, &ctx.model, &reference, &opts)
                .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?,
        );
    }
    let glitch_deg = args.glitch_deg.unwrap_or(ctx.glitch_deg);
    if glitch_deg != r.glitch_deg {
        r.set_glitch_threshold(trial, glitch_deg);
    }
    progress.finish();
    if args.json {
        outln!("{}", serde_json::to_string_pretty(&r)?)?;
    } else {
        out!("{}", format_text(&r))?;
        if let Some(reference) = &r.reference {
            outln!()?;
            out!("{}", acm_workbench::reference::format_text(reference))?;
        }
    }
    Ok(0)
}
