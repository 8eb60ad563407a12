//! Errors of trial files, located by file, line and column.

/// A problem with a trial file: where it is and what was expected (line 0 when
/// the file as a whole is meant).
pub type TrialError = crate::located::LocatedError;
