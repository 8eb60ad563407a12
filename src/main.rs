//! `acmw`: the ACM workbench. Bare `acmw` opens the terminal workbench; the
//! subcommands run every operation headless.

use clap::Parser;

mod cli;

fn main() {
    let args = cli::Cli::parse();
    std::process::exit(cli::run(args));
}
