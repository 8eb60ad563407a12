//! Time as it really comes: an irregularly sampled trial gives the figures of
//! the same motion sampled regularly, and a stream with a gap and a glitch is
//! read back exactly, with the gap, the borrowing window and the glitch reported.

use acm_workbench::acm::{RunControl, Variant};
use acm_workbench::correct::correct_trial;
use acm_workbench::correct::pipeline::{self, Setup};
use acm_workbench::limits::{LimitTable, Settings};
use acm_workbench::metrics::trial_figures;
use acm_workbench::model::Model;
use acm_workbench::report::format_text;
use acm_workbench::rotation::{angle_between_deg, quat_axis_angle_deg, quat_from_wxyz};
use acm_workbench::simulate::{simulate, SimConfig};
use acm_workbench::trial::glitch::{glitches, DEFAULT_GLITCH_DEG};
use acm_workbench::trial::timing::timing;
use acm_workbench::trial::{read_trial, write_trial, Trial, TrialFormat};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The samples `idx` of `t`.
fn pick(t: &Trial, idx: &[usize], name: &str) -> Trial {
    t.select(idx, name)
}

/// One full-body motion (13 IMUs, 5-30 deg misalignments, 0.3 deg noise),
/// 140 s simulated at 200 Hz, seen twice: regularly at 50 Hz (every 4th
/// sample) and irregularly at 50 Hz on average (one sample at a random place in
/// each 20 ms, so intervals run from 5 to 35 ms).
///
/// 140 s, not 150 s: at 150 s a fifth window appears (T - win is a whole number
/// of hops), and the two samplings' lengths, a few ms apart, would fall on
/// either side of that edge.
///
/// Tolerances: both are 7000 samples of the same smooth motion, so per-sample
/// means differ only by where in each 20 ms the sample falls. Measured when
/// written (printed with --nocapture): raw joint mean excursion within 0.012 deg
/// per sample, samples outside the limits within 0.24 percentage points,
/// per-window corrections within 0.36 deg of each other, corrected excursion
/// within 0.011 deg, mean correction angle within 0.17 deg. The bounds are
/// about three times those: 0.05 deg, 0.6 points, 1 deg, 0.05 deg, 0.5 deg.
#[test]
fn irregular_sampling_gives_the_figures_of_regular_sampling() {
    let fine = simulate(&SimConfig {
        duration_s: 140.0,
        rate_hz: 200.0,
        ..SimConfig::full_body(5)
    })
    .unwrap()
    .trial;
    let n = fine.len() / 4;
    let regular_idx: Vec<usize> = (0..n).map(|k| 4 * k).collect();
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let irregular_idx: Vec<usize> = (0..n).map(|k| 4 * k + rng.random_range(0..4)).collect();
    let regular = pick(&fine, &regular_idx, "regular");
    let irregular = pick(&fine, &irregular_idx, "irregular");
    let tr = timing(&irregular.time_s);
    assert!(tr.irregular && tr.gaps.is_empty(), "{tr:?}");
    assert!(!timing(&regular.time_s).irregular);

    let model = Model::infant13();
    let limits = LimitTable::default_table();
    let settings = Settings::default();
    let before_r = trial_figures(&regular, None, None, &model, &limits);
    let before_i = trial_figures(&irregular, None, None, &model, &limits);
    // Largest differences seen, for the record (printed with --nocapture).
    let mut worst = [0.0f64; 5];
    for (a, b) in before_r.iter().zip(&before_i) {
        let (ea, eb) = (&a.excursion, &b.excursion);
        worst[0] = worst[0].max((ea.joint_mean_excursion_deg - eb.joint_mean_excursion_deg).abs());
        for k in 0..3 {
            worst[1] = worst[1].max((ea.pct_outside[k] - eb.pct_outside[k]).abs());
        }
        assert!(
            (ea.joint_mean_excursion_deg - eb.joint_mean_excursion_deg).abs() < 0.05,
            "{}: raw excursion {} vs {}",
            a.joint,
            ea.joint_mean_excursion_deg,
            eb.joint_mean_excursion_deg
        );
        for k in 0..3 {
            assert!(
                (ea.pct_outside[k] - eb.pct_outside[k]).abs() < 0.6,
                "{}",
                a.joint
            );
        }
    }
    for variant in [Variant::Basic, Variant::Drift] {
        let run = |t: &Trial| {
            correct_trial(
                t,
                &model,
                &limits,
                &settings,
                variant,
                &RunControl::default(),
            )
            .unwrap()
        };
        let (cr, ci) = (run(&regular), run(&irregular));
        for (jr, ji) in cr.joints.iter().zip(&ci.joints) {
            assert_eq!(jr.windows.len(), ji.windows.len(), "{variant} {}", jr.joint);
            for (wr, wi) in jr.windows.iter().zip(&ji.windows) {
                assert!(
                    (wr.start_s - wi.start_s).abs() < 0.05,
                    "{variant} {}",
                    jr.joint
                );
                let d = angle_between_deg(
                    &quat_from_wxyz(wr.correction),
                    &quat_from_wxyz(wi.correction),
                );
                worst[2] = worst[2].max(d);
                assert!(
                    d < 1.0,
                    "{variant} {} window {}: corrections {d} deg apart",
                    jr.joint,
                    wr.start_s
                );
            }
        }
        let after_r = trial_figures(&cr.corrected, Some(&regular), None, &model, &limits);
        let after_i = trial_figures(&ci.corrected, Some(&irregular), None, &model, &limits);
        for (a, b) in after_r.iter().zip(&after_i) {
            let (x, y) = (
                a.excursion.joint_mean_excursion_deg,
                b.excursion.joint_mean_excursion_deg,
            );
            assert!(
                (x - y).abs() < 0.05,
                "{variant} {}: corrected excursion {x} vs {y}",
                a.joint
            );
            let (sa, sb) = (a.shift.unwrap(), b.shift.unwrap());
            worst[3] = worst[3].max((x - y).abs());
            worst[4] =
                worst[4].max((sa.mean_correction_angle_deg - sb.mean_correction_angle_deg).abs());
            assert!(
                (sa.mean_correction_angle_deg - sb.mean_correction_angle_deg).abs() < 0.5,
                "{variant} {}",
                a.joint
            );
        }
    }
    eprintln!(
        "irregular vs regular, largest differences: raw excursion {:.3} deg, outside {:.2} points, window corrections {:.2} deg apart, corrected excursion {:.3} deg, mean correction angle {:.2} deg",
        worst[0], worst[1], worst[2], worst[3], worst[4]
    );
}

/// A knee stream at 50 Hz with jittered times, no samples from 70 s to 125 s,
/// and one corrupted calf sample at 200 s.
fn gappy_glitchy_knee() -> Trial {
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let model = Model::infant13();
    let mut t = simulate(&SimConfig {
        duration_s: 300.0,
        ..acm_workbench::simulate::preset("knee_calf_z15").unwrap()
    })
    .unwrap()
    .trial;
    assert_eq!(model.name, "infant13");
    let keep: Vec<usize> = (0..t.len())
        .filter(|&i| !(70.0..125.0).contains(&t.time_s[i]))
        .collect();
    for x in &mut t.time_s {
        *x += rng.random_range(-0.004..0.004);
    }
    let calf = t.imu_mut("l_calf").unwrap();
    calf.orientation[10_000] *= quat_axis_angle_deg([0.0, 0.0, 1.0], 150.0);
    pick(&t, &keep, "gappy.csv")
}

#[test]
fn stream_with_gap_and_glitch_reads_back_and_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("gappy.csv");
    let trial = gappy_glitchy_knee();
    write_trial(&trial, &path, TrialFormat::QuatCsv).unwrap();
    let model = Model::infant13();
    let back = read_trial(&path, &model).unwrap();
    assert_eq!(back.time_s, trial.time_s);
    for (a, b) in back.imus.iter().zip(&trial.imus) {
        for (qa, qb) in a.orientation.iter().zip(&b.orientation) {
            let (qa, qb) = (qa.into_inner(), qb.into_inner());
            assert!((qa - qb).norm().min((qa + qb).norm()) < 1e-9);
        }
    }
    assert!(back.warnings.is_empty(), "{:?}", back.warnings);

    let tm = timing(&back.time_s);
    assert_eq!(tm.gaps.len(), 1, "{tm:?}");
    let g = tm.gaps[0];
    assert_eq!(g.index, 3500);
    assert!(
        (g.from_s - 69.98).abs() < 0.01 && (g.to_s - 125.0).abs() < 0.01,
        "{g:?}"
    );
    assert!(tm.irregular);
    // Length 300 s from the span, not 12250 samples * 20 ms = 245 s.
    assert!(
        (back.duration_s() - 300.0).abs() < 0.02,
        "{}",
        back.duration_s()
    );

    let found = glitches(&back, DEFAULT_GLITCH_DEG);
    assert_eq!(found.len(), 1, "{found:?}");
    // Sample 10000 of the full stream is sample 10000 - 2750 after the gap.
    assert_eq!(
        (found[0].imu.as_str(), found[0].index, found[0].spike),
        ("l_calf", 7250, true)
    );
    assert!(
        (found[0].jump_deg - 150.0).abs() < 10.0,
        "{}",
        found[0].jump_deg
    );

    // The report says all of it; the glitch stays in the data.
    let limits = LimitTable::default_table();
    let settings = Settings::default();
    let setup = Setup {
        model: &model,
        limits: &limits,
        limits_source: "table_3_2.csv",
        settings: &settings,
    };
    let corrections = pipeline::correct_many(
        &back,
        setup,
        &[Variant::Drift],
        None,
        &RunControl::default(),
    )
    .unwrap();
    let r = pipeline::report_input(&back, setup, None).report(&corrections);
    let text = format_text(&r);
    assert!(text.contains("time: 1 gap without samples"), "{text}");
    assert!(text.contains("time: irregular sample times"), "{text}");
    assert!(
        text.contains(
            "time: window 60.0-120.0 s has 10.0 s of data (gaps): solved on 30.0-150.0 s"
        ),
        "{text}"
    );
    assert!(
        text.contains("glitches: 1 orientation glitch") && text.contains("l_calf at 200.0"),
        "{text}"
    );
    // Never smoothed: the glitch sample is still 150 deg from its neighbours.
    let calf = &back.imu("l_calf").unwrap().orientation;
    assert!(angle_between_deg(&calf[7249], &calf[7250]) > 140.0);
}
