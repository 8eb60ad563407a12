//! `acmw batch`: correct every trial of folders or patterns into one folder,
//! with a manifest a re-run resumes from; `--shard K/N` for clusters,
//! `--merge` to join the shards' manifests.

use super::common::{
    load_calibration, load_context, variant_parser, EngineArgs, PoseArgs, PrecisionArgs,
};
use acm_workbench::batch::manifest::{Manifest, Status};
use acm_workbench::batch::{discover, Batch, Event, Shard};
use acm_workbench::correct::pipeline::Preparation;
use acm_workbench::model::Model;
use acm_workbench::trial::TrialFormat;
use acm_workbench::variant::Variant;
use clap::Args;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::atomic::{AtomicUsize, Ordering};

#[derive(Debug, Args)]
pub struct BatchArgs {
    /// Trials: files, folders (their trials, not recursive) or glob patterns
    /// (quoted, e.g. 'archive/*/walk*.csv.gz').
    #[arg(required_unless_present = "merge")]
    pub inputs: Vec<String>,
    /// Folder of the outputs (`<stem>.<variant>.<ext>` and sidecars) and of
    /// the manifest (`manifest.json`, `manifest.csv`; per shard
    /// `manifest.shard-K-of-N.*`).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Correction variant (repeatable: one output per variant).
    #[arg(long, value_parser = variant_parser(), default_value = "drift-centroid")]
    pub variant: Vec<Variant>,
    /// Trials corrected at once [default: all cores]; outputs do not depend on it.
    #[arg(long, value_name = "N")]
    pub jobs: Option<usize>,
    /// Only shard K of N (1 <= K <= N) of the trial list, e.g. `--shard
    /// $SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT` with `--array=1-N`.
    /// A trial's shard follows from its file name alone.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<Shard>,
    /// Join the shard manifests in --out into manifest.json and manifest.csv
    /// (after all shards finished); corrects nothing.
    #[arg(long, conflicts_with_all = ["inputs", "shard"])]
    pub merge: bool,
    /// Output format [default: the input's].
    #[arg(long, value_parser = super::common::named_parser::<TrialFormat>())]
    pub format: Option<TrialFormat>,
    /// Apply this functional calibration (`acmw calibrate`) to every trial first.
    #[arg(long)]
    pub calibration: Option<PathBuf>,
    #[command(flatten)]
    pub engine: EngineArgs,
    #[command(flatten)]
    pub pose: PoseArgs,
    #[command(flatten)]
    pub output_precision: PrecisionArgs,
    /// No progress bar and no line per trial (failures and the summary only),
    /// for logs.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Runs `acmw batch`; exits 1 when a trial failed (the manifest says which).
pub fn run(args: BatchArgs) -> anyhow::Result<i32> {
    if args.merge {
        return merge(&args);
    }
    anyhow::ensure!(
        args.engine.threads.is_none(),
        "--threads does not apply to batch: --jobs N sets the workers"
    );
    let trials = discover(&args.inputs)?;
    let mut ctx = load_context(&args.engine, || Ok(Model::infant13()))?;
    args.output_precision.apply(&mut ctx.settings);
    let model: Option<Model> = args.engine.model.as_ref().map(|_| ctx.model.clone());
    let pose = args.pose.calibration(model.as_ref().unwrap_or(&ctx.model));
    let preparation = Preparation {
        calibration: load_calibration(args.calibration.as_deref())?,
        pose,
    };
    let mut variants: Vec<Variant> = Vec::new();
    for v in &args.variant {
        if !variants.contains(v) {
            variants.push(*v);
        }
    }
    let jobs = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    anyhow::ensure!(jobs > 0, "--jobs must be at least 1");
    let batch = Batch {
        model: model.as_ref(),
        limits: &ctx.limits,
        limits_source: &ctx.limits_source,
        settings: &ctx.settings,
        preparation: &preparation,
        variants: &variants,
        format: args.format,
        out_dir: &args.out,
        jobs,
        shard: args.shard,
    };
    let mine = batch.select(&trials).len();
    let bar = progress_bar(mine as u64, args.quiet);
    let counter = AtomicUsize::new(0);
    let quiet = args.quiet;
    let observe = |e: Event| match e {
        Event::Started { .. } => {}
        Event::Finished { rows, resumed } => {
            let k = counter.fetch_add(1, Ordering::SeqCst) + 1;
            let Some(first) = rows.first() else { return };
            for r in rows.iter().filter(|r| r.status == Status::Failed) {
                let line = format!(
                    "failed {} ({}): {}",
                    r.trial,
                    r.variant,
                    r.error.as_deref().unwrap_or("")
                );
                bar.suspend(|| eprintln!("{line}"));
            }
            if !quiet && bar.is_hidden() && rows.iter().all(|r| r.status == Status::Ok) {
                let what = if resumed { "done earlier" } else { "ok" };
                let wall: f64 = rows.iter().map(|r| r.wall_s).fold(0.0, f64::max);
                eprintln!("[{k}/{mine}] {}: {what} ({wall:.1} s)", first.trial);
            }
            bar.inc(1);
        }
    };
    let manifest = batch.run(&trials, &observe)?;
    bar.finish_and_clear();
    let failed = manifest
        .rows
        .iter()
        .filter(|r| r.status == Status::Failed)
        .count();
    let ok = manifest.rows.len() - failed;
    let shard = args
        .shard
        .map(|s| format!(" (shard {s})"))
        .unwrap_or_default();
    eprintln!(
        "{mine} trials{shard}: {ok} outputs ok, {failed} failed; manifest {}",
        args.out
            .join(Manifest::file_name(args.shard, "json"))
            .display()
    );
    Ok(if failed > 0 { super::EXIT_FAILURE } else { 0 })
}

/// A bar with the trials done, the rate and the time left; hidden with
/// `--quiet` or when standard error is no terminal.
fn progress_bar(len: u64, quiet: bool) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::hidden());
    }
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template(
            "{wide_bar} {pos}/{len} trials  {per_sec}  {elapsed_precise} elapsed  ETA {eta_precise}",
        )
        .expect("a valid template"),
    );
    bar
}

/// `acmw batch --merge`: joins the shard manifests of --out.
fn merge(args: &BatchArgs) -> anyhow::Result<i32> {
    let parts = Manifest::load_shards(&args.out)?;
    let n = parts.len();
    let merged = Manifest::merge(parts)?;
    let (json, csv) = merged.save(&args.out)?;
    let failed = merged
        .rows
        .iter()
        .filter(|r| r.status == Status::Failed)
        .count();
    if !args.quiet {
        eprintln!(
            "{n} shard manifests merged: {} rows ({failed} failed) -> {} and {}",
            merged.rows.len(),
            json.display(),
            csv.display()
        );
    }
    Ok(0)
}
