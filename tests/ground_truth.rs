//! The engine against simulated trials whose truth is known.
//!
//! Tolerances: the knee trials are noise-free, so the only error left is the
//! method's own (lambda1 stops a correction at the limit); 0.05 deg per sample
//! of excursion and 2 deg of flexion range are the acceptance figures. The
//! full-body figures compare variants on the same data, so noise cancels out.

mod common;

use acm_workbench::acm::{Correction, Variant};
use acm_workbench::limits::LimitTable;
use acm_workbench::metrics::{excursion_figures, joint_angles, truth_figures};
use acm_workbench::model::Model;
use acm_workbench::simulate::{preset, simulate, KneeAxis, KneeImu, SimConfig, Simulated};
use acm_workbench::trial::Trial;
use common::engine::{median, run};

fn knee_angles(trial: &Trial) -> Vec<[f64; 3]> {
    let model = Model::infant13();
    joint_angles(trial, model.joint("l_knee").unwrap()).unwrap()
}

fn range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    values.fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)))
}

fn knee_case(imu: KneeImu, axis: KneeAxis) -> (Simulated, Correction) {
    let sim = simulate(&SimConfig::knee(imu, axis, 15.0)).unwrap();
    let c = run(&sim.trial, Variant::Basic);
    (sim, c)
}

fn mean_excursion(angles: &[[f64; 3]]) -> f64 {
    let t = LimitTable::default_table();
    excursion_figures(angles, &t.joint_limits("l_knee", "knee", false).unwrap())
        .joint_mean_excursion_deg
}

#[test]
fn knee_calf_misaligned_about_z_is_restored() {
    let (sim, c) = knee_case(KneeImu::Calf, KneeAxis::Z);
    let raw = knee_angles(&sim.trial);
    let cor = knee_angles(&c.corrected);
    // Figure 4-2: large apparent ab/adduction and rotation, shortened flexion.
    assert!(mean_excursion(&raw) > 5.0, "{}", mean_excursion(&raw));
    let (lo, hi) = range(raw.iter().map(|a| a[1]));
    assert!(hi - lo < 58.0, "raw flexion {lo}..{hi}");
    // After: inside the limits, flexion within 2 deg of the true 15..75.
    assert!(mean_excursion(&cor) <= 0.05, "{}", mean_excursion(&cor));
    let (lo, hi) = range(cor.iter().map(|a| a[1]));
    assert!(
        (lo - 15.0).abs() < 2.0 && (hi - 75.0).abs() < 2.0,
        "{lo}..{hi}"
    );
}

#[test]
fn knee_calf_misaligned_about_x_is_left_inside_the_band() {
    let (sim, c) = knee_case(KneeImu::Calf, KneeAxis::X);
    let raw = knee_angles(&sim.trial);
    let cor = knee_angles(&c.corrected);
    assert!(
        raw.iter().all(|a| (a[0] - 15.0).abs() < 1e-6),
        "raw rotation offset is 15 deg"
    );
    assert!(mean_excursion(&cor) <= 0.05);
    let (lo, hi) = range(cor.iter().map(|a| a[1]));
    assert!(
        (lo - 15.0).abs() < 2.0 && (hi - 75.0).abs() < 2.0,
        "{lo}..{hi}"
    );
    // The source's finding: lambda1 makes the cheapest fix the one that just
    // brings the angles inside, so the rotation is left anywhere inside the
    // +/-5 deg band (here it spans most of it with flexion), not at the true 0,
    // and the correction is smaller than the 15 deg misalignment.
    let (xlo, xhi) = range(cor.iter().map(|a| a[0]));
    let xmean = cor.iter().map(|a| a[0]).sum::<f64>() / cor.len() as f64;
    assert!(xlo > -5.05 && xhi < 5.05, "rotation {xlo}..{xhi}");
    assert!(
        xhi - xlo > 3.0 && xmean > 2.0,
        "rotation {xlo}..{xhi}, mean {xmean}"
    );
    let angle = c.joints[0].windows[0].angle_deg;
    assert!(angle < 14.0, "correction {angle} deg of the true 15");
    eprintln!("calf 15 deg about X: rotation left at {xlo:.2}..{xhi:.2} (mean {xmean:.2}), correction {angle:.2} deg");
}

#[test]
fn knee_thigh_misalignment_is_not_undone_by_the_calf() {
    // The ACM corrects the distal IMU of each joint; with no base IMU the thigh
    // is never corrected, so its error can only be traded against the calf's.
    let (sim, c) = knee_case(KneeImu::Thigh, KneeAxis::Z);
    let cor = knee_angles(&c.corrected);
    let truth = knee_angles(&sim.truth.segments);
    let rms_flexion = (cor
        .iter()
        .zip(&truth)
        .map(|(a, t)| (a[1] - t[1]).powi(2))
        .sum::<f64>()
        / cor.len() as f64)
        .sqrt();
    assert!(mean_excursion(&cor) < mean_excursion(&knee_angles(&sim.trial)));
    assert!(rms_flexion > 2.0, "flexion error {rms_flexion} deg remains");
}

/// Per joint of the drifting full-body preset: uncorrected, true and corrected
/// mean excursion, and the RMS error (all axes) per variant.
struct JointRow {
    joint: String,
    drifting_imu: bool,
    excess: f64,
    removed: [f64; 3],
    rms: [f64; 3],
}

fn full_body_rows() -> Vec<JointRow> {
    let sim = simulate(&preset("full_body_drift").unwrap()).unwrap();
    let model = Model::infant13();
    let table = LimitTable::default_table();
    let drifting: Vec<String> = sim
        .truth
        .meta
        .drifts
        .iter()
        .map(|d| d.imu.clone())
        .collect();
    assert!(sim.truth.meta.drifts.iter().all(|d| d.rate_deg_s <= 0.1));
    // The ACM variants (the baselines are compared in tests/baselines.rs).
    let runs: Vec<Correction> = [Variant::Basic, Variant::Drift, Variant::DriftCentroid]
        .iter()
        .map(|&v| run(&sim.trial, v))
        .collect();
    model
        .joints
        .iter()
        .map(|j| {
            let lim = table.joint_limits(&j.name, &j.kind, false).unwrap();
            let exc = |t: &Trial| {
                excursion_figures(&joint_angles(t, j).unwrap(), &lim).joint_mean_excursion_deg
            };
            let raw = exc(&sim.trial);
            let truth = exc(&sim.truth.segments);
            let true_angles = joint_angles(&sim.truth.segments, j).unwrap();
            let td = &sim.truth.segments.imu(&j.distal).unwrap().orientation;
            let mut removed = [0.0; 3];
            let mut rms = [0.0; 3];
            for (k, c) in runs.iter().enumerate() {
                removed[k] = (raw - exc(&c.corrected)) / (raw - truth);
                let d = &c.corrected.imu(&j.distal).unwrap().orientation;
                let f = truth_figures(&joint_angles(&c.corrected, j).unwrap(), &true_angles, d, td);
                rms[k] = (f.rms_error_deg.iter().map(|e| e * e).sum::<f64>() / 3.0).sqrt();
            }
            JointRow {
                joint: j.name.clone(),
                drifting_imu: drifting.contains(&j.proximal) || drifting.contains(&j.distal),
                excess: raw - truth,
                removed,
                rms,
            }
        })
        .collect()
}

#[test]
fn full_body_with_drift_against_truth() {
    let rows = full_body_rows();
    eprintln!("joint        excess  removed basic/drift/centroid   RMS basic/drift/centroid");
    for r in &rows {
        eprintln!(
            "{:<12} {:6.2}  {:5.0}% {:5.0}% {:5.0}%   {:6.2} {:6.2} {:6.2}{}",
            r.joint,
            r.excess,
            100.0 * r.removed[0],
            100.0 * r.removed[1],
            100.0 * r.removed[2],
            r.rms[0],
            r.rms[1],
            r.rms[2],
            if r.drifting_imu {
                "  (drifting IMU)"
            } else {
                ""
            }
        );
    }
    let mut checked = 0;
    for r in rows.iter().filter(|r| r.excess > 1.0) {
        assert!(
            r.removed[1] >= 0.6,
            "{}: drift removed {:.0}%",
            r.joint,
            100.0 * r.removed[1]
        );
        checked += 1;
    }
    assert!(checked >= 5, "the preset must exercise the rule");
    let drifting: Vec<&JointRow> = rows.iter().filter(|r| r.drifting_imu).collect();
    assert_eq!(drifting.len(), 4);
    let basic = median(drifting.iter().map(|r| r.rms[0]).collect());
    let drift = median(drifting.iter().map(|r| r.rms[1]).collect());
    assert!(
        drift <= basic,
        "median RMS over drifting joints: drift {drift} > basic {basic}"
    );
}
