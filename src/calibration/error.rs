//! Errors of calibration files (recordings, protocols, calibration results),
//! located by file, line and column.

/// A problem with a calibration file: where it is and what was expected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}", crate::input::located(.file, .line, .column, .message))]
pub struct CalibrationError {
    /// The file as the user named it (or `<built-in NAME>`).
    pub file: String,
    /// 1-based line in the (decompressed) text; 0 when the file as a whole is meant.
    pub line: u64,
    /// 1-based column (CSV field, or TOML character); 0 when a whole line or the file is meant.
    pub column: usize,
    /// What was found and what was expected.
    pub message: String,
}

impl CalibrationError {
    /// An error at a place in a file.
    pub fn at(
        file: impl Into<String>,
        line: u64,
        column: usize,
        message: impl Into<String>,
    ) -> Self {
        CalibrationError {
            file: file.into(),
            line,
            column,
            message: message.into(),
        }
    }

    /// An error about the file as a whole.
    pub fn file(file: impl Into<String>, message: impl Into<String>) -> Self {
        CalibrationError::at(file, 0, 0, message)
    }

    /// A TOML parse error of `text`, located by its span.
    pub fn toml(file: &str, text: &str, e: &toml::de::Error) -> Self {
        let (line, column) = e
            .span()
            .map(|sp| line_col(text, sp.start))
            .unwrap_or((0, 0));
        CalibrationError::at(file, line, column, e.message().trim().to_string())
    }
}

pub use crate::input::line_col;
