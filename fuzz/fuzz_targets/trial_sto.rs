//! OpenSim `.sto` trials: a trial or a located error, never a panic.
#![no_main]
use acm_workbench::model::Model;
use acm_workbench::trial::{read_trial_from_str, trial_to_string, TrialFormat};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let model = Model::infant13();
    if let Ok(trial) = read_trial_from_str(text, "f.sto", TrialFormat::Sto, &model) {
        let again = trial_to_string(&trial, TrialFormat::Sto);
        let back = read_trial_from_str(&again, "g.sto", TrialFormat::Sto, &model)
            .expect("a written trial reads back");
        assert_eq!(back.time_s, trial.time_s);
    }
});
