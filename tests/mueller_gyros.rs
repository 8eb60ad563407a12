//! The Mueller et al. (2017) elbow baseline with gyroscopes against the same
//! trial with rates derived from the orientations, on simulated
//! elbows whose axes and angles are known: a regular 50 Hz trial, and a
//! thinned, irregular one with a gap, where central differences of the
//! orientations are coarse and gyros are not.

use acm_workbench::acm::{RunControl, Variant};
use acm_workbench::baselines::mueller::angle_between_axes_deg;
use acm_workbench::baselines::{BaselineRecord, RateSource};
use acm_workbench::correct::correct_trial;
use acm_workbench::limits::{LimitTable, Settings};
use acm_workbench::metrics::joint_angles;
use acm_workbench::model::Model;
use acm_workbench::rotation::wrap180;
use acm_workbench::simulate::{simulate, SimConfig, Simulated};
use acm_workbench::trial::timing::timing;
use acm_workbench::trial::Trial;
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Realistic gyroscope white noise, deg/s per axis (an MTw-class sensor's
/// noise density of about 0.01 deg/s/sqrt(Hz) gives under 0.1 deg/s at these
/// rates; 1 leaves room for the errors a real sensor adds).
const GYRO_NOISE_DEG_S: f64 = 1.0;

/// What Mueller found on one trial: axis errors (deg), Z-Y-X RMS errors of
/// the corrected elbow angles against the truth (deg), and the rate source.
#[derive(Debug)]
struct Figures {
    axis_err: [f64; 2],
    rms: [f64; 3],
    rates: RateSource,
}

fn angles(trial: &Trial) -> Vec<[f64; 3]> {
    let model = Model::infant13();
    joint_angles(trial, model.joint("l_elbow").unwrap()).unwrap()
}

fn rms(a: &[[f64; 3]], truth: &[[f64; 3]], axis: usize) -> f64 {
    let s: f64 = a
        .iter()
        .zip(truth)
        .map(|(x, t)| wrap180(x[axis] - t[axis]).powi(2))
        .sum();
    (s / a.len() as f64).sqrt()
}

/// Mueller on `trial`, judged against `sim`'s truth at the trial's samples
/// `idx` (indices into the simulated trial).
fn mueller(label: &str, trial: &Trial, sim: &Simulated, idx: &[usize]) -> Figures {
    let c = correct_trial(
        trial,
        &Model::infant13(),
        &LimitTable::default_table(),
        &Settings::default(),
        Variant::Mueller,
        &RunControl::default(),
    )
    .unwrap();
    let j = c.joint("l_elbow").unwrap();
    let Some(BaselineRecord::Mueller {
        fit: Some(fit),
        rates,
    }) = &j.baseline
    else {
        panic!("{label}: no axes estimated")
    };
    let ma = sim.truth.meta.misalignment("l_upper_arm").unwrap();
    let mb = sim.truth.meta.misalignment("l_forearm").unwrap();
    // IMU = segment * M: a segment axis n is M^-1 n in the IMU frame.
    let (np, nd) = Model::infant13()
        .joint("l_elbow")
        .unwrap()
        .two_axis_hinge()
        .segment_axes();
    let ea = angle_between_axes_deg(
        &fit.proximal_axis.into(),
        &(ma.inverse() * Vector3::from(np)),
    );
    let eb = angle_between_axes_deg(&fit.distal_axis.into(), &(mb.inverse() * Vector3::from(nd)));
    let truth = angles(&sim.truth.segments.select(idx, "truth"));
    let a = angles(&c.corrected);
    let f = Figures {
        axis_err: [ea, eb],
        rms: [0, 1, 2].map(|k| rms(&a, &truth, k)),
        rates: *rates,
    };
    eprintln!(
        "{label:<36} rates from {:<12} axis errors {:.2} / {:.2} deg, RMS X (flexion) / Y / Z {:.2} / {:.2} / {:.2} deg, J {:.4}, {} samples",
        format!("{:?}", f.rates).to_lowercase(),
        ea,
        eb,
        f.rms[0],
        f.rms[1],
        f.rms[2],
        fit.cost,
        fit.samples
    );
    f
}

/// The trial without its gyroscope columns.
fn without_gyros(trial: &Trial) -> Trial {
    let mut t = trial.clone();
    t.imus.iter_mut().for_each(|s| s.gyro = None);
    t
}

/// Regular 50 Hz elbow, both IMUs 20 deg off their hinge axes, 0.5 deg RMS
/// orientation noise per sample, gyros with 1 deg/s white noise.
///
/// Measured when written (printed with --nocapture): gyros axis errors
/// 0.11 / 0.04 deg, flexion RMS 0.41 deg; orientations 0.51 / 0.25 deg, 0.61
/// deg. Both must recover the axes within 3 deg and the flexion within 3 deg
/// RMS (the acceptance bar); the gyros' axes within 0.5 deg (4 times the
/// measured). What flexion error is left is mostly the orientation noise of
/// the two sensors (0.5 deg RMS each), which no rate source removes.
#[test]
fn elbow_mueller_with_gyros_recovers_the_axes_and_the_flexion() {
    let sim = simulate(&SimConfig::elbow(3, 20.0).with_gyro(GYRO_NOISE_DEG_S)).unwrap();
    let all: Vec<usize> = (0..sim.trial.len()).collect();
    let g = mueller("elbow 50 Hz, gyros", &sim.trial, &sim, &all);
    let o = mueller(
        "elbow 50 Hz, orientations",
        &without_gyros(&sim.trial),
        &sim,
        &all,
    );
    assert_eq!(
        (g.rates, o.rates),
        (RateSource::Gyroscopes, RateSource::Orientations)
    );
    for f in [&g, &o] {
        assert!(f.axis_err.iter().all(|e| *e < 3.0), "{f:?}");
        assert!(f.rms[0] < 3.0, "flexion {f:?}");
    }
    assert!(g.axis_err.iter().all(|e| *e < 0.5), "{g:?}");
}

/// The elbow simulated at 200 Hz, then kept at one random sample in each
/// `every` fine samples (irregular intervals) and nothing from `gap_s`.
fn thinned(sim: &Simulated, every: usize, gap_s: (f64, f64), seed: u64) -> Vec<usize> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let t = &sim.trial.time_s;
    (0..t.len() / every)
        .map(|k| every * k + rng.random_range(0..every))
        .filter(|&i| !(gap_s.0..gap_s.1).contains(&t[i]))
        .collect()
}

/// Thinned and irregular, with a gap: each elbow simulated at 200 Hz, then one
/// sample kept at a random place in each 50 ms (20 Hz on average, intervals
/// 5-95 ms) and none from 100 s to 160 s. Central differences of the
/// orientations are now off-centre and coarse; gyros read the rate at the
/// sample itself. Five seeds (misalignment axes and noise differ; the motion
/// is the same), so that one lucky draw decides nothing.
///
/// Measured when written (printed with --nocapture), mean over the seeds of
/// the proximal / distal axis error: gyros 0.43 / 0.12 deg (worst 1.14),
/// orientations 1.15 / 0.33 deg (worst 2.32). Per seed the gyros win but
/// once (seed 1: 1.14 vs 0.63 deg on the proximal axis). Bounds: every gyro run within the 3 deg bar (axes and
/// flexion RMS) and its axes within 1.5 deg; over the seeds the gyros' mean
/// axis error at most half the orientations' (measured 0.37 of it).
#[test]
fn thinned_irregular_elbow_with_a_gap_gyros_beat_derived_rates() {
    let seeds = 0..5u64;
    let n = seeds.clone().count() as f64;
    let (mut mean_g, mut mean_o) = ([0.0f64; 2], [0.0f64; 2]);
    for seed in seeds {
        let cfg = SimConfig {
            rate_hz: 200.0,
            ..SimConfig::elbow(seed, 20.0).with_gyro(GYRO_NOISE_DEG_S)
        };
        let sim = simulate(&cfg).unwrap();
        let idx = thinned(&sim, 10, (100.0, 160.0), seed + 8);
        let trial = sim.trial.select(&idx, "thinned.csv");
        let tm = timing(&trial.time_s);
        assert!(tm.irregular && tm.gaps.len() == 1, "{tm:?}");
        let g = mueller(&format!("seed {seed} thinned, gyros"), &trial, &sim, &idx);
        let o = mueller(
            &format!("seed {seed} thinned, orientations"),
            &without_gyros(&trial),
            &sim,
            &idx,
        );
        assert_eq!(
            (g.rates, o.rates),
            (RateSource::Gyroscopes, RateSource::Orientations)
        );
        assert!(g.axis_err.iter().all(|e| *e < 1.5), "seed {seed}: {g:?}");
        assert!(g.rms[0] < 3.0, "seed {seed}: {g:?}");
        for k in 0..2 {
            mean_g[k] += g.axis_err[k] / n;
            mean_o[k] += o.axis_err[k] / n;
        }
    }
    eprintln!(
        "thinned, mean axis errors: gyros {:.2} / {:.2} deg, orientations {:.2} / {:.2} deg",
        mean_g[0], mean_g[1], mean_o[0], mean_o[1]
    );
    let (g, o) = (mean_g[0] + mean_g[1], mean_o[0] + mean_o[1]);
    assert!(
        g < 0.5 * o,
        "gyros {g} vs orientations {o} (sum of mean axis errors)"
    );
}
