//! The calibration screen's job: read and calibrate the folder's recordings.

use crate::calibration::{calibrate, is_calibration_recording, Protocol, Recording};
use crate::ui::msg::{CalibEntry, Msg};
use std::path::Path;
use std::sync::Arc;

/// The protocol file the workbench uses when the folder has one.
pub const FOLDER_PROTOCOL: &str = "protocol.toml";

/// Reads and calibrates every recording in `dir` with the folder's
/// `protocol.toml`, or the built-in protocol when there is none.
pub fn scan(dir: &Path) -> Msg {
    let (protocol, label) = match crate::input::read_text(&dir.join(FOLDER_PROTOCOL)) {
        Ok(text) => (
            Protocol::from_toml(&text, FOLDER_PROTOCOL).map_err(|e| e.to_string()),
            FOLDER_PROTOCOL.to_string(),
        ),
        Err(_) => {
            let p = Protocol::default_protocol();
            let label = format!("<built-in {}>", p.name);
            (Ok(p), label)
        }
    };
    let mut files: Vec<String> = std::fs::read_dir(dir)
        .map(|rd| {
            rd.filter_map(|e| e.ok())
                .map(|e| e.path())
                .filter(|p| p.is_file() && is_calibration_recording(p))
                .filter_map(|p| p.file_name().map(|n| n.to_string_lossy().into_owned()))
                .collect()
        })
        .unwrap_or_default();
    files.sort();
    let entries = files
        .into_iter()
        .map(|file| {
            let result = match &protocol {
                Err(m) => Err(m.clone()),
                Ok(p) => Recording::read(&dir.join(&file))
                    .map(|r| Arc::new(calibrate(&r, p)))
                    .map_err(|e| {
                        // Name the file as the folder shows it.
                        crate::calibration::CalibrationError {
                            file: file.clone(),
                            ..e
                        }
                        .to_string()
                    }),
            };
            CalibEntry { file, result }
        })
        .collect();
    Msg::Calibrations(entries, label)
}

/// Writes the demo folder's calibration recordings into `dir`: `cal.calib.csv`
/// (the built-in protocol simulated at 50 Hz, 4 repetitions per movement, the
/// thorax rotation TR sloppy) and `bad.calib.csv` (a malformed number on line 3).
pub fn write_demo_recordings(dir: &Path) -> Result<(), String> {
    use crate::calibration::simulate::{simulate, CalibSimConfig, Sloppiness};
    let mut config = CalibSimConfig {
        rate_hz: 50.0,
        reps: 4,
        ..CalibSimConfig::default()
    };
    config.overrides.insert(
        "TR".into(),
        Sloppiness {
            wobble_deg: 30.0,
            bias_deg: 6.0,
        },
    );
    let sim = simulate(&Protocol::default_protocol(), &config).map_err(|e| e.to_string())?;
    std::fs::write(dir.join("cal.calib.csv"), sim.recording.to_csv()).map_err(|e| e.to_string())?;
    std::fs::write(
        dir.join("bad.calib.csv"),
        "time,label,upper_back_ax,upper_back_ay,upper_back_az,upper_back_gx,upper_back_gy,upper_back_gz\n0,supine,0,0,9.8,0,0,0\n0.02,supine,0,0,9.8,0,1..5,0\n",
    )
    .map_err(|e| e.to_string())
}
