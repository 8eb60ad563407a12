//! The one error type of every parser: a problem located in a file by line
//! and column, and what was expected there.
//!
//! Trial, limit-table, settings, model, calibration and sidecar readers all
//! report a [`LocatedError`] (under their own alias names, such as
//! `trial::TrialError`); the command line maps it to one exit code (bad input)
//! through [`is_bad_input`].

use crate::input::line_col;

/// A problem with an input file: where it is and what was expected.
///
/// Shown as `file:line:column: message`, or `file:line: message` when the
/// whole line is meant, or `file: message` when the file as a whole is meant.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}", self.shown())]
pub struct LocatedError {
    /// The file as the user named it (or `<built-in NAME>`).
    pub file: String,
    /// 1-based line in the (decompressed) text; 0 when the file as a whole is meant.
    pub line: u64,
    /// 1-based column (CSV field, or character); 0 when the whole line or file is meant.
    pub column: usize,
    /// What was found and what was expected.
    pub message: String,
}

impl LocatedError {
    /// An error at a place in a file.
    pub fn at(
        file: impl Into<String>,
        line: u64,
        column: usize,
        message: impl Into<String>,
    ) -> Self {
        LocatedError {
            file: file.into(),
            line,
            column,
            message: message.into(),
        }
    }

    /// An error about the file as a whole (cannot open, empty, ...).
    pub fn file(file: impl Into<String>, message: impl Into<String>) -> Self {
        LocatedError::at(file, 0, 0, message)
    }

    /// The error as the user reads it: the place, then the message.
    fn shown(&self) -> String {
        let LocatedError {
            file,
            line,
            column,
            message,
        } = self;
        match (line, column) {
            (0, _) => format!("{file}: {message}"),
            (_, 0) => format!("{file}:{line}: {message}"),
            _ => format!("{file}:{line}:{column}: {message}"),
        }
    }

    /// A TOML parse error of `text`, located by its span.
    pub fn toml(file: &str, text: &str, e: &toml::de::Error) -> Self {
        let (line, column) = e
            .span()
            .map(|sp| line_col(text, sp.start))
            .unwrap_or((0, 0));
        LocatedError::at(file, line, column, e.message().trim().to_string())
    }
}

/// Whether an error, or any error in its chain of sources, comes from
/// malformed input data (a located parse or validation error), as opposed to a failure of the machine
/// (I/O, a full disk) or of the program.
pub fn is_bad_input(e: &(dyn std::error::Error + 'static)) -> bool {
    let mut next = Some(e);
    while let Some(err) = next {
        if err.is::<LocatedError>() {
            return true;
        }
        next = err.source();
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shows_file_line_column_and_message() {
        let e = LocatedError::at("t.csv", 3, 2, "expected a number");
        assert_eq!(e.to_string(), "t.csv:3:2: expected a number");
        let e = LocatedError::at("t.csv", 3, 0, "a short row");
        assert_eq!(e.to_string(), "t.csv:3: a short row");
        assert_eq!(
            LocatedError::file("t.csv", "empty").to_string(),
            "t.csv: empty"
        );
        let toml_text = "a = 1\nb = =\n";
        let te = toml::from_str::<toml::Table>(toml_text).unwrap_err();
        let e = LocatedError::toml("s.toml", toml_text, &te);
        assert_eq!((e.line, e.column), (2, 5), "{e}");
    }

    #[test]
    fn bad_input_is_found_through_the_chain() {
        #[derive(Debug, thiserror::Error)]
        #[error("wrapped")]
        struct Wrapper(#[source] LocatedError);
        let located = LocatedError::file("x", "bad");
        assert!(is_bad_input(&Wrapper(located)));
        let io = std::io::Error::other("disk full");
        assert!(!is_bad_input(&io));
    }
}
