//! Pose calibration in the workbench: `P` on the trial screen calibrates the
//! open trial at the cursor (the subject in the model's default pose there,
//! heading from the base IMU) and re-runs every variant on the calibrated
//! trial; `P` again goes back to the trial as read.

use super::app::{App, Effect, LoadState, Loaded};
use crate::limits::LimitTable;
use crate::metrics::trial_figures;
use crate::pose::convention::check_conventions;
use crate::pose::{calibrate, PoseCalibration, PoseTime};
use std::collections::BTreeMap;
use std::sync::Arc;

/// `P`: calibrates the open trial at the cursor, or undoes the calibration.
pub fn toggle(app: &mut App) -> Vec<Effect> {
    let Some(file) = app.open.clone() else {
        return vec![];
    };
    let Some(loaded) = app.entry(&file).and_then(|e| e.loaded()).cloned() else {
        return vec![];
    };
    if let Some(raw) = loaded.uncalibrated.clone() {
        app.info("pose calibration off: the trial as read");
        return replace(app, &file, raw);
    }
    // The sample under the cursor, so that the recorded time is a sample's.
    let t = &loaded.trial.time_s;
    let origin = t.first().copied().unwrap_or(0.0);
    let cursor = app.view.cursor_s;
    let i = t.partition_point(|&x| x - origin < cursor);
    let at = [i.saturating_sub(1), i]
        .into_iter()
        .filter_map(|k| t.get(k).map(|x| x - origin))
        .min_by(|a, b| (a - cursor).abs().total_cmp(&(b - cursor).abs()))
        .unwrap_or(0.0);
    let calibration = PoseCalibration {
        at: PoseTime::At(at),
        setup: loaded.model.pose,
    };
    app.info(format!("pose calibration at {at:.2} s ..."));
    vec![Effect::PoseCalibrate {
        file,
        loaded,
        calibration,
        limits: app.limits.table.clone(),
    }]
}

/// The work of [`Effect::PoseCalibrate`]: the calibrated trial with its
/// figures against `limits`.
pub fn calibrate_job(
    file: &str,
    loaded: &Arc<Loaded>,
    calibration: &PoseCalibration,
    limits: &LimitTable,
) -> super::app::Msg {
    let result = calibrate(&loaded.trial, &loaded.model, calibration)
        .map(|(mut trial, record)| {
            let checks = check_conventions(&trial, &loaded.model, limits, true);
            trial.warnings.extend(checks);
            let before = trial_figures(&trial, None, loaded.truth.as_ref(), &loaded.model, limits);
            Arc::new(Loaded {
                trial,
                before,
                angles: Default::default(),
                pose: Some(record),
                uncalibrated: Some(loaded.clone()),
                ..(**loaded).clone()
            })
        })
        .map_err(|e| e.to_string());
    super::app::Msg::PoseCalibrated(file.to_string(), result)
}

/// A calibration finished: show the calibrated trial and correct it.
pub fn calibrated(app: &mut App, file: &str, result: Result<Arc<Loaded>, String>) -> Vec<Effect> {
    match result {
        Ok(l) => {
            if let Some(p) = &l.pose {
                let checks = check_conventions(&l.trial, &l.model, &app.limits.table, true);
                let note = match checks.first() {
                    Some(w) => format!("; {} convention warning(s), first: {w}", checks.len()),
                    None => String::new(),
                };
                app.info(format!(
                    "pose calibration at {}: heading corrected by {:.1} deg; P undoes{note}",
                    short(p.calibration.at),
                    p.heading_deg
                ));
            }
            replace(app, file, l)
        }
        Err(m) => {
            app.error(m);
            vec![]
        }
    }
}

/// Puts `loaded` in place of the entry's trial, drops the results of the
/// old one (and any job still running on it) and corrects the new one.
fn replace(app: &mut App, file: &str, loaded: Arc<Loaded>) -> Vec<Effect> {
    let Some(e) = app.entry_mut(file) else {
        return vec![];
    };
    e.load = LoadState::Loaded(loaded);
    e.results = BTreeMap::new();
    e.report = None;
    e.chosen = None;
    e.running = None;
    e.gen += 1;
    app.run_effect(file, None).into_iter().collect()
}

/// The status text of a calibrated trial: `pose@12.30s`.
pub fn label(loaded: &Loaded) -> Option<String> {
    loaded
        .pose
        .as_ref()
        .map(|p| format!("pose@{}", short(p.calibration.at)))
}

/// A calibration time for the screen: `12.30s` or `1.00-2.00s`.
fn short(at: PoseTime) -> String {
    match at {
        PoseTime::At(t) => format!("{t:.2}s"),
        PoseTime::Span(a, b) => format!("{a:.2}-{b:.2}s"),
    }
}
