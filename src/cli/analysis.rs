//! `acmw suggest-limits` and `acmw centroids`: tables derived from clean
//! trials (thesis 3.1.2 and 3.3), thin layers over `acm_workbench::analysis`.

use super::common::{default_limits_dir, load_context, Context, EngineArgs};
use acm_workbench::analysis::centroid::centroids;
use acm_workbench::analysis::histogram::{histograms, DEFAULT_BIN_DEG};
use acm_workbench::analysis::suggest::{suggest_limits, write_table, SuggestOptions};
use acm_workbench::analysis::{
    pool_by_joint, pool_by_table_row, trial_refs, JointSamples, TimeSpan,
};
use acm_workbench::limits::LimitsDir;
use acm_workbench::model::Model;
use acm_workbench::trial::{detect_model, read_trial, Trial};
use anyhow::{bail, Context as _};
use clap::Args;
use std::path::{Path, PathBuf};

/// The time span of every trial, seconds from its first sample.
#[derive(Debug, Clone, Args)]
pub struct SpanArgs {
    /// Start of the span, seconds from each trial's first sample.
    #[arg(long = "from", default_value_t = 0.0)]
    pub from_s: f64,
    /// End of the span, seconds (exclusive) [default: 30, the source's; `end` for
    /// the whole trial].
    #[arg(long = "to", value_parser = parse_end)]
    pub to_s: Option<f64>,
}

fn parse_end(s: &str) -> Result<f64, String> {
    if s == "end" {
        return Ok(f64::INFINITY);
    }
    s.parse::<f64>()
        .map_err(|_| format!("expected seconds or `end`, found '{s}'"))
}

impl SpanArgs {
    /// The span, `default_end_s` when `--to` is not given; checks start < end.
    pub fn span(&self, default_end_s: f64) -> anyhow::Result<TimeSpan> {
        let span = TimeSpan {
            start_s: self.from_s,
            end_s: self.to_s.unwrap_or(default_end_s),
        };
        if !(span.start_s.is_finite() && span.start_s >= 0.0 && span.end_s > span.start_s) {
            bail!(
                "expected 0 <= --from < --to, found {} and {}",
                span.start_s,
                span.end_s
            );
        }
        Ok(span)
    }
}

/// Model and limit table options (the engine's others do not apply here).
#[derive(Debug, Clone, Args)]
pub struct TableArgs {
    /// Body model: `infant13`, `opensim` or a model TOML file [default: the
    /// built-in model that knows most of the first trial's IMUs].
    #[arg(long)]
    pub model: Option<String>,
    /// The current limit table CSV [default: the table named in
    /// ./joint_limits/settings.toml, else the built-in Table 3-2].
    #[arg(long)]
    pub limits: Option<PathBuf>,
}

#[derive(Debug, Args)]
pub struct SuggestArgs {
    /// Clean trials (no obvious drift) to take the ranges from (any input
    /// `acmw correct` reads: CSV, `.sto`, Xsens exports, a folder or mapping XML).
    #[arg(required = true)]
    pub trials: Vec<PathBuf>,
    /// Where to write the suggested table (never the current table's file).
    #[arg(short, long)]
    pub out: PathBuf,
    #[command(flatten)]
    pub span: SpanArgs,
    #[command(flatten)]
    pub table: TableArgs,
    /// Print the diff only; write nothing.
    #[arg(long)]
    pub dry_run: bool,
    /// Suggest a swing-twist table (docs/method.md section 5.1): from the
    /// current table when it is one, else from the shipped swing_twist.csv.
    #[arg(long)]
    pub swing_twist: bool,
}

#[derive(Debug, Args)]
pub struct CentroidArgs {
    /// Trials with little drift to take the mean angles from (any input
    /// `acmw correct` reads: CSV, `.sto`, Xsens exports, a folder or mapping XML).
    #[arg(required = true)]
    pub trials: Vec<PathBuf>,
    /// Where to write the centroid table (CSV) [default: print it only].
    #[arg(short, long)]
    pub out: Option<PathBuf>,
    /// One row per joint instead of per limit table row (left and right apart).
    #[arg(long)]
    pub by_joint: bool,
    #[command(flatten)]
    pub span: SpanArgs,
    #[command(flatten)]
    pub table: TableArgs,
}

/// The context (model and current table) and every trial read with its model.
pub fn load_trials(table: &TableArgs, paths: &[PathBuf]) -> anyhow::Result<(Context, Vec<Trial>)> {
    let engine = EngineArgs {
        model: table.model.clone(),
        limits: table.limits.clone(),
        ..EngineArgs::default()
    };
    let ctx = load_context(&engine, || {
        Ok(paths
            .first()
            .map_or_else(Model::infant13, |p| detect_model(p)))
    })?;
    let trials = paths
        .iter()
        .map(|p| read_trial(p, &ctx.model))
        .collect::<Result<Vec<_>, _>>()?;
    Ok((ctx, trials))
}

/// The samples of `span` per joint (`by_joint`) or per limit table row; an
/// error when there are none.
pub fn pooled(
    ctx: &Context,
    trials: &[Trial],
    span: TimeSpan,
    by_joint: bool,
) -> anyhow::Result<Vec<JointSamples>> {
    let refs = trial_refs(trials, &ctx.model);
    let pooled = if by_joint {
        pool_by_joint(&refs, span)
    } else {
        pool_by_table_row(&refs, span, &ctx.limits)
    };
    if pooled.is_empty() {
        bail!(
            "no joint of model '{}' has samples in {}",
            ctx.model.name,
            span.label()
        );
    }
    Ok(pooled)
}

/// The file of the current table: `--limits`, else the one settings.toml names.
fn original_table(table: &TableArgs) -> anyhow::Result<PathBuf> {
    if let Some(p) = &table.limits {
        return Ok(p.clone());
    }
    let dir = default_limits_dir();
    let d = LimitsDir::load(&dir)?;
    Ok(dir.join(d.settings.table))
}

/// Runs `acmw suggest-limits`.
pub fn run_suggest(a: SuggestArgs) -> anyhow::Result<i32> {
    let span = a.span.span(TimeSpan::FIRST_30_S.end_s)?;
    let (ctx, trials) = load_trials(&a.table, &a.trials)?;
    if a.swing_twist {
        return run_suggest_swing_twist(&a, span, &ctx, &trials);
    }
    let pooled = pooled(&ctx, &trials, span, false)?;
    let hists = histograms(&pooled, &ctx.limits, &ctx.model, DEFAULT_BIN_DEG);
    let s = suggest_limits(&ctx.limits, &hists, span, SuggestOptions::default());
    outln!(
        "Suggested limits from {} trial(s), {} (90% of the samples around the mean); against {}:",
        trials.len(),
        span.label(),
        ctx.limits_source
    )?;
    finish_suggestion(&a, s.diff_lines(), &s.table)
}

/// A suggestion's end: its diff lines printed, and the table written to
/// `--out` (beside the original's comments) unless `--dry-run`.
fn finish_suggestion(
    a: &SuggestArgs,
    diff: impl IntoIterator<Item = String>,
    table: &acm_workbench::limits::LimitTable,
) -> anyhow::Result<i32> {
    for line in diff {
        outln!("{line}")?;
    }
    if a.dry_run {
        return Ok(super::EXIT_OK);
    }
    let original = original_table(&a.table)?;
    write_table(table, &a.out, Some(&original))?;
    outln!("wrote {}", a.out.display())?;
    Ok(super::EXIT_OK)
}

/// `acmw suggest-limits --swing-twist`: the swing-twist suggestion's diff,
/// and the table written unless `--dry-run`.
fn run_suggest_swing_twist(
    a: &SuggestArgs,
    span: TimeSpan,
    ctx: &Context,
    trials: &[Trial],
) -> anyhow::Result<i32> {
    use acm_workbench::analysis::suggest_swing::suggest_swing_twist;
    let refs = trial_refs(trials, &ctx.model);
    let s = suggest_swing_twist(&ctx.limits, &refs, span, SuggestOptions::default());
    if s.rows.iter().all(|r| r.samples == 0) {
        bail!(
            "no joint of model '{}' has samples in {}",
            ctx.model.name,
            span.label()
        );
    }
    outln!(
        "Suggested swing-twist limits from {} trial(s), {} (90% of the samples around the mean); against {}:",
        trials.len(),
        span.label(),
        if ctx.limits.swing_twist.is_some() {
            ctx.limits_source.as_str()
        } else {
            "<built-in swing_twist.csv>"
        }
    )?;
    finish_suggestion(a, s.diff_lines(), &s.table)
}

/// Runs `acmw centroids`.
pub fn run_centroids(a: CentroidArgs) -> anyhow::Result<i32> {
    let span = a.span.span(TimeSpan::FIRST_30_S.end_s)?;
    let (ctx, trials) = load_trials(&a.table, &a.trials)?;
    let pooled = pooled(&ctx, &trials, span, a.by_joint)?;
    let table = centroids(&pooled, span);
    let csv = table.to_csv();
    out!("{csv}")?;
    if let Some(out) = &a.out {
        write_csv(out, &csv)?;
        eprintln!("wrote {}", out.display());
    }
    Ok(super::EXIT_OK)
}

fn write_csv(out: &Path, csv: &str) -> anyhow::Result<()> {
    acm_workbench::save::atomic_write(out, csv.as_bytes())
        .with_context(|| format!("{}: cannot write", out.display()))
}
