//! OpenSense Xsens mappings (XML) and MT Manager exports: parsed or a located error.
#![no_main]
use acm_workbench::trial::mapping::parse_mapping;
use acm_workbench::trial::xsens::parse_export;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let _ = parse_mapping(text, "m.xml");
    let _ = parse_export(text, "e.txt");
});
