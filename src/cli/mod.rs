//! Command-line interface: one module per subcommand, all thin layers over the library.
//!
//! Exit codes: 0 success; 1 failure while working (could not write, ...);
//! 2 usage error (bad flags, from clap); 3 bad input data (a malformed trial,
//! limit table or model: the message names file, line and column);
//! 4 no terminal for the workbench.

use clap::{Parser, Subcommand};
use std::path::PathBuf;

/// `println!` to standard output that returns an `io::Result` instead of
/// panicking when the reader has gone (`acmw report T | head`).
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($arg)*)
    }};
}

/// `print!` to standard output, as [`outln!`].
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        write!(std::io::stdout().lock(), $($arg)*)
    }};
}

mod analysis;
mod batch;
mod calibrate;
mod common;
mod correct;
mod follow;
mod plot;
mod render;
mod report;
mod simulate;

/// Exit code: success.
pub const EXIT_OK: i32 = 0;
/// Exit code: failure while working.
pub const EXIT_FAILURE: i32 = 1;
/// Exit code: malformed input data.
#[allow(dead_code)] // used once a command reads input files
pub const EXIT_BAD_INPUT: i32 = 3;
/// Exit code: the workbench needs a terminal.
pub const EXIT_NO_TERMINAL: i32 = 4;

#[derive(Debug, Parser)]
#[command(
    name = "acmw",
    version,
    about = "Correct IMU joint angles with the Anatomical Constraint Method"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Folder of trials to open in the workbench (default: ./sample_trials).
    pub dir: Option<PathBuf>,
    /// Folder of limit tables and settings.toml the workbench reads and saves
    /// [default: ./joint_limits; the built-in tables when it has none].
    #[arg(long, value_name = "DIR")]
    pub limits_dir: Option<PathBuf>,
    /// Body model the workbench reads every trial with: `infant13`, `opensim`,
    /// `opensense_lower`, `full_body16` or a model TOML file [default: per
    /// trial, the built-in model that knows most of its IMUs].
    #[arg(long)]
    pub model: Option<String>,
    /// Watch the trials and limits folders by reading them every SECONDS, for
    /// network file systems that deliver no change notifications.
    #[arg(long, value_name = "SECONDS", value_parser = parse_poll)]
    pub poll: Option<f64>,
    /// Colour theme of the workbench: dark, light or high-contrast (NO_COLOR is honoured).
    #[arg(long, global = true, default_value = "dark")]
    pub theme: String,
    /// Plain ASCII markers in the charts and views, for fonts without braille
    /// or block symbols.
    #[arg(long, global = true)]
    pub ascii: bool,
    /// Leave the mouse to the terminal (its own text selection) instead of
    /// capturing clicks and the wheel.
    #[arg(long)]
    pub no_mouse: bool,
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Correct a trial and write the corrected trial plus a sidecar JSON.
    Correct(correct::CorrectArgs),
    /// Correct every trial of folders or patterns into one folder, with a
    /// resumable manifest; shards for clusters.
    Batch(batch::BatchArgs),
    /// Correct a trial while another program writes it: corrected rows as they land, then the final correction.
    Follow(follow::FollowArgs),
    /// Print the figures (docs/method.md section 16) before and after each variant.
    Report(report::ReportArgs),
    /// Simulate a trial with known misalignment and drift, and write its truth beside it.
    Simulate(simulate::SimulateArgs),
    /// Print a workbench screen as text (trials, trial, compare, limits, help, calibration,
    /// histogram, scatter, globe, applied, stick, heading).
    Render(render::RenderArgs),
    /// Suggest a limit table from the 90% intervals of clean trials; prints the diff.
    SuggestLimits(analysis::SuggestArgs),
    /// Mean joint angles over the first 30 s of trials, as a centroid table.
    Centroids(analysis::CentroidArgs),
    /// Write a figure as SVG or PNG: traces, histogram, scatter or globe.
    Plot(plot::PlotArgs),
    /// Functional calibration of a recording (Ricci et al. 2014): rho table, residuals, calibration file.
    Calibrate(calibrate::CalibrateArgs),
}

/// Runs the parsed command line; returns the process exit code.
pub fn run(cli: Cli) -> i32 {
    let result = match cli.command {
        Some(Command::Correct(a)) => correct::run(a),
        Some(Command::Batch(a)) => batch::run(a),
        Some(Command::Follow(a)) => follow::run(a),
        Some(Command::Report(a)) => report::run(a),
        Some(Command::Simulate(a)) => simulate::run(a),
        Some(Command::Render(a)) => render::run(a, &cli.theme, cli.ascii),
        Some(Command::SuggestLimits(a)) => analysis::run_suggest(a),
        Some(Command::Centroids(a)) => analysis::run_centroids(a),
        Some(Command::Plot(a)) => plot::run(a),
        Some(Command::Calibrate(a)) => calibrate::run(a),
        None => workbench(
            cli.dir,
            &cli.theme,
            cli.limits_dir,
            cli.model,
            cli.poll,
            Display {
                ascii: cli.ascii,
                mouse: !cli.no_mouse,
            },
        ),
    };
    match result {
        Ok(code) => code,
        // The reader of our output closed it (`| head`): stop quietly.
        Err(e) if is_broken_pipe(&e) => EXIT_OK,
        Err(e) => {
            eprintln!("acmw: {e:#}");
            if is_bad_input(&e) {
                EXIT_BAD_INPUT
            } else {
                EXIT_FAILURE
            }
        }
    }
}

/// The error is standard output's reader having gone away.
fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// How the workbench draws and listens.
struct Display {
    /// `--ascii`.
    ascii: bool,
    /// Not `--no-mouse`.
    mouse: bool,
}

/// Bare `acmw`: the terminal workbench, when there is a terminal.
fn workbench(
    dir: Option<PathBuf>,
    theme: &str,
    limits_dir: Option<PathBuf>,
    model: Option<String>,
    poll: Option<f64>,
    display: Display,
) -> anyhow::Result<i32> {
    use std::io::IsTerminal;
    if !(std::io::stdin().is_terminal() && std::io::stdout().is_terminal()) {
        eprintln!(
            "acmw: the workbench needs a terminal; see `acmw --help` for the headless commands (correct, report, render, simulate)"
        );
        return Ok(EXIT_NO_TERMINAL);
    }
    // TERM decides what the terminal is sent: no colours to a terminal
    // without them, no mouse or synchronized-output codes where they are
    // unknown.
    let caps = acm_workbench::ui::term::Caps::from_env();
    let no_color = std::env::var_os("NO_COLOR").is_some_and(|v| !v.is_empty()) || !caps.colour;
    let theme = acm_workbench::ui::theme::Theme::builtin(theme, no_color)
        .map_err(anyhow::Error::msg)?
        .with_ascii(display.ascii);
    let model = model
        .map(|m| acm_workbench::model::Model::load(&m))
        .transpose()?;
    let signal = acm_workbench::ui::runtime::run(acm_workbench::ui::runtime::Options {
        dir: dir.unwrap_or_else(|| PathBuf::from("sample_trials")),
        limits_dir: limits_dir.unwrap_or_else(common::default_limits_dir),
        model,
        poll: poll.map(std::time::Duration::from_secs_f64),
        theme,
        caps,
        mouse: display.mouse,
    })?;
    Ok(signal.map_or(EXIT_OK, acm_workbench::ui::signals::exit_status))
}

/// A polling interval in seconds: positive and at most a day.
fn parse_poll(s: &str) -> Result<f64, String> {
    let v: f64 = s.trim().parse().map_err(|e| format!("'{s}': {e}"))?;
    if v > 0.0 && v <= 86_400.0 {
        Ok(v)
    } else {
        Err(format!("expected seconds in (0, 86400], found {s}"))
    }
}

/// Whether an error comes from malformed input data (exit code 3).
fn is_bad_input(e: &anyhow::Error) -> bool {
    acm_workbench::located::is_bad_input(e.as_ref())
}
