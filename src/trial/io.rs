//! Reading and writing trial files (filled in by the trial I/O work).

use super::{Trial, TrialError, TrialFormat};
use crate::model::Model;
use std::path::Path;

/// Reads a trial, picking the format from the file name (`.csv`, `.sto`, optionally `.gz`).
pub fn read_trial(path: &Path, _model: &Model) -> Result<Trial, TrialError> {
    Err(TrialError::file(
        path.display().to_string(),
        "reader not written yet",
    ))
}

/// Writes a trial in `format`; gzip-compressed when the path ends in `.gz`. Atomic.
pub fn write_trial(_trial: &Trial, path: &Path, _format: TrialFormat) -> Result<(), TrialError> {
    Err(TrialError::file(
        path.display().to_string(),
        "writer not written yet",
    ))
}
