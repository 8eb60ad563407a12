//! What the files the tool reads and writes are called: the suffixes that
//! make a name a trial, a truth, a calibration recording, and the names of
//! the files written after another (corrected outputs, coordinates,
//! calibration results, truths). The readers and writers ask here instead of
//! matching suffixes themselves.

use std::path::Path;

/// The suffixes a corrected trial's name drops before its variant is added
/// (`walk.csv.gz` -> `walk`; an OpenSense mapping `walk.xml` -> `walk`).
pub const TRIAL_SUFFIXES: [&str; 4] = [".gz", ".csv", ".sto", ".xml"];

/// The suffixes an IMU inverse kinematics output drops before `.coordinates.csv`.
pub const OUTPUT_SUFFIXES: [&str; 3] = [".gz", ".csv", ".sto"];

/// The suffixes a functional calibration recording drops before
/// `.calibration.toml` (`walk.calib.csv.gz` -> `walk`).
pub const RECORDING_SUFFIXES: [&str; 3] = [".gz", ".csv", ".calib"];

/// The suffixes a simulated recording drops before `.truth.json`
/// (`x.calib.csv.gz` -> `x.calib`).
pub const CSV_SUFFIXES: [&str; 2] = [".gz", ".csv"];

/// The file name of `path` (lossy) without the `suffixes`, tried in order,
/// each removed once when the name (so far) ends with it, ignoring ASCII case.
pub fn stem_without(path: &Path, suffixes: &[&str]) -> String {
    let name = path.file_name().unwrap_or_default().to_string_lossy();
    let lower = name.to_ascii_lowercase();
    let mut stem_len = name.len();
    for ext in suffixes {
        if lower[..stem_len].ends_with(ext) {
            stem_len -= ext.len();
        }
    }
    name[..stem_len].to_string()
}

/// True when `path`'s name could be an OpenSense mapping: it ends in `.xml`
/// (any case). Its content decides whether it is one.
pub fn is_mapping_name(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("xml"))
}

/// True when `path`'s name is a functional calibration recording:
/// `*.calib.csv`, optionally `.gz` (any case). Such files are never trials.
pub fn is_calibration_recording(path: &Path) -> bool {
    let Some(name) = path.file_name() else {
        return false;
    };
    let name = name.to_string_lossy().to_ascii_lowercase();
    let stem = name.strip_suffix(".gz").unwrap_or(&name);
    stem.ends_with(".calib.csv") && stem.len() > ".calib.csv".len()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stems_drop_the_suffixes_in_order_whatever_the_case() {
        let stem = |p: &str, s: &[&str]| stem_without(Path::new(p), s);
        assert_eq!(stem("d/Walk.STO.gz", &TRIAL_SUFFIXES), "Walk");
        assert_eq!(stem("walk.xml", &TRIAL_SUFFIXES), "walk");
        assert_eq!(stem("a.csv.sto", &TRIAL_SUFFIXES), "a.csv");
        assert_eq!(stem("w.basic.csv", &OUTPUT_SUFFIXES), "w.basic");
        assert_eq!(stem("walk.calib.csv.gz", &RECORDING_SUFFIXES), "walk");
        assert_eq!(stem("x.calib.csv.gz", &CSV_SUFFIXES), "x.calib");
        assert_eq!(stem("noext", &TRIAL_SUFFIXES), "noext");
    }

    #[test]
    fn calibration_recordings_are_named_calib_csv() {
        assert!(is_calibration_recording(Path::new("a/walk.calib.csv.gz")));
        assert!(is_calibration_recording(Path::new("W.CALIB.CSV")));
        assert!(!is_calibration_recording(Path::new(".calib.csv")));
        assert!(!is_calibration_recording(Path::new("walk.csv")));
    }

    #[test]
    fn mapping_names_end_in_xml() {
        assert!(is_mapping_name(Path::new("d/Walk.XML")));
        assert!(!is_mapping_name(Path::new("walk.xml.csv")));
        assert!(!is_mapping_name(Path::new("xml")));
    }
}
