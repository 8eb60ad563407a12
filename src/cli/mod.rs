//! Command-line interface: one module per subcommand, all thin layers over the library.
//!
//! Exit codes: 0 success; 1 failure while working (could not write, ...);
//! 2 usage error (bad flags, from clap); 3 bad input data (a malformed trial,
//! limit table or model: the message names file, line and column);
//! 4 no terminal for the workbench.

use clap::{Parser, Subcommand};
use std::path::PathBuf;

mod common;
mod correct;
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
#[allow(dead_code)] // used by the workbench
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
}

#[derive(Debug, Subcommand)]
pub enum Command {
    /// Correct a trial and write the corrected trial plus a sidecar JSON.
    Correct(correct::CorrectArgs),
    /// Print the figures (METHOD.md section 6) before and after each variant.
    Report(report::ReportArgs),
    /// Simulate a trial with known misalignment and drift, and write its truth beside it.
    Simulate(simulate::SimulateArgs),
}

/// Runs the parsed command line; returns the process exit code.
pub fn run(cli: Cli) -> i32 {
    let result = match cli.command {
        Some(Command::Correct(a)) => correct::run(a),
        Some(Command::Report(a)) => report::run(a),
        Some(Command::Simulate(a)) => simulate::run(a),
        None => {
            use clap::CommandFactory;
            let _ = Cli::command().print_help();
            return EXIT_OK;
        }
    };
    match result {
        Ok(code) => code,
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

/// Whether an error comes from malformed input data (exit code 3).
fn is_bad_input(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.is::<acm_workbench::trial::TrialError>()
            || c.is::<acm_workbench::limits::LimitsError>()
            || c.is::<acm_workbench::model::ModelError>()
    })
}
