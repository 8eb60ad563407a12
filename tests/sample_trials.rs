//! The shipped sample trials load cleanly and still match the simulator that
//! their truth files name (the truth's segments are re-simulated from them).

use acm_workbench::model::Model;
use acm_workbench::rotation::angle_between_deg;
use acm_workbench::simulate::simulate;
use acm_workbench::simulate::truth::load_truth_beside;
use acm_workbench::trial::read_trial;
use std::path::Path;

#[test]
fn sample_trials_match_their_truth() {
    let model = Model::infant13();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("sample_trials");
    let names = [
        "knee_calf_z15.csv.gz",
        "full_body_clean.csv.gz",
        "full_body_drift.csv.gz",
        "elbow_20.csv.gz",
    ];
    for name in names {
        let path = dir.join(name);
        let trial = read_trial(&path, &model).unwrap();
        assert!(trial.warnings.is_empty(), "{name}: {:?}", trial.warnings);
        let truth = load_truth_beside(&path, &model)
            .expect("truth beside")
            .unwrap();
        truth.check_against(&trial).unwrap();
        // The file is the simulator's output rounded to 6 decimals.
        let again = simulate(&truth.meta.config).unwrap().trial;
        for imu in &trial.imus {
            let sim = &again.imu(&imu.name).unwrap().orientation;
            let worst = imu
                .orientation
                .iter()
                .zip(sim)
                .map(|(a, b)| angle_between_deg(a, b))
                .fold(0.0, f64::max);
            assert!(
                worst < 1e-3,
                "{name} {}: {worst} deg from the simulator",
                imu.name
            );
        }
    }
}
