//! Reading and writing trial files.
//!
//! Formats (see [`TrialFormat`]):
//!
//! * canonical CSV: `time,<imu>_qw,<imu>_qx,<imu>_qy,<imu>_qz,...`, time in seconds,
//!   quaternions scalar first, `G_R_imu`;
//! * Euler CSV (CHR-UM6): `time,<imu>_roll,<imu>_pitch,<imu>_yaw,...` in degrees,
//!   orientation `Rz(yaw) * Ry(pitch) * Rx(roll)`;
//! * OpenSim `.sto` (OpenSense): `key=value` header lines up to `endheader`, a
//!   tab-separated label line `time<TAB><imu>...`, then rows of time and one
//!   `w,x,y,z` cell per IMU;
//! * any of these gzip-compressed, when the name ends in `.gz`.
//!
//! Both CSV formats may also carry gyroscope readings: per IMU the three
//! columns `<imu>_gx,<imu>_gy,<imu>_gz`, angular rate in rad/s in the sensor
//! frame (all three or none; anywhere after `time`, written right after the
//! IMU's orientation columns). `.sto` files have none; writing a trial with
//! gyros to `.sto` leaves them out.
//!
//! `.csv` files are told apart by their header (`_qw` vs `_roll/_pitch/_yaw`).
//! IMU names are mapped to canonical names with [`Model::canonical_imu`]; IMUs the
//! model does not know are kept under the name found, with a warning.

use super::format::{holder, kind_of_name, Holder, Kind};
use super::{Trial, TrialError, TrialFormat};
use crate::model::Model;
use crate::rotation::{canonical, euler_zyx_deg};
use std::fmt::Write as _;
use std::io::{BufRead, BufReader, Read, Write as _};
use std::path::{Path, PathBuf};

mod file;
pub(crate) mod number;
pub(crate) mod parse;

use super::precision::{push_fixed, AngleNumbers, Fixed, Precision};
pub use file::TrialFile;
use number::push_f64;
use parse::{classify_csv_header, first_header, parse_header, parse_trial, LineIter};

/// A cheap look at a trial file: its format and IMUs, without the samples.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TrialHeader {
    pub format: TrialFormat,
    /// Whether the file is gzip-compressed.
    pub gzip: bool,
    /// Canonical names of the IMUs the model knows, in file order.
    pub imus: Vec<String>,
    /// IMUs the model does not know, as named in the file (the engine ignores them).
    pub unknown_imus: Vec<String>,
}

/// Largest header [`read_trial_header`] and [`detect_format`] read before giving up.
const HEAD_LIMIT: usize = 4 << 20;

fn origin_of(path: &Path) -> String {
    path.display().to_string()
}

fn name_of(origin: &str) -> String {
    Path::new(origin)
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| origin.to_string())
}

/// What holds the trial at `path`: `None` for Xsens exports (a folder, an
/// `.xml` mapping, a `.txt` export, or a `.csv` that starts like an MT
/// Manager export: this one looks at the file's first bytes), else the text
/// file's kind and compression.
fn text_kind(path: &Path) -> Result<Option<(Kind, bool)>, TrialError> {
    Ok(match holder(path)? {
        Holder::Exports => None,
        Holder::Text { kind, gzip }
            if kind == Kind::Csv && !gzip && super::xsens_trial::is_export_file(path) =>
        {
            None
        }
        Holder::Text { kind, gzip } => Some((kind, gzip)),
    })
}

/// True when `path` is a trial the workbench lists: a trial file
/// ([`is_trial_file`]), an OpenSense mapping XML, or a folder of Xsens exports.
pub fn is_trial_path(path: &Path) -> bool {
    use super::xsens_trial::{is_export_file, is_export_folder, is_mapping_file};
    if path.is_dir() {
        is_export_folder(path)
    } else {
        is_trial_file(path) || is_mapping_file(path) || is_export_file(path)
    }
}

/// The trials in folder `dir` (not recursive), in no particular order: trial
/// files, OpenSense mapping XMLs, and folders of Xsens exports that no listed
/// mapping reads (a mapping's folder is its trial, not a second one).
pub fn folder_trials(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    use super::xsens_trial::{is_mapping_file, resolve};
    let paths: Vec<PathBuf> = std::fs::read_dir(dir)?
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| is_trial_path(p))
        .collect();
    let read_by_mapping: Vec<PathBuf> = paths
        .iter()
        .filter(|p| p.is_file() && is_mapping_file(p))
        .filter_map(|xml| resolve(xml).ok())
        .flat_map(|s| {
            s.files
                .into_iter()
                .filter_map(|(f, _)| f.parent().map(Path::to_path_buf))
        })
        .collect();
    Ok(paths
        .into_iter()
        .filter(|p| !(p.is_dir() && read_by_mapping.contains(p)))
        .collect())
}

/// True when `path`'s name is a trial file: it ends in `.csv`, `.sto`, `.csv.gz` or
/// `.sto.gz` and is not a truth file (`*.truth.csv`, `*.truth.sto`, optionally `.gz`)
/// nor an optical reference (`*.reference.csv`).
/// Sidecars (`.json`), backups (`.bak`), temporary files and calibration
/// recordings (`*.calib.csv`, see [`crate::file_names::is_calibration_recording`])
/// never qualify.
pub fn is_trial_file(path: &Path) -> bool {
    if crate::file_names::is_calibration_recording(path) {
        return false;
    }
    let Some(name) = path.file_name() else {
        return false;
    };
    let name = name.to_string_lossy().to_ascii_lowercase();
    let stem = name.strip_suffix(".gz").unwrap_or(&name);
    // Truths and optical references (`<trial>.reference.csv`) sit beside trials.
    if stem.ends_with(".truth.csv")
        || stem.ends_with(".truth.sto")
        || stem.ends_with(".reference.csv")
    {
        return false;
    }
    kind_of_name(path).is_some()
}

fn cannot_read(origin: &str, e: std::io::Error) -> TrialError {
    TrialError::file(origin, format!("cannot read: {e}"))
}

fn bad_gzip(origin: &str, e: std::io::Error) -> TrialError {
    TrialError::file(
        origin,
        format!(
            "invalid gzip data ({e}): expected a gzip-compressed file, as the name ends in .gz"
        ),
    )
}

/// Turns decompressed bytes into text, locating invalid UTF-8 by line and field.
fn to_text(bytes: Vec<u8>, origin: &str, kind: Kind, gzip: bool) -> Result<String, TrialError> {
    if !gzip && bytes.starts_with(&[0x1f, 0x8b]) {
        return Err(TrialError::at(
            origin,
            1,
            1,
            "expected text, found gzip-compressed data (name the file *.gz to read it)",
        ));
    }
    String::from_utf8(bytes).map_err(|e| {
        let bytes = e.as_bytes();
        let at = e.utf8_error().valid_up_to().min(bytes.len());
        let before = &bytes[..at];
        let line = before.iter().filter(|&&b| b == b'\n').count() as u64 + 1;
        let start = before
            .iter()
            .rposition(|&b| b == b'\n')
            .map_or(0, |i| i + 1);
        let sep = if kind == Kind::Sto { b'\t' } else { b',' };
        let column = before[start..].iter().filter(|&&b| b == sep).count() + 1;
        TrialError::at(
            origin,
            line,
            column,
            format!(
                "expected UTF-8 text, found invalid byte 0x{:02x}",
                bytes[at.min(bytes.len().saturating_sub(1))]
            ),
        )
    })
}

/// Reads only the header lines: for CSV the first non-blank line, for `.sto` up to
/// the first non-blank line after `endheader`.
fn read_head(path: &Path, kind: Kind, gzip: bool) -> Result<String, TrialError> {
    let origin = origin_of(path);
    let file = crate::input::open_regular(path).map_err(|e| cannot_read(&origin, e))?;
    let mut reader: Box<dyn BufRead> = if gzip {
        Box::new(BufReader::new(flate2::read::MultiGzDecoder::new(
            BufReader::new(file),
        )))
    } else {
        Box::new(BufReader::new(file))
    };
    let mut buf = Vec::new();
    let mut ended = kind == Kind::Csv;
    loop {
        let start = buf.len();
        let n = reader
            .by_ref()
            .take((HEAD_LIMIT - start.min(HEAD_LIMIT)) as u64)
            .read_until(b'\n', &mut buf)
            .map_err(|e| {
                if gzip {
                    bad_gzip(&origin, e)
                } else {
                    cannot_read(&origin, e)
                }
            })?;
        if n == 0 || buf.len() >= HEAD_LIMIT {
            break;
        }
        let line = buf[start..].trim_ascii();
        if line.is_empty() || (kind == Kind::Csv && line.starts_with(b"#")) {
            continue;
        }
        if ended {
            break;
        }
        if line.eq_ignore_ascii_case(b"endheader") {
            ended = true;
        }
    }
    to_text(buf, &origin, kind, gzip)
}

/// Format and compression of a trial file: `*.csv` is [`TrialFormat::QuatCsv`] or
/// [`TrialFormat::EulerCsv`] as its header says (`_qw` columns vs
/// `_roll/_pitch/_yaw`), `*.sto` is [`TrialFormat::Sto`]; each optionally `.gz`.
/// Reads only the first line of a CSV file.
pub fn detect_format(path: &Path) -> Result<(TrialFormat, bool), TrialError> {
    match text_kind(path)? {
        None => Ok((TrialFormat::Xsens, false)),
        Some((Kind::Sto, gzip)) => Ok((TrialFormat::Sto, gzip)),
        Some((Kind::Csv, gzip)) => {
            let head = read_head(path, Kind::Csv, gzip)?;
            match first_header(&head) {
                Some(h) => Ok((classify_csv_header(h), gzip)),
                None => Err(TrialError::at(
                    origin_of(path),
                    1,
                    1,
                    "empty file: expected a header line starting with 'time'",
                )),
            }
        }
    }
}

/// Reads a trial ([`TrialFile::read`], then [`TrialFile::trial`]): the
/// format from the file name (`.csv`, `.sto`, optionally `.gz`; Xsens
/// exports) and, for CSV, the header. `Trial::name` is the file name.
pub fn read_trial(path: &Path, model: &Model) -> Result<Trial, TrialError> {
    TrialFile::read(path)?.trial(model)
}

/// Reads a trial from text in `format`; `origin` names the file in errors, and its
/// last path component becomes `Trial::name`.
pub fn read_trial_from_str(
    text: &str,
    origin: &str,
    format: TrialFormat,
    model: &Model,
) -> Result<Trial, TrialError> {
    parse_trial(text, origin, &name_of(origin), format, model)
}

/// Reads the data rows `rows` of a canonical or Euler CSV whose header (any
/// `#` comment lines and the column header) is `header`, as [`read_trial`]
/// reads them: the same columns, numbers and errors. `first_line` is the
/// 1-based line of the file `rows` starts at, for located errors. Times must
/// increase within `rows`; the checks of a whole trial's time axis (rate,
/// span) are left to the caller, who sees the rows before and after.
/// `rows` must hold at least one data row.
pub fn read_rows_from_str(
    header: &str,
    rows: &str,
    first_line: u64,
    origin: &str,
    model: &Model,
) -> Result<Trial, TrialError> {
    let format = first_header(header).map_or(TrialFormat::QuatCsv, classify_csv_header);
    let layout = parse_header(&mut LineIter::new(header), origin, format, model)?;
    parse::parse_rows(
        LineIter::starting_at(rows, first_line),
        layout,
        origin,
        &name_of(origin),
        format,
        false,
    )
}

/// The format of a CSV trial from its header line: canonical (`<imu>_qw`...)
/// or Euler (`<imu>_roll`...).
pub fn csv_format_of_header(header_line: &str) -> TrialFormat {
    classify_csv_header(header_line)
}

/// Reads only the header of a trial file: format, compression and IMU names.
/// The header is checked as [`read_trial`] would check it.
pub fn read_trial_header(path: &Path, model: &Model) -> Result<TrialHeader, TrialError> {
    TrialHead::read(path)?.header(model)
}

/// An Xsens trial's header: its sensor names as `model` knows them.
fn xsens_header(names: &[String], model: &Model) -> TrialHeader {
    let (known, unknown): (Vec<&String>, Vec<&String>) =
        names.iter().partition(|n| model.canonical_imu(n).is_some());
    TrialHeader {
        format: TrialFormat::Xsens,
        gzip: false,
        imus: known
            .iter()
            .filter_map(|n| model.canonical_imu(n).map(str::to_string))
            .collect(),
        unknown_imus: unknown.into_iter().cloned().collect(),
    }
}

/// The header lines of a trial, read once from disk, to be interpreted with
/// any number of models ([`TrialHead::header`]).
#[derive(Debug, Clone)]
pub struct TrialHead {
    origin: String,
    gzip: bool,
    lines: HeadLines,
}

#[derive(Debug, Clone)]
enum HeadLines {
    /// A CSV or `.sto` file's header lines, in the format they belong to.
    Text(TrialFormat, String),
    /// The sensor names of an Xsens trial (mapping or folder of exports).
    Xsens(Vec<String>),
}

impl TrialHead {
    /// Reads the header of the trial at `path` (the first lines only).
    pub fn read(path: &Path) -> Result<TrialHead, TrialError> {
        let origin = origin_of(path);
        let Some((kind, gzip)) = text_kind(path)? else {
            let names = super::xsens_trial::imu_names(path)?;
            return Ok(TrialHead::of_exports(origin, names));
        };
        let head = read_head(path, kind, gzip)?;
        let format = match kind {
            Kind::Sto => TrialFormat::Sto,
            Kind::Csv => first_header(&head).map_or(TrialFormat::QuatCsv, classify_csv_header),
        };
        Ok(TrialHead::of_text(origin, gzip, format, &head))
    }

    /// The header lines `head` of a CSV or `.sto` file in `format`.
    fn of_text(origin: String, gzip: bool, format: TrialFormat, head: &str) -> TrialHead {
        TrialHead {
            origin,
            gzip,
            lines: HeadLines::Text(format, head.to_string()),
        }
    }

    /// The sensor names (before aliases) of a trial of Xsens exports.
    fn of_exports(origin: String, names: Vec<String>) -> TrialHead {
        TrialHead {
            origin,
            gzip: false,
            lines: HeadLines::Xsens(names),
        }
    }

    /// The trial's format.
    pub fn format(&self) -> TrialFormat {
        match &self.lines {
            HeadLines::Text(format, _) => *format,
            HeadLines::Xsens(_) => TrialFormat::Xsens,
        }
    }

    /// Whether the file is gzip-compressed.
    pub fn gzip(&self) -> bool {
        self.gzip
    }

    /// The built-in model that fits the trial best (from its header only):
    /// the one that recognises most of its IMUs, and among those the one
    /// with fewest IMUs the trial lacks (so an 8-sensor OpenSense trial gets
    /// `opensense_lower`, not the 12-IMU `opensim`); the first built-in model
    /// when none recognises any.
    pub fn detect_model(&self) -> Model {
        super::best_model(Some(self))
    }

    /// The header as `model` names its IMUs, checked as [`read_trial`] would check it.
    pub fn header(&self, model: &Model) -> Result<TrialHeader, TrialError> {
        let (format, head) = match &self.lines {
            HeadLines::Xsens(names) => return Ok(xsens_header(names, model)),
            HeadLines::Text(format, head) => (*format, head),
        };
        let layout = parse_header(&mut LineIter::new(head), &self.origin, format, model)?;
        let (known, unknown): (Vec<_>, Vec<_>) = layout.imus.into_iter().partition(|c| c.known);
        Ok(TrialHeader {
            format,
            gzip: self.gzip,
            imus: known.into_iter().map(|c| c.name).collect(),
            unknown_imus: unknown.into_iter().map(|c| c.found).collect(),
        })
    }
}

/// Writes a trial in `format`; gzip-compressed when the path ends in `.gz`.
/// Orientation numbers are written with the decimals they were read with
/// ([`Precision::Auto`]). Atomic, keeping the previous file as `<name>.bak`
/// ([`crate::save::atomic_write`]).
pub fn write_trial(
    trial: &Trial,
    path: &Path,
    format: TrialFormat,
) -> Result<(), crate::save::WriteError> {
    write_trial_hashed(trial, path, format, Precision::Auto).map(|_| ())
}

/// [`write_trial`] with orientation numbers at `precision`, returning the
/// SHA-256 (hex) of the bytes written (the file as stored, compressed when
/// gzip), hashed from memory as they go to disk rather than read back.
pub fn write_trial_hashed(
    trial: &Trial,
    path: &Path,
    format: TrialFormat,
    precision: Precision,
) -> Result<String, crate::save::WriteError> {
    let origin = origin_of(path);
    let refused = |message: String| crate::save::WriteError {
        path: origin.clone(),
        message,
    };
    if !format.row().writable {
        let writable: Vec<&str> = (super::format::FORMATS.iter())
            .filter(|r| r.writable)
            .map(|r| r.name)
            .collect();
        return Err(refused(format!(
            "cannot write {}: expected {}",
            format.row().help,
            writable.join(", ")
        )));
    }
    if let Some(bad) = trial.imus.iter().find(|s| {
        s.gyro
            .as_ref()
            .is_some_and(|g| g.len() != trial.time_s.len())
    }) {
        return Err(refused(format!(
            "cannot write: IMU '{}' has {} gyroscope readings, expected one per time ({})",
            bad.name,
            bad.gyro.as_ref().map_or(0, Vec::len),
            trial.time_s.len()
        )));
    }
    if let Some(bad) = trial
        .imus
        .iter()
        .find(|s| s.orientation.len() != trial.time_s.len())
    {
        return Err(refused(format!(
            "cannot write: IMU '{}' has {} samples, expected one per time ({})",
            bad.name,
            bad.orientation.len(),
            trial.time_s.len()
        )));
    }
    let gzip = match kind_of_name(path) {
        Some((_, gz)) => gz,
        None => path.to_string_lossy().to_ascii_lowercase().ends_with(".gz"),
    };
    let named = kind_of_name(path).map(|(k, _)| if k == Kind::Sto { "sto" } else { "csv" });
    if named.is_some_and(|ext| ext != format.extension()) {
        return Err(refused(format!(
            "cannot write {format:?} to this file name: expected a name ending in .{}",
            format.extension()
        )));
    }
    let text = trial_to_string_at(trial, format, precision);
    let bytes = if gzip {
        let mut enc = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
        enc.write_all(text.as_bytes())
            .and_then(|_| enc.finish())
            .map_err(|e| refused(format!("cannot compress: {e}")))?
    } else {
        text.into_bytes()
    };
    // Hashed on one worker while the other writes (and flushes) the file.
    let (sha256, written) = rayon::join(
        || crate::input::sha256_hex(&bytes),
        || crate::save::atomic_write(path, &bytes),
    );
    written.map_err(|e| crate::save::WriteError::io(path, &e))?;
    Ok(sha256)
}

/// Appends `first` then the numbers of `values` separated by `sep`, each as
/// `{}` writes it ([`push_f64`]), or in fixed notation with `style`.
#[inline]
fn push_cells(out: &mut String, first: char, sep: char, values: &[f64], style: Option<Fixed>) {
    for (k, &v) in values.iter().enumerate() {
        out.push(if k == 0 { first } else { sep });
        match style {
            Some(style) => push_fixed(out, v, style),
            None => push_f64(out, v),
        }
    }
}

/// Rows formatted in one part: the parts are the same at any thread count.
const ROWS_PER_PART: usize = 1024;

/// Appends rows `0..n` to `out`, each written by `row`: parts of
/// [`ROWS_PER_PART`] rows formatted in parallel, appended in order (the
/// same text as one pass). `per_row`: the bytes a row is expected to take.
fn rows_in_parts(
    out: &mut String,
    n: usize,
    per_row: usize,
    row: impl Fn(&mut String, usize) + Sync,
) {
    use rayon::prelude::*;
    if n <= ROWS_PER_PART {
        (0..n).for_each(|i| row(out, i));
        return;
    }
    let parts: Vec<String> = (0..n.div_ceil(ROWS_PER_PART))
        .into_par_iter()
        .map(|p| {
            let rows = p * ROWS_PER_PART..((p + 1) * ROWS_PER_PART).min(n);
            let mut part = String::with_capacity(rows.len() * per_row);
            rows.for_each(|i| row(&mut part, i));
            part
        })
        .collect();
    out.reserve(parts.iter().map(String::len).sum());
    parts.iter().for_each(|p| out.push_str(p));
}

/// The text of a trial in `format` (uncompressed), orientation numbers with
/// the decimals they were read with ([`trial_to_string_at`] with
/// [`Precision::Auto`]).
pub fn trial_to_string(trial: &Trial, format: TrialFormat) -> String {
    trial_to_string_at(trial, format, Precision::Auto)
}

/// The text of a trial in `format` (uncompressed). Orientation numbers
/// (quaternion components, Euler angles) are written at `precision`
/// against the trial's [`Trial::orientation_decimals`]
/// ([`Precision::style`]); times and gyroscope readings, and orientations
/// at full precision, in Rust's shortest round-trip formatting.
/// Quaternions are written with `w >= 0`. In the CSV formats an IMU's
/// gyroscope readings, when it has them, follow its orientation columns as
/// `<imu>_gx,<imu>_gy,<imu>_gz` (rad/s, sensor frame); `.sto` has no place
/// for them.
pub fn trial_to_string_at(trial: &Trial, format: TrialFormat, precision: Precision) -> String {
    let numbers = AngleNumbers::written_in(format);
    let style = precision.style(trial.orientation_decimals, numbers);
    let n = trial
        .imus
        .iter()
        .flat_map(|s| std::iter::once(s.orientation.len()).chain(s.gyro.as_ref().map(Vec::len)))
        .fold(trial.time_s.len(), usize::min);
    let per_row = 12 + trial.imus.len() * 4 * 22;
    let mut out = String::with_capacity(256 + n * per_row);
    // Writing into a String cannot fail.
    match format {
        TrialFormat::QuatCsv | TrialFormat::EulerCsv => {
            let suffixes: &[&str] = if format == TrialFormat::QuatCsv {
                &["qw", "qx", "qy", "qz"]
            } else {
                &["roll", "pitch", "yaw"]
            };
            out.push_str("time");
            for s in &trial.imus {
                for suf in suffixes {
                    let _ = write!(out, ",{}_{suf}", s.name);
                }
                if s.gyro.is_some() {
                    for suf in parse::GYRO_SUFFIXES {
                        let _ = write!(out, ",{}_{suf}", s.name);
                    }
                }
            }
            out.push('\n');
            rows_in_parts(&mut out, n, per_row, |out, i| {
                push_f64(out, trial.time_s[i]);
                for s in &trial.imus {
                    let q = &s.orientation[i];
                    if format == TrialFormat::QuatCsv {
                        let q = canonical(q);
                        push_cells(out, ',', ',', &[q.w, q.i, q.j, q.k], style);
                    } else {
                        push_cells(out, ',', ',', &euler_zyx_deg(q), style);
                    }
                    if let Some(g) = &s.gyro {
                        let w = &g[i];
                        push_cells(out, ',', ',', &[w.x, w.y, w.z], None);
                    }
                }
                out.push('\n');
            });
        }
        TrialFormat::Sto | TrialFormat::Xsens => {
            let _ = write!(
                out,
                "\nDataRate={:.6}\nDataType=Quaternion\nversion=3\nOpenSimVersion=4.1\nendheader\ntime",
                trial.rate_hz()
            );
            for s in &trial.imus {
                let _ = write!(out, "\t{}", s.name);
            }
            out.push('\n');
            rows_in_parts(&mut out, n, per_row, |out, i| {
                push_f64(out, trial.time_s[i]);
                for s in &trial.imus {
                    let q = canonical(&s.orientation[i]);
                    push_cells(out, '\t', ',', &[q.w, q.i, q.j, q.k], style);
                }
                out.push('\n');
            });
        }
    }
    out
}

#[cfg(test)]
mod tests;
