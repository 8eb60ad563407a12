//! Errors of trial files, located by file, line and column.

/// A problem with a trial file: where it is and what was expected.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}", crate::input::located(.file, .line, .column, .message))]
pub struct TrialError {
    /// The file as the user named it.
    pub file: String,
    /// 1-based line in the (decompressed) text; 0 when the file as a whole is meant.
    pub line: u64,
    /// 1-based column (field index); 0 when the whole line or file is meant.
    pub column: usize,
    /// What was found and what was expected.
    pub message: String,
}

impl TrialError {
    /// An error at a place in a file.
    pub fn at(
        file: impl Into<String>,
        line: u64,
        column: usize,
        message: impl Into<String>,
    ) -> Self {
        TrialError {
            file: file.into(),
            line,
            column,
            message: message.into(),
        }
    }

    /// An error about the file as a whole (cannot open, empty, ...).
    pub fn file(file: impl Into<String>, message: impl Into<String>) -> Self {
        TrialError::at(file, 0, 0, message)
    }
}
