//! The `hinge` variant on two-axis joints (the elbows of `infant13`, marked
//! `hinge = "z-x"`): the elbow test (static upper arm, forearm flexing 20-130
//! deg and pronating +-28 deg at once, both IMUs misaligned) and simulated
//! full-body trials, where the elbow also moves its Y angle by up to +-5.5
//! deg, which the two-axis model holds constant.
//!
//! Figures (printed, and quoted in the README): RMS error of the X and Z
//! angles against the truth per elbow and knee, the axis errors (the largest
//! over the windows) in the proximal and the distal IMU frame, and the turn of
//! each IMU's misalignment about its hinge axis, which no axis estimate sees.

mod common;

use acm_workbench::acm::{Correction, Variant};
use acm_workbench::baselines::mueller::{angle_between_axes_deg, swing};
use acm_workbench::metrics::joint_angles;
use acm_workbench::model::Model;
use acm_workbench::rotation::wrap180;
use acm_workbench::simulate::{preset, simulate, simulate_with, SimConfig, Simulated};
use common::engine::{run, run_on};
use nalgebra::Vector3;

/// RMS error of `joint`'s X and Z angles (table convention) against the
/// truth, degrees.
fn rms_xz(model: &Model, c: &Correction, sim: &Simulated, joint: &str) -> [f64; 2] {
    let j = model.joint(joint).unwrap();
    let got = joint_angles(&c.corrected, j).unwrap();
    let want = joint_angles(&sim.truth.segments, j).unwrap();
    [0, 2].map(|k| {
        let s: f64 = (got.iter().zip(&want))
            .map(|(g, w)| wrap180(g[k] - w[k]).powi(2))
            .sum();
        (s / got.len() as f64).sqrt()
    })
}

/// The largest axis error over the windows where the axis was used, in the
/// proximal and the distal IMU frame (against `M^-1 n`), degrees, and how
/// many windows used each axis.
fn axis_errors(
    model: &Model,
    c: &Correction,
    sim: &Simulated,
    joint: &str,
) -> ([f64; 2], (usize, usize)) {
    let j = model.joint(joint).unwrap();
    let rec = c
        .joint(joint)
        .unwrap()
        .hinge
        .as_ref()
        .expect("hinge record");
    let (np, nd) = j.hinge.unwrap().segment_axes();
    let m = |imu: &str| sim.truth.meta.misalignment(imu).unwrap().inverse();
    let (tp, td) = (
        m(&j.proximal) * Vector3::from(np),
        m(&j.distal) * Vector3::from(nd),
    );
    let worst = rec.windows.iter().fold([0.0f64; 2], |e, w| {
        let ep = (w.proximal_axis).map_or(0.0, |a| angle_between_axes_deg(&a.into(), &tp));
        let ed = (w.distal_axis).map_or(0.0, |b| angle_between_axes_deg(&b.into(), &td));
        [e[0].max(ep), e[1].max(ed)]
    });
    (worst, rec.windows_used())
}

/// The turn of an IMU's misalignment `M` about segment axis `n` that no axis
/// estimate sees: the twist about `n` of `S^-1 M^-1`, `S` the least rotation
/// taking `n` onto `M^-1 n`; degrees.
fn hidden_turn_deg(sim: &Simulated, imu: &str, n: [f64; 3]) -> f64 {
    let n = Vector3::from(n);
    let mi = sim.truth.meta.misalignment(imu).unwrap().inverse();
    let t = swing(&n, &(mi * n)).inverse() * mi;
    wrap180(2f64.to_degrees() * t.imag().dot(&n).atan2(t.w))
}

#[test]
fn the_elbow_test_with_both_imus_misaligned() {
    // Each IMU tilted by 5-30 deg off its hinge axis (about a random axis
    // perpendicular to it), clean and with 1 deg of noise per IMU.
    let model = Model::infant13();
    for noise in [0.0, 1.0] {
        for angle in [5.0, 10.0, 15.0, 20.0, 25.0, 30.0] {
            let mut cfg = SimConfig::elbow(3, angle);
            cfg.noise_deg = noise;
            cfg.duration_s = 120.0;
            let sim = simulate(&cfg).unwrap();
            let h = run(&sim.trial, Variant::Hinge);
            let dc = run(&sim.trial, Variant::DriftCentroid);
            let (ax, used) = axis_errors(&model, &h, &sim, "l_elbow");
            let [hx, hz] = rms_xz(&model, &h, &sim, "l_elbow");
            let [dx, dz] = rms_xz(&model, &dc, &sim, "l_elbow");
            eprintln!(
                "elbow test {angle:>4} deg noise {noise}: axis error upper arm / forearm {:.2} / {:.2} deg; RMS X/Z hinge {hx:.2}/{hz:.2}, drift-centroid {dx:.2}/{dz:.2}",
                ax[0], ax[1]
            );
            let rec = h.joint("l_elbow").unwrap().hinge.as_ref().unwrap();
            assert_eq!(used, (rec.windows.len(), rec.windows.len()));
            // No shoulder (no base IMU): the elbow's limits turn the upper arm.
            assert!(rec.proximal_turned_by_axis);
            assert!(hx <= 2.0 && hz <= 2.0, "{angle} {noise}: {hx} / {hz}");
            if noise == 0.0 {
                assert!(ax[0] < 0.1 && ax[1] < 0.1, "{angle}: axes {ax:?}");
                assert!(hx < 0.1 && hz < 0.1, "{angle}: {hx} / {hz}");
            } else {
                // The upper arm's axis is seen through +-28 deg of pronation
                // only; its error goes mostly into the Y angle.
                assert!(ax[0] < 5.0 && ax[1] < 1.0, "{angle}: axes {ax:?}");
                // Two IMUs with 1 deg noise each: about 0.8 deg per angle.
                assert!(hx < 1.5 && hz < 1.5, "{angle}: {hx} / {hz}");
            }
            if angle >= 10.0 {
                assert!(hx.max(hz) < dx.max(dz), "{angle} {noise}");
            }
        }
    }
}

#[test]
fn the_elbow_test_in_standing_frames() {
    // full_body16 and opensim put the elbow's pronation on the segments' z
    // and its flexion on their y: marked `z-y` (`Joint::two_axis_hinge`).
    let cfg = SimConfig::elbow(3, 20.0);
    for name in ["full_body16", "opensim"] {
        let mut model = Model::builtin(name).unwrap();
        for j in model.joints.iter_mut().filter(|j| j.kind == "elbow") {
            j.hinge = Some(j.two_axis_hinge());
        }
        let sim = simulate_with(&cfg, &model).unwrap();
        let h = run_on(&model, &sim.trial, Variant::Hinge);
        let (ax, _) = axis_errors(&model, &h, &sim, "l_elbow");
        let [hx, hz] = rms_xz(&model, &h, &sim, "l_elbow");
        eprintln!(
            "{name} elbow test 20 deg: hinge {}, axis errors {:.2} / {:.2} deg, RMS X/Z {hx:.2}/{hz:.2}",
            model.joint("l_elbow").unwrap().hinge.unwrap().name(),
            ax[0],
            ax[1]
        );
        assert!(ax[0] < 3.0 && ax[1] < 1.0, "{name}: {ax:?}");
        assert!(hx < 1.5 && hz < 1.5, "{name}: {hx} / {hz}");
    }
}

#[test]
fn an_elbow_that_barely_moves_falls_back_to_drift_centroid() {
    let sim = simulate(&SimConfig::elbow(3, 20.0)).unwrap();
    let mut trial = sim.trial.clone();
    let fore = trial
        .imus
        .iter_mut()
        .find(|i| i.name == "l_forearm")
        .unwrap();
    let q0 = fore.orientation[0];
    fore.orientation.iter_mut().for_each(|q| *q = q0);
    let h = run(&trial, Variant::Hinge);
    let rec = h.joint("l_elbow").unwrap().hinge.as_ref().unwrap();
    assert_eq!(rec.windows_used(), (0, 0));
    assert!(rec.windows.iter().all(|w| w.fallback.is_some()));
    assert!(h.corrected == run(&trial, Variant::DriftCentroid).corrected);
}

#[test]
fn full_body_knees_and_elbows() {
    // Four random bodies (5 min, 5-30 deg misalignment about random axes, 0.3
    // deg noise) and the two full-body sample trials (`full_body_drift`: two
    // IMUs drift in heading).
    let model = Model::infant13();
    let mut cases: Vec<(String, SimConfig)> = [1u64, 2, 3, 4]
        .map(|s| (format!("seed {s}"), SimConfig::full_body(s)))
        .into();
    for p in ["full_body_clean", "full_body_drift"] {
        cases.push((p.to_string(), preset(p).unwrap()));
    }
    let (mut sum_h, mut sum_d) = (0.0, 0.0);
    let mut hh_checks = Vec::new();
    let mut elbows_within_2 = 0;
    for (label, cfg) in cases {
        let sim = simulate(&cfg).unwrap();
        let h = run(&sim.trial, Variant::Hinge);
        let hh = run(&sim.trial, Variant::HingeHeading);
        let dc = run(&sim.trial, Variant::DriftCentroid);
        for joint in ["l_knee", "r_knee", "l_elbow", "r_elbow"] {
            let (hh_ax, _) = axis_errors(&model, &hh, &sim, joint);
            let [gx, gz] = rms_xz(&model, &hh, &sim, joint);
            eprintln!(
                "{label:<15} {joint:<8} hinge-heading: axis error proximal {:.2} distal {:.2} deg; RMS X/Z {gx:.2}/{gz:.2}",
                hh_ax[0], hh_ax[1]
            );
            hh_checks.push(((label.clone(), joint), hh_ax, [gx, gz]));
            let j = model.joint(joint).unwrap();
            let (np, nd) = j.hinge.unwrap().segment_axes();
            let (ax, used) = axis_errors(&model, &h, &sim, joint);
            let [hx, hz] = rms_xz(&model, &h, &sim, joint);
            let [dx, dz] = rms_xz(&model, &dc, &sim, joint);
            eprintln!(
                "{label:<15} {joint:<8} axes used {}/{} of {}: axis error proximal {:.2} distal {:.2} deg (hidden turns {:.1} / {:.1}); RMS X/Z hinge {hx:.2}/{hz:.2}, drift-centroid {dx:.2}/{dz:.2}",
                used.0, used.1, h.joint(joint).unwrap().windows.len(),
                ax[0], ax[1],
                hidden_turn_deg(&sim, &j.proximal, np),
                hidden_turn_deg(&sim, &j.distal, nd),
            );
            if j.kind == "elbow" {
                // Pronation is decided by the elbow's own limits; flexion
                // keeps what of the forearm's turn about its flexion axis the
                // limits 0..160 do not reach over the trial (the held turn).
                // full_body_drift's right upper arm drifts in heading: its
                // joint rotations leave the two-axis model within a window,
                // whose axis ends 14 deg off (X 7.01 there, at most 2.1
                // elsewhere). Seed 4's left elbow had both axes 5-7 deg off
                // in single windows (2.19 / 2.28) before the windows pooled
                // their axes (0.46 / 0.51: 0.98 / 1.49).
                let (x_bound, z_bound) = match (label.as_str(), joint) {
                    ("full_body_drift", "r_elbow") => (7.5, 4.5),
                    _ => (7.0, 2.0),
                };
                // The windows pool their axes: within 0.51 deg in the worst
                // window but on the drifting upper arm (each window's own
                // fit: up to 6.6 deg).
                if (label.as_str(), joint) != ("full_body_drift", "r_elbow") {
                    assert!(ax[0].max(ax[1]) < 1.0, "{label} {joint}: axes {ax:?}");
                }
                assert!(hz <= z_bound, "{label} {joint}: Z {hz}");
                assert!(hx <= x_bound, "{label} {joint}: X {hx}");
                elbows_within_2 += usize::from(hx <= 2.0 && hz <= 2.0);
                sum_h += hx + hz;
                sum_d += dx + dz;
            } else {
                // The knees (one-axis, tests/hinge.rs): within 2 deg but on
                // full_body_clean's r_knee (X 2.5) and full_body_drift's
                // drifting l_calf (2.8 / 2.6).
                assert!(hx <= 3.0 && hz <= 3.0, "{label} {joint}: {hx} / {hz}");
            }
        }
    }
    eprintln!(
        "elbows, sum of RMS X and Z: hinge {sum_h:.1}, drift-centroid {sum_d:.1} deg; {elbows_within_2} of 12 within 2 deg on both"
    );
    // Windows on their own (each turn from 0): 3 of 12, sum 62 of 136; with
    // the held turn but each window's own axes: 9 of 12, sum 35.9 of 126.
    assert!(
        elbows_within_2 >= 10,
        "{elbows_within_2} of 12 elbows within 2 deg"
    );
    assert!(sum_h < 0.4 * sum_d, "{sum_h} vs {sum_d}");
    // hinge-heading: the heading drift removed first, the drifting upper arm
    // and calf have steady axes again and their joints come within 2 deg;
    // elsewhere it is hinge to within a few hundredths of a degree.
    let mut sum_hh = 0.0;
    let mut within_2 = 0;
    for ((label, joint), ax, [x, z]) in hh_checks {
        // Knees are not pooled (one window's principal direction: up to 2.3
        // deg on the de-drifted calf, 9.5 without the heading removed); the
        // drifting upper arm's pooled axis ends 1.1 deg off (14.3 without).
        let axis_bound = if joint.ends_with("elbow") { 1.5 } else { 2.5 };
        assert!(
            ax[0].max(ax[1]) < axis_bound,
            "{label} {joint}: axes {ax:?}"
        );
        if joint.ends_with("elbow") {
            assert!(x <= 7.0 && z <= 2.0, "{label} {joint}: {x} / {z}");
            within_2 += usize::from(x <= 2.0 && z <= 2.0);
            sum_hh += x + z;
        } else {
            assert!(x <= 2.5 && z <= 2.0, "{label} {joint}: {x} / {z}");
        }
        if label == "full_body_drift" && ["r_elbow", "l_knee"].contains(&joint) {
            assert!(x <= 2.0 && z <= 1.5, "{label} {joint}: {x} / {z}");
        }
    }
    eprintln!("hinge-heading elbows: sum {sum_hh:.1} deg, {within_2} of 12 within 2 deg");
    assert!(within_2 >= 11, "{within_2} of 12");
    assert!(sum_hh < sum_h - 5.0, "{sum_hh} vs {sum_h}");
}
