//! What the command-line integration tests share: running `acmw`.
#![allow(dead_code)] // each test file uses what it needs

pub mod engine;

use std::path::Path;
use std::process::{Command, Output};

/// Runs the `acmw` binary with `args` in the folder `dir`.
pub fn acmw(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_acmw"))
        .current_dir(dir)
        .args(args)
        .output()
        .unwrap()
}

/// The standard output of a run that must have succeeded (its standard
/// error in the failure message otherwise).
pub fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Runs `acmw` and requires it to succeed.
pub fn acmw_ok(dir: &Path, args: &[&str]) -> Output {
    let out = acmw(dir, args);
    assert!(
        out.status.success(),
        "acmw {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    out
}
