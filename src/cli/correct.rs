//! `acmw correct`: correct a trial, write the corrected trial and its sidecar.

use super::common::{load_context, Context, EngineArgs, Progress};
use acm_workbench::acm::{correct_trial, RunControl, Variant};
use acm_workbench::metrics::trial_figures;
use acm_workbench::save::atomic_write;
use acm_workbench::sidecar::{sha256_hex, sidecar_path, FiguresRecord, InputRecord, Sidecar};
use acm_workbench::trial::{detect_format, read_trial, write_trial, Trial, TrialFormat};
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Debug, Args)]
pub struct CorrectArgs {
    /// The trial to correct (.csv, .sto, optionally .gz).
    pub input: PathBuf,
    /// Output trial [default: corrected/<name>.<variant>.<ext> beside the input].
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Correction variant.
    #[arg(long, value_enum, default_value_t = Variant::DriftCentroid)]
    pub variant: Variant,
    /// Output format [default: the input's].
    #[arg(long, value_enum)]
    pub format: Option<TrialFormat>,
    /// Sidecar JSON path [default: <output>.acmw.json].
    #[arg(long)]
    pub sidecar: Option<PathBuf>,
    /// Take variant, settings, model and limit table from an earlier sidecar
    /// (reproduces that run exactly).
    #[arg(long, conflicts_with_all = ["variant", "model", "limits", "lambda1", "window", "hop"])]
    pub from_sidecar: Option<PathBuf>,
    #[command(flatten)]
    pub engine: EngineArgs,
    /// No progress or summary output.
    #[arg(short, long)]
    pub quiet: bool,
}

/// The default output path: `corrected/<stem>.<variant>.<ext>[.gz]` beside the input.
pub fn default_output(input: &Path, variant: Variant, format: TrialFormat, gzip: bool) -> PathBuf {
    let name = input.file_name().unwrap_or_default().to_string_lossy();
    let stem = name
        .trim_end_matches(".gz")
        .trim_end_matches(".csv")
        .trim_end_matches(".sto")
        .to_string();
    let ext = match format {
        TrialFormat::Sto => "sto",
        _ => "csv",
    };
    let gz = if gzip { ".gz" } else { "" };
    input
        .parent()
        .unwrap_or(Path::new("."))
        .join("corrected")
        .join(format!("{stem}.{variant}.{ext}{gz}"))
}

/// Runs `acmw correct`.
pub fn run(args: CorrectArgs) -> anyhow::Result<i32> {
    let (ctx, variant) = match &args.from_sidecar {
        Some(p) => {
            let s = Sidecar::load(p)?;
            let limits = s.table()?;
            if let Some(n) = args.engine.threads {
                let _ = rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build_global();
            }
            let ctx = Context {
                model: s.model.clone(),
                limits,
                limits_source: s.limits.source.clone(),
                settings: s.settings,
            };
            (ctx, s.variant)
        }
        None => (load_context(&args.engine, Some(&args.input))?, args.variant),
    };
    let (in_format, gzip) = detect_format(&args.input)?;
    let trial = read_trial(&args.input, &ctx.model)?;
    if !args.quiet {
        for w in &trial.warnings {
            eprintln!("warning: {w}");
        }
    }
    let format = args.format.unwrap_or(in_format);
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| default_output(&args.input, variant, format, gzip));
    let progress = Progress::new(&format!("{} {variant}", trial.name), args.quiet);
    let report = |d: usize, t: usize| progress.update(d, t);
    let control = RunControl {
        cancel: None,
        progress: Some(&report),
    };
    let correction = correct_trial(
        &trial,
        &ctx.model,
        &ctx.limits,
        &ctx.settings,
        variant,
        &control,
    )?;
    progress.finish();
    if let Some(dir) = output.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir)?;
    }
    write_trial(&correction.corrected, &output, format)?;
    let sidecar = build_sidecar(
        &args.input,
        &trial,
        &output,
        format,
        &ctx,
        &correction,
        in_format,
    )?;
    let sc_path = args
        .sidecar
        .clone()
        .unwrap_or_else(|| sidecar_path(&output));
    atomic_write(&sc_path, sidecar.to_json().as_bytes())?;
    if !args.quiet {
        for s in &correction.skipped {
            eprintln!("skipped {}: {}", s.joint, s.reason);
        }
        println!(
            "{}: {variant}, {} joints corrected -> {} (sidecar {})",
            trial.name,
            correction.joints.len(),
            output.display(),
            sc_path.display()
        );
    }
    Ok(0)
}

fn build_sidecar(
    input: &Path,
    trial: &Trial,
    output: &Path,
    format: TrialFormat,
    ctx: &Context,
    correction: &acm_workbench::acm::Correction,
    in_format: TrialFormat,
) -> anyhow::Result<Sidecar> {
    let bytes = std::fs::read(input)?;
    let record = InputRecord {
        file: input.display().to_string(),
        format: in_format,
        sha256: sha256_hex(&bytes),
        samples: trial.len(),
        imus: trial.imus.iter().map(|i| i.name.clone()).collect(),
    };
    let figures = FiguresRecord {
        before: trial_figures(trial, None, None, &ctx.model, &ctx.limits),
        after: trial_figures(
            &correction.corrected,
            Some(trial),
            None,
            &ctx.model,
            &ctx.limits,
        ),
    };
    let mut s = Sidecar::new(
        record,
        output,
        format,
        &ctx.model,
        &ctx.limits,
        &ctx.limits_source,
        correction,
        figures,
    );
    s.warnings = trial.warnings.clone();
    Ok(s)
}
