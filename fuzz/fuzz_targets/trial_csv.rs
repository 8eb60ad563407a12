//! Quaternion and Euler CSV trials: any bytes read to a trial or a located
//! error, and a trial read writes back to text that reads to the same trial.
#![no_main]
use acm_workbench::model::Model;
use acm_workbench::trial::{read_trial_from_str, trial_to_string, TrialFormat};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let model = Model::infant13();
    for format in [TrialFormat::QuatCsv, TrialFormat::EulerCsv] {
        match read_trial_from_str(text, "f.csv", format, &model) {
            Ok(trial) => {
                let again = trial_to_string(&trial, TrialFormat::QuatCsv);
                let back = read_trial_from_str(&again, "g.csv", TrialFormat::QuatCsv, &model)
                    .expect("a written trial reads back");
                assert_eq!(back.time_s, trial.time_s);
            }
            Err(e) => assert!(e.file == "f.csv"),
        }
    }
});
