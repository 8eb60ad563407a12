//! IMU inverse kinematics throughput: 13 IMUs at 50 Hz, one core.
//!
//! Run with `cargo bench --bench ik`. Each case solves a 60-second trial
//! (3,000 frames, frames in order, each warm-started from the last; the solver
//! uses no threads). Real-time ratio = 60 s / measured time; the target
//! is at least 20. Cases:
//! - `exact`: orientations that the model's reduced degrees of freedom can
//!   reproduce exactly (residuals vanish);
//! - `noisy`: the same motion with 1 deg RMS noise per IMU;
//! - `misaligned`: every non-base IMU 10-30 deg off its segment and 0.5 deg
//!   noise, no calibration: large residuals, coordinates pressed on the hard
//!   limits, Gauss-Newton converging linearly (the hard case).
//!
//! The ratios are printed once before the timings.

use acm_workbench::acm::RunControl;
use acm_workbench::ik::sim::{simulate, IkSimConfig};
use acm_workbench::ik::{solve_trial, SolverOptions};
use acm_workbench::model::Model;
use acm_workbench::trial::Trial;
use criterion::{criterion_group, criterion_main, Criterion};
use std::time::{Duration, Instant};

const SECONDS: f64 = 60.0;

fn cases() -> Vec<(&'static str, Trial)> {
    let model = Model::infant13();
    let clean = IkSimConfig::clean(SECONDS);
    let noisy = IkSimConfig {
        noise_deg: 1.0,
        ..clean
    };
    let misaligned = IkSimConfig {
        reach: 1.0,
        misalignment_deg: [10.0, 30.0],
        noise_deg: 0.5,
        seed: 11,
        ..clean
    };
    vec![
        ("exact", simulate(&model, &clean).trial),
        ("noisy", simulate(&model, &noisy).trial),
        ("misaligned", simulate(&model, &misaligned).trial),
    ]
}

fn solve(trial: &Trial, model: &Model) -> f64 {
    let sol = solve_trial(
        trial,
        model,
        &SolverOptions::default(),
        &RunControl::default(),
    )
    .unwrap()
    .unwrap();
    sol.run.summary().mean_iterations
}

fn bench(c: &mut Criterion) {
    let model = Model::infant13();
    let cases = cases();
    for (name, trial) in &cases {
        assert_eq!(trial.imus.len(), 13);
        let start = Instant::now();
        let steps = solve(trial, &model);
        let t = start.elapsed().as_secs_f64();
        println!(
            "ik {name}: 60 s of 13 IMUs at 50 Hz in {:.1} ms: {:.0}x real time, {steps:.2} steps per frame",
            t * 1e3,
            SECONDS / t
        );
    }
    let mut g = c.benchmark_group("ik_60s_13imu_50hz");
    g.sample_size(10).measurement_time(Duration::from_secs(8));
    for (name, trial) in &cases {
        g.bench_function(*name, |b| b.iter(|| solve(trial, &model)));
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
