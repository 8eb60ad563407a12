//! Errors of calibration files (recordings, protocols, calibration results),
//! located by file, line and column.

/// A problem with a calibration file: where it is and what was expected.
pub type CalibrationError = crate::located::LocatedError;

pub use crate::input::line_col;
