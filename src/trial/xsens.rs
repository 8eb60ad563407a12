//! Xsens MT Manager text exports: one tab-separated file per sensor.
//!
//! ```text
//! // Update Rate: 100.0Hz
//! // Filter Profile: human (46.1)
//! PacketCounter<TAB>SampleTimeFine<TAB>...<TAB>Mat[1][1]<TAB>Mat[2][1]<TAB>...<TAB>Mat[3][3]
//! 00472<TAB>...
//! ```
//!
//! Lines starting `//` are comments (`// Update Rate: <Hz>` gives the rate); the
//! first other line is the header. The orientation `G_R_sensor` (sensor frame to
//! the Xsens global frame, Z up) comes from, in this order of preference:
//!
//! * `Quat_q0 Quat_q1 Quat_q2 Quat_q3` (scalar first);
//! * `Mat[i][j]`, i = row, j = column, 1-based, the nine entries in any order
//!   (MT Manager lists them column by column: `Mat[1][1] Mat[2][1] Mat[3][1] Mat[1][2] ...`);
//! * `Roll Pitch Yaw` (or `Euler_X Euler_Y Euler_Z`), degrees, `Rz(yaw) Ry(pitch) Rx(roll)`.
//!
//! Optional `Gyr_X Gyr_Y Gyr_Z` columns (MT Manager's calibrated rate of turn,
//! rad/s in the sensor frame) are read as the sensor's gyroscope readings; all
//! three or none.
//!
//! `PacketCounter` is a 16-bit counter that wraps from 65535 to 0; it is unwrapped
//! here and is what sensors are aligned on ([`super::xsens_trial`]).

use super::io::parse::{show, LineIter, NORM_NOTE, NORM_TOLERANCE};
use super::TrialError;
use crate::rotation::{quat_from_euler_zyx_deg, Quat};
use nalgebra::{Matrix3, Quaternion, Rotation3, UnitQuaternion, Vector3};

/// The packet counter's modulus (it is 16 bits wide).
pub const COUNTER_MODULUS: u64 = 1 << 16;

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

/// One sensor's export, read.
#[derive(Debug, Clone)]
pub struct XsensExport {
    /// The file as the user named it (for messages).
    pub origin: String,
    /// The rate of `// Update Rate: <Hz>`, when the file has that comment.
    pub rate_hz: Option<f64>,
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
}

/// Column indices (0-based) of what the reader needs.
struct Columns {
    counter: usize,
    kind: OrientationColumns,
    /// Quaternion: w x y z; matrix: row-major R[0][0], R[0][1], ...; Euler: roll pitch yaw.
    fields: Vec<usize>,
    /// `Gyr_X Gyr_Y Gyr_Z`, when present.
    gyro: Option<[usize; 3]>,
}

/// The gyroscope columns: all of `Gyr_X Gyr_Y Gyr_Z`, none, or an error at
/// the first one present when some are missing.
fn gyro_columns(
    header: &[&str],
    origin: &str,
    line: u64,
) -> Result<Option<[usize; 3]>, TrialError> {
    const NAMES: [&str; 3] = ["Gyr_X", "Gyr_Y", "Gyr_Z"];
    let found = NAMES.map(|n| find(header, n));
    match found {
        [Some(x), Some(y), Some(z)] => Ok(Some([x, y, z])),
        [None, None, None] => Ok(None),
        _ => {
            let first = found.iter().flatten().min().copied().unwrap_or(0);
            let missing: Vec<&str> = NAMES
                .iter()
                .zip(found)
                .filter(|(_, f)| f.is_none())
                .map(|(n, _)| *n)
                .collect();
            Err(TrialError::at(
                origin,
                line,
                first + 1,
                format!(
                    "incomplete gyroscope columns: missing {}; expected all of Gyr_X, Gyr_Y, Gyr_Z (rad/s, sensor frame) or none",
                    missing.join(" and ")
                ),
            ))
        }
    }
}

fn find(header: &[&str], name: &str) -> Option<usize> {
    header.iter().position(|h| h.eq_ignore_ascii_case(name))
}

fn find_all(header: &[&str], names: &[String]) -> Option<Vec<usize>> {
    names.iter().map(|n| find(header, n)).collect()
}

fn columns(header: &[&str], origin: &str, line: u64) -> Result<Columns, TrialError> {
    let counter = find(header, "PacketCounter").ok_or_else(|| {
        TrialError::at(
            origin,
            line,
            1,
            "expected a 'PacketCounter' column (sensors are aligned on it); export it from MT Manager",
        )
    })?;
    let gyro = gyro_columns(header, origin, line)?;
    let quat: Vec<String> = (0..4).map(|k| format!("Quat_q{k}")).collect();
    if let Some(fields) = find_all(header, &quat) {
        return Ok(Columns {
            counter,
            kind: OrientationColumns::Quaternion,
            fields,
            gyro,
        });
    }
    let mat: Vec<String> = (1..=3)
        .flat_map(|i| (1..=3).map(move |j| format!("Mat[{i}][{j}]")))
        .collect();
    if let Some(fields) = find_all(header, &mat) {
        return Ok(Columns {
            counter,
            kind: OrientationColumns::Matrix,
            fields,
            gyro,
        });
    }
    for names in [["Roll", "Pitch", "Yaw"], ["Euler_X", "Euler_Y", "Euler_Z"]] {
        let names: Vec<String> = names.iter().map(|s| s.to_string()).collect();
        if let Some(fields) = find_all(header, &names) {
            return Ok(Columns {
                counter,
                kind: OrientationColumns::Euler,
                fields,
                gyro,
            });
        }
    }
    Err(TrialError::at(
        origin,
        line,
        header.len() + 1,
        "no orientation columns: expected Quat_q0..Quat_q3, the nine Mat[i][j] or Roll Pitch Yaw",
    ))
}

/// `100.0Hz` of a `// Update Rate: 100.0Hz` comment.
fn rate_of_comment(comment: &str) -> Option<f64> {
    let (key, value) = comment.split_once(':')?;
    if !key.trim().eq_ignore_ascii_case("update rate") {
        return None;
    }
    let v = value.trim();
    let v = v
        .strip_suffix("Hz")
        .or_else(|| v.strip_suffix("hz"))
        .unwrap_or(v);
    // Any number: the trial's assembly checks it is a usable rate.
    v.trim().parse::<f64>().ok()
}

fn cell<'a>(
    cells: &[&'a str],
    k: usize,
    origin: &str,
    line: u64,
    what: &str,
) -> Result<&'a str, TrialError> {
    match cells.get(k) {
        Some(c) if !c.trim().is_empty() => Ok(c.trim()),
        Some(_) => Err(TrialError::at(
            origin,
            line,
            k + 1,
            format!("expected a number for {what}, found an empty cell"),
        )),
        None => Err(TrialError::at(
            origin,
            line,
            cells.len() + 1,
            format!(
                "too few fields: expected {what} in tab-separated field {}, found {} fields",
                k + 1,
                cells.len()
            ),
        )),
    }
}

fn number(
    cells: &[&str],
    k: usize,
    origin: &str,
    line: u64,
    what: &str,
) -> Result<f64, TrialError> {
    let c = cell(cells, k, origin, line, what)?;
    match c.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(TrialError::at(
            origin,
            line,
            k + 1,
            format!("expected a finite number for {what}, found {}", show(c)),
        )),
    }
}

/// Reads one export from its text; `origin` names the file in errors.
pub fn parse_export(text: &str, origin: &str) -> Result<XsensExport, TrialError> {
    let mut lines = LineIter::new(text);
    let mut rate_hz = None;
    let (header_line, header_text) = loop {
        let Some((n, l)) = lines.next_nonblank() else {
            return Err(TrialError::at(
                origin,
                lines.line_no().max(1),
                1,
                "no header: expected '// ...' comment lines then a tab-separated header with PacketCounter",
            ));
        };
        match l.trim_start().strip_prefix("//") {
            Some(c) => rate_hz = rate_hz.or_else(|| rate_of_comment(c)),
            None => break (n, l),
        }
    };
    let header: Vec<&str> = header_text.split('\t').map(str::trim).collect();
    let cols = columns(&header, origin, header_line)?;
    let mut out = XsensExport {
        origin: origin.to_string(),
        rate_hz,
        counters: Vec::new(),
        lines: Vec::new(),
        orientation: Vec::new(),
        columns: cols.kind,
        gyro: cols.gyro.map(|_| Vec::new()),
        renormalised: 0,
    };
    let mut last_raw: Option<(u64, u64)> = None;
    let mut wraps = 0u64;
    for (line, text) in lines.by_ref() {
        if text.trim().is_empty() || text.trim_start().starts_with("//") {
            continue;
        }
        let cells: Vec<&str> = text.split('\t').collect();
        let raw = counter_cell(&cells, cols.counter, origin, line)?;
        if let Some((prev, prev_line)) = last_raw {
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
                    wraps += 1;
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
        last_raw = Some((raw, line));
        let q = orientation(&cells, &cols, &header, origin, line, &mut out.renormalised)?;
        if let (Some(fields), Some(g)) = (cols.gyro, &mut out.gyro) {
            let [x, y, z] = fields.map(|k| number(&cells, k, origin, line, header[k]));
            g.push(Vector3::new(x?, y?, z?));
        }
        out.counters.push(raw + wraps * COUNTER_MODULUS);
        out.lines.push(line);
        out.orientation.push(q);
    }
    if out.counters.is_empty() {
        return Err(TrialError::at(
            origin,
            lines.line_no() + 1,
            1,
            format!("no samples: expected data rows after the header on line {header_line}"),
        ));
    }
    Ok(out)
}

fn counter_cell(cells: &[&str], k: usize, origin: &str, line: u64) -> Result<u64, TrialError> {
    let c = cell(cells, k, origin, line, "PacketCounter")?;
    match c.parse::<u64>() {
        Ok(v) if v < COUNTER_MODULUS => Ok(v),
        _ => Err(TrialError::at(
            origin,
            line,
            k + 1,
            format!("expected a packet counter 0..65535, found {}", show(c)),
        )),
    }
}

fn orientation(
    cells: &[&str],
    cols: &Columns,
    header: &[&str],
    origin: &str,
    line: u64,
    renormalised: &mut usize,
) -> Result<Quat, TrialError> {
    let mut v = [0.0f64; 9];
    for (slot, &k) in v.iter_mut().zip(&cols.fields) {
        *slot = number(cells, k, origin, line, header[k])?;
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
        assert_eq!(rate_of_comment(" Update Rate: 100.0Hz"), Some(100.0));
        assert_eq!(rate_of_comment(" Update Rate: 60 Hz"), Some(60.0));
        assert_eq!(rate_of_comment(" Filter Profile: human (46.1)"), None);
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
