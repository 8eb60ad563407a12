//! `acmw plot KIND TRIAL... -o OUT.svg|png`: figures for papers. The
//! dispatch stays small: each kind has its own function building its figure
//! from the library (`acm_workbench::plot`).

mod views;

use super::analysis::{load_trials, pooled, SpanArgs, TableArgs};
use super::common::{set_threads, Context};
use acm_workbench::acm::{RunControl, Variant};
use acm_workbench::analysis::histogram::{joint_histogram, DEFAULT_BIN_DEG};
use acm_workbench::analysis::TimeSpan;
use acm_workbench::correct::correct_trial;
use acm_workbench::limits::Settings;
use acm_workbench::metrics::joint_angles;
use acm_workbench::plot::{self, histogram::Histograms, traces::Traces, PlotKind};
use acm_workbench::trial::Trial;
use anyhow::{anyhow, bail};
use clap::Args;
use std::path::PathBuf;

#[derive(Debug, Args)]
pub struct PlotArgs {
    /// What to draw.
    #[arg(value_parser = crate::cli::common::named_parser::<PlotKind>())]
    pub kind: PlotKind,
    /// Trials (any input `acmw correct` reads): `traces` draws the first;
    /// `histogram` pools them all.
    #[arg(required = true)]
    pub trials: Vec<PathBuf>,
    /// Output file; `.svg` or `.png` picks the format.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Joint, or for `histogram` also a limit table row (`hip` pools l_hip and
    /// r_hip) [default: the model's first joint].
    #[arg(long)]
    pub joint: Option<String>,
    /// Correction variant drawn beside the uncorrected angles (`traces`).
    #[arg(long, value_parser = super::common::variant_parser(), default_value = "drift-centroid")]
    pub variant: Variant,
    /// Draw the uncorrected angles only (`traces`, `scatter`, `globe`; no correction is run).
    #[arg(long)]
    pub uncorrected: bool,
    /// Colour points by time instead of by limit class (`scatter`, `globe`).
    #[arg(long)]
    pub time_colour: bool,
    /// Size in pixels, WxH.
    #[arg(long, default_value = "1200x800", value_parser = super::render::parse_size)]
    pub size: (u16, u16),
    /// Time span [default: the whole trial for `traces`, the first 30 s for `histogram`].
    #[command(flatten)]
    pub span: SpanArgs,
    #[command(flatten)]
    pub table: TableArgs,
    /// Worker threads for the correction [default: all cores]; results do not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
}

/// Runs `acmw plot`.
pub fn run(a: PlotArgs) -> anyhow::Result<i32> {
    plot::Format::from_path(&a.output)?;
    set_threads(a.threads);
    let (ctx, trials) = load_trials(&a.table, &a.trials)?;
    let size = (u32::from(a.size.0), u32::from(a.size.1));
    match a.kind {
        PlotKind::Traces => traces(&a, &ctx, &trials[0], size)?,
        PlotKind::Histogram => histogram(&a, &ctx, &trials, size)?,
        PlotKind::Scatter => views::scatter(&a, &ctx, &trials[0], size)?,
        PlotKind::Globe => views::globe(&a, &ctx, &trials[0], size)?,
    }
    outln!("wrote {}", a.output.display())?;
    Ok(super::EXIT_OK)
}

/// The joint asked for, else the model's first joint.
fn joint_name(a: &PlotArgs, ctx: &Context) -> anyhow::Result<String> {
    match &a.joint {
        Some(j) => Ok(j.clone()),
        None => ctx
            .model
            .joints
            .first()
            .map(|j| j.name.clone())
            .ok_or_else(|| anyhow!("model '{}' has no joints", ctx.model.name)),
    }
}

/// One joint's angles, uncorrected and (unless `--uncorrected`) corrected
/// with the variant asked for, Z-Y-X degrees per sample.
pub struct JointSeries<'m> {
    pub joint: &'m acm_workbench::model::Joint,
    pub raw: Vec<[f64; 3]>,
    /// The variant's name and the corrected angles.
    pub corrected: Option<(String, Vec<[f64; 3]>)>,
}

/// The angles of the joint asked for in `trial`.
pub fn joint_series<'m>(
    a: &PlotArgs,
    ctx: &'m Context,
    trial: &Trial,
) -> anyhow::Result<JointSeries<'m>> {
    let name = joint_name(a, ctx)?;
    let joint = ctx
        .model
        .joint(&name)
        .ok_or_else(|| anyhow!("no joint '{name}' in model '{}'", ctx.model.name))?;
    let raw = joint_angles(trial, joint)
        .ok_or_else(|| anyhow!("{}: lacks an IMU of joint '{name}'", trial.name))?;
    let corrected = if a.uncorrected {
        None
    } else {
        let settings: Settings = ctx.settings;
        ctx.check_trial(trial, std::path::Path::new(&trial.name))?;
        let c = correct_trial(
            trial,
            &ctx.model,
            &ctx.limits,
            &settings,
            a.variant,
            &RunControl::default(),
        )?;
        joint_angles(&c.corrected, joint).map(|v| (a.variant.name().to_string(), v))
    };
    Ok(JointSeries {
        joint,
        raw,
        corrected,
    })
}

fn traces(a: &PlotArgs, ctx: &Context, trial: &Trial, size: (u32, u32)) -> anyhow::Result<()> {
    let JointSeries {
        joint,
        raw,
        corrected,
    } = joint_series(a, ctx, trial)?;
    let name = joint.name.clone();
    let span = a.span.span(f64::INFINITY)?;
    let end = span.end_s.min(trial.duration_s());
    if end <= span.start_s {
        bail!("{}: no samples in {}", trial.name, span.label());
    }
    let fig = Traces {
        title: format!("{}  {name}", trial.name),
        time_s: &trial.time_s,
        raw: &raw,
        corrected: corrected.as_ref().map(|(l, v)| (l.clone(), v.as_slice())),
        limits: ctx.limits.joint_limits(&joint.name, &joint.kind, true),
        span_s: (span.start_s, end),
    };
    plot::write(&fig, &a.output, size)?;
    Ok(())
}

fn histogram(
    a: &PlotArgs,
    ctx: &Context,
    trials: &[Trial],
    size: (u32, u32),
) -> anyhow::Result<()> {
    let name = joint_name(a, ctx)?;
    let span = a.span.span(TimeSpan::FIRST_30_S.end_s)?;
    // A joint's name gives its own samples; a table row's pools its joints.
    let groups = pooled(ctx, trials, span, ctx.model.joint(&name).is_some())?;
    let group = groups
        .iter()
        .find(|g| g.name == name)
        .ok_or_else(|| anyhow!("no samples of '{name}' in {}", span.label()))?;
    let hist = joint_histogram(group, &ctx.limits, &ctx.model, DEFAULT_BIN_DEG);
    let fig = Histograms {
        title: format!(
            "{name} ({}), {} trial(s), {}",
            group.joints.join(", "),
            group.trials,
            span.label()
        ),
        hist: &hist,
    };
    plot::write(&fig, &a.output, size)?;
    Ok(())
}
