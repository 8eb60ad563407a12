//! Does a trial sit where the limit table's centroids are?
//!
//! The centroid term (docs/method.md section 5; `lambda2` of the table, on in
//! the variants with the centroid term) pulls each joint towards the table's
//! centroid, the mean posture of the population the table was made from
//! (Table 3-3: infants' spontaneous movement). A trial of another posture,
//! a crawl with the hips flexed 60-100 deg against a hip centroid of 12 deg,
//! is pulled away from where it sits. The check warns, per joint and axis,
//! when at least [`ONE_SIDE_SHARE`] of the samples lie on one side of the
//! centroid and their median distance from it is at least [`FAR_DEG`],
//! naming the joint and suggesting centroids from the lab's own clean trials.

use crate::limits::LimitTable;
use crate::metrics::model_joint_angles;
use crate::model::{Axis, Model};
use crate::rotation::wrap180;
use crate::trial::Trial;

/// Share of the samples on one side of the centroid that counts as one-sided.
pub const ONE_SIDE_SHARE: f64 = 0.9;
/// Median distance from the centroid (degrees) that counts as far: beyond
/// what a misaligned IMU offsets (5-30 deg in the simulations, whose
/// misaligned trials the centroid term is meant to bring back).
pub const FAR_DEG: f64 = 40.0;

/// The phrase every warning of [`check_centroids`] carries.
const MARK: &str = "the trial sits far from the table's centroid";

/// Whether `warning` came from [`check_centroids`] (to check a trial again
/// after it changed, e.g. by a pose calibration).
pub fn is_centroid_warning(warning: &str) -> bool {
    warning.contains(MARK)
}

/// Warnings about joints of `trial` that sit far on one side of the table's
/// centroid on some axis, for the joints whose centroid term is on
/// (`lambda2 > 0`). Angles in the table's convention, degrees.
pub fn check_centroids(trial: &Trial, model: &Model, limits: &LimitTable) -> Vec<String> {
    check_centroids_of(&model_joint_angles(trial, model), model, limits)
}

/// As [`check_centroids`], from the trial's joint angles
/// ([`model_joint_angles`]: one entry per joint of `model`, in its order).
pub fn check_centroids_of(
    angles: &[Option<Vec<[f64; 3]>>],
    model: &Model,
    limits: &LimitTable,
) -> Vec<String> {
    let mut out = Vec::new();
    for (joint, angles) in model.joints.iter().zip(angles) {
        let Some(lim) = limits.joint_limits(&joint.name, &joint.kind, true) else {
            continue;
        };
        let (Some(centroid), true) = (lim.centroid_deg, lim.lambda2 > 0.0) else {
            continue;
        };
        let Some(angles) = angles else {
            continue;
        };
        if angles.len() < 10 {
            continue;
        }
        let n = angles.len() as f64;
        let mut far = Vec::new();
        for axis in Axis::ALL {
            let k = axis.index();
            let mut d: Vec<f64> = angles.iter().map(|a| wrap180(a[k] - centroid[k])).collect();
            let above = d.iter().filter(|&&x| x > 0.0).count() as f64 / n;
            let below = d.iter().filter(|&&x| x < 0.0).count() as f64 / n;
            let share = above.max(below);
            let mid = d.len() / 2;
            let (_, median, _) = d.select_nth_unstable_by(mid, f64::total_cmp);
            let median = *median;
            if share >= ONE_SIDE_SHARE && median.abs() >= FAR_DEG {
                far.push(format!(
                    "{} {:.0}% {} its centroid {} deg (median {:+.1} deg)",
                    axis.name(),
                    100.0 * share,
                    if above > below { "above" } else { "below" },
                    centroid[k],
                    median
                ));
            }
        }
        if !far.is_empty() {
            out.push(format!(
                "{}: {MARK} ({}): the centroid term (lambda2 = {}, in the variants with the centroid term) pulls the joint towards another population's posture (unless an IMU is that far off); estimate centroids from the lab's own clean trials (acmw centroids TRIAL... --out FILE) or use a variant without the centroid term",
                joint.name,
                far.join("; "),
                lim.lambda2
            ));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulate::{preset, simulate_with};

    /// A crawl (hips flexed 62-98 deg) sits far above the hips' centroid
    /// (12 deg of flexion): both hips are named, on Y, and nothing else;
    /// the sample-like full-body simulation (around the centroids) passes.
    #[test]
    fn a_crawl_is_named_at_the_hips_and_a_trial_around_the_centroids_passes() {
        let model = Model::infant13();
        let table = LimitTable::default_table();
        let crawl = simulate_with(&preset("full_body_crawl").unwrap(), &model).unwrap();
        let w = check_centroids(&crawl.trial, &model, &table);
        assert_eq!(w.len(), 2, "{w:#?}");
        for (w, hip) in w.iter().zip(["l_hip", "r_hip"]) {
            assert!(w.starts_with(&format!("{hip}: ")), "{w}");
            assert!(w.contains("y 100% above its centroid 12 deg"), "{w}");
            assert!(
                !w.contains("; x ") && !w.contains("(x ") && !w.contains(" z "),
                "{w}"
            );
            assert!(w.contains("acmw centroids"), "{w}");
            assert!(is_centroid_warning(w));
        }
        let clean = simulate_with(&preset("full_body_clean").unwrap(), &model).unwrap();
        let w = check_centroids(&clean.truth.segments, &model, &table);
        assert!(w.is_empty(), "{w:#?}");
        let w = check_centroids(&clean.trial, &model, &table);
        assert!(w.is_empty(), "{w:#?}");
    }
}
