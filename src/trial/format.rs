//! Every trial format in one table ([`FORMATS`]): its name, what holds it on
//! disk and how it is recognised, its reader and its writer (where there is
//! one), and which format a corrected trial of it is written in. Everything
//! that asks what a path holds, reads or names a trial goes through here
//! ([`holder`], [`could_name_trial`], [`TrialFormat::row`]) instead of
//! matching extensions itself.

use super::{TrialError, TrialFormat};
use std::path::Path;

/// What holds trials of a format on disk.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// One text file with this extension (`.csv`, `.sto`), optionally `.gz`.
    File { extension: &'static str },
    /// MT Manager exports: one `.txt` (or export-like `.csv`) per sensor, named
    /// by an OpenSense mapping `.xml` or gathered by a folder.
    Exports,
}

/// The parser of a format: one text file, or a set of Xsens exports.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reader {
    /// [`super::io::parse`]: the header, then one row per sample.
    Text,
    /// [`super::xsens_trial`]: the exports aligned on the packet counter.
    Exports,
}

/// One trial format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FormatRow {
    pub format: TrialFormat,
    /// The name in files and on the command line (`quat-csv`).
    pub name: &'static str,
    /// One line for help texts.
    pub help: &'static str,
    pub layout: Layout,
    /// How a path is recognised as this format.
    pub detection: &'static str,
    pub reader: Reader,
    /// Whether trials can be written in this format ([`super::write_trial`]).
    pub writable: bool,
    /// The format a corrected trial of this one is written in by default.
    pub output: TrialFormat,
    /// Whether a growing trial of this format can be followed (`acmw
    /// follow`): uncompressed, one complete sample per appended line (for
    /// Xsens exports, a folder of them, one line per packet in each).
    pub followable: bool,
}

/// The formats the program reads, in [`TrialFormat`] order.
pub const FORMATS: [FormatRow; 4] = [
    FormatRow {
        format: TrialFormat::QuatCsv,
        name: "quat-csv",
        help: "time,<imu>_qw,<imu>_qx,<imu>_qy,<imu>_qz,... (canonical CSV)",
        layout: Layout::File { extension: "csv" },
        detection: "*.csv[.gz] whose header names <imu>_qw columns",
        reader: Reader::Text,
        writable: true,
        output: TrialFormat::QuatCsv,
        followable: true,
    },
    FormatRow {
        format: TrialFormat::EulerCsv,
        name: "euler-csv",
        help: "time,<imu>_roll,<imu>_pitch,<imu>_yaw,..., degrees, Z-Y-X",
        layout: Layout::File { extension: "csv" },
        detection: "*.csv[.gz] whose header names <imu>_roll/_pitch/_yaw columns",
        reader: Reader::Text,
        writable: true,
        output: TrialFormat::EulerCsv,
        followable: true,
    },
    FormatRow {
        format: TrialFormat::Sto,
        name: "sto",
        help: "OpenSim orientation .sto (OpenSense)",
        layout: Layout::File { extension: "sto" },
        detection: "*.sto[.gz]",
        reader: Reader::Text,
        writable: true,
        output: TrialFormat::Sto,
        followable: false,
    },
    FormatRow {
        format: TrialFormat::Xsens,
        name: "xsens",
        help: "Xsens MT Manager exports (read only)",
        layout: Layout::Exports,
        detection: "a folder of exports, an OpenSense mapping *.xml, a *.txt export, or a *.csv that starts like an export (// comments, PacketCounter)",
        reader: Reader::Exports,
        writable: false,
        output: TrialFormat::Sto,
        followable: true,
    },
];

impl TrialFormat {
    /// This format's row of [`FORMATS`].
    pub fn row(self) -> &'static FormatRow {
        FORMATS
            .iter()
            .find(|r| r.format == self)
            .expect("every format has a row")
    }

    /// The format a corrected trial is written in by default: the input's own,
    /// or `.sto` (what OpenSense makes of them) for Xsens exports.
    pub fn output_default(self) -> TrialFormat {
        self.row().output
    }

    /// The extension (without dot or `.gz`) of a file written in this format
    /// or, for a read-only format, in its default output format.
    pub fn extension(self) -> &'static str {
        match self.row().layout {
            Layout::File { extension } => extension,
            Layout::Exports => self.output_default().extension(),
        }
    }
}

/// Text file kinds: a CSV (canonical or Euler, told apart by the header) or
/// an OpenSim `.sto`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    Csv,
    Sto,
}

/// What holds the trial at a path, as far as its name (and whether it is a
/// folder) tells.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Holder {
    /// A CSV or `.sto` file, gzip-compressed or not. An uncompressed `.csv`
    /// may still turn out to be a single Xsens export (by its first line).
    Text { kind: Kind, gzip: bool },
    /// A folder of exports, a mapping `.xml` or a `.txt` export.
    Exports,
}

/// `(kind, gzip)` from a file name, if it names a text trial format.
pub(crate) fn kind_of_name(path: &Path) -> Option<(Kind, bool)> {
    let name = path.file_name()?.to_string_lossy().to_ascii_lowercase();
    let (stem, gz) = match name.strip_suffix(".gz") {
        Some(s) => (s, true),
        None => (name.as_str(), false),
    };
    let extension_of = |f: &FormatRow| match f.layout {
        Layout::File { extension } => Some(extension),
        Layout::Exports => None,
    };
    FORMATS.iter().filter_map(extension_of).find_map(|ext| {
        let long_enough = stem.len() > ext.len() + 1;
        let kind = if ext == "sto" { Kind::Sto } else { Kind::Csv };
        (long_enough && stem.ends_with(&format!(".{ext}"))).then_some((kind, gz))
    })
}

/// True when `path` is a folder, or its name ends in `.xml` or `.txt` (any
/// case): a trial of Xsens exports, whatever the file holds.
fn names_exports(path: &Path) -> bool {
    path.is_dir()
        || path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("xml") || e.eq_ignore_ascii_case("txt"))
}

/// What holds the trial at `path`, from its name; an error naming every
/// accepted input when the name fits none.
pub(crate) fn holder(path: &Path) -> Result<Holder, TrialError> {
    if names_exports(path) {
        return Ok(Holder::Exports);
    }
    let (kind, gzip) = kind_of_name(path).ok_or_else(|| {
        TrialError::file(
            path.display().to_string(),
            format!(
                "unknown trial file type: expected {}",
                super::ACCEPTED_INPUTS
            ),
        )
    })?;
    Ok(Holder::Text { kind, gzip })
}

/// True when `path`'s name alone may name a trial (the file need not exist,
/// so a removed trial is still recognised): a trial file name
/// ([`super::is_trial_file`]), a folder, or an `.xml` mapping or `.txt`
/// export. Whether it holds one is [`super::is_trial_path`]'s to say.
pub fn could_name_trial(path: &Path) -> bool {
    super::is_trial_file(path) || names_exports(path)
}

/// True when `path` names a file that can be followed while it grows: an
/// uncompressed CSV, the file layout of the [`FormatRow::followable`]
/// formats (what the workbench follows).
pub fn is_followable_name(path: &Path) -> bool {
    !path.is_dir() && kind_of_name(path) == Some((Kind::Csv, false))
}

/// True when `path` can be followed while it grows (`acmw follow`): a file
/// [`is_followable_name`] accepts, or a folder, read as the Xsens exports
/// (the [`Layout::Exports`] followable format) that are, or will be,
/// written into it.
pub fn is_followable(path: &Path) -> bool {
    let exports = FORMATS
        .iter()
        .any(|r| r.followable && r.layout == Layout::Exports);
    is_followable_name(path) || (exports && path.is_dir())
}

/// True when trials in `format` can be written as a growing stream (`acmw
/// follow`'s live rows): followable and writable.
pub fn is_stream_format(format: TrialFormat) -> bool {
    let row = format.row();
    row.followable && row.writable
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_format_has_one_row_in_enum_order() {
        let order = [
            TrialFormat::QuatCsv,
            TrialFormat::EulerCsv,
            TrialFormat::Sto,
            TrialFormat::Xsens,
        ];
        assert_eq!(FORMATS.map(|r| r.format), order);
        for f in order {
            assert_eq!(f.row().format, f);
            assert!(f.output_default().row().writable, "{f:?}");
        }
        assert_eq!(TrialFormat::Xsens.extension(), "sto");
        assert_eq!(TrialFormat::EulerCsv.extension(), "csv");
    }

    #[test]
    fn names_tell_the_holder() {
        let h = |p: &str| holder(Path::new(p)).ok();
        let text = |kind, gzip| Some(Holder::Text { kind, gzip });
        assert_eq!(h("a/Walk.CSV.gz"), text(Kind::Csv, true));
        assert_eq!(h("w.sto"), text(Kind::Sto, false));
        assert_eq!(h("m.XML"), Some(Holder::Exports));
        assert_eq!(h("s_00B4.txt"), Some(Holder::Exports));
        assert_eq!(h(".csv"), None);
        assert_eq!(h("x.dat"), None);
        assert!(could_name_trial(Path::new("gone.txt")));
        assert!(could_name_trial(Path::new("gone.sto.gz")));
        assert!(!could_name_trial(Path::new("gone.truth.csv")));
        assert!(is_followable_name(Path::new("live.csv")));
        assert!(!is_followable_name(Path::new("live.csv.gz")));
        assert!(!is_followable_name(Path::new("live.sto")));
        let dir = std::env::temp_dir();
        assert!(is_followable(&dir) && !is_followable_name(&dir));
        assert!(is_followable(Path::new("live.csv")));
        assert!(!is_followable(Path::new("m.xml")));
        assert!(is_stream_format(TrialFormat::QuatCsv) && is_stream_format(TrialFormat::EulerCsv));
        assert!(!is_stream_format(TrialFormat::Xsens) && !is_stream_format(TrialFormat::Sto));
    }
}
