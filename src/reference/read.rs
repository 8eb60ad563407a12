//! Reading (and, for tests and simulations, writing) optical references.
//!
//! * CSV: `time,<joint>_x,<joint>_y,<joint>_z,...`, seconds and degrees in the
//!   tool's own convention, any subset of joints and axes; `#` lines above the
//!   header are comments; an empty cell or `NaN` is a gap.
//! * OpenSim `.mot` (marker-based inverse kinematics): header lines up to
//!   `endheader` (`inDegrees=no` means radians), a label line `time <coordinate>...`,
//!   rows separated by tabs or spaces; each coordinate the model's
//!   `reference_coordinates` names becomes a joint axis, with its sign.
//! * C3D (Vicon, Qualisys): every point component `<label>.x|y|z` the model's
//!   `reference_coordinates` names (Plug-in Gait's `LKneeAngles`, `RHipAngles`,
//!   ...), or a point named as a joint (`r_knee`, its x, y, z the joint's);
//!   time is frames / point rate from 0 at the first frame; points with a negative
//!   residual are gaps.

use super::{Channel, Reference};
use crate::model::{Axis, Model};
use crate::trial::TrialError;
use std::path::Path;

/// A reference beside a trial that the workbench picks up: `<trial stem>.reference.{csv,mot,c3d}`.
pub const REFERENCE_BESIDE: &str = "reference";

/// The reference file beside a trial, if there is one:
/// `<trial stem>.reference.csv`, `.mot` or `.c3d` (in that order), the stem
/// being the trial's name without `.gz` and its format extension
/// (`walk.csv.gz` -> `walk.reference.csv`; a folder of exports: its name).
pub fn reference_beside(trial_path: &Path) -> Option<std::path::PathBuf> {
    let name = trial_path.file_name()?.to_string_lossy().into_owned();
    let name = name.strip_suffix(".gz").unwrap_or(&name);
    let stem = match name.rfind('.') {
        Some(i) if i > 0 && !trial_path.is_dir() => &name[..i],
        _ => name,
    };
    ["csv", "mot", "c3d"]
        .iter()
        .map(|ext| trial_path.with_file_name(format!("{stem}.{REFERENCE_BESIDE}.{ext}")))
        .find(|p| p.is_file())
}

/// Reads a reference, the format from the file name (`.csv`, `.mot`, `.c3d`).
pub fn read_reference(path: &Path, model: &Model) -> Result<Reference, TrialError> {
    let origin = path.display().to_string();
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let bytes =
        std::fs::read(path).map_err(|e| TrialError::file(&origin, format!("cannot read: {e}")))?;
    let reference = match ext.as_str() {
        "c3d" => read_c3d(&bytes, &origin, model)?,
        "csv" | "mot" | "sto" => {
            let text = String::from_utf8(bytes)
                .map_err(|e| TrialError::file(&origin, format!("expected UTF-8 text: {e}")))?;
            if ext == "csv" {
                read_csv(&text, &origin, model)?
            } else {
                read_mot(&text, &origin, model)?
            }
        }
        _ => return Err(TrialError::file(
            &origin,
            "unknown reference type: expected .csv (time,<joint>_x,...), .mot (OpenSim) or .c3d",
        )),
    };
    if reference.channels.is_empty() {
        let found = if reference.ignored.is_empty() {
            "no columns".to_string()
        } else {
            reference.ignored.join(", ")
        };
        return Err(TrialError::file(
            &origin,
            format!(
                "no joint axis of model {} in the reference (found {found}); expected <joint>_x|y|z columns or coordinates named in the model's [reference_coordinates]",
                model.name
            ),
        ));
    }
    Ok(reference)
}

/// `(joint, axis)` of a CSV column `<joint>_<x|y|z>` whose joint the model has.
fn csv_channel(model: &Model, label: &str) -> Option<(String, Axis)> {
    let (joint, axis) = label.rsplit_once('_')?;
    let axis = match axis.to_ascii_lowercase().as_str() {
        "x" => Axis::X,
        "y" => Axis::Y,
        "z" => Axis::Z,
        _ => return None,
    };
    let joint = model
        .joints
        .iter()
        .find(|j| j.name.eq_ignore_ascii_case(joint))?;
    Some((joint.name.clone(), axis))
}

fn number(cell: &str, origin: &str, line: u64, column: usize) -> Result<f64, TrialError> {
    let c = cell.trim();
    if c.is_empty() || c.eq_ignore_ascii_case("nan") {
        return Ok(f64::NAN);
    }
    match c.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        _ => Err(TrialError::at(
            origin,
            line,
            column,
            format!("expected a number (or an empty cell for a gap), found '{c}'"),
        )),
    }
}

/// Checks that times strictly increase; `line` numbers each row.
fn push_time(time: &mut Vec<f64>, t: f64, origin: &str, line: u64) -> Result<(), TrialError> {
    if t.is_nan() {
        return Err(TrialError::at(
            origin,
            line,
            1,
            "expected a time, found a gap",
        ));
    }
    if let Some(&prev) = time.last() {
        if t <= prev {
            return Err(TrialError::at(
                origin,
                line,
                1,
                format!("time {t} s does not increase (previous {prev} s)"),
            ));
        }
    }
    time.push(t);
    Ok(())
}

/// Rows of delimited numbers into a reference; `columns` holds, per field
/// after the time, the channel index it feeds and its sign.
fn fill_rows<'a>(
    rows: impl Iterator<Item = (u64, &'a str)>,
    split: fn(&str) -> Vec<&str>,
    columns: &[Option<(usize, f64)>],
    reference: &mut Reference,
) -> Result<(), TrialError> {
    let origin = reference.origin.clone();
    for (line, text) in rows {
        if text.trim().is_empty() {
            continue;
        }
        let cells = split(text);
        if cells.len() != columns.len() + 1 {
            return Err(TrialError::at(
                &origin,
                line,
                cells.len().min(columns.len() + 1),
                format!(
                    "expected {} fields (time and {} columns), found {}",
                    columns.len() + 1,
                    columns.len(),
                    cells.len()
                ),
            ));
        }
        let t = number(cells[0], &origin, line, 1)?;
        push_time(&mut reference.time_s, t, &origin, line)?;
        for (k, col) in columns.iter().enumerate() {
            if let Some((channel, sign)) = col {
                let v = number(cells[k + 1], &origin, line, k + 2)?;
                reference.channels[*channel].values_deg.push(sign * v);
            }
        }
    }
    if reference.time_s.is_empty() {
        return Err(TrialError::file(&origin, "no rows after the header"));
    }
    Ok(())
}

fn numbered(text: &str) -> impl Iterator<Item = (u64, &str)> {
    text.lines()
        .enumerate()
        .map(|(i, l)| (i as u64 + 1, l.strip_suffix('\r').unwrap_or(l)))
}

fn new_channel(joint: String, axis: Axis, source: String) -> Channel {
    Channel {
        joint,
        axis,
        source,
        values_deg: Vec::new(),
    }
}

fn read_csv(text: &str, origin: &str, model: &Model) -> Result<Reference, TrialError> {
    let mut lines = numbered(text);
    let (line, header) = lines
        .by_ref()
        .find(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .ok_or_else(|| {
            TrialError::at(
                origin,
                1,
                1,
                "empty file: expected a header time,<joint>_x,...",
            )
        })?;
    let labels: Vec<&str> = header.split(',').map(str::trim).collect();
    if !matches!(labels[0].to_ascii_lowercase().as_str(), "time" | "time_s") {
        return Err(TrialError::at(
            origin,
            line,
            1,
            format!(
                "expected the first column to be 'time' (seconds), found '{}'",
                labels[0]
            ),
        ));
    }
    let mut reference = Reference {
        origin: origin.to_string(),
        time_s: Vec::new(),
        channels: Vec::new(),
        ignored: Vec::new(),
    };
    let mut columns = Vec::new();
    for label in &labels[1..] {
        match csv_channel(model, label) {
            Some((joint, axis)) => {
                if reference
                    .channels
                    .iter()
                    .any(|c| c.joint == joint && c.axis == axis)
                {
                    return Err(TrialError::at(
                        origin,
                        line,
                        columns.len() + 2,
                        format!("column '{label}' repeats a joint axis"),
                    ));
                }
                columns.push(Some((reference.channels.len(), 1.0)));
                reference
                    .channels
                    .push(new_channel(joint, axis, label.to_string()));
            }
            None => {
                columns.push(None);
                reference.ignored.push(label.to_string());
            }
        }
    }
    fill_rows(lines, |l| l.split(',').collect(), &columns, &mut reference)?;
    Ok(reference)
}

fn split_whitespace_or_tab(l: &str) -> Vec<&str> {
    if l.contains('\t') {
        l.split('\t').collect()
    } else {
        l.split_whitespace().collect()
    }
}

fn read_mot(text: &str, origin: &str, model: &Model) -> Result<Reference, TrialError> {
    let mut lines = numbered(text);
    let mut in_degrees = true;
    let mut ended = false;
    for (_, l) in lines.by_ref() {
        let t = l.trim();
        if t.eq_ignore_ascii_case("endheader") {
            ended = true;
            break;
        }
        if let Some((k, v)) = t.split_once('=') {
            if k.trim().eq_ignore_ascii_case("inDegrees") {
                in_degrees = !v.trim().eq_ignore_ascii_case("no");
            }
        }
    }
    if !ended {
        return Err(TrialError::at(
            origin,
            1,
            1,
            "expected an OpenSim header ending in a line 'endheader'",
        ));
    }
    let (line, header) = lines
        .by_ref()
        .find(|(_, l)| !l.trim().is_empty())
        .ok_or_else(|| TrialError::file(origin, "no label line after endheader"))?;
    let labels: Vec<&str> = split_whitespace_or_tab(header)
        .into_iter()
        .map(str::trim)
        .collect();
    if !labels[0].eq_ignore_ascii_case("time") {
        return Err(TrialError::at(
            origin,
            line,
            1,
            format!(
                "expected the first label to be 'time', found '{}'",
                labels[0]
            ),
        ));
    }
    let scale = if in_degrees {
        1.0
    } else {
        180.0 / std::f64::consts::PI
    };
    let mut reference = Reference {
        origin: origin.to_string(),
        time_s: Vec::new(),
        channels: Vec::new(),
        ignored: Vec::new(),
    };
    let mut columns = Vec::new();
    for label in &labels[1..] {
        match model.reference_target(label) {
            Some(t) => {
                let sign = if t.negated { -scale } else { scale };
                columns.push(Some((reference.channels.len(), sign)));
                let source = format!("{}{label}", if t.negated { "-" } else { "" });
                reference
                    .channels
                    .push(new_channel(t.joint, t.axis, source));
            }
            None => {
                columns.push(None);
                reference.ignored.push(label.to_string());
            }
        }
    }
    fill_rows(lines, split_whitespace_or_tab, &columns, &mut reference)?;
    Ok(reference)
}

fn read_c3d(bytes: &[u8], origin: &str, model: &Model) -> Result<Reference, TrialError> {
    // The parser indexes its input without checking every length; a damaged
    // file becomes an error here, not a crash.
    // The panic message is not for the user: the hook is silenced meanwhile
    // and put back after.
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let parsed =
        std::panic::catch_unwind(|| c3dio::C3d::from_bytes(bytes).map_err(|e| format!("{e:?}")));
    std::panic::set_hook(hook);
    let c3d = match parsed {
        Ok(Ok(c)) => c,
        Ok(Err(e)) => {
            return Err(TrialError::file(origin, format!("invalid C3D: {e}")));
        }
        Err(_) => return Err(TrialError::file(origin, "invalid C3D: damaged file")),
    };
    let points = &c3d.points;
    let rate = f64::from(points.frame_rate);
    if !(rate.is_finite() && rate > 0.0) {
        return Err(TrialError::file(
            origin,
            format!("expected a positive point rate, found {rate} Hz"),
        ));
    }
    let frames = points.rows();
    let mut reference = Reference {
        origin: origin.to_string(),
        time_s: (0..frames).map(|i| i as f64 / rate).collect(),
        channels: Vec::new(),
        ignored: Vec::new(),
    };
    for (col, label) in points.labels.iter().enumerate().take(points.cols()) {
        let label = label.trim();
        let joint = model
            .joints
            .iter()
            .find(|j| j.name.eq_ignore_ascii_case(label));
        let mut used = false;
        for (k, c) in ["x", "y", "z"].iter().enumerate() {
            let target = match joint {
                Some(j) => Some((j.name.clone(), Axis::ALL[k], false)),
                None => model
                    .reference_target(&format!("{label}.{c}"))
                    .map(|t| (t.joint, t.axis, t.negated)),
            };
            let Some((joint, axis, negated)) = target else {
                continue;
            };
            used = true;
            let sign = if negated { -1.0 } else { 1.0 };
            let values = (0..frames)
                .map(|f| {
                    let p = &points[f][col];
                    if p.residual < 0.0 {
                        f64::NAN
                    } else {
                        sign * f64::from(p.point[k])
                    }
                })
                .collect();
            reference.channels.push(Channel {
                joint,
                axis,
                source: format!("{}{label}.{c}", if negated { "-" } else { "" }),
                values_deg: values,
            });
        }
        if !used {
            reference.ignored.push(label.to_string());
        }
    }
    Ok(reference)
}

/// Writes a reference CSV: `time` then one column per `(name, values)`, degrees.
pub fn write_csv(
    path: &Path,
    time_s: &[f64],
    columns: &[(String, Vec<f64>)],
) -> std::io::Result<()> {
    let mut out = String::from("time");
    for (name, _) in columns {
        out.push(',');
        out.push_str(name);
    }
    out.push('\n');
    for (i, t) in time_s.iter().enumerate() {
        out.push_str(&t.to_string());
        for (_, v) in columns {
            out.push(',');
            out.push_str(&v[i].to_string());
        }
        out.push('\n');
    }
    crate::save::atomic_write(path, out.as_bytes())
}

/// Writes an OpenSim `.mot` of coordinates in degrees (`inDegrees=yes`).
pub fn write_mot(
    path: &Path,
    time_s: &[f64],
    columns: &[(String, Vec<f64>)],
) -> std::io::Result<()> {
    let mut out = format!(
        "Coordinates\nversion=1\nnRows={}\nnColumns={}\ninDegrees=yes\nendheader\ntime",
        time_s.len(),
        columns.len() + 1
    );
    for (name, _) in columns {
        out.push('\t');
        out.push_str(name);
    }
    out.push('\n');
    for (i, t) in time_s.iter().enumerate() {
        out.push_str(&t.to_string());
        for (_, v) in columns {
            out.push('\t');
            out.push_str(&v[i].to_string());
        }
        out.push('\n');
    }
    crate::save::atomic_write(path, out.as_bytes())
}

/// Writes a C3D holding one point per `(label, [x, y, z])` (degrees, as
/// Plug-in Gait stores its angles) at `rate_hz`, first frame 1.
pub fn write_c3d(
    path: &Path,
    rate_hz: f64,
    points: &[(String, [Vec<f64>; 3])],
) -> Result<(), String> {
    let frames = points.first().map_or(0, |(_, p)| p[0].len());
    let mut c3d = c3dio::C3d::new();
    // The writer looks every section's group up, data or none.
    for group in [
        "POINT",
        "ANALOG",
        "FORCE_PLATFORM",
        "EVENT",
        "EVENT_CONTEXT",
        "MANUFACTURER",
        "SEG",
    ] {
        c3d.parameters.insert_group(group, String::new());
    }
    let mut grid = grid::Grid::new(frames, points.len());
    for (col, (_, xyz)) in points.iter().enumerate() {
        for f in 0..frames {
            grid[f][col] =
                c3dio::MarkerPoint::new(xyz[0][f] as f32, xyz[1][f] as f32, xyz[2][f] as f32);
        }
    }
    c3d.points.points = grid;
    c3d.points.labels = points.iter().map(|(l, _)| l.clone()).collect();
    c3d.points.descriptions = points.iter().map(|_| "angle".to_string()).collect();
    c3d.points.units = ['d', 'e', 'g', ' '];
    c3d.points.frame_rate = rate_hz as f32;
    c3d.points.scale_factor = 1.0;
    c3d.points.format = c3dio::DataFormat::Float;
    c3d.points.first_frame = 1;
    c3d.points.last_frame = frames as u16;
    c3d.write_path(path.to_path_buf())
        .map(|_| ())
        .map_err(|e| format!("{}: cannot write C3D: {e:?}", path.display()))
}
