//! The joint-coordinates file of an `ik` run:
//! `time,base_qw,base_qx,base_qy,base_qz,<joint>_<axis>...,rms_error_deg,iterations`,
//! one row per frame; time in seconds, the base orientation (segment to
//! global) as a unit quaternion, coordinates in degrees.

use super::IkRun;
use crate::save::atomic_write;
use std::path::{Path, PathBuf};

/// Where the coordinates of the corrected trial `output` go:
/// `<output without .csv/.sto/.gz>.coordinates.csv` beside it.
pub fn coordinates_path(output: &Path) -> PathBuf {
    let stem = crate::file_names::stem_without(output, &crate::file_names::OUTPUT_SUFFIXES);
    output.with_file_name(format!("{stem}.coordinates.csv"))
}

/// The coordinates file as text.
pub fn coordinates_csv(run: &IkRun) -> String {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut header: Vec<String> = ["time", "base_qw", "base_qx", "base_qy", "base_qz"]
        .map(String::from)
        .to_vec();
    header.extend(run.coordinates.iter().map(|c| c.label()));
    header.extend(["rms_error_deg".into(), "iterations".into()]);
    w.write_record(&header).expect("writes to memory");
    for (i, t) in run.time_s.iter().enumerate() {
        let b = run.base[i];
        let mut row: Vec<String> = [*t, b.w, b.i, b.j, b.k]
            .iter()
            .map(f64::to_string)
            .collect();
        row.extend(run.frame(i).iter().map(f64::to_string));
        row.push(run.rms_error_deg[i].to_string());
        row.push(run.iterations[i].to_string());
        w.write_record(&row).expect("writes to memory");
    }
    String::from_utf8(w.into_inner().expect("writes to memory")).expect("UTF-8 numbers and names")
}

/// Writes the coordinates file atomically (keeping a `.bak`).
pub fn write_coordinates(run: &IkRun, path: &Path) -> anyhow::Result<()> {
    atomic_write(path, coordinates_csv(run).as_bytes())
        .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))
}
