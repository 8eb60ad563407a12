//! `acmw simulate`: write a simulated trial and its truth.

use clap::Args;

#[derive(Debug, Args)]
pub struct SimulateArgs {}

/// Runs `acmw simulate`.
pub fn run(_args: SimulateArgs) -> anyhow::Result<i32> {
    anyhow::bail!("not written yet")
}
