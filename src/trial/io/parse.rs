//! Parsers of the three text formats (already decompressed and decoded).
//!
//! Every problem becomes a [`TrialError`] with the 1-based line and column
//! (field index) and what was expected; nothing here panics on any input.

use super::number::parse_f64;
use crate::model::Model;
use crate::rotation::{quat_from_euler_zyx_deg, Quat};
use crate::trial::precision::{AngleNumbers, Tally};
use crate::trial::{ImuSeries, Trial, TrialError, TrialFormat};
use nalgebra::{Quaternion, Vector3};

/// A quaternion whose norm is further than this from 1 is an error.
pub(crate) const NORM_TOLERANCE: f64 = 0.01;
/// Quaternions off unit norm by more than this (but within [`NORM_TOLERANCE`]) are
/// counted in the renormalisation warning. Smaller deviations come from printing
/// with few digits (four decimals stay within 1e-4) and are normalised silently.
pub(crate) const NORM_NOTE: f64 = 1e-4;

/// Lines of a text with 1-based numbers, `\r\n` or `\n` endings.
#[derive(Clone)]
pub(crate) struct LineIter<'a> {
    rest: Option<&'a str>,
    line_no: u64,
}

impl<'a> LineIter<'a> {
    pub(crate) fn new(text: &'a str) -> Self {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        LineIter {
            rest: Some(text),
            line_no: 0,
        }
    }

    /// Lines of a part of a file whose first line is line `first` (1-based).
    pub(crate) fn starting_at(text: &'a str, first: u64) -> Self {
        LineIter {
            rest: Some(text),
            line_no: first.saturating_sub(1),
        }
    }

    /// Number of the last line returned (0 before the first).
    pub(crate) fn line_no(&self) -> u64 {
        self.line_no
    }

    /// The next non-blank line.
    pub(crate) fn next_nonblank(&mut self) -> Option<(u64, &'a str)> {
        self.find(|(_, l)| !l.trim().is_empty())
    }

    /// The next line that is neither blank nor a `#` comment (a CSV header).
    pub(crate) fn next_header(&mut self) -> Option<(u64, &'a str)> {
        self.find(|(_, l)| {
            let t = l.trim();
            !t.is_empty() && !t.starts_with('#')
        })
    }
}

impl<'a> Iterator for LineIter<'a> {
    type Item = (u64, &'a str);

    fn next(&mut self) -> Option<(u64, &'a str)> {
        let rest = self.rest?;
        let (line, next) = match rest.find('\n') {
            Some(i) => (&rest[..i], Some(&rest[i + 1..])),
            None => (rest, None),
        };
        if next.is_none() && line.is_empty() {
            // Text ending in a newline has no further (empty) line.
            self.rest = None;
            return None;
        }
        self.rest = next;
        self.line_no += 1;
        Some((self.line_no, line.strip_suffix('\r').unwrap_or(line)))
    }
}

/// Quotes text found in a file for a message: at most 40 characters, escaped.
pub(crate) fn show(s: &str) -> String {
    let mut out: String = s.chars().take(40).collect();
    if out.len() < s.len() {
        out.push_str("...");
    }
    format!("'{}'", out.escape_debug())
}

/// One IMU's columns as laid out in the file.
#[derive(Debug, Clone)]
pub(crate) struct ImuCol {
    /// The name as written in the file.
    pub found: String,
    /// Canonical name when the model knows it, else the name as found.
    pub name: String,
    /// Whether the model knows this IMU.
    pub known: bool,
    /// 0-based index of its first field.
    pub first_field: usize,
    /// 0-based indices of its gyroscope columns `<imu>_gx,<imu>_gy,<imu>_gz`
    /// (rad/s, sensor frame), when the header has them (CSV only).
    pub gyro: Option<[usize; 3]>,
}

/// What the header says: columns, IMUs, and where the data starts.
#[derive(Debug, Clone)]
pub(crate) struct Layout {
    /// Header fields as found (trimmed); index 0 is `time`.
    pub columns: Vec<String>,
    pub imus: Vec<ImuCol>,
    /// Line of the column header.
    pub header_line: u64,
    /// Notes about the header (IMUs not in the model).
    pub warnings: Vec<String>,
}

const QUAT_SUFFIXES: [&str; 4] = ["qw", "qx", "qy", "qz"];
const EULER_SUFFIXES: [&str; 3] = ["roll", "pitch", "yaw"];
/// Suffixes of the optional gyroscope columns (rad/s, sensor frame).
pub(crate) const GYRO_SUFFIXES: [&str; 3] = ["gx", "gy", "gz"];

/// `(imu, axis)` of a gyroscope column `<imu>_gx|gy|gz` (axis 0, 1, 2).
fn gyro_column(field: &str) -> Option<(&str, usize)> {
    let (prefix, suffix) = split_suffix(field)?;
    let axis = GYRO_SUFFIXES
        .iter()
        .position(|s| suffix.eq_ignore_ascii_case(s))?;
    (!prefix.is_empty()).then_some((prefix, axis))
}

fn split_suffix(field: &str) -> Option<(&str, &str)> {
    let i = field.rfind('_')?;
    Some((&field[..i], &field[i + 1..]))
}

/// Decides quaternion vs Euler CSV from a header line: the first column named
/// `<imu>_q{w,x,y,z}` or `<imu>_{roll,pitch,yaw}` decides; quaternions when none does.
pub(crate) fn classify_csv_header(header: &str) -> TrialFormat {
    for field in header.split(',').skip(1) {
        if let Some((_, suffix)) = split_suffix(field.trim()) {
            if QUAT_SUFFIXES.iter().any(|s| suffix.eq_ignore_ascii_case(s)) {
                return TrialFormat::QuatCsv;
            }
            if EULER_SUFFIXES
                .iter()
                .any(|s| suffix.eq_ignore_ascii_case(s))
            {
                return TrialFormat::EulerCsv;
            }
        }
    }
    TrialFormat::QuatCsv
}

/// The first line of `text` that is neither blank nor a `#` comment (the CSV
/// header), if any.
pub(crate) fn first_header(text: &str) -> Option<&str> {
    LineIter::new(text).next_header().map(|(_, l)| l)
}

fn empty_file(origin: &str, format: TrialFormat) -> TrialError {
    let what = match format {
        TrialFormat::QuatCsv => "a header line 'time,<imu>_qw,<imu>_qx,<imu>_qy,<imu>_qz,...'",
        TrialFormat::EulerCsv => "a header line 'time,<imu>_roll,<imu>_pitch,<imu>_yaw,...'",
        TrialFormat::Sto => "an OpenSim .sto header (DataRate=..., DataType=Quaternion, endheader)",
        TrialFormat::Xsens => "an Xsens MT Manager export (read through its folder or mapping XML)",
    };
    TrialError::at(origin, 1, 1, format!("empty file: expected {what}"))
}

/// Checks the first label is `time` (or `time_s`, seconds either way) and there
/// is at least one more.
fn check_time_and_count(
    origin: &str,
    line: u64,
    labels: &[String],
    what: &str,
) -> Result<(), TrialError> {
    let first = labels.first().map(String::as_str).unwrap_or("");
    if !(first.eq_ignore_ascii_case("time") || first.eq_ignore_ascii_case("time_s")) {
        return Err(TrialError::at(
            origin,
            line,
            1,
            format!(
                "expected the first column to be 'time', found {} ('time_s' is accepted too; seconds)",
                show(first)
            ),
        ));
    }
    if labels.len() < 2 {
        return Err(TrialError::at(
            origin,
            line,
            2,
            format!("no IMU columns: expected {what} after 'time'"),
        ));
    }
    Ok(())
}

/// Maps IMU names to the model, rejecting repeats, noting unknown ones.
fn resolve_imus(
    origin: &str,
    line: u64,
    model: &Model,
    found: Vec<(String, usize)>,
    warnings: &mut Vec<String>,
) -> Result<Vec<ImuCol>, TrialError> {
    let mut imus: Vec<ImuCol> = Vec::with_capacity(found.len());
    for (name_found, field) in found {
        let (name, known) = match model.canonical_imu(&name_found) {
            Some(c) => (c.to_string(), true),
            None => (name_found.clone(), false),
        };
        if let Some(prev) = imus.iter().find(|c| c.name == name) {
            let also = if prev.found == name_found {
                String::new()
            } else {
                format!(" (as {})", show(&prev.found))
            };
            return Err(TrialError::at(
                origin,
                line,
                field + 1,
                format!(
                    "repeated IMU: {} is {}, already in column {}{also}; expected each IMU once",
                    show(&name_found),
                    show(&name),
                    prev.first_field + 1
                ),
            ));
        }
        if !known {
            warnings.push(format!(
                "IMU {} (column {}) is not in model {} and will be ignored",
                show(&name_found),
                field + 1,
                model.name
            ));
        }
        imus.push(ImuCol {
            found: name_found,
            name,
            known,
            first_field: field,
            gyro: None,
        });
    }
    Ok(imus)
}

/// Parses a CSV header (quaternion or Euler) from the next non-blank line.
pub(crate) fn parse_csv_header(
    lines: &mut LineIter<'_>,
    origin: &str,
    format: TrialFormat,
    model: &Model,
) -> Result<Layout, TrialError> {
    let (line, text) = lines
        .next_header()
        .ok_or_else(|| empty_file(origin, format))?;
    let suffixes: &[&str] = if format == TrialFormat::EulerCsv {
        &EULER_SUFFIXES
    } else {
        &QUAT_SUFFIXES
    };
    let columns: Vec<String> = text.split(',').map(|f| f.trim().to_string()).collect();
    let pattern = suffixes
        .iter()
        .map(|s| format!("<imu>_{s}"))
        .collect::<Vec<_>>()
        .join(",");
    check_time_and_count(origin, line, &columns, &pattern)?;
    let mut found = Vec::new();
    let mut gyros = Vec::new();
    let mut k = 1;
    while k < columns.len() {
        let field = &columns[k];
        if let Some((imu, axis)) = gyro_column(field) {
            gyros.push((imu.to_string(), axis, k));
            k += 1;
            continue;
        }
        let prefix = match split_suffix(field) {
            Some((p, s)) if !p.is_empty() && s.eq_ignore_ascii_case(suffixes[0]) => p,
            _ => {
                return Err(TrialError::at(
                    origin,
                    line,
                    k + 1,
                    format!(
                    "expected a column '<imu>_{}' starting an IMU's columns {pattern}, found {}",
                    suffixes[0],
                    show(field)
                ),
                ))
            }
        };
        for (j, s) in suffixes.iter().enumerate().skip(1) {
            let want = format!("{prefix}_{s}");
            let ok = match columns.get(k + j).and_then(|c| split_suffix(c)) {
                Some((p, got)) => p == prefix && got.eq_ignore_ascii_case(s),
                None => false,
            };
            if !ok {
                let got = match columns.get(k + j) {
                    Some(c) => show(c),
                    None => "the end of the header line".to_string(),
                };
                return Err(TrialError::at(
                    origin,
                    line,
                    k + j + 1,
                    format!(
                        "expected column {} after {} (each IMU has columns {pattern} in this order), found {got}",
                        show(&want),
                        show(&columns[k + j - 1]),
                    ),
                ));
            }
        }
        found.push((prefix.to_string(), k));
        k += suffixes.len();
    }
    if found.is_empty() {
        return Err(TrialError::at(
            origin,
            line,
            2,
            format!("no orientation columns: expected {pattern} for each IMU (gyroscope columns <imu>_gx,<imu>_gy,<imu>_gz come with them)"),
        ));
    }
    let mut warnings = Vec::new();
    let mut imus = resolve_imus(origin, line, model, found, &mut warnings)?;
    attach_gyros(origin, line, model, &columns, &mut imus, gyros)?;
    Ok(Layout {
        columns,
        imus,
        header_line: line,
        warnings,
    })
}

/// Gives each IMU its gyroscope columns `(imu, axis, field)`: each names an IMU
/// with orientation columns (as written or through the model's aliases), no
/// axis twice, all three axes or none.
fn attach_gyros(
    origin: &str,
    line: u64,
    model: &Model,
    columns: &[String],
    imus: &mut [ImuCol],
    gyros: Vec<(String, usize, usize)>,
) -> Result<(), TrialError> {
    let mut partial: Vec<[Option<usize>; 3]> = vec![[None; 3]; imus.len()];
    for (imu, axis, field) in gyros {
        let canonical = model.canonical_imu(&imu).unwrap_or(&imu);
        let Some(k) = imus
            .iter()
            .position(|c| c.found == imu || c.name == canonical)
        else {
            return Err(TrialError::at(
                origin,
                line,
                field + 1,
                format!(
                    "gyroscope column {} names IMU {}, which has no orientation columns; expected gyroscope columns only for IMUs of the file",
                    show(&columns[field]),
                    show(&imu)
                ),
            ));
        };
        if let Some(prev) = partial[k][axis] {
            return Err(TrialError::at(
                origin,
                line,
                field + 1,
                format!(
                    "repeated gyroscope column {} (already column {} {}); expected each of <imu>_gx,<imu>_gy,<imu>_gz once",
                    show(&columns[field]),
                    prev + 1,
                    show(&columns[prev])
                ),
            ));
        }
        partial[k][axis] = Some(field);
    }
    for (c, p) in imus.iter_mut().zip(partial) {
        match p {
            [Some(x), Some(y), Some(z)] => c.gyro = Some([x, y, z]),
            [None, None, None] => {}
            _ => {
                let first = p.iter().flatten().min().copied().unwrap_or(0);
                let missing: Vec<String> = GYRO_SUFFIXES
                    .iter()
                    .zip(p)
                    .filter(|(_, f)| f.is_none())
                    .map(|(s, _)| format!("'{}_{s}'", c.found))
                    .collect();
                return Err(TrialError::at(
                    origin,
                    line,
                    first + 1,
                    format!(
                        "incomplete gyroscope columns for {}: missing {}; expected all three of {}_gx,{}_gy,{}_gz (rad/s, sensor frame) or none",
                        show(&c.found),
                        missing.join(" and "),
                        c.found,
                        c.found,
                        c.found
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Parses an OpenSim `.sto` header: `key=value` lines up to `endheader`, then the
/// tab-separated column labels.
pub(crate) fn parse_sto_header(
    lines: &mut LineIter<'_>,
    origin: &str,
    model: &Model,
) -> Result<Layout, TrialError> {
    let mut any = false;
    let mut ended = false;
    for (line, text) in lines.by_ref() {
        let t = text.trim();
        if !t.is_empty() {
            any = true;
        }
        if t.eq_ignore_ascii_case("endheader") {
            ended = true;
            break;
        }
        if let Some((key, value)) = t.split_once('=') {
            if key.trim().eq_ignore_ascii_case("DataType")
                && !value.trim().eq_ignore_ascii_case("Quaternion")
            {
                return Err(TrialError::at(
                    origin,
                    line,
                    1,
                    format!(
                        "expected DataType=Quaternion (an orientation .sto), found DataType={}",
                        show(value.trim())
                    ),
                ));
            }
        }
    }
    if !any {
        return Err(empty_file(origin, TrialFormat::Sto));
    }
    if !ended {
        return Err(TrialError::at(
            origin,
            1,
            1,
            "missing 'endheader': expected an OpenSim .sto header (DataRate=..., DataType=Quaternion, ...) closed by a line 'endheader'",
        ));
    }
    let (line, text) = lines.next_nonblank().ok_or_else(|| {
        TrialError::at(
            origin,
            lines.line_no() + 1,
            1,
            "expected the column labels 'time<TAB><imu><TAB>...' after 'endheader', found the end of the file",
        )
    })?;
    let columns: Vec<String> = text.split('\t').map(|f| f.trim().to_string()).collect();
    check_time_and_count(origin, line, &columns, "tab-separated IMU names")?;
    let mut found = Vec::new();
    for (k, c) in columns.iter().enumerate().skip(1) {
        if c.is_empty() {
            return Err(TrialError::at(
                origin,
                line,
                k + 1,
                "expected an IMU name as column label, found an empty label",
            ));
        }
        if c.contains(',') {
            return Err(TrialError::at(
                origin,
                line,
                k + 1,
                format!(
                    "expected an IMU name as column label (labels are tab-separated), found {}",
                    show(c)
                ),
            ));
        }
        found.push((c.clone(), k));
    }
    let mut warnings = Vec::new();
    let imus = resolve_imus(origin, line, model, found, &mut warnings)?;
    Ok(Layout {
        columns,
        imus,
        header_line: line,
        warnings,
    })
}

/// Parses a header of either kind.
pub(crate) fn parse_header(
    lines: &mut LineIter<'_>,
    origin: &str,
    format: TrialFormat,
    model: &Model,
) -> Result<Layout, TrialError> {
    match format {
        TrialFormat::Sto => parse_sto_header(lines, origin, model),
        _ => parse_csv_header(lines, origin, format, model),
    }
}

/// Per-IMU tally of renormalised samples.
#[derive(Default, Clone)]
struct Renorm {
    count: usize,
    worst_off: f64,
    worst_norm: f64,
    worst_line: u64,
}

/// Samples collected so far, with the checks every row gets.
struct Acc<'a> {
    origin: &'a str,
    time: Vec<f64>,
    last_line: u64,
    /// Line of each sample, to locate time-axis errors.
    lines: Vec<u64>,
    series: Vec<Vec<Quat>>,
    /// Gyroscope readings per IMU (empty for IMUs without gyroscope columns).
    gyro: Vec<Vec<Vector3<f64>>>,
    renorm: Vec<Renorm>,
    /// Decimal places of the orientation numbers read.
    tally: Tally,
    /// What the orientation numbers are.
    numbers: AngleNumbers,
}

impl<'a> Acc<'a> {
    fn new(origin: &'a str, n_imus: usize, numbers: AngleNumbers) -> Self {
        Acc {
            origin,
            time: Vec::new(),
            last_line: 0,
            lines: Vec::new(),
            series: vec![Vec::new(); n_imus],
            gyro: vec![Vec::new(); n_imus],
            renorm: vec![Renorm::default(); n_imus],
            tally: Tally::default(),
            numbers,
        }
    }

    fn push_time(&mut self, t: f64, line: u64) -> Result<(), TrialError> {
        if let Some(&prev) = self.time.last() {
            if t <= prev {
                let what = if t == prev {
                    format!(
                        "repeated time {t} (also on line {}); expected times to strictly increase",
                        self.last_line
                    )
                } else {
                    format!(
                        "time {t} is before the previous time {prev} (line {}); expected times to strictly increase",
                        self.last_line
                    )
                };
                return Err(TrialError::at(self.origin, line, 1, what));
            }
        }
        self.time.push(t);
        self.lines.push(line);
        self.last_line = line;
        Ok(())
    }

    fn push_quat(
        &mut self,
        k: usize,
        q: [f64; 4],
        line: u64,
        column: usize,
        imu: &str,
    ) -> Result<(), TrialError> {
        let n = (q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]).sqrt();
        if n == 0.0 {
            return Err(TrialError::at(
                self.origin,
                line,
                column,
                format!("expected a unit quaternion for {imu}, found the zero quaternion"),
            ));
        }
        let off = (n - 1.0).abs();
        if off.is_nan() || off > NORM_TOLERANCE {
            return Err(TrialError::at(
                self.origin,
                line,
                column,
                format!(
                    "expected a unit quaternion for {imu} (norm within {NORM_TOLERANCE} of 1), found norm {n}"
                ),
            ));
        }
        if off > NORM_NOTE {
            let r = &mut self.renorm[k];
            r.count += 1;
            if off > r.worst_off {
                r.worst_off = off;
                r.worst_norm = n;
                r.worst_line = line;
            }
        }
        self.series[k].push(Quat::new_unchecked(Quaternion::new(
            q[0] / n,
            q[1] / n,
            q[2] / n,
            q[3] / n,
        )));
        Ok(())
    }

    fn finish(
        self,
        name: &str,
        layout: Layout,
        end_line: u64,
        check_axis: bool,
    ) -> Result<Trial, TrialError> {
        if self.time.is_empty() {
            return Err(TrialError::at(
                self.origin,
                end_line,
                1,
                format!(
                    "no samples: expected data rows after the header on line {}",
                    layout.header_line
                ),
            ));
        }
        let axis = if check_axis {
            crate::trial::timing::check_time_axis(&self.time)
        } else {
            Ok(())
        };
        if let Err((i, message)) = axis {
            let line = if i == 0 { self.lines[0] } else { self.lines[i] };
            return Err(TrialError::at(self.origin, line, 1, message));
        }
        let mut warnings = layout.warnings;
        let n = self.time.len();
        for (col, r) in layout.imus.iter().zip(&self.renorm) {
            if r.count > 0 {
                warnings.push(format!(
                    "{}: renormalised {} of {n} quaternions that were off unit norm (worst norm {} on line {})",
                    col.name, r.count, r.worst_norm, r.worst_line
                ));
            }
        }
        let imus = layout
            .imus
            .into_iter()
            .zip(self.series)
            .zip(self.gyro)
            .map(|((c, orientation), gyro)| {
                let gyro = c.gyro.map(|_| gyro);
                ImuSeries::new(c.name, orientation).with_gyro(gyro)
            })
            .collect();
        Ok(Trial {
            name: name.to_string(),
            time_s: self.time,
            imus,
            warnings,
            orientation_decimals: self.tally.finish(self.numbers),
        })
    }
}

/// Parses one number cell; `what` names the column in messages.
#[inline]
fn number(
    cell: &str,
    origin: &str,
    line: u64,
    column: usize,
    what: &str,
) -> Result<f64, TrialError> {
    let t = cell.trim_ascii();
    match parse_f64(t) {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(TrialError::at(
            origin,
            line,
            column,
            format!("expected a finite number for {what}, found {}", show(t)),
        )),
        Err(_) if t.is_empty() => Err(TrialError::at(
            origin,
            line,
            column,
            format!("expected a number for {what}, found an empty cell"),
        )),
        Err(_) => Err(TrialError::at(
            origin,
            line,
            column,
            format!("expected a number for {what}, found {}", show(t)),
        )),
    }
}

/// Replaces `cells` with the fields of `line` separated by the ASCII byte
/// `sep`, in one pass over its bytes; returns their number.
#[inline]
fn split_into<'a>(line: &'a str, sep: u8, cells: &mut Vec<&'a str>) -> usize {
    debug_assert!(sep.is_ascii());
    cells.clear();
    let mut start = 0;
    for (i, &b) in line.as_bytes().iter().enumerate() {
        if b == sep {
            // An ASCII separator is always a character boundary.
            cells.push(&line[start..i]);
            start = i + 1;
        }
    }
    cells.push(&line[start..]);
    cells.len()
}

fn ragged(origin: &str, line: u64, expected: usize, found: usize, unit: &str) -> TrialError {
    let column = if found < expected {
        found + 1
    } else {
        expected + 1
    };
    let how = if found < expected {
        "too few"
    } else {
        "too many"
    };
    TrialError::at(
        origin,
        line,
        column,
        format!("{how} fields: expected {expected} {unit}-separated fields, found {found}"),
    )
}

/// Reads a whole trial from text in `format`.
pub(crate) fn parse_trial(
    text: &str,
    origin: &str,
    name: &str,
    format: TrialFormat,
    model: &Model,
) -> Result<Trial, TrialError> {
    if format == TrialFormat::Xsens {
        return Err(empty_file(origin, format));
    }
    let mut lines = LineIter::new(text);
    let layout = parse_header(&mut lines, origin, format, model)?;
    parse_rows(lines, layout, origin, name, format, true)
}

/// Reads the data rows that follow a parsed header: `lines` continues after
/// the header (its line numbers are the file's). `check_axis`: check the
/// times as a whole trial's ([`crate::trial::timing::check_time_axis`]);
/// without it the rows are only checked to increase.
///
/// Rows of a large text are parsed in parallel parts cut at line ends (the
/// same parts at any thread count) and joined in order; when any part fails,
/// or the times do not increase across a cut, the rows are read again in
/// one pass, which reports the first error in the file as it always has.
pub(crate) fn parse_rows(
    mut lines: LineIter<'_>,
    layout: Layout,
    origin: &str,
    name: &str,
    format: TrialFormat,
    check_axis: bool,
) -> Result<Trial, TrialError> {
    let numbers = if format == TrialFormat::EulerCsv {
        AngleNumbers::EulerDeg
    } else {
        AngleNumbers::Quaternion
    };
    if lines.rest.is_some_and(|r| r.len() >= PARALLEL_FROM_BYTES) {
        if let Some((acc, end)) = parse_parts(&lines, &layout, origin, format, numbers) {
            return acc.finish(name, layout, end + 1, check_axis);
        }
    }
    let mut acc = Acc::new(origin, layout.imus.len(), numbers);
    rows_into(&mut acc, &mut lines, &layout, origin, format)?;
    let end = lines.line_no() + 1;
    acc.finish(name, layout, end, check_axis)
}

/// Texts of data rows at least this long are parsed in parallel parts.
const PARALLEL_FROM_BYTES: usize = 1 << 20;
/// The length a part aims at (it ends at the first line end after it).
pub(crate) const PART_BYTES: usize = 1 << 18;

/// The rows after the header in `lines`, parsed in parts of about
/// [`PART_BYTES`] in parallel and joined in order, with the number of the
/// text's last line; `None` when a part fails or times do not increase
/// across a cut (the caller then reads the rows in one pass).
fn parse_parts<'a>(
    lines: &LineIter<'_>,
    layout: &Layout,
    origin: &'a str,
    format: TrialFormat,
    numbers: AngleNumbers,
) -> Option<(Acc<'a>, u64)> {
    use rayon::prelude::*;
    let text = lines.rest?;
    let bytes = text.as_bytes();
    let mut cuts = vec![0];
    let mut at = 0;
    while at + PART_BYTES < bytes.len() {
        let Some(nl) = bytes[at + PART_BYTES..].iter().position(|&b| b == b'\n') else {
            break;
        };
        at += PART_BYTES + nl + 1;
        cuts.push(at);
    }
    cuts.push(bytes.len());
    // A cut is after a newline, an ASCII byte: always a character boundary.
    let parts: Vec<&str> = cuts.windows(2).map(|w| &text[w[0]..w[1]]).collect();
    let newlines: Vec<u64> = parts
        .par_iter()
        .map(|p| p.bytes().filter(|&b| b == b'\n').count() as u64)
        .collect();
    let mut first = Vec::with_capacity(parts.len());
    let mut line = lines.line_no() + 1;
    for n in &newlines {
        first.push(line);
        line += n;
    }
    let parsed: Vec<Option<(Acc, u64)>> = parts
        .par_iter()
        .zip(first)
        .map(|(&part, first)| {
            let mut acc = Acc::new(origin, layout.imus.len(), numbers);
            let mut it = LineIter::starting_at(part, first);
            rows_into(&mut acc, &mut it, layout, origin, format).ok()?;
            Some((acc, it.line_no()))
        })
        .collect();
    let parsed: Vec<(Acc, u64)> = parsed.into_iter().collect::<Option<_>>()?;
    let end = parsed.last().map_or(lines.line_no(), |(_, e)| *e);
    let rows: usize = parsed.iter().map(|(a, _)| a.time.len()).sum();
    let mut all = Acc::new(origin, layout.imus.len(), numbers);
    all.time.reserve_exact(rows);
    all.lines.reserve_exact(rows);
    for (k, s) in all.series.iter_mut().enumerate() {
        s.reserve_exact(rows);
        if layout.imus[k].gyro.is_some() {
            all.gyro[k].reserve_exact(rows);
        }
    }
    for (part, _) in parsed {
        if let (Some(&prev), Some(&t)) = (all.time.last(), part.time.first()) {
            if t <= prev {
                return None;
            }
        }
        all.time.extend_from_slice(&part.time);
        all.lines.extend_from_slice(&part.lines);
        if !part.time.is_empty() {
            all.last_line = part.last_line;
        }
        for (a, p) in all.series.iter_mut().zip(&part.series) {
            a.extend_from_slice(p);
        }
        for (a, p) in all.gyro.iter_mut().zip(&part.gyro) {
            a.extend_from_slice(p);
        }
        for (a, p) in all.renorm.iter_mut().zip(&part.renorm) {
            a.count += p.count;
            // As one pass keeps it: the first of the worst.
            if p.worst_off > a.worst_off {
                (a.worst_off, a.worst_norm, a.worst_line) =
                    (p.worst_off, p.worst_norm, p.worst_line);
            }
        }
        all.tally.merge(part.tally);
    }
    Some((all, end))
}

/// Reads the data rows of `lines` into `acc`, stopping at the first error.
fn rows_into(
    acc: &mut Acc<'_>,
    lines: &mut LineIter<'_>,
    layout: &Layout,
    origin: &str,
    format: TrialFormat,
) -> Result<(), TrialError> {
    let ncols = layout.columns.len();
    match format {
        TrialFormat::QuatCsv | TrialFormat::EulerCsv => {
            let euler = format == TrialFormat::EulerCsv;
            let group = if euler { 3 } else { 4 };
            let mut vals = [0.0f64; 4];
            let mut cells: Vec<&str> = Vec::with_capacity(ncols);
            for (line, text) in lines.by_ref() {
                if text.trim().is_empty() {
                    continue;
                }
                let nf = split_into(text, b',', &mut cells);
                if nf != ncols {
                    return Err(ragged(origin, line, ncols, nf, "comma"));
                }
                let cell =
                    |col: usize| number(cells[col], origin, line, col + 1, &layout.columns[col]);
                let t = number(cells[0], origin, line, 1, "time")?;
                acc.push_time(t, line)?;
                for (k, imu) in layout.imus.iter().enumerate() {
                    for (j, v) in vals.iter_mut().take(group).enumerate() {
                        *v = cell(imu.first_field + j)?;
                        acc.tally.see(cells[imu.first_field + j].trim_ascii());
                    }
                    if euler {
                        acc.series[k].push(quat_from_euler_zyx_deg([vals[0], vals[1], vals[2]]));
                    } else {
                        acc.push_quat(k, vals, line, imu.first_field + 1, &imu.found)?;
                    }
                    if let Some([x, y, z]) = imu.gyro {
                        acc.gyro[k].push(Vector3::new(cell(x)?, cell(y)?, cell(z)?));
                    }
                }
            }
        }
        TrialFormat::Sto | TrialFormat::Xsens => {
            const PARTS: [&str; 4] = ["w", "x", "y", "z"];
            let mut cells: Vec<&str> = Vec::with_capacity(ncols);
            let mut split: Vec<&str> = Vec::with_capacity(4);
            for (line, text) in lines.by_ref() {
                if text.trim().is_empty() {
                    continue;
                }
                let nf = split_into(text, b'\t', &mut cells);
                if nf != ncols {
                    return Err(ragged(origin, line, ncols, nf, "tab"));
                }
                let t = number(cells[0], origin, line, 1, "time")?;
                acc.push_time(t, line)?;
                // The IMUs' cells follow `time` in order (one per label).
                for ((k, imu), &cell) in layout.imus.iter().enumerate().zip(&cells[1..]) {
                    let col = imu.first_field + 1;
                    let parts = split_into(cell, b',', &mut split);
                    if parts != 4 {
                        return Err(TrialError::at(
                            origin,
                            line,
                            col,
                            format!(
                                "expected 4 comma-separated numbers w,x,y,z for {}, found {parts} ({})",
                                imu.found,
                                show(cell.trim())
                            ),
                        ));
                    }
                    let mut q = [0.0f64; 4];
                    for ((v, &part), p) in q.iter_mut().zip(&split).zip(PARTS) {
                        *v = match parse_f64(part.trim_ascii()) {
                            Ok(v) if v.is_finite() => v,
                            // The column's name is built only for the message.
                            _ => number(part, origin, line, col, &format!("{} {p}", imu.found))?,
                        };
                        acc.tally.see(part.trim_ascii());
                    }
                    acc.push_quat(k, q, line, col, &imu.found)?;
                }
            }
        }
    }
    Ok(())
}
