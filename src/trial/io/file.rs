//! A trial's input read from disk once: its format, its SHA-256 and its
//! content, from which the header ([`TrialHead`]), the body model that fits
//! it and the trial itself are all taken without reading again.

use super::parse::{classify_csv_header, first_header, parse_trial};
use super::{bad_gzip, cannot_read, name_of, to_text, TrialHead};
use crate::model::Model;
use crate::trial::format::{holder, Holder, Kind};
use crate::trial::xsens_trial::{self, XsensSource};
use crate::trial::{Trial, TrialError, TrialFormat};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// A trial's input as read from disk, once.
#[derive(Debug, Clone)]
pub struct TrialFile {
    /// The path the trial was named by (a file, a mapping XML or a folder).
    pub path: PathBuf,
    pub format: TrialFormat,
    /// Whether the file was gzip-compressed.
    pub gzip: bool,
    /// SHA-256 (hex) of the bytes read: the file as stored (compressed when
    /// gzip), or for Xsens exports the mapping XML followed by every export
    /// in order. What a sidecar records as its input's hash.
    pub sha256: String,
    content: Content,
}

#[derive(Debug, Clone)]
enum Content {
    /// The decompressed, decoded text of a CSV or `.sto` file.
    Text(Kind, String),
    /// Xsens exports: where they are, and each export's bytes.
    Exports(XsensSource, Vec<Vec<u8>>),
}

impl TrialFile {
    /// Reads the trial at `path`: the whole file (or every export) once,
    /// hashed as read. Errors name the file (and the line and column of
    /// text that is not UTF-8).
    pub fn read(path: &Path) -> Result<TrialFile, TrialError> {
        let origin = path.display().to_string();
        let (kind, gzip) = match holder(path)? {
            Holder::Exports => return TrialFile::exports(path, xsens_trial::resolve(path)?, None),
            Holder::Text { kind, gzip } => (kind, gzip),
        };
        let raw = crate::input::read_bytes(path).map_err(|e| cannot_read(&origin, e))?;
        if kind == Kind::Csv && !gzip && xsens_trial::starts_like_export_bytes(&raw) {
            return TrialFile::exports(path, xsens_trial::resolve(path)?, Some(raw));
        }
        let sha256 = crate::input::sha256_hex(&raw);
        let bytes = if gzip {
            crate::input::gunzip_capped(&raw).map_err(|e| {
                if e.kind() == std::io::ErrorKind::InvalidData
                    && e.to_string().contains("more than")
                {
                    TrialError::file(&origin, format!("cannot read: {e}"))
                } else {
                    bad_gzip(&origin, e)
                }
            })?
        } else {
            raw
        };
        let text = to_text(bytes, &origin, kind, gzip)?;
        let format = match kind {
            Kind::Sto => TrialFormat::Sto,
            Kind::Csv => first_header(&text).map_or(TrialFormat::QuatCsv, classify_csv_header),
        };
        Ok(TrialFile {
            path: path.to_path_buf(),
            format,
            gzip,
            sha256,
            content: Content::Text(kind, text),
        })
    }

    /// The Xsens trial of `source`: every export read (`single`: the one
    /// export's bytes, already read), the mapping's bytes and the exports'
    /// hashed in order.
    fn exports(
        path: &Path,
        source: XsensSource,
        single: Option<Vec<u8>>,
    ) -> Result<TrialFile, TrialError> {
        let exports = match single {
            Some(bytes) => vec![bytes],
            None => (source.files.iter())
                .map(|(f, _)| {
                    crate::input::read_bytes(f)
                        .map_err(|e| cannot_read(&f.display().to_string(), e))
                })
                .collect::<Result<Vec<_>, _>>()?,
        };
        let mut hash = Sha256::new();
        hash.update(source.mapping_text.as_bytes());
        exports.iter().for_each(|b| hash.update(b));
        let sha256 = hash.finalize().iter().map(|b| format!("{b:02x}")).collect();
        Ok(TrialFile {
            path: path.to_path_buf(),
            format: TrialFormat::Xsens,
            gzip: false,
            sha256,
            content: Content::Exports(source, exports),
        })
    }

    /// The header: format and IMU names, as [`TrialHead::read`] would read them.
    pub fn head(&self) -> TrialHead {
        let origin = self.path.display().to_string();
        match &self.content {
            Content::Text(kind, text) => {
                TrialHead::of_text(origin, self.gzip, self.format, head_of(text, *kind))
            }
            Content::Exports(source, _) => TrialHead::of_exports(
                origin,
                source.files.iter().map(|(_, n)| n.clone()).collect(),
            ),
        }
    }

    /// The built-in model that fits the trial best ([`TrialHead::detect_model`]).
    pub fn detect_model(&self) -> Model {
        self.head().detect_model()
    }

    /// The trial with `model`'s IMU names; `Trial::name` is the last
    /// component of the path.
    pub fn trial(&self, model: &Model) -> Result<Trial, TrialError> {
        let origin = self.path.display().to_string();
        match &self.content {
            Content::Text(_, text) => {
                parse_trial(text, &origin, &name_of(&origin), self.format, model)
            }
            Content::Exports(source, exports) => {
                xsens_trial::trial_of_exports(&self.path, source, exports, model)
            }
        }
    }
}

/// The header lines at the start of `text`, as [`super::read_head`] reads
/// them from disk: for CSV up to the first line neither blank nor a `#`
/// comment, for `.sto` up to the first non-blank line after `endheader`.
fn head_of(text: &str, kind: Kind) -> &str {
    let mut ended = kind == Kind::Csv;
    let mut at = 0;
    while at < text.len() {
        let end = text[at..].find('\n').map_or(text.len(), |i| at + i + 1);
        let line = text[at..end].trim_ascii();
        at = end;
        if line.is_empty() || (kind == Kind::Csv && line.starts_with('#')) {
            continue;
        }
        if ended {
            break;
        }
        if line.eq_ignore_ascii_case("endheader") {
            ended = true;
        }
    }
    &text[..at]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_head_of_a_text_ends_after_its_header_line() {
        let csv = "\n# note\ntime,a_qw\n0,1\n";
        assert_eq!(head_of(csv, Kind::Csv), "\n# note\ntime,a_qw\n");
        let sto = "DataRate=100\nendheader\n\ntime\ta\n0\t1,0,0,0\n";
        assert_eq!(
            head_of(sto, Kind::Sto),
            "DataRate=100\nendheader\n\ntime\ta\n"
        );
        assert_eq!(head_of("time,a_qw", Kind::Csv), "time,a_qw");
        assert_eq!(head_of("", Kind::Sto), "");
    }
}
