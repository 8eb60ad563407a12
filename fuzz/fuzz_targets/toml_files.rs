//! Settings, models and calibration files: parsed or a located error; what
//! parses writes back to text that parses to the same value.
#![no_main]
use acm_workbench::calibration::Calibration;
use acm_workbench::limits::SettingsFile;
use acm_workbench::model::Model;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(s) = SettingsFile::parse(text, "s.toml") {
        assert_eq!(
            SettingsFile::parse(&s.to_toml(), "again.toml").expect("reads back"),
            s
        );
    }
    let _ = Model::from_toml(text, "m.toml");
    if let Ok(c) = Calibration::from_toml(text, "c.toml") {
        assert_eq!(
            Calibration::from_toml(&c.to_toml(), "again.toml").expect("reads back"),
            c
        );
    }
});
