//! `acmw plot scatter|globe`: the 3-D scatter projections and the
//! globographic plot of one joint, uncorrected beside corrected
//! (`acm_workbench::plot::{scatter, globe}`).

use super::{joint_series, PlotArgs};
use crate::cli::common::Context;
use acm_workbench::analysis::globe::JointAxes;
use acm_workbench::analysis::scatter::Colouring;
use acm_workbench::plot::{self, globe::Globe, scatter::Scatter};
use acm_workbench::trial::Trial;
use anyhow::{anyhow, bail};

fn colouring(a: &PlotArgs) -> Colouring {
    if a.time_colour {
        Colouring::Time
    } else {
        Colouring::Limits
    }
}

/// The samples of the time span asked for (the whole trial by default).
fn span_of<'a>(a: &PlotArgs, trial: &Trial, v: &'a [[f64; 3]]) -> anyhow::Result<&'a [[f64; 3]]> {
    let span = a.span.span(f64::INFINITY)?;
    let t0 = trial.time_s.first().copied().unwrap_or(0.0);
    let i = trial.time_s.partition_point(|&t| t - t0 < span.start_s);
    let j = trial.time_s.partition_point(|&t| t - t0 <= span.end_s);
    if j <= i {
        bail!("{}: no samples in {}", trial.name, span.label());
    }
    Ok(&v[i..j.min(v.len())])
}

/// `acmw plot scatter`.
pub fn scatter(a: &PlotArgs, ctx: &Context, trial: &Trial, size: (u32, u32)) -> anyhow::Result<()> {
    let s = joint_series(a, ctx, trial)?;
    let raw = span_of(a, trial, &s.raw)?;
    let cor = match &s.corrected {
        Some((l, v)) => Some((l.clone(), span_of(a, trial, v)?)),
        None => None,
    };
    let fig = Scatter {
        title: format!("{}  {}  Z-Y-X angles", trial.name, s.joint.name),
        raw,
        corrected: cor,
        range_deg: ctx
            .limits
            .joint_limits(&s.joint.name, &s.joint.kind, false)
            .map(|l| l.range_deg),
        colouring: colouring(a),
    };
    plot::write(&fig, &a.output, size)?;
    Ok(())
}

/// `acmw plot globe`.
pub fn globe(a: &PlotArgs, ctx: &Context, trial: &Trial, size: (u32, u32)) -> anyhow::Result<()> {
    let s = joint_series(a, ctx, trial)?;
    let raw = span_of(a, trial, &s.raw)?;
    let cor = match &s.corrected {
        Some((l, v)) => Some((l.clone(), span_of(a, trial, v)?)),
        None => None,
    };
    let limits = ctx
        .limits
        .joint_limits(&s.joint.name, &s.joint.kind, false)
        .ok_or_else(|| anyhow!("no limits for joint '{}'", s.joint.name))?;
    let range = limits.range_deg;
    let fig = Globe {
        title: format!(
            "{}  {} direction around {}",
            trial.name, s.joint.distal, s.joint.name
        ),
        distal: s.joint.distal.clone(),
        raw,
        corrected: cor,
        range_deg: range,
        axes: JointAxes::of(&ctx.limits, &s.joint.name, &s.joint.kind),
        colouring: colouring(a),
        swing: limits.swing_twist,
    };
    plot::write(&fig, &a.output, size)?;
    Ok(())
}
