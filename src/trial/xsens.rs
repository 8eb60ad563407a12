//! Xsens MT Manager text exports: one file per sensor.
//!
//! ```text
//! // Update Rate: 100.0Hz
//! // Filter Profile: human (46.1)
//! PacketCounter<TAB>SampleTimeFine<TAB>...<TAB>Mat[1][1]<TAB>Mat[2][1]<TAB>...<TAB>Mat[3][3]
//! 00472<TAB>...
//! ```
//!
//! Lines starting `//` are comments (`// Update Rate: <Hz>` gives the rate,
//! `// Coordinate system: ENU|NED|NWU` the global frame); the first other line
//! is the header. Fields are separated by tabs, commas or semicolons, whichever
//! the header uses most (MT Manager's "export as" choices); with semicolons a
//! decimal comma is accepted (`0,125`). Cells may be quoted. Columns may stand
//! in any order and others (`SampleTimeFine`, `UTC_*`, `Acc_X`, ...) are
//! ignored. Names are matched without regard to case, spaces, `_` or `-`, so
//! MT Manager's older and newer spellings read alike (`PacketCounter`,
//! `Packet Counter`, `Counter`; `Quat_q0`, `q0`, `Quat_W`; `Gyr_X`, `Gyro_X`).
//!
//! The orientation `G_R_sensor` (sensor frame to the Xsens global frame, Z up)
//! comes from, in this order of preference:
//!
//! * `Quat_q0 Quat_q1 Quat_q2 Quat_q3` (scalar first; also `q0..q3`,
//!   `Quat_W Quat_X Quat_Y Quat_Z`);
//! * `Mat[i][j]`, i = row, j = column, 1-based, the nine entries in any order
//!   (MT Manager lists them column by column: `Mat[1][1] Mat[2][1] Mat[3][1] Mat[1][2] ...`);
//! * `Roll Pitch Yaw` (or `Euler_X Euler_Y Euler_Z`), degrees, `Rz(yaw) Ry(pitch) Rx(roll)`.
//!
//! Optional `Gyr_X Gyr_Y Gyr_Z` columns (MT Manager's calibrated rate of turn,
//! rad/s in the sensor frame) are read as the sensor's gyroscope readings; all
//! three or none.
//!
//! `PacketCounter` is a 16-bit counter that wraps from 65535 to 0; it is unwrapped
//! here and is what sensors are aligned on ([`super::xsens_trial`]). Without an
//! `Update Rate` comment the rate comes from `SampleTimeFine` (ticks of 100 us).

use super::io::parse::{show, LineIter, NORM_NOTE, NORM_TOLERANCE};
use super::TrialError;
use crate::rotation::{quat_from_euler_zyx_deg, Quat};
use crate::trial::precision::{AngleNumbers, Decimals, Tally};
use nalgebra::{Matrix3, Quaternion, Rotation3, UnitQuaternion, Vector3};

/// The packet counter's modulus (it is 16 bits wide).
pub const COUNTER_MODULUS: u64 = 1 << 16;

/// `SampleTimeFine` ticks per second (it counts 100 us steps).
pub const SAMPLE_TIME_FINE_HZ: f64 = 10_000.0;

/// Largest deviation of `R^T R` from the identity (any entry) accepted for a
/// `Mat[i][j]` rotation matrix; six printed decimals stay within 1e-5.
pub const MATRIX_TOLERANCE: f64 = 0.01;

/// Where a file keeps its orientation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OrientationColumns {
    /// `Quat_q0..q3`.
    Quaternion,
    /// `Mat[i][j]`.
    Matrix,
    /// `Roll Pitch Yaw`, degrees.
    Euler,
}

/// The field separator of an export, found from its header line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Delimiter {
    Tab,
    Comma,
    Semicolon,
}

impl Delimiter {
    /// The separator character.
    pub fn char(self) -> char {
        match self {
            Delimiter::Tab => '\t',
            Delimiter::Comma => ',',
            Delimiter::Semicolon => ';',
        }
    }

    /// `tab`, `comma` or `semicolon` (for messages).
    pub fn name(self) -> &'static str {
        match self {
            Delimiter::Tab => "tab",
            Delimiter::Comma => "comma",
            Delimiter::Semicolon => "semicolon",
        }
    }

    /// The separator the header line uses most (tab, then semicolon, then
    /// comma among equals: a semicolon file may hold decimal commas).
    pub fn of_header(header: &str) -> Delimiter {
        let count = |c: char| header.matches(c).count();
        let (tab, semi, comma) = (count('\t'), count(';'), count(','));
        if tab >= semi && tab >= comma && tab > 0 {
            Delimiter::Tab
        } else if semi >= comma && semi > 0 {
            Delimiter::Semicolon
        } else if comma > 0 {
            Delimiter::Comma
        } else {
            Delimiter::Tab
        }
    }
}

/// One sensor's export, read.
#[derive(Debug, Clone)]
pub struct XsensExport {
    /// The file as the user named it (for messages).
    pub origin: String,
    /// The rate of `// Update Rate: <Hz>`, when the file has that comment.
    pub rate_hz: Option<f64>,
    /// Line and column (1-based, characters) of that rate's value; 1 and 1
    /// without one.
    pub rate_at: (u64, usize),
    /// The rate implied by `SampleTimeFine` (median ticks per packet), when the
    /// file has that column filled in.
    pub sample_time_rate_hz: Option<f64>,
    /// `// Coordinate system: ...` (ENU, NED, NWU), when given.
    pub coordinate_system: Option<String>,
    /// The field separator found.
    pub delimiter: Delimiter,
    /// Unwrapped packet counter per sample (strictly increasing).
    pub counters: Vec<u64>,
    /// Line of each sample (1-based).
    pub lines: Vec<u64>,
    /// `G_R_sensor` per sample, Xsens global frame.
    pub orientation: Vec<Quat>,
    /// Which columns the orientation came from.
    pub columns: OrientationColumns,
    /// Rate of turn per sample from `Gyr_X Gyr_Y Gyr_Z`, rad/s, sensor frame;
    /// `None` when the export has no such columns.
    pub gyro: Option<Vec<Vector3<f64>>>,
    /// Quaternions renormalised by more than [`NORM_NOTE`] (count).
    pub renormalised: usize,
    /// Decimal places of the quaternion or Euler numbers read (`None` for
    /// rotation matrices and numbers at full precision).
    pub decimals: Option<Decimals>,
}

/// Column indices (0-based) of what the reader needs.
struct Columns {
    counter: usize,
    kind: OrientationColumns,
    /// Quaternion: w x y z; matrix: row-major R[0][0], R[0][1], ...; Euler: roll pitch yaw.
    fields: Vec<usize>,
    /// `Gyr_X Gyr_Y Gyr_Z`, when present.
    gyro: Option<[usize; 3]>,
    /// `SampleTimeFine`, when present.
    sample_time: Option<usize>,
}

/// Accepted spellings of the packet counter column.
const COUNTER_NAMES: [&str; 3] = ["PacketCounter", "Counter", "PacketCount"];
/// Accepted spellings of the quaternion columns, scalar first.
const QUAT_NAMES: [[&str; 4]; 3] = [
    ["Quat_q0", "Quat_q1", "Quat_q2", "Quat_q3"],
    ["q0", "q1", "q2", "q3"],
    ["Quat_W", "Quat_X", "Quat_Y", "Quat_Z"],
];
/// Accepted spellings of the Euler columns (roll, pitch, yaw; degrees).
const EULER_NAMES: [[&str; 3]; 2] = [["Roll", "Pitch", "Yaw"], ["Euler_X", "Euler_Y", "Euler_Z"]];
/// Accepted spellings of the gyroscope columns (rad/s, sensor frame).
const GYRO_NAMES: [[&str; 3]; 2] = [["Gyr_X", "Gyr_Y", "Gyr_Z"], ["Gyro_X", "Gyro_Y", "Gyro_Z"]];

/// A header name reduced for matching: unquoted, lower case, without spaces, `_` and `-`.
fn key(name: &str) -> String {
    name.trim()
        .trim_matches('"')
        .chars()
        .filter(|c| !matches!(c, ' ' | '_' | '-'))
        .flat_map(char::to_lowercase)
        .collect()
}

fn find(keys: &[String], name: &str) -> Option<usize> {
    let k = key(name);
    keys.iter().position(|h| *h == k)
}

fn find_all(keys: &[String], names: &[&str]) -> Option<Vec<usize>> {
    names.iter().map(|n| find(keys, n)).collect()
}

/// The gyroscope columns: all three of one spelling, none, or an error at
/// the first one present when some are missing.
fn gyro_columns(
    keys: &[String],
    origin: &str,
    line: u64,
) -> Result<Option<[usize; 3]>, TrialError> {
    for names in GYRO_NAMES {
        let found = names.map(|n| find(keys, n));
        match found {
            [Some(x), Some(y), Some(z)] => return Ok(Some([x, y, z])),
            [None, None, None] => continue,
            _ => {
                let first = found.iter().flatten().min().copied().unwrap_or(0);
                let missing: Vec<&str> = names
                    .iter()
                    .zip(found)
                    .filter(|(_, f)| f.is_none())
                    .map(|(n, _)| *n)
                    .collect();
                return Err(TrialError::at(
                    origin,
                    line,
                    first + 1,
                    format!(
                        "incomplete gyroscope columns: missing {}; expected all of {} (rad/s, sensor frame) or none",
                        missing.join(" and "),
                        names.join(", ")
                    ),
                ));
            }
        }
    }
    Ok(None)
}

fn columns(header: &[&str], origin: &str, line: u64) -> Result<Columns, TrialError> {
    let keys: Vec<String> = header.iter().map(|h| key(h)).collect();
    let counter = COUNTER_NAMES
        .iter()
        .find_map(|n| find(&keys, n))
        .ok_or_else(|| {
            TrialError::at(
                origin,
                line,
                1,
                format!(
                    "expected a 'PacketCounter' column (sensors are aligned on it; also read as 'Counter'), found {} {}: {}; export it from MT Manager",
                    header.len(),
                    if header.len() == 1 { "column" } else { "columns" },
                    show(&header.join(" | "))
                ),
            )
        })?;
    let gyro = gyro_columns(&keys, origin, line)?;
    let sample_time = find(&keys, "SampleTimeFine");
    let with = |kind, fields| Columns {
        counter,
        kind,
        fields,
        gyro,
        sample_time,
    };
    for names in QUAT_NAMES {
        if let Some(fields) = find_all(&keys, &names) {
            return Ok(with(OrientationColumns::Quaternion, fields));
        }
    }
    let mat: Vec<String> = (1..=3)
        .flat_map(|i| (1..=3).map(move |j| format!("Mat[{i}][{j}]")))
        .collect();
    let mat: Vec<&str> = mat.iter().map(String::as_str).collect();
    if let Some(fields) = find_all(&keys, &mat) {
        return Ok(with(OrientationColumns::Matrix, fields));
    }
    for names in EULER_NAMES {
        if let Some(fields) = find_all(&keys, &names) {
            return Ok(with(OrientationColumns::Euler, fields));
        }
    }
    Err(TrialError::at(
        origin,
        line,
        header.len() + 1,
        "no orientation columns: expected Quat_q0..Quat_q3, the nine Mat[i][j] or Roll Pitch Yaw",
    ))
}

/// The value of a `// Update Rate: 100.0Hz` comment: `None` when the
/// comment is another; else the rate in Hz, or why the value is not one
/// (not a number, or not finite and positive). `value` is the text after the
/// colon, trimmed (what messages show).
fn rate_of_comment(comment: &str) -> Option<(&str, Result<f64, String>)> {
    let value = comment_value(comment, "update rate")?;
    let v = value
        .strip_suffix("Hz")
        .or_else(|| value.strip_suffix("hz"))
        .unwrap_or(value);
    let rate = match v.trim().replace(',', ".").parse::<f64>() {
        Ok(r) if r.is_finite() && r > 0.0 => Ok(r),
        Ok(r) => Err(format!(
            "update rate '{value}' is invalid: expected a finite positive rate in Hz, found {r}"
        )),
        Err(_) => Err(format!(
            "update rate '{value}' is invalid: expected a rate in Hz such as 100.0Hz"
        )),
    };
    Some((value, rate))
}

/// The value of a `// Key: value` comment when its key is `key` (any case).
fn comment_value<'a>(comment: &'a str, key: &str) -> Option<&'a str> {
    let (k, value) = comment.split_once(':')?;
    k.trim().eq_ignore_ascii_case(key).then(|| value.trim())
}

/// The rate implied by `SampleTimeFine` readings: ticks per second over the
/// median ticks per packet (readings that are missing or step backwards are
/// left out). `None` without two usable readings.
fn rate_of_sample_time(counters: &[u64], ticks: &[Option<f64>]) -> Option<f64> {
    let mut per_packet: Vec<f64> = counters
        .windows(2)
        .zip(ticks.windows(2))
        .filter_map(|(c, t)| {
            let (a, b) = (t[0]?, t[1]?);
            (b > a).then(|| (b - a) / (c[1] - c[0]) as f64)
        })
        .collect();
    if per_packet.is_empty() {
        return None;
    }
    let mid = per_packet.len() / 2;
    let (_, m, _) = per_packet.select_nth_unstable_by(mid, f64::total_cmp);
    let hz = SAMPLE_TIME_FINE_HZ / *m;
    hz.is_finite().then_some(hz)
}

/// How one export's cells are read: where, and with which separator.
struct Cells<'a> {
    origin: &'a str,
    delimiter: Delimiter,
}

impl Cells<'_> {
    fn cell<'c>(
        &self,
        cells: &[&'c str],
        k: usize,
        line: u64,
        what: &str,
    ) -> Result<&'c str, TrialError> {
        match cells.get(k).map(|c| c.trim().trim_matches('"').trim()) {
            Some(c) if !c.is_empty() => Ok(c),
            Some(_) => Err(TrialError::at(
                self.origin,
                line,
                k + 1,
                format!("expected a number for {what}, found an empty cell"),
            )),
            None => Err(TrialError::at(
                self.origin,
                line,
                cells.len() + 1,
                format!(
                    "too few fields: expected {what} in {}-separated field {}, found {} fields",
                    self.delimiter.name(),
                    k + 1,
                    cells.len()
                ),
            )),
        }
    }

    /// A number; with semicolons a decimal comma is read as a point.
    fn parse(&self, c: &str) -> Option<f64> {
        let v = match c.parse::<f64>() {
            Ok(v) => v,
            Err(_) if self.delimiter == Delimiter::Semicolon && c.contains(',') => {
                c.replace(',', ".").parse::<f64>().ok()?
            }
            Err(_) => return None,
        };
        v.is_finite().then_some(v)
    }

    fn number(&self, cells: &[&str], k: usize, line: u64, what: &str) -> Result<f64, TrialError> {
        let c = self.cell(cells, k, line, what)?;
        self.parse(c).ok_or_else(|| {
            TrialError::at(
                self.origin,
                line,
                k + 1,
                format!("expected a finite number for {what}, found {}", show(c)),
            )
        })
    }

    fn counter(&self, cells: &[&str], k: usize, line: u64) -> Result<u64, TrialError> {
        let c = self.cell(cells, k, line, "PacketCounter")?;
        match c.parse::<u64>() {
            Ok(v) if v < COUNTER_MODULUS => Ok(v),
            _ => Err(TrialError::at(
                self.origin,
                line,
                k + 1,
                format!("expected a packet counter 0..65535, found {}", show(c)),
            )),
        }
    }
}

/// Reads one export from its text; `origin` names the file in errors.
pub fn parse_export(text: &str, origin: &str) -> Result<XsensExport, TrialError> {
    let mut reader = ExportReader::new(origin);
    let mut lines = LineIter::new(text);
    let mut cells: Vec<&str> = Vec::new();
    for (n, l) in lines.by_ref() {
        reader.line(n, l, &mut cells)?;
    }
    reader.finish(lines.line_no())
}

/// The header of an export, once read.
struct Header {
    line: u64,
    delimiter: Delimiter,
    names: Vec<String>,
    cols: Columns,
}

/// An export read line by line, as its lines arrive: the comments and the
/// header, then one sample per data row. [`parse_export`] reads a whole
/// file through it; a follower of a growing export feeds it the complete
/// lines appended since its last look.
pub struct ExportReader {
    /// The samples so far (and the comments' rate and frame).
    out: XsensExport,
    header: Option<Header>,
    /// `SampleTimeFine` per sample, when the column exists.
    ticks: Vec<Option<f64>>,
    /// The last raw counter and its line.
    last_raw: Option<(u64, u64)>,
    /// Wraps of the 16-bit counter so far.
    wraps: u64,
    /// Decimal places of the orientation numbers so far.
    tally: Tally,
}

impl ExportReader {
    /// A reader of the export `origin` (named in errors) that has read nothing.
    pub fn new(origin: &str) -> ExportReader {
        ExportReader {
            out: XsensExport {
                origin: origin.to_string(),
                rate_hz: None,
                rate_at: (1, 1),
                sample_time_rate_hz: None,
                coordinate_system: None,
                delimiter: Delimiter::Tab,
                counters: Vec::new(),
                lines: Vec::new(),
                orientation: Vec::new(),
                columns: OrientationColumns::Quaternion,
                gyro: None,
                renormalised: 0,
                decimals: None,
            },
            header: None,
            ticks: Vec::new(),
            last_raw: None,
            wraps: 0,
            tally: Tally::default(),
        }
    }

    /// The decimal places of the quaternion or Euler numbers read so far
    /// (`None` for rotation matrices, full precision, or nothing read).
    pub fn decimals(&self) -> Option<Decimals> {
        match self.header.as_ref()?.cols.kind {
            OrientationColumns::Quaternion => self.tally.finish(AngleNumbers::Quaternion),
            OrientationColumns::Euler => self.tally.finish(AngleNumbers::EulerDeg),
            OrientationColumns::Matrix => None,
        }
    }

    /// Whether the header line was read (the comments before it are all in).
    pub fn has_header(&self) -> bool {
        self.header.is_some()
    }

    /// The export as read so far: its comments' rate and frame, the samples
    /// of the rows read (`sample_time_rate_hz` is filled in by [`ExportReader::finish`]).
    pub fn export(&self) -> &XsensExport {
        &self.out
    }

    /// The rate [`ExportReader::finish`] would find from `SampleTimeFine`
    /// on the rows read so far (`None`: no such column, or fewer than two
    /// usable readings).
    pub fn sample_time_rate_hz(&self) -> Option<f64> {
        self.header.as_ref()?.cols.sample_time?;
        rate_of_sample_time(&self.out.counters, &self.ticks)
    }

    /// Reads the complete lines `text` whose first is 1-based line
    /// `first_line` of the file (a byte-order mark at the file's start is skipped).
    pub fn push_lines(&mut self, text: &str, first_line: u64) -> Result<(), TrialError> {
        let text = if first_line == 1 {
            text.strip_prefix('\u{feff}').unwrap_or(text)
        } else {
            text
        };
        let mut cells: Vec<&str> = Vec::new();
        for (n, l) in LineIter::starting_at(text, first_line) {
            self.line(n, l, &mut cells)?;
        }
        Ok(())
    }

    /// Reads line `n` (without its newline); `cells` is scratch space.
    fn line<'t>(&mut self, n: u64, l: &'t str, cells: &mut Vec<&'t str>) -> Result<(), TrialError> {
        let Some(header) = &self.header else {
            return self.head_line(n, l);
        };
        let text = l;
        let line = n;
        if text.trim().is_empty() || text.trim_start().starts_with("//") {
            return Ok(());
        }
        let origin = self.out.origin.as_str();
        let cols = &header.cols;
        let names = &header.names;
        let reader = Cells {
            origin,
            delimiter: header.delimiter,
        };
        cells.clear();
        cells.extend(text.split(header.delimiter.char()));
        let raw = reader.counter(cells, cols.counter, line)?;
        if let Some((prev, prev_line)) = self.last_raw {
            if raw == prev {
                return Err(TrialError::at(
                    origin,
                    line,
                    cols.counter + 1,
                    format!("repeated packet counter {raw} (also on line {prev_line}); expected each packet once"),
                ));
            }
            if raw < prev {
                if prev - raw > COUNTER_MODULUS / 2 {
                    self.wraps += 1;
                } else {
                    return Err(TrialError::at(
                        origin,
                        line,
                        cols.counter + 1,
                        format!("packet counter went back from {prev} (line {prev_line}) to {raw}; expected it to increase (wrapping from 65535 to 0)"),
                    ));
                }
            }
        }
        let mut renormalised = 0;
        let q = orientation(&reader, cells, cols, names, line, &mut renormalised)?;
        for &k in &cols.fields {
            // Read by `orientation`: present and not empty.
            self.tally.see(cells[k].trim().trim_matches('"').trim());
        }
        let gyro = match cols.gyro {
            Some(fields) => {
                let [x, y, z] = fields.map(|k| reader.number(cells, k, line, &names[k]));
                Some(Vector3::new(x?, y?, z?))
            }
            None => None,
        };
        if let Some(k) = cols.sample_time {
            self.ticks.push(
                cells
                    .get(k)
                    .and_then(|c| reader.parse(c.trim().trim_matches('"'))),
            );
        }
        self.last_raw = Some((raw, line));
        let out = &mut self.out;
        out.renormalised += renormalised;
        if let (Some(g), Some(v)) = (&mut out.gyro, gyro) {
            g.push(v);
        }
        out.counters.push(raw + self.wraps * COUNTER_MODULUS);
        out.lines.push(line);
        out.orientation.push(q);
        Ok(())
    }

    /// A line before the header: blank, a `//` comment, or the header.
    fn head_line(&mut self, n: u64, l: &str) -> Result<(), TrialError> {
        if l.trim().is_empty() {
            return Ok(());
        }
        let origin = self.out.origin.as_str();
        if let Some(c) = l.trim_start().strip_prefix("//") {
            if let (None, Some((value, rate))) = (self.out.rate_hz, rate_of_comment(c)) {
                // Column (characters) of the value in the line.
                let offset = value.as_ptr() as usize - l.as_ptr() as usize;
                let column = l[..offset].chars().count() + 1;
                self.out.rate_at = (n, column);
                self.out.rate_hz = Some(rate.map_err(|m| TrialError::at(origin, n, column, m))?);
            }
            if self.out.coordinate_system.is_none() {
                self.out.coordinate_system =
                    comment_value(c, "coordinate system").map(|v| v.to_ascii_uppercase());
            }
            return Ok(());
        }
        let delimiter = Delimiter::of_header(l);
        let names: Vec<&str> = l.split(delimiter.char()).map(str::trim).collect();
        let cols = columns(&names, origin, n)?;
        self.out.delimiter = delimiter;
        self.out.columns = cols.kind;
        self.out.gyro = cols.gyro.map(|_| Vec::new());
        self.header = Some(Header {
            line: n,
            delimiter,
            names: names.into_iter().map(str::to_string).collect(),
            cols,
        });
        Ok(())
    }

    /// The export, once its last line (1-based `last_line`, 0 for an empty
    /// file) was read: an error without a header or without samples.
    pub fn finish(mut self, last_line: u64) -> Result<XsensExport, TrialError> {
        let origin = self.out.origin.as_str();
        let Some(header) = &self.header else {
            return Err(TrialError::at(
                origin,
                last_line.max(1),
                1,
                "no header: expected '// ...' comment lines then a header with PacketCounter",
            ));
        };
        if self.out.counters.is_empty() {
            return Err(TrialError::at(
                origin,
                last_line + 1,
                1,
                format!(
                    "no samples: expected data rows after the header on line {}",
                    header.line
                ),
            ));
        }
        if header.cols.sample_time.is_some() {
            self.out.sample_time_rate_hz = rate_of_sample_time(&self.out.counters, &self.ticks);
        }
        self.out.decimals = self.decimals();
        Ok(self.out)
    }
}

fn orientation(
    reader: &Cells,
    cells: &[&str],
    cols: &Columns,
    header: &[String],
    line: u64,
    renormalised: &mut usize,
) -> Result<Quat, TrialError> {
    let origin = reader.origin;
    let mut v = [0.0f64; 9];
    for (slot, &k) in v.iter_mut().zip(&cols.fields) {
        *slot = reader.number(cells, k, line, &header[k])?;
    }
    let first = cols.fields[0] + 1;
    match cols.kind {
        OrientationColumns::Quaternion => {
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]).sqrt();
            let off = (n - 1.0).abs();
            if off.is_nan() || off > NORM_TOLERANCE {
                return Err(TrialError::at(
                    origin,
                    line,
                    first,
                    format!("expected a unit quaternion (norm within {NORM_TOLERANCE} of 1), found norm {n}"),
                ));
            }
            if off > NORM_NOTE {
                *renormalised += 1;
            }
            Ok(Quat::new_unchecked(Quaternion::new(
                v[0] / n,
                v[1] / n,
                v[2] / n,
                v[3] / n,
            )))
        }
        OrientationColumns::Matrix => {
            let m = Matrix3::from_row_slice(&v);
            let off = (m.transpose() * m - Matrix3::identity()).abs().max();
            if off.is_nan() || off > MATRIX_TOLERANCE || m.determinant() <= 0.0 {
                return Err(TrialError::at(
                    origin,
                    line,
                    first,
                    format!(
                        "expected a rotation matrix in Mat[i][j] (orthonormal within {MATRIX_TOLERANCE}, determinant +1), found R^T R off identity by {off:.3e} and determinant {:.4}",
                        m.determinant()
                    ),
                ));
            }
            let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(m));
            Ok(Quat::new_normalize(q.into_inner()))
        }
        OrientationColumns::Euler => Ok(quat_from_euler_zyx_deg([v[0], v[1], v[2]])),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::angle_between_deg;

    #[test]
    fn update_rate_comment() {
        let rate = |c: &str| rate_of_comment(c).map(|(_, r)| r);
        assert_eq!(rate(" Update Rate: 100.0Hz"), Some(Ok(100.0)));
        assert_eq!(rate(" Update Rate: 60 Hz"), Some(Ok(60.0)));
        assert_eq!(rate(" Filter Profile: human (46.1)"), None);
        for bad in ["0Hz", "-100Hz", "nanHz", "infHz", "fastHz"] {
            let comment = format!(" Update Rate: {bad}");
            let r = rate(&comment);
            assert!(
                matches!(&r, Some(Err(m)) if m.contains(&format!("'{bad}' is invalid"))),
                "{bad}: {r:?}"
            );
        }
    }

    #[test]
    fn delimiter_and_spellings() {
        assert_eq!(
            Delimiter::of_header("PacketCounter\tQuat_q0"),
            Delimiter::Tab
        );
        assert_eq!(
            Delimiter::of_header("PacketCounter,Quat_q0,Quat_q1"),
            Delimiter::Comma
        );
        assert_eq!(
            Delimiter::of_header("PacketCounter;Quat_q0"),
            Delimiter::Semicolon
        );
        assert_eq!(key("\"Packet Counter\""), key("PacketCounter"));
        assert_eq!(key("Quat_Q0"), key("quatq0"));
        // Semicolons with decimal commas, quoted cells, newer spellings.
        let text = "//  Update Rate: 50,0Hz\n\"Packet Counter\";\"Quat_W\";\"Quat_X\";\"Quat_Y\";\"Quat_Z\"\n1;\"0,6\";0,8;0;0\n";
        let e = parse_export(text, "a.txt").unwrap();
        assert_eq!((e.rate_hz, e.delimiter), (Some(50.0), Delimiter::Semicolon));
        assert!(
            (e.orientation[0].w - 0.6).abs() < 1e-15 && (e.orientation[0].i - 0.8).abs() < 1e-15
        );
        let e = parse_export(
            "// Coordinate system: NED\nCounter,q0,q1,q2,q3\n7,1,0,0,0\n",
            "b.txt",
        )
        .unwrap();
        assert_eq!(e.coordinate_system.as_deref(), Some("NED"));
        assert_eq!(e.counters, [7]);
    }

    #[test]
    fn counter_wraps_and_matrix_reads_column_major_header() {
        // Rotation of 90 deg about Z: R = [[0,-1,0],[1,0,0],[0,0,1]], listed column by column.
        let text = "// Update Rate: 100.0Hz\nPacketCounter\tMat[1][1]\tMat[2][1]\tMat[3][1]\tMat[1][2]\tMat[2][2]\tMat[3][2]\tMat[1][3]\tMat[2][3]\tMat[3][3]\n65535\t0\t1\t0\t-1\t0\t0\t0\t0\t1\n00000\t0\t1\t0\t-1\t0\t0\t0\t0\t1\n";
        let e = parse_export(text, "a.txt").unwrap();
        assert_eq!(e.counters, [65535, 65536]);
        assert_eq!(e.rate_hz, Some(100.0));
        let want = crate::rotation::quat_axis_angle_deg([0.0, 0.0, 1.0], 90.0);
        assert!(angle_between_deg(&e.orientation[0], &want) < 1e-9);
    }

    #[test]
    fn errors_name_line_and_column() {
        let head = "// x\nPacketCounter\tQuat_q0\tQuat_q1\tQuat_q2\tQuat_q3\n";
        let e =
            parse_export(&format!("{head}1\t1\t0\t0\t0\n1\t1\t0\t0\t0\n"), "s.txt").unwrap_err();
        assert_eq!((e.line, e.column), (4, 1), "{e}");
        assert!(e.message.contains("repeated packet counter"), "{e}");
        let e =
            parse_export(&format!("{head}5\t1\t0\t0\t0\n4\t1\t0\t0\t0\n"), "s.txt").unwrap_err();
        assert!(e.message.contains("went back"), "{e}");
        let e = parse_export(&format!("{head}5\t2\t0\t0\t0\n"), "s.txt").unwrap_err();
        assert_eq!((e.line, e.column), (3, 2), "{e}");
        let e = parse_export(&format!("{head}5\t1\t0\tx\t0\n"), "s.txt").unwrap_err();
        assert_eq!((e.line, e.column), (3, 4), "{e}");
        let e = parse_export(&format!("{head}5\t1\t0\n"), "s.txt").unwrap_err();
        assert_eq!((e.line, e.column), (3, 4), "{e}");
        let e = parse_export("// x\nPacketCounter\tAcc_X\n1\t2\n", "s.txt").unwrap_err();
        assert_eq!((e.line, e.column), (2, 3), "{e}");
        assert!(e.message.contains("no orientation columns"), "{e}");
        let e = parse_export("// x\nSampleTimeFine\tQuat_q0\n", "s.txt").unwrap_err();
        assert!(e.message.contains("PacketCounter"), "{e}");
        // A reflection is not a rotation.
        let refl = "PacketCounter\tMat[1][1]\tMat[2][1]\tMat[3][1]\tMat[1][2]\tMat[2][2]\tMat[3][2]\tMat[1][3]\tMat[2][3]\tMat[3][3]\n1\t-1\t0\t0\t0\t1\t0\t0\t0\t1\n";
        let e = parse_export(refl, "m.txt").unwrap_err();
        assert_eq!((e.line, e.column), (2, 2), "{e}");
    }
}
