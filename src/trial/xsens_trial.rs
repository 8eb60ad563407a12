//! A trial made of Xsens exports (one file per sensor), aligned on the packet counter.
//!
//! A trial is named by its mapping XML ([`super::mapping`]) or by a folder of
//! exports. The mapping's exports are looked for beside the XML, then in its
//! immediate subfolders (OpenSense's example keeps them in `IMUData/`). A folder
//! uses a mapping XML inside it, else one in its parent folder whose exports it
//! holds, else names each sensor by its serial (the file name after its last `_`).
//!
//! Sensors are aligned on the unwrapped packet counter: only packets every
//! sensor recorded are kept (as OpenSense does), time is
//! `(counter - first kept counter) / rate` in seconds, and packets a sensor
//! lacks become gaps in the time vector, each one reported. Gyroscope columns
//! (`Gyr_X Gyr_Y Gyr_Z`, rad/s, sensor frame) are aligned the same way.

use super::mapping::{looks_like_mapping, parse_mapping, sensor_to_opensim, Mapping};
use super::precision::Decimals;
use super::xsens::{parse_export, ExportReader, XsensExport, COUNTER_MODULUS};
use super::{ImuSeries, Trial, TrialError};
use crate::model::Model;
use crate::rotation::Quat;
use std::path::{Path, PathBuf};

/// The files of an Xsens trial and the names of their sensors.
#[derive(Debug, Clone)]
pub struct XsensSource {
    /// The mapping used, with its path.
    pub mapping: Option<(PathBuf, Mapping)>,
    /// The mapping's text as read (empty without a mapping): the first part
    /// of what the trial's hash covers.
    pub mapping_text: String,
    /// Export files with the IMU name each stands for (as found, before aliases).
    pub files: Vec<(PathBuf, String)>,
}

fn read_text(path: &Path) -> Result<String, TrialError> {
    crate::input::read_text(path)
        .map_err(|e| TrialError::file(path.display().to_string(), format!("cannot read: {e}")))
}

/// True when `path` is an XML file holding an OpenSense Xsens mapping.
pub fn is_mapping_file(path: &Path) -> bool {
    let xml = crate::file_names::is_mapping_name(path);
    xml && path.is_file() && head(path, 1 << 16).is_some_and(|t| looks_like_mapping(&t))
}

/// The first `limit` bytes of a file as text (lossy), if it can be read.
fn head(path: &Path, limit: u64) -> Option<String> {
    use std::io::Read;
    let mut buf = Vec::new();
    std::fs::File::open(path)
        .ok()?
        .take(limit)
        .read_to_end(&mut buf)
        .ok()?;
    Some(String::from_utf8_lossy(&buf).into_owned())
}

/// True when `path` is a `.txt` or `.csv` file that starts like an MT Manager
/// export (a `//` comment, or a header with a packet counter column).
pub fn is_export_file(path: &Path) -> bool {
    let ext = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("txt") || e.eq_ignore_ascii_case("csv"));
    ext && path.is_file() && head(path, 4096).is_some_and(|t| starts_like_export(&t))
}

/// The text's first non-blank line is a `//` comment or names a packet counter.
fn starts_like_export(text: &str) -> bool {
    let first = text
        .trim_start_matches('\u{feff}')
        .lines()
        .find(|l| !l.trim().is_empty())
        .unwrap_or("");
    let lower = first.to_ascii_lowercase();
    first.trim_start().starts_with("//")
        || lower.contains("packetcounter")
        || lower.contains("packet counter")
}

/// [`is_export_file`]'s look at a file, on its bytes: they start like an export.
pub(crate) fn starts_like_export_bytes(bytes: &[u8]) -> bool {
    starts_like_export(&String::from_utf8_lossy(&bytes[..bytes.len().min(4096)]))
}

/// The serial an export's file name ends in (after its last `_`).
fn serial_of(path: &Path) -> String {
    let stem = path
        .file_stem()
        .unwrap_or_default()
        .to_string_lossy()
        .into_owned();
    stem.rsplit('_').next().unwrap_or(&stem).to_string()
}

fn sorted_entries(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|rd| rd.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    v.sort();
    v
}

/// True when `dir` is a folder holding at least one Xsens export.
pub fn is_export_folder(dir: &Path) -> bool {
    dir.is_dir() && sorted_entries(dir).iter().any(|p| is_export_file(p))
}

/// The folders a mapping at `xml` reads its exports from: where its first
/// sensor's export is, beside the XML or in an immediate subfolder.
fn export_folder(xml: &Path, mapping: &Mapping) -> Option<PathBuf> {
    let dir = xml.parent().unwrap_or(Path::new("."));
    let dir = if dir.as_os_str().is_empty() {
        Path::new(".")
    } else {
        dir
    };
    let first = format!("{}{}", mapping.trial_prefix, mapping.sensors[0].file_suffix);
    std::iter::once(dir.to_path_buf())
        .chain(sorted_entries(dir).into_iter().filter(|p| p.is_dir()))
        .find(|d| export_in(d, &first).is_file())
}

/// The export `<stem>.txt` in `dir`, or `<stem>.csv` when only that exists.
fn export_in(dir: &Path, stem: &str) -> PathBuf {
    let txt = dir.join(format!("{stem}.txt"));
    let csv = dir.join(format!("{stem}.csv"));
    if !txt.is_file() && csv.is_file() {
        csv
    } else {
        txt
    }
}

/// True when `name` names a file in a folder, not a path out of it.
fn is_plain_file_name(name: &str) -> bool {
    !name.is_empty()
        && name != "."
        && name != ".."
        && !name.contains(['/', '\\', '\0'])
        && !name.contains(':')
}

/// Every export a mapping names is a plain file name (trial_prefix + name +
/// `.txt`), so that a mapping never reads files outside its folders.
fn check_export_names(xml: &Path, mapping: &Mapping) -> Result<(), TrialError> {
    for s in &mapping.sensors {
        let file = format!("{}{}", mapping.trial_prefix, s.file_suffix);
        if !is_plain_file_name(&file) {
            return Err(TrialError::at(
                xml.display().to_string(),
                s.line,
                1,
                format!(
                    "sensor '{}': export name {file:?} (trial_prefix + name) leaves the mapping's folder; expected a plain file name",
                    s.file_suffix
                ),
            ));
        }
    }
    Ok(())
}

fn files_of_mapping(
    xml: &Path,
    mapping: &Mapping,
    folder: &Path,
) -> Result<Vec<(PathBuf, String)>, TrialError> {
    mapping
        .sensors
        .iter()
        .map(|s| {
            let f = export_in(
                folder,
                &format!("{}{}", mapping.trial_prefix, s.file_suffix),
            );
            if f.is_file() {
                Ok((f, s.name_in_model.clone()))
            } else {
                Err(TrialError::at(
                    xml.display().to_string(),
                    s.line,
                    1,
                    format!(
                        "sensor '{}' ({}): expected its export {} (trial_prefix + name + .txt)",
                        s.file_suffix,
                        s.name_in_model,
                        f.display()
                    ),
                ))
            }
        })
        .collect()
}

/// Reads the mapping at `xml` and finds its exports.
fn resolve_mapping(xml: &Path) -> Result<XsensSource, TrialError> {
    let origin = xml.display().to_string();
    let mapping_text = read_text(xml)?;
    let mapping = parse_mapping(&mapping_text, &origin)?;
    check_export_names(xml, &mapping)?;
    let folder = export_folder(xml, &mapping).ok_or_else(|| {
        let s = &mapping.sensors[0];
        TrialError::at(
            &origin,
            s.line,
            1,
            format!(
                "expected the export {}{}.txt beside the mapping or in a folder next to it",
                mapping.trial_prefix, s.file_suffix
            ),
        )
    })?;
    let files = files_of_mapping(xml, &mapping, &folder)?;
    Ok(XsensSource {
        mapping: Some((xml.to_path_buf(), mapping)),
        mapping_text,
        files,
    })
}

/// A mapping (in `dir` or its parent) whose exports are in `dir`.
fn mapping_for_folder(dir: &Path) -> Option<PathBuf> {
    let parent = dir.parent().filter(|p| !p.as_os_str().is_empty());
    let candidates = sorted_entries(dir)
        .into_iter()
        .chain(parent.map(sorted_entries).unwrap_or_default());
    for xml in candidates.filter(|p| is_mapping_file(p)) {
        let Ok(text) = crate::input::read_text(&xml) else {
            continue;
        };
        let Ok(m) = parse_mapping(&text, "") else {
            continue;
        };
        if check_export_names(&xml, &m).is_err() {
            continue;
        }
        let first = format!("{}{}", m.trial_prefix, m.sensors[0].file_suffix);
        if export_in(dir, &first).is_file() {
            return Some(xml);
        }
    }
    None
}

/// Resolves an Xsens trial path: a mapping XML, a folder of exports, or a
/// single export (a trial of one IMU, named as a mapping beside it names it,
/// else by its serial).
pub fn resolve(path: &Path) -> Result<XsensSource, TrialError> {
    if !path.is_dir() {
        let xml = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("xml"));
        if xml || !path.is_file() {
            return resolve_mapping(path);
        }
        return Ok(single_export(path));
    }
    if let Some(xml) = mapping_for_folder(path) {
        let mut source = resolve_mapping(&xml)?;
        let inside = source.files.iter().all(|(f, _)| f.parent() == Some(path));
        if inside {
            return Ok(source);
        }
        source.files.retain(|(f, _)| f.parent() == Some(path));
    }
    let files: Vec<(PathBuf, String)> = sorted_entries(path)
        .into_iter()
        .filter(|p| is_export_file(p))
        .map(|p| {
            let serial = serial_of(&p);
            (p, serial)
        })
        .collect();
    if files.is_empty() {
        return Err(TrialError::file(
            path.display().to_string(),
            "no Xsens exports: expected MT Manager .txt exports (// comments, a header with PacketCounter) in this folder",
        ));
    }
    Ok(XsensSource {
        mapping: None,
        mapping_text: String::new(),
        files,
    })
}

/// One export as a trial: its IMU named by a mapping in its folder (or the
/// folder above) that lists it, else by its serial.
fn single_export(path: &Path) -> XsensSource {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let file = path.file_name().map(|n| n.to_string_lossy().into_owned());
    let named = [dir.to_path_buf(), dir.join("..")]
        .into_iter()
        .filter(|d| d.is_dir())
        .flat_map(|d| sorted_entries(&d))
        .filter(|p| is_mapping_file(p))
        .find_map(|xml| {
            let text = std::fs::read_to_string(&xml).ok()?;
            let m = parse_mapping(&text, "").ok()?;
            let s = m.sensors.iter().find(|s| {
                let stem = format!("{}{}", m.trial_prefix, s.file_suffix);
                [".txt", ".csv"]
                    .map(|e| format!("{stem}{e}"))
                    .iter()
                    .any(|n| file.as_deref() == Some(n.as_str()))
            })?;
            let name = s.name_in_model.clone();
            Some((xml, name, m, text))
        });
    match named {
        Some((xml, name, m, text)) => XsensSource {
            mapping: Some((xml, m)),
            mapping_text: text,
            files: vec![(path.to_path_buf(), name)],
        },
        None => XsensSource {
            mapping: None,
            mapping_text: String::new(),
            files: vec![(path.to_path_buf(), serial_of(path))],
        },
    }
}

/// The IMU names of an Xsens trial, as found (before aliases), without reading the data.
pub fn imu_names(path: &Path) -> Result<Vec<String>, TrialError> {
    Ok(resolve(path)?.files.into_iter().map(|(_, n)| n).collect())
}

/// Reads an Xsens trial (mapping XML, folder or single export): exports
/// parsed, aligned on the packet counter, rotated by the mapping's
/// `sensor_to_opensim_rotations` if any, IMU names mapped through `model`'s
/// aliases. `Trial::name` is the path's last component.
pub fn read_xsens_trial(path: &Path, model: &Model) -> Result<Trial, TrialError> {
    super::TrialFile::read(path)?.trial(model)
}

/// The trial of the exports of `source` (read as `exports`, in the order of
/// its files) named by `path`.
pub(crate) fn trial_of_exports(
    path: &Path,
    source: &XsensSource,
    exports: &[Vec<u8>],
    model: &Model,
) -> Result<Trial, TrialError> {
    check_some_imu(path, source, model)?;
    let mut parsed = Vec::with_capacity(source.files.len());
    for ((f, name), bytes) in source.files.iter().zip(exports) {
        let origin = f.display().to_string();
        let text = crate::input::str_of(bytes)
            .map_err(|e| TrialError::at(&origin, e.line, e.column, e.error.to_string()))?;
        parsed.push((name.clone(), parse_export(text, &origin)?));
    }
    assemble(&trial_name(path), parsed, rotation_of(source), model)
}

/// The name of the trial at `path`: its last component.
fn trial_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| path.display().to_string())
}

/// The mapping's `sensor_to_opensim_rotations`, if any.
fn rotation_of(source: &XsensSource) -> Option<Quat> {
    source
        .mapping
        .as_ref()
        .and_then(|(_, m)| m.sensor_to_opensim_rad)
        .map(sensor_to_opensim)
}

/// An error when no export of a trial of several (or of a folder) names an
/// IMU of `model`.
fn check_some_imu(path: &Path, source: &XsensSource, model: &Model) -> Result<(), TrialError> {
    let single = source.files.len() == 1 && source.files[0].0 == path;
    if !single
        && source
            .files
            .iter()
            .all(|(_, n)| model.canonical_imu(n).is_none())
    {
        return Err(no_imu_error(path, source, model));
    }
    Ok(())
}

/// Exports still being written (one per sensor, each appended to), aligned
/// as they grow: the packets every sensor recorded, in counter order, as
/// soon as every sensor has written past them, so that the rows handed
/// out are those [`read_xsens_trial`] keeps of the finished exports, with
/// the same times and orientations.
///
/// Two things are fixed when the first rows are handed out and not
/// revisited: the wrap shifts (from each file's first counter, as the
/// whole-file reader finds them) and the rate: the exports' `Update Rate`
/// comment, else `SampleTimeFine` over the rows read by then (at least
/// [`GROWING_RATE_ROWS`] per file), where the whole-file reader takes it
/// over the whole export.
pub struct GrowingExports {
    name: String,
    files: Vec<(PathBuf, String)>,
    readers: Vec<ExportReader>,
    rotation: Option<Quat>,
    model: Model,
    aligned: Option<Alignment>,
}

/// Rows each export has before a rate is taken from its `SampleTimeFine`.
pub const GROWING_RATE_ROWS: usize = 16;

/// What the first rows fixed.
struct Alignment {
    rate_hz: f64,
    /// Added to each file's counters.
    shifts: Vec<u64>,
    /// The first packet every sensor may share.
    start: u64,
    /// Next row of the first file to look at.
    next: usize,
    /// Per file, the row the last shared packet was found at.
    pos: Vec<usize>,
}

impl GrowingExports {
    /// The exports of `source` (the trial named by `path`), read as their
    /// lines arrive ([`GrowingExports::push_lines`]); an error when none of
    /// them names an IMU of `model`.
    pub fn new(path: &Path, source: &XsensSource, model: &Model) -> Result<Self, TrialError> {
        check_some_imu(path, source, model)?;
        Ok(GrowingExports {
            name: trial_name(path),
            files: source.files.clone(),
            readers: (source.files.iter())
                .map(|(f, _)| ExportReader::new(&f.display().to_string()))
                .collect(),
            rotation: rotation_of(source),
            model: model.clone(),
            aligned: None,
        })
    }

    /// Reads the complete lines `text` of export `k` (in the source's
    /// order), whose first is 1-based line `first_line` of that file.
    pub fn push_lines(&mut self, k: usize, text: &str, first_line: u64) -> Result<(), TrialError> {
        self.readers[k].push_lines(text, first_line)
    }

    /// Whether every export's header line was read.
    pub fn headers_read(&self) -> bool {
        self.readers.iter().all(ExportReader::has_header)
    }

    /// The rows every sensor has written since the last call, aligned on
    /// the packet counter, as a trial of those samples (`None`: no new row).
    pub fn aligned(&mut self) -> Result<Option<Trial>, TrialError> {
        if self.aligned.is_none() {
            let Some(a) = self.first_alignment()? else {
                return Ok(None);
            };
            self.aligned = Some(a);
        }
        let Some(a) = self.aligned.as_mut() else {
            return Ok(None);
        };
        let exports: Vec<&XsensExport> = self.readers.iter().map(ExportReader::export).collect();
        let shifts = a.shifts.clone();
        let shifted = |k: usize, i: usize| exports[k].counters[i] + shifts[k];
        // Every sensor has written past this packet: what it lacks, it lacks.
        let end = (0..exports.len())
            .map(|k| shifted(k, exports[k].counters.len() - 1))
            .min()
            .unwrap_or(0);
        let mut kept: Vec<SharedPacket> = Vec::new();
        while a.next < exports[0].counters.len() {
            let c = shifted(0, a.next);
            if c > end {
                break;
            }
            a.next += 1;
            if c < a.start {
                continue;
            }
            let mut idx = Vec::with_capacity(exports.len());
            for (k, e) in exports.iter().enumerate() {
                while a.pos[k] < e.counters.len() && shifted(k, a.pos[k]) < c {
                    a.pos[k] += 1;
                }
                if a.pos[k] < e.counters.len() && shifted(k, a.pos[k]) == c {
                    idx.push(a.pos[k]);
                }
            }
            if idx.len() == exports.len() {
                kept.push((c, idx));
            }
        }
        if kept.is_empty() {
            return Ok(None);
        }
        let view: Vec<(&str, &XsensExport)> = (self.files.iter())
            .zip(&exports)
            .map(|((_, n), e)| (n.as_str(), *e))
            .collect();
        let mut ignored = Vec::new();
        let imus = imu_series(&view, &kept, self.rotation, &self.model, &mut ignored)?;
        let time_s = kept
            .iter()
            .map(|(c, _)| (c - a.start) as f64 / a.rate_hz)
            .collect();
        Ok(Some(Trial {
            name: self.name.clone(),
            time_s,
            imus,
            warnings: vec![],
            orientation_decimals: merged(self.readers.iter().map(ExportReader::decimals)),
        }))
    }

    /// The rate and wrap shifts, once every export has its header and a
    /// first row (and, for a rate from `SampleTimeFine`, enough rows).
    fn first_alignment(&self) -> Result<Option<Alignment>, TrialError> {
        let exports: Vec<&XsensExport> = self.readers.iter().map(ExportReader::export).collect();
        if !self.headers_read() || exports.iter().any(|e| e.counters.is_empty()) {
            return Ok(None);
        }
        let commented = exports.iter().any(|e| e.rate_hz.is_some());
        let rows = exports.iter().map(|e| e.counters.len()).min().unwrap_or(0);
        if !commented && rows < GROWING_RATE_ROWS {
            return Ok(None);
        }
        // The exports' rates as the whole-file reader weighs them.
        let heads: Vec<(String, XsensExport)> = (self.readers.iter())
            .map(|r| {
                let e = r.export();
                let head = XsensExport {
                    origin: e.origin.clone(),
                    rate_hz: e.rate_hz,
                    rate_at: e.rate_at,
                    sample_time_rate_hz: r.sample_time_rate_hz(),
                    coordinate_system: None,
                    delimiter: e.delimiter,
                    counters: vec![],
                    lines: vec![],
                    orientation: vec![],
                    columns: e.columns,
                    gyro: None,
                    renormalised: 0,
                    decimals: None,
                };
                (String::new(), head)
            })
            .collect();
        let rate_hz = common_rate(&heads)?;
        let firsts: Vec<u64> = exports.iter().map(|e| e.counters[0]).collect();
        let shifts = wrap_shifts(&firsts);
        let start = firsts
            .iter()
            .zip(&shifts)
            .map(|(c, s)| c + s)
            .max()
            .unwrap_or(0);
        Ok(Some(Alignment {
            rate_hz,
            shifts,
            start,
            next: 0,
            pos: vec![0; exports.len()],
        }))
    }
}

/// The error for a folder or mapping none of whose sensors is an IMU of
/// `model`: the names found and, without a mapping, the mapping XML to write.
fn no_imu_error(path: &Path, source: &XsensSource, model: &Model) -> TrialError {
    let names: Vec<&str> = source.files.iter().map(|(_, n)| n.as_str()).collect();
    let others: Vec<&str> = crate::model::BUILTIN_MODELS
        .iter()
        .filter_map(|(n, _)| {
            let m = Model::builtin(n).ok()?;
            (m.name != model.name && names.iter().any(|i| m.canonical_imu(i).is_some()))
                .then_some(*n)
        })
        .collect();
    let hint = if others.is_empty() {
        String::new()
    } else {
        format!(" (model {} knows them: pass --model)", others.join(", "))
    };
    let imus = model.imus.join(", ");
    let Some((xml, _)) = &source.mapping else {
        let dir = if path.is_dir() {
            path
        } else {
            path.parent().unwrap_or(Path::new("."))
        };
        return TrialError::file(
            path.display().to_string(),
            format!(
                "no sensor maps to an IMU of model {}{hint}: found {} exports named by serial ({}) and no mapping XML beside them or in the folder above. Write {} (each name_in_model one of {imus}):\n{}",
                model.name,
                names.len(),
                names.join(", "),
                dir.join("myIMUMappings.xml").display(),
                mapping_template(&source.files)
            ),
        );
    };
    TrialError::file(
        xml.display().to_string(),
        format!(
            "no sensor maps to an IMU of model {}{hint}: the mapping's name_in_model values are {}; expected IMUs of the model ({imus}) or its aliases",
            model.name,
            names.join(", ")
        ),
    )
}

/// An OpenSense mapping XML for these exports, `name_in_model` left to fill in.
fn mapping_template(files: &[(PathBuf, String)]) -> String {
    let prefix = files
        .first()
        .and_then(|(f, serial)| {
            let stem = f.file_stem()?.to_string_lossy().into_owned();
            Some(
                stem.strip_suffix(serial.as_str())?
                    .trim_end_matches('_')
                    .to_string(),
            )
        })
        .unwrap_or_default();
    let mut xml = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\" ?>\n<OpenSimDocument Version=\"40000\">\n  <XsensDataReaderSettings>\n    <trial_prefix>{prefix}</trial_prefix>\n    <ExperimentalSensors>\n"
    );
    for (_, serial) in files {
        xml.push_str(&format!(
            "      <ExperimentalSensor name=\"_{serial}\">\n        <name_in_model>?</name_in_model>\n      </ExperimentalSensor>\n"
        ));
    }
    xml.push_str("    </ExperimentalSensors>\n  </XsensDataReaderSettings>\n</OpenSimDocument>");
    xml
}

/// Counters shifted by whole wraps so that every file starts within half a
/// wrap of the first file's start (files of one recording start together).
fn align_wraps(exports: &mut [(String, XsensExport)]) {
    let firsts: Vec<u64> = exports.iter().map(|(_, e)| e.counters[0]).collect();
    for ((_, e), s) in exports.iter_mut().zip(wrap_shifts(&firsts)) {
        e.counters.iter_mut().for_each(|c| *c += s);
    }
}

/// What [`align_wraps`] adds to each file's counters, from each file's
/// first (unwrapped) counter.
fn wrap_shifts(firsts: &[u64]) -> Vec<u64> {
    let Some(&reference) = firsts.first() else {
        return vec![];
    };
    let m = COUNTER_MODULUS as i128;
    let shifts: Vec<i128> = firsts
        .iter()
        .map(|&c| ((reference as i128 - c as i128) as f64 / m as f64).round() as i128 * m)
        .collect();
    let lowest = shifts.iter().copied().min().unwrap_or(0);
    shifts.into_iter().map(|s| (s - lowest) as u64).collect()
}

fn common_rate(exports: &[(String, XsensExport)]) -> Result<f64, TrialError> {
    let mut rate: Option<(f64, &str)> = None;
    for (_, e) in exports {
        if let Some(r) = e.rate_hz {
            check_rate(r, &e.origin, e.rate_at)?;
            match rate {
                None => rate = Some((r, &e.origin)),
                Some((r0, o0)) if (r - r0).abs() > 1e-9 * r0 => {
                    return Err(TrialError::at(
                        &e.origin,
                        e.rate_at.0,
                        e.rate_at.1,
                        format!("update rate {r} Hz differs from {r0} Hz of {o0}; expected one rate for all sensors"),
                    ))
                }
                _ => {}
            }
        }
    }
    if let Some((r, _)) = rate {
        return Ok(r);
    }
    // No `Update Rate` comment anywhere: the first export's SampleTimeFine.
    let found = exports
        .iter()
        .find_map(|(_, e)| Some((e.sample_time_rate_hz?, &e.origin)));
    if let Some((r, origin)) = found {
        // Derived from the SampleTimeFine column, not from one place.
        check_rate(r, origin, (0, 0)).map_err(|mut e| {
            e.message = format!("SampleTimeFine steps give an {}", e.message);
            e
        })?;
    }
    found
        .map(|(r, _)| r)
        .ok_or_else(|| {
            TrialError::at(
                &exports[0].1.origin,
                1,
                1,
                "no update rate: expected a comment line '// Update Rate: <Hz>' or a filled-in SampleTimeFine column in at least one export",
            )
        })
}

/// A warning when an export says its global frame is not Z-up.
fn frame_warning(exports: &[(String, XsensExport)]) -> Option<String> {
    exports.iter().find_map(|(_, e)| {
        let system = e.coordinate_system.as_deref()?;
        (system == "NED").then(|| {
            format!(
                "{} says 'Coordinate system: NED' (Z down): pass --vertical z-down",
                file_name(&e.origin)
            )
        })
    })
}

/// The update rate of an export is a rate a trial can have: finite, with a
/// sample interval within the bounds every reader keeps to.
/// `at`: line and column of the value the rate came from.
fn check_rate(rate_hz: f64, origin: &str, at: (u64, usize)) -> Result<(), TrialError> {
    use crate::trial::timing::{MAX_MEDIAN_DT_S, MIN_MEDIAN_DT_S};
    let (lo, hi) = (1.0 / MAX_MEDIAN_DT_S, (1.0 / MIN_MEDIAN_DT_S).round());
    if rate_hz.is_finite() && (lo..=hi).contains(&rate_hz) {
        return Ok(());
    }
    Err(TrialError::at(
        origin,
        at.0,
        at.1,
        format!(
            "update rate {} Hz: expected a finite rate from one sample an hour to {hi} Hz (a sample interval between {MIN_MEDIAN_DT_S} s and {MAX_MEDIAN_DT_S} s)",
            if (1e-3..1e7).contains(&rate_hz.abs()) {
                rate_hz.to_string()
            } else {
                format!("{rate_hz:e}")
            }
        ),
    ))
}

/// Runs of counters missing inside a file, as `(first missing, count)`.
fn missing_runs(counters: &[u64]) -> Vec<(u64, u64)> {
    counters
        .windows(2)
        .filter(|w| w[1] > w[0] + 1)
        .map(|w| (w[0] + 1, w[1] - w[0] - 1))
        .collect()
}

/// Aligns parsed exports into one trial.
pub(crate) fn assemble(
    name: &str,
    mut exports: Vec<(String, XsensExport)>,
    rotation: Option<Quat>,
    model: &Model,
) -> Result<Trial, TrialError> {
    let rate = common_rate(&exports)?;
    align_wraps(&mut exports);
    let (start, end, kept) = shared_packets(&exports)?;
    let mut warnings: Vec<String> = frame_warning(&exports).into_iter().collect();
    warnings.extend(coverage_warnings(&exports, start, end, kept.len()));
    let view: Vec<(&str, &XsensExport)> = exports.iter().map(|(n, e)| (n.as_str(), e)).collect();
    let imus = imu_series(&view, &kept, rotation, model, &mut warnings)?;
    let time_s: Vec<f64> = kept
        .iter()
        .map(|(c, _)| (c - start) as f64 / rate)
        .collect();
    if let Err((i, message)) = crate::trial::timing::check_time_axis(&time_s) {
        return Err(TrialError::file(
            exports[0].1.origin.clone(),
            format!("packet {}: {message}", kept[i].0),
        ));
    }
    Ok(Trial {
        name: name.to_string(),
        time_s,
        imus,
        warnings,
        orientation_decimals: merged(exports.iter().map(|(_, e)| e.decimals)),
    })
}

/// The decimal places of a trial's exports' orientation numbers, as if
/// read from one file.
fn merged(mut each: impl Iterator<Item = Option<Decimals>>) -> Option<Decimals> {
    let first = each.next()?;
    each.fold(first, Decimals::merge)
}

/// A packet every export recorded: its counter and its index in each export.
type SharedPacket = (u64, Vec<usize>);

/// The packets every export recorded, between the latest first counter
/// (`start`) and the earliest last one (`end`); an error when there are none.
fn shared_packets(
    exports: &[(String, XsensExport)],
) -> Result<(u64, u64, Vec<SharedPacket>), TrialError> {
    let start = exports
        .iter()
        .map(|(_, e)| e.counters[0])
        .max()
        .unwrap_or(0);
    let end = exports
        .iter()
        .map(|(_, e)| *e.counters.last().unwrap_or(&0))
        .min()
        .unwrap_or(0);
    if start > end {
        return Err(TrialError::file(
            exports[0].1.origin.clone(),
            format!("the sensors share no packet: their counters cover {start} and {end} apart; expected exports of one recording"),
        ));
    }
    // Indices, per file, of the packets every file has.
    let mut pos = vec![0usize; exports.len()];
    let mut kept: Vec<SharedPacket> = Vec::new();
    for &c in exports[0]
        .1
        .counters
        .iter()
        .filter(|&&c| c >= start && c <= end)
    {
        let mut idx = Vec::with_capacity(exports.len());
        for (k, (_, e)) in exports.iter().enumerate() {
            while pos[k] < e.counters.len() && e.counters[pos[k]] < c {
                pos[k] += 1;
            }
            if pos[k] < e.counters.len() && e.counters[pos[k]] == c {
                idx.push(pos[k]);
            }
        }
        if idx.len() == exports.len() {
            kept.push((c, idx));
        }
    }
    if kept.is_empty() {
        return Err(TrialError::file(
            exports[0].1.origin.clone(),
            format!("the sensors share no packet between counters {start} and {end}: expected exports of one recording with at least one packet every sensor recorded"),
        ));
    }
    Ok((start, end, kept))
}

/// What the alignment left out: packets before `start` or after `end` some
/// sensor recorded (`kept` samples remain), and each sensor's missing runs.
fn coverage_warnings(
    exports: &[(String, XsensExport)],
    start: u64,
    end: u64,
    kept: usize,
) -> Vec<String> {
    let mut warnings = Vec::new();
    let firsts: Vec<u64> = exports.iter().map(|(_, e)| e.counters[0]).collect();
    let lasts: Vec<u64> = exports
        .iter()
        .map(|(_, e)| *e.counters.last().unwrap_or(&0))
        .collect();
    let spread = |v: &[u64]| v.iter().max() != v.iter().min();
    let range = |v: &[u64]| {
        let (lo, hi) = (v.iter().min().unwrap_or(&0), v.iter().max().unwrap_or(&0));
        if lo == hi {
            format!("{lo}")
        } else {
            format!("{lo}..{hi}")
        }
    };
    if spread(&firsts) || spread(&lasts) {
        warnings.push(format!(
            "sensors start at packet {} and end at packet {}: kept packets {start}..{end} ({kept} samples), which every sensor recorded",
            range(&firsts),
            range(&lasts),
        ));
    }
    for (imu, e) in exports {
        let inside: Vec<u64> = e
            .counters
            .iter()
            .copied()
            .filter(|&c| c >= start && c <= end)
            .collect();
        let runs = missing_runs(&inside);
        if !runs.is_empty() {
            let total: u64 = runs.iter().map(|r| r.1).sum();
            let list: Vec<String> = runs
                .iter()
                .take(3)
                .map(|(c, n)| format!("{n} from packet {c}"))
                .collect();
            let more = if runs.len() > 3 { ", ..." } else { "" };
            warnings.push(format!(
                "{imu} ({}): {total} packets missing ({}{more}); those samples are left out of every sensor (gaps)",
                file_name(&e.origin),
                list.join(", ")
            ));
        }
    }
    warnings
}

/// Each export's orientations (turned by `rotation`) and gyroscope readings
/// at the `kept` packets, named through `model`'s aliases; warnings for
/// IMUs the model lacks and for renormalised quaternions.
fn imu_series(
    exports: &[(&str, &XsensExport)],
    kept: &[SharedPacket],
    rotation: Option<Quat>,
    model: &Model,
    warnings: &mut Vec<String>,
) -> Result<Vec<ImuSeries>, TrialError> {
    let mut imus: Vec<ImuSeries> = Vec::with_capacity(exports.len());
    for (k, &(found, e)) in exports.iter().enumerate() {
        let canonical = match model.canonical_imu(found) {
            Some(c) => c.to_string(),
            None => {
                warnings.push(format!(
                    "IMU '{found}' ({}) is not in model {} and will be ignored",
                    file_name(&e.origin),
                    model.name
                ));
                found.to_string()
            }
        };
        if let Some(prev) = imus.iter().position(|s| s.name == canonical) {
            return Err(TrialError::file(
                e.origin.clone(),
                format!(
                    "repeated IMU: '{found}' is '{canonical}', as is {}; expected each IMU once",
                    file_name(&exports[prev].1.origin)
                ),
            ));
        }
        if e.renormalised > 0 {
            warnings.push(format!(
                "{canonical}: renormalised {} quaternions that were off unit norm by more than 1e-4",
                e.renormalised
            ));
        }
        let orientation = kept
            .iter()
            .map(|(_, idx)| {
                let q = e.orientation[idx[k]];
                rotation.map_or(q, |r| r * q)
            })
            .collect();
        // Gyros are picked by the same packet indices as the orientations, so
        // they stay aligned; the mapping's rotation turns the global frame only
        // (on the left), which leaves sensor-frame rates as they are.
        let gyro = e
            .gyro
            .as_ref()
            .map(|g| kept.iter().map(|(_, idx)| g[idx[k]]).collect());
        imus.push(ImuSeries::new(canonical, orientation).with_gyro(gyro));
    }
    Ok(imus)
}

fn file_name(origin: &str) -> String {
    Path::new(origin)
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| origin.to_string())
}
