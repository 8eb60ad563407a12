//! The pose calibration job: the trial calibrated at a time, with its figures.

use crate::limits::LimitTable;
use crate::metrics::trial_figures;
use crate::pose::convention::check_conventions;
use crate::pose::{calibrate, PoseCalibration};
use crate::ui::msg::Msg;
use crate::ui::workbench::Loaded;
use std::sync::Arc;

/// The work of [`Effect::PoseCalibrate`]: the calibrated trial with its
/// figures against `limits`.
pub fn calibrate_job(
    file: &str,
    loaded: &Arc<Loaded>,
    calibration: &PoseCalibration,
    limits: &LimitTable,
) -> Msg {
    let result = calibrate(&loaded.trial, &loaded.model, calibration)
        .map(|(mut trial, record)| {
            let checks = check_conventions(&trial, &loaded.model, limits, true);
            trial.warnings.extend(checks);
            // The load's centroid warnings were of the uncalibrated angles.
            trial
                .warnings
                .retain(|w| !crate::pose::centroid_check::is_centroid_warning(w));
            let centroids =
                crate::pose::centroid_check::check_centroids(&trial, &loaded.model, limits);
            trial.warnings.extend(centroids);
            let before = trial_figures(&trial, None, loaded.truth.as_ref(), &loaded.model, limits);
            Arc::new(Loaded {
                trial,
                before,
                angles: Default::default(),
                pose: Some(record),
                uncalibrated: Some(loaded.clone()),
                // Outputs on disk are of the trial as read.
                on_disk: Default::default(),
                ..(**loaded).clone()
            })
        })
        .map_err(|e| e.to_string());
    Msg::PoseCalibrated(file.to_string(), result)
}
