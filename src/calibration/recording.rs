//! Calibration recordings: raw accelerometer and gyroscope readings per IMU,
//! each row labelled with the protocol movement being performed.
//!
//! CSV (optionally gzip-compressed, `.gz`):
//!
//! ```text
//! time,label,<imu>_ax,<imu>_ay,<imu>_az,<imu>_gx,<imu>_gy,<imu>_gz,...
//! 0.00,supine,0.02,-0.11,9.80,0.3,-0.1,0.2,...
//! ```
//!
//! `time` in seconds, strictly increasing; `label` a movement label of the
//! protocol, or empty for rows between movements (ignored). Per IMU three
//! accelerometer columns (any unit: readings are normalised; m/s^2 usually) and
//! three gyroscope columns in degrees per second, both in the sensor frame.
//! Lines starting with `#` are comments. By convention recordings are named
//! `*.calib.csv` (or `*.calib.csv.gz`) so that the workbench lists them as
//! calibration recordings and not as trials.

use super::error::CalibrationError;
use std::fmt::Write as _;
use std::io::Read;
use std::path::Path;

/// Readings of one IMU, one per row, in the sensor frame.
#[derive(Debug, Clone, PartialEq)]
pub struct ImuReadings {
    /// IMU name as in the header.
    pub name: String,
    /// Accelerometer `[x, y, z]` (specific force; any unit).
    pub acc: Vec<[f64; 3]>,
    /// Gyroscope `[x, y, z]`, degrees per second.
    pub gyro: Vec<[f64; 3]>,
}

/// A calibration recording.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// File name without folder.
    pub name: String,
    /// Sample times, seconds, strictly increasing.
    pub time_s: Vec<f64>,
    /// Distinct labels in order of first appearance.
    pub labels: Vec<String>,
    /// Per row the index into `labels`, or `None` for an unlabelled row.
    pub label_of: Vec<Option<u32>>,
    /// IMUs in header order.
    pub imus: Vec<ImuReadings>,
}

const CHANNELS: [&str; 6] = ["ax", "ay", "az", "gx", "gy", "gz"];

pub use crate::file_names::is_calibration_recording;

impl Recording {
    /// Number of rows.
    pub fn len(&self) -> usize {
        self.time_s.len()
    }

    /// True when there are no rows.
    pub fn is_empty(&self) -> bool {
        self.time_s.is_empty()
    }

    /// The readings of an IMU (name matched case-insensitively).
    pub fn imu(&self, name: &str) -> Option<&ImuReadings> {
        self.imus.iter().find(|i| i.name.eq_ignore_ascii_case(name))
    }

    /// Rows carrying `label`.
    pub fn rows(&self, label: &str) -> Vec<usize> {
        let Some(k) = self.labels.iter().position(|l| l == label) else {
            return vec![];
        };
        (0..self.len())
            .filter(|&i| self.label_of[i] == Some(k as u32))
            .collect()
    }

    /// Nominal sampling rate, Hz (1 / median interval; 0 when unknown).
    pub fn rate_hz(&self) -> f64 {
        let dt = crate::trial::median_dt(&self.time_s);
        if dt > 0.0 {
            1.0 / dt
        } else {
            0.0
        }
    }

    /// Reads a recording (gzip when the name ends in `.gz`).
    pub fn read(path: &Path) -> Result<Recording, CalibrationError> {
        let origin = path.display().to_string();
        let raw = crate::input::read_bytes(path)
            .map_err(|e| CalibrationError::file(&origin, format!("cannot read: {e}")))?;
        let gz = origin.to_ascii_lowercase().ends_with(".gz");
        let bytes = if gz {
            let mut out = Vec::new();
            flate2::read::MultiGzDecoder::new(&raw[..])
                .read_to_end(&mut out)
                .map_err(|e| CalibrationError::file(&origin, format!("invalid gzip data: {e}")))?;
            out
        } else {
            raw
        };
        Recording::parse(&bytes, &origin)
    }

    /// Parses recording bytes; `origin` names the file in errors and its last
    /// component becomes the name.
    pub fn parse(bytes: &[u8], origin: &str) -> Result<Recording, CalibrationError> {
        let mut rdr = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .comment(Some(b'#'))
            .trim(csv::Trim::All)
            .from_reader(bytes);
        let mut records = rdr.byte_records();
        let err = |line: u64, col: usize, m: String| CalibrationError::at(origin, line, col, m);
        let csv_err = |e: csv::Error| {
            let line = e.position().map_or(0, |p| p.line());
            err(line, 0, format!("malformed CSV: {e}"))
        };
        let header = loop {
            match records.next() {
                None => {
                    return Err(err(
                        1,
                        1,
                        "empty file: expected a header line time,label,<imu>_ax,...".into(),
                    ))
                }
                Some(r) => {
                    let r = r.map_err(csv_err)?;
                    if r.iter().any(|f| !f.is_empty()) {
                        break r;
                    }
                }
            }
        };
        let hline = header.position().map_or(1, |p| p.line());
        let (names, slots) = parse_header(&header, hline, origin)?;
        let width = header.len();
        let mut rec = Recording {
            name: Path::new(origin)
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_else(|| origin.to_string()),
            time_s: vec![],
            labels: vec![],
            label_of: vec![],
            imus: names
                .iter()
                .map(|n| ImuReadings {
                    name: n.clone(),
                    acc: vec![],
                    gyro: vec![],
                })
                .collect(),
        };
        for r in records {
            let r = r.map_err(csv_err)?;
            let line = r.position().map_or(0, |p| p.line());
            if r.iter().all(|f| f.is_empty()) {
                continue;
            }
            if r.len() != width {
                return Err(err(
                    line,
                    r.len().min(width) + 1,
                    format!(
                        "expected {width} fields as in the header, found {}",
                        r.len()
                    ),
                ));
            }
            let num = |col: usize| -> Result<f64, CalibrationError> {
                let f = std::str::from_utf8(&r[col]).map_err(|_| {
                    err(
                        line,
                        col + 1,
                        "expected UTF-8 text, found invalid bytes".into(),
                    )
                })?;
                let v: f64 = f
                    .parse()
                    .map_err(|_| err(line, col + 1, format!("expected a number, found '{f}'")))?;
                if v.is_finite() {
                    Ok(v)
                } else {
                    Err(err(
                        line,
                        col + 1,
                        format!("expected a finite number, found '{f}'"),
                    ))
                }
            };
            let t = num(0)?;
            if let Some(&prev) = rec.time_s.last() {
                if t <= prev {
                    return Err(err(
                        line,
                        1,
                        format!("time {t} does not increase (previous row: {prev})"),
                    ));
                }
            }
            rec.time_s.push(t);
            let label = std::str::from_utf8(&r[1])
                .map_err(|_| err(line, 2, "expected UTF-8 text, found invalid bytes".into()))?;
            rec.label_of.push(if label.is_empty() {
                None
            } else {
                let k = match rec.labels.iter().position(|l| l == label) {
                    Some(k) => k,
                    None => {
                        rec.labels.push(label.to_string());
                        rec.labels.len() - 1
                    }
                };
                Some(k as u32)
            });
            for (k, imu) in rec.imus.iter_mut().enumerate() {
                let c = &slots[k];
                imu.acc.push([num(c[0])?, num(c[1])?, num(c[2])?]);
                imu.gyro.push([num(c[3])?, num(c[4])?, num(c[5])?]);
            }
        }
        if rec.time_s.is_empty() {
            return Err(err(
                hline + 1,
                1,
                "expected data rows after the header".into(),
            ));
        }
        Ok(rec)
    }

    /// Rounds every reading to `decimals` decimals (a sensor's resolution).
    pub fn round(&mut self, decimals: u32) {
        let f = 10f64.powi(decimals.min(15) as i32);
        let r = |v: &mut [f64; 3]| v.iter_mut().for_each(|x| *x = (*x * f).round() / f);
        for i in &mut self.imus {
            i.acc.iter_mut().for_each(r);
            i.gyro.iter_mut().for_each(r);
        }
    }

    /// The recording as CSV text (the format [`Recording::parse`] reads).
    pub fn to_csv(&self) -> String {
        let mut out = String::from("time,label");
        for i in &self.imus {
            for c in CHANNELS {
                let _ = write!(out, ",{}_{c}", i.name);
            }
        }
        out.push('\n');
        for r in 0..self.len() {
            let label = self.label_of[r].map_or("", |k| self.labels[k as usize].as_str());
            let _ = write!(out, "{},{label}", self.time_s[r]);
            for i in &self.imus {
                let [ax, ay, az] = i.acc[r];
                let [gx, gy, gz] = i.gyro[r];
                let _ = write!(out, ",{ax},{ay},{az},{gx},{gy},{gz}");
            }
            out.push('\n');
        }
        out
    }
}

/// IMU names and, per IMU, the columns of `ax ay az gx gy gz`.
type Layout = (Vec<String>, Vec<[usize; 6]>);

fn parse_header(h: &csv::ByteRecord, line: u64, origin: &str) -> Result<Layout, CalibrationError> {
    let err = |col: usize, m: String| CalibrationError::at(origin, line, col, m);
    let field = |i: usize| String::from_utf8_lossy(&h[i]).to_string();
    if h.is_empty() || !field(0).eq_ignore_ascii_case("time") {
        return Err(err(
            1,
            format!("expected 'time' as the first column, found '{}'", field(0)),
        ));
    }
    if h.len() < 2 || !field(1).eq_ignore_ascii_case("label") {
        let f = if h.len() > 1 { field(1) } else { String::new() };
        return Err(err(
            2,
            format!("expected 'label' as the second column, found '{f}'"),
        ));
    }
    let mut names: Vec<String> = vec![];
    let mut slots: Vec<[Option<usize>; 6]> = vec![];
    for i in 2..h.len() {
        let f = field(i);
        let lower = f.to_ascii_lowercase();
        let found = CHANNELS
            .iter()
            .position(|c| lower.ends_with(&format!("_{c}")) && lower.len() > c.len() + 1);
        let Some(ch) = found else {
            return Err(err(
                i + 1,
                format!("expected a column <imu>_ax, _ay, _az, _gx, _gy or _gz, found '{f}'"),
            ));
        };
        let imu = &f[..f.len() - 3];
        let k = match names.iter().position(|n| n.eq_ignore_ascii_case(imu)) {
            Some(k) => k,
            None => {
                names.push(imu.to_string());
                slots.push([None; 6]);
                names.len() - 1
            }
        };
        if slots[k][ch].is_some() {
            return Err(err(i + 1, format!("column '{f}' appears twice")));
        }
        slots[k][ch] = Some(i);
    }
    if names.is_empty() {
        return Err(err(
            3,
            "expected IMU columns <imu>_ax,...,<imu>_gz after 'label'".into(),
        ));
    }
    let mut out = vec![];
    for (k, s) in slots.iter().enumerate() {
        let mut cols = [0; 6];
        for (c, slot) in s.iter().enumerate() {
            cols[c] = slot.ok_or_else(|| {
                err(
                    0,
                    format!(
                        "IMU '{}' lacks column '{}_{}'",
                        names[k], names[k], CHANNELS[c]
                    ),
                )
            })?;
        }
        out.push(cols);
    }
    Ok((names, out))
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEAD: &str = "time,label,a_ax,a_ay,a_az,a_gx,a_gy,a_gz\n";

    fn parse(text: &str) -> Result<Recording, CalibrationError> {
        Recording::parse(text.as_bytes(), "dir/r.calib.csv")
    }

    #[test]
    fn reads_rows_labels_and_round_trips() {
        let r = parse(&format!(
            "# comment\n{HEAD}0,supine,0,0,9.8,0.1,0,0\n0.01,,0,0,9.8,0,0,0\n0.02,TR,0,0,9.8,50,1,2\n"
        ))
        .unwrap();
        assert_eq!(r.name, "r.calib.csv");
        assert_eq!(r.len(), 3);
        assert_eq!(r.labels, ["supine", "TR"]);
        assert_eq!(r.rows("TR"), [2]);
        assert_eq!(r.rows("none"), Vec::<usize>::new());
        assert_eq!(r.imu("A").unwrap().gyro[2], [50.0, 1.0, 2.0]);
        let again = Recording::parse(r.to_csv().as_bytes(), "dir/r.calib.csv").unwrap();
        assert_eq!(again, r);
    }

    #[test]
    fn errors_name_line_and_column() {
        let e = parse(&format!("{HEAD}0,s,0,0,x,0,0,0\n")).unwrap_err();
        assert_eq!(
            (e.file.as_str(), e.line, e.column),
            ("dir/r.calib.csv", 2, 5)
        );
        assert!(e.message.contains("expected a number, found 'x'"), "{e}");
        let e = parse(&format!("{HEAD}0,s,0,0,0,0,0,0\n0,s,0,0,0,0,0,0\n")).unwrap_err();
        assert_eq!((e.line, e.column), (3, 1));
        assert!(e.message.contains("does not increase"), "{e}");
        let e = parse(&format!("{HEAD}0,s,0,0,0,0,0\n")).unwrap_err();
        assert_eq!((e.line, e.column), (2, 8), "{e}");
        let e = parse(&format!("{HEAD}0,s,0,0,inf,0,0,0\n")).unwrap_err();
        assert!(e.message.contains("finite"), "{e}");
        let e = parse("time,label,a_ax,a_ay,a_az,a_gx,a_gy,a_speed\n").unwrap_err();
        assert_eq!((e.line, e.column), (1, 8), "{e}");
        let e = parse("time,label,a_ax,a_ay,a_az,a_gx,a_gy\n0,s,0,0,0,0,0\n").unwrap_err();
        assert!(e.message.contains("lacks column 'a_gz'"), "{e}");
        let e = parse("t,label,a_ax\n").unwrap_err();
        assert_eq!((e.line, e.column), (1, 1), "{e}");
        let e = parse(HEAD).unwrap_err();
        assert_eq!(e.line, 2, "{e}");
        assert_eq!(parse("").unwrap_err().line, 1);
    }

    #[test]
    fn recording_names() {
        assert!(is_calibration_recording(Path::new("x/a.calib.csv")));
        assert!(is_calibration_recording(Path::new("A.CALIB.CSV.GZ")));
        assert!(!is_calibration_recording(Path::new(".calib.csv")));
        assert!(!is_calibration_recording(Path::new("a.csv")));
    }
}
