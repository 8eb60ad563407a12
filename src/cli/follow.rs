//! `acmw follow`: correct a trial while another program is still writing it.
//! A thin layer over `acm_workbench::follow` (reading, schedule,
//! extrapolation, background solves) and the pipeline (the final correction).

use super::common::{
    load_calibration, load_context, load_prepared, variant_parser, EngineArgs, PoseArgs,
    PrecisionArgs,
};
use acm_workbench::acm::{RunControl, Variant};
use acm_workbench::correct::pipeline::{self, Preparation, Source};
use acm_workbench::follow::{
    exports_ready, push, Extrapolation, Follower, FollowerConfig, LiveSource, Look,
};
use acm_workbench::trial::format::{is_followable, is_stream_format};
use acm_workbench::trial::{detect_model, trial_to_string_at, TrialFormat};
use anyhow::Context as _;
use clap::Args;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

#[derive(Debug, Args)]
pub struct FollowArgs {
    /// The trial another program is appending to: a canonical CSV
    /// (`time,<imu>_qw,_qx,_qy,_qz,...`) or an Euler CSV
    /// (`time,<imu>_roll,_pitch,_yaw,...`), not compressed (it need not
    /// exist yet), or a folder of Xsens MT Manager exports, one per sensor,
    /// that MT Manager appends to (rows aligned on the packet counter).
    pub input: PathBuf,
    /// Write the live corrected rows to this file (created afresh, appended
    /// and flushed per batch) instead of standard output.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// The final correction [default: corrected/<name>.<variant>.<ext> beside
    /// the input, as `acmw correct` writes it].
    #[arg(long)]
    pub corrected: Option<PathBuf>,
    /// Sidecar JSON path of the final correction [default: <corrected>.acmw.json].
    #[arg(long)]
    pub sidecar: Option<PathBuf>,
    /// Correction variant.
    #[arg(long, value_parser = variant_parser(), default_value = "drift-centroid")]
    pub variant: Variant,
    /// Output format of the live rows and the final trial [default: the
    /// input's; for Xsens exports, quat-csv live and the final trial as
    /// `acmw correct` writes it].
    #[arg(long, value_parser = super::common::named_parser::<TrialFormat>())]
    pub format: Option<TrialFormat>,
    /// How rows past the last solved window are corrected.
    #[arg(long, value_parser = super::common::named_parser::<Extrapolation>(), default_value = "rate")]
    pub extrapolate: Extrapolation,
    /// Solve the growing trial every SECONDS of trial time until the first
    /// window is complete (0: not before it); rows before the first solve
    /// are written uncorrected.
    #[arg(long, value_name = "SECONDS", default_value = "10", value_parser = parse_seconds)]
    pub warmup: f64,
    /// Stop at this many seconds of trial time after the first sample.
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds)]
    pub until: Option<f64>,
    /// Stop when the file has not grown for SECONDS.
    #[arg(long, value_name = "SECONDS", value_parser = parse_seconds)]
    pub idle_exit: Option<f64>,
    /// Look at the file at least every SECONDS (file change notifications
    /// wake it sooner where the file system delivers them).
    #[arg(long, value_name = "SECONDS", default_value = "0.2", value_parser = parse_seconds)]
    pub poll: f64,
    /// Apply this functional calibration (`acmw calibrate`) to every row
    /// first, live and in the final correction, as `acmw correct
    /// --calibration` applies it.
    #[arg(long, value_name = "FILE")]
    pub calibration: Option<PathBuf>,
    #[command(flatten)]
    pub engine: EngineArgs,
    /// Pose calibration: rows go out as read, and nothing is solved, until
    /// a row later than its time or span arrives; then it is found on the
    /// rows so far and applied to every later row and solve.
    #[command(flatten)]
    pub pose: PoseArgs,
    /// Also the live rows' precision (`auto`: as the rows read so far had).
    #[command(flatten)]
    pub output_precision: PrecisionArgs,
    /// No messages on standard error but errors.
    #[arg(short, long)]
    pub quiet: bool,
}

/// Seconds: finite, at least 0, at most a year.
fn parse_seconds(s: &str) -> Result<f64, String> {
    let v: f64 = s.trim().parse().map_err(|e| format!("'{s}': {e}"))?;
    if (0.0..=3.2e7).contains(&v) {
        Ok(v)
    } else {
        Err(format!("expected seconds in [0, 3.2e7], found {s}"))
    }
}

/// Where the live rows go.
struct Sink {
    file: Option<(std::fs::File, PathBuf)>,
    header_written: bool,
}

impl Sink {
    fn open(path: Option<&Path>) -> anyhow::Result<Sink> {
        let file = path
            .map(|p| {
                std::fs::File::create(p)
                    .map(|f| (f, p.to_path_buf()))
                    .with_context(|| format!("{}: cannot create", p.display()))
            })
            .transpose()?;
        Ok(Sink {
            file,
            header_written: false,
        })
    }

    /// Starts the stream over: the file is emptied, standard output gets a
    /// new header line before the next rows.
    fn restart(&mut self) -> anyhow::Result<()> {
        if let Some((f, p)) = &mut self.file {
            f.set_len(0)
                .and_then(|_| std::io::Seek::rewind(f))
                .with_context(|| format!("{}: cannot empty", p.display()))?;
        }
        self.header_written = false;
        Ok(())
    }

    /// Writes `text` (the batch as a trial file: header line, rows) and flushes.
    fn write(&mut self, text: &str) -> anyhow::Result<()> {
        let body = if self.header_written {
            text.split_once('\n').map_or("", |(_, rows)| rows)
        } else {
            text
        };
        self.header_written = true;
        match &mut self.file {
            Some((f, p)) => f
                .write_all(body.as_bytes())
                .and_then(|_| f.flush())
                .with_context(|| format!("{}: cannot write", p.display())),
            None => {
                let mut out = std::io::stdout().lock();
                out.write_all(body.as_bytes())?;
                out.flush()?;
                Ok(())
            }
        }
    }
}

/// Why following ended.
#[derive(Debug, PartialEq)]
enum End {
    Until,
    Idle,
    Interrupted,
}

/// Waits until the file holds a complete header line (its first line that
/// is neither blank nor a `#` comment), so the model can be chosen from it.
fn wait_for_header(
    path: &Path,
    poll: Duration,
    stop: &AtomicBool,
    idle: Option<Duration>,
) -> anyhow::Result<bool> {
    let start = Instant::now();
    loop {
        if path.is_dir() {
            if exports_ready(path) {
                return Ok(true);
            }
        } else if let Ok(text) = acm_workbench::input::read_bytes(path) {
            let text = String::from_utf8_lossy(&text);
            let complete = text.split_inclusive('\n').any(|l| {
                let t = l.trim_start_matches('\u{feff}').trim();
                l.ends_with('\n') && !t.is_empty() && !t.starts_with('#')
            });
            if complete {
                return Ok(true);
            }
        }
        if stop.load(Ordering::Relaxed) || idle.is_some_and(|d| start.elapsed() >= d) {
            return Ok(false);
        }
        std::thread::sleep(poll.min(Duration::from_millis(50)));
    }
}

/// Runs `acmw follow`.
pub fn run(args: FollowArgs) -> anyhow::Result<i32> {
    let input = &args.input;
    let name = input.display().to_string();
    if !is_followable(input) {
        anyhow::bail!(
            "{name}: acmw follow reads a growing canonical or Euler CSV (a name ending in .csv, not compressed) or a folder of Xsens exports; `acmw correct` reads the other formats once they are complete"
        );
    }
    if args.format.is_some_and(|f| !is_stream_format(f)) {
        anyhow::bail!("--format: acmw follow writes quat-csv or euler-csv");
    }
    // A bad calibration file is reported before waiting for the trial.
    let calibration = load_calibration(args.calibration.as_deref())?;
    let stop = Arc::new(AtomicBool::new(false));
    for sig in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
        signal_hook::flag::register(sig, Arc::clone(&stop))?;
    }
    let poll = Duration::from_secs_f64(args.poll.max(0.001));
    let idle = args.idle_exit.map(Duration::from_secs_f64);
    if !wait_for_header(input, poll, &stop, idle)? {
        if input.is_dir() {
            anyhow::bail!("{name}: no Xsens exports with complete header lines arrived: expected MT Manager exports being written into this folder");
        }
        anyhow::bail!("{name}: no header line arrived: expected a trial being written");
    }
    let mut ctx = load_context(&args.engine, || Ok(detect_model(input)))?;
    args.output_precision.apply(&mut ctx.settings);
    let variant = args.variant;
    let config = FollowerConfig {
        model: ctx.model.clone(),
        limits: ctx.limits.clone(),
        limits_source: ctx.limits_source.clone(),
        settings: ctx.settings,
        variant,
        extrapolation: args.extrapolate,
        warmup_s: args.warmup,
        until_s: args.until,
        calibration,
        pose: args.pose.calibration(&ctx.model),
    };
    let s = &ctx.settings;
    if !args.quiet {
        let warm = if args.warmup > 0.0 && args.warmup < s.window_s {
            format!(
                "every {} s until the first window is complete, then ",
                args.warmup
            )
        } else {
            String::new()
        };
        eprintln!(
            "following {name}: {variant}, solved {warm}as each {} s window completes (hop {} s); rows past the last solve are extrapolated ({})",
            s.window_s,
            s.hop_s,
            acm_workbench::names::Named::name(args.extrapolate)
        );
        if let Some(c) = &config.calibration {
            eprintln!(
                "calibration {} ({} IMUs) applied to every row first",
                c.file,
                c.imus.len()
            );
        }
        if let Some(p) = &config.pose {
            eprintln!(
                "pose calibration at {} s: rows go out as read (neither calibrated nor corrected) until a row after {} s arrives",
                p.at,
                p.at.end_s()
            );
        }
    }
    let mut reading = LiveSource::new(input, &config.model);
    let mut follower = Follower::new(&name, config);
    let mut sink = Sink::open(args.output.as_deref())?;
    let (wake_tx, wake_rx) = crossbeam_channel::unbounded::<()>();
    let _watcher = watch(input, wake_tx, args.quiet);
    let mut format: Option<TrialFormat> = args.format;
    let mut last_growth = Instant::now();
    let mut pose_said = false;
    let end = loop {
        if stop.load(Ordering::Relaxed) {
            break End::Interrupted;
        }
        let before = reading.offset();
        match reading.poll()? {
            Look::Nothing => {}
            Look::Restarted(reason) => {
                eprintln!("{name} {reason}: starting over");
                follower.restart();
                pose_said = false;
                sink.restart()?;
                format = args.format;
            }
            got => {
                let range = push(&mut follower, got)?;
                if !range.is_empty() {
                    let fmt = *format
                        .get_or_insert_with(|| follower.format().unwrap_or(TrialFormat::QuatCsv));
                    if let Some(batch) = follower.corrected(range) {
                        sink.write(&trial_to_string_at(&batch, fmt, s.precision))?;
                    }
                }
            }
        }
        if reading.offset() != before {
            last_growth = Instant::now();
        }
        if let (Some(found), false) = (follower.pose(), pose_said) {
            pose_said = true;
            match found {
                Ok(p) if !args.quiet => eprintln!(
                    "pose calibration at {} s ({} samples), heading correction {:.2} deg: later rows are calibrated and corrected",
                    p.calibration.at, p.samples, p.heading_deg
                ),
                Ok(_) => {}
                Err(e) => eprintln!("{name}: {e}; rows go on as read"),
            }
        }
        for solved in follower.poll_solved() {
            if args.quiet {
                continue;
            }
            match &solved.error {
                None => eprintln!(
                    "solved 0-{:.1} s ({} samples) in {:.2} s; later rows extrapolate from it",
                    solved.point_s,
                    solved.samples,
                    solved.elapsed.as_secs_f64()
                ),
                Some(e) => eprintln!("could not solve 0-{:.1} s: {e}", solved.point_s),
            }
        }
        if follower.reached_until() {
            break End::Until;
        }
        if idle.is_some_and(|d| last_growth.elapsed() >= d) {
            break End::Idle;
        }
        // Sleep until the file changes or the poll interval passes.
        if wake_rx.recv_timeout(poll).is_ok() {
            while wake_rx.try_recv().is_ok() {}
        }
    };
    follower.stop();
    // What the writer added since the last look, up to the end.
    if end != End::Until {
        while let got @ (Look::Lines { .. } | Look::Samples(_)) = reading.poll()? {
            let range = push(&mut follower, got)?;
            if let (false, Some(batch)) = (range.is_empty(), follower.corrected(range.clone())) {
                let fmt = format.unwrap_or(TrialFormat::QuatCsv);
                sink.write(&trial_to_string_at(&batch, fmt, s.precision))?;
            }
        }
    }
    if !args.quiet {
        let why = match end {
            End::Until => format!("reached {} s", args.until.unwrap_or(0.0)),
            End::Idle => format!("no growth for {} s", args.idle_exit.unwrap_or(0.0)),
            End::Interrupted => "interrupted".into(),
        };
        eprintln!("{name}: {why}; writing the final correction");
    }
    let preparation = follower.config().preparation();
    final_correction(
        &args,
        &ctx,
        &preparation,
        &follower,
        &reading,
        end == End::Until,
    )
}

/// Watches the input's folder (or the folder of exports) for changes (each wakes the loop); `None` when
/// notifications are not available (the poll interval alone then paces it).
fn watch(
    input: &Path,
    wake: crossbeam_channel::Sender<()>,
    quiet: bool,
) -> Option<notify::RecommendedWatcher> {
    use notify::Watcher;
    // A folder of exports is watched itself; a file, through its folder.
    let dir = match input.parent() {
        _ if input.is_dir() => input.to_path_buf(),
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let mut w = notify::recommended_watcher(move |_event| {
        let _ = wake.send(());
    })
    .ok()?;
    match w.watch(&dir, notify::RecursiveMode::NonRecursive) {
        Ok(()) => Some(w),
        Err(e) => {
            if !quiet {
                eprintln!(
                    "note: no change notifications for {} ({e}); looking at the file every poll interval",
                    dir.display()
                );
            }
            None
        }
    }
}

/// The final correction, as `acmw correct` makes it: of the file itself
/// when every line of it was read, else of the rows read (cut at
/// `--until`, or without a last line the writer left unfinished).
fn final_correction(
    args: &FollowArgs,
    ctx: &super::common::Context,
    preparation: &Preparation,
    follower: &Follower,
    reading: &LiveSource,
    cut: bool,
) -> anyhow::Result<i32> {
    let input = &args.input;
    let whole = !cut && reading.read_whole();
    let (source, prepared) = if whole {
        let file = pipeline::read(input)?;
        load_prepared(ctx, &file, preparation, false, args.quiet)?
    } else {
        let trial = follower
            .trial()
            .with_context(|| format!("{}: no samples were read", input.display()))?
            .clone();
        if !args.quiet {
            eprintln!(
                "{}: the final correction covers the {} rows read (0-{:.2} s); the file {}",
                input.display(),
                trial.len(),
                trial.time_s[trial.len() - 1] - trial.time_s[0],
                if cut {
                    "continues past --until"
                } else {
                    "ends in an unfinished line or changed meanwhile"
                }
            );
        }
        // The whole file as it is now, for its format and the sidecar's hash.
        let source = Source::of(&pipeline::read(input)?);
        let prepared = pipeline::prepare(trial, ctx.setup(), preparation)
            .map_err(|e| anyhow::anyhow!("{}: {e}", input.display()))?;
        if !args.quiet {
            for w in &prepared.calibration_warnings {
                eprintln!("warning: {w}");
            }
        }
        (source, prepared)
    };
    let trial = &prepared.trial;
    if !args.quiet {
        for w in &trial.warnings {
            eprintln!("warning: {w}");
        }
    }
    let mut output = source.default_output(args.variant, args.format);
    if let Some(o) = &args.corrected {
        output.path = o.clone();
    }
    output.sidecar = args.sidecar.clone();
    let correction = pipeline::correct(trial, ctx.setup(), args.variant, &RunControl::default())?;
    let sc_path = pipeline::save(&source, &prepared, &correction, ctx.setup(), &output)?;
    if !args.quiet {
        for s in &correction.skipped {
            eprintln!("skipped {}: {}", s.joint, s.reason);
        }
        eprintln!(
            "{}: {}, {} joints corrected -> {} (sidecar {})",
            trial.name,
            args.variant,
            correction.joints.len(),
            output.path.display(),
            sc_path.display()
        );
    }
    Ok(0)
}
