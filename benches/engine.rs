//! Engine benchmarks: loading, whole-trial correction of 5- and
//! 30-minute 13-IMU trials at 50 Hz, one joint re-corrected, the heading-drift
//! variants against the source's (`-- heading`), and peak memory.
//!
//! Run with `cargo bench --bench engine`. The memory figure is printed once
//! before the timings: peak heap growth during a `drift-centroid` correction,
//! as a multiple of the decoded orientation data (samples x IMUs x 32 bytes).

use acm_workbench::acm::window::layout;
use acm_workbench::acm::{correct_joint, RunControl, Variant};
use acm_workbench::correct::correct_trial;
use acm_workbench::limits::{LimitTable, Settings};
use acm_workbench::model::Model;
use acm_workbench::rotation::Quat;
use acm_workbench::simulate::{preset, simulate, SimConfig};
use acm_workbench::trial::{read_trial, write_trial, Trial, TrialFormat};
use criterion::{criterion_group, criterion_main, Criterion};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

/// Counts live heap bytes and their peak.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let now = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(now, Ordering::Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }
}

#[global_allocator]
static ALLOC: Counting = Counting;

/// A 13-IMU, 50 Hz trial with random 5-30 deg misalignments and 0.3 deg noise.
/// No drift: a heading drift grows with the trial (0.05 deg/s is 90 deg after
/// 30 minutes), which would change the problem, not only its size.
fn trial(minutes: f64) -> Trial {
    let mut cfg = SimConfig::full_body(5);
    cfg.duration_s = minutes * 60.0;
    simulate(&cfg).unwrap().trial
}

fn run(t: &Trial, variant: Variant) {
    correct_trial(
        t,
        &Model::infant13(),
        &LimitTable::default_table(),
        &Settings::default(),
        variant,
        &RunControl::default(),
    )
    .unwrap();
}

fn peak_memory_ratio(t: &Trial) -> f64 {
    let decoded = t.len() * t.imus.len() * std::mem::size_of::<Quat>() + t.len() * 8;
    let base = LIVE.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    run(t, Variant::DriftCentroid);
    (PEAK.load(Ordering::Relaxed) - base) as f64 / decoded as f64
}

fn benches(c: &mut Criterion) {
    let five = trial(5.0);
    let thirty = trial(30.0);
    for (name, t) in [("5 min", &five), ("30 min", &thirty)] {
        eprintln!(
            "peak heap during drift-centroid, {name}: {:.2} x the decoded orientations",
            peak_memory_ratio(t)
        );
    }

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("five.csv");
    write_trial(&five, &path, TrialFormat::QuatCsv).unwrap();
    let model = Model::infant13();
    c.bench_function("load 5 min 13 IMU csv", |b| {
        b.iter(|| read_trial(&path, &model).unwrap())
    });

    let mut g = c.benchmark_group("correct");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    g.bench_function("drift-centroid 5 min", |b| {
        b.iter(|| run(&five, Variant::DriftCentroid))
    });
    g.bench_function("drift 5 min", |b| b.iter(|| run(&five, Variant::Drift)));
    g.bench_function("basic 5 min", |b| b.iter(|| run(&five, Variant::Basic)));
    g.bench_function("drift-centroid 30 min", |b| {
        b.iter(|| run(&thirty, Variant::DriftCentroid))
    });

    // One joint (the hip, with the centroid term) re-corrected from its
    // measured rotations, as after a limit edit.
    let table = LimitTable::default_table();
    // The engine solves its joints in their table axes (`cost_limits`).
    let lim = table
        .cost_limits(Model::infant13().joint("l_hip").unwrap(), true)
        .unwrap();
    let base = &five.imu("base").unwrap().orientation;
    let thigh = &five.imu("l_thigh").unwrap().orientation;
    let measured: Vec<Quat> = base
        .iter()
        .zip(thigh)
        .map(|(p, c)| p.inverse() * c)
        .collect();
    let windows = layout(&five.time_s, 60.0, 30.0);
    g.bench_function("one joint drift-centroid 5 min", |b| {
        b.iter(|| correct_joint(&five.time_s, &measured, &windows, &lim, 0.05))
    });
    g.finish();

    // The heading model against the source's on the same 5-minute trials, one
    // without drift and the drifting preset (the target: within 2x).
    let drifting = simulate(&preset("full_body_drift").unwrap()).unwrap().trial;
    let mut g = c.benchmark_group("heading");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    for (name, t) in [("5 min", &five), ("5 min drifting", &drifting)] {
        for v in [
            Variant::Drift,
            Variant::DriftHeading,
            Variant::DriftCentroid,
            Variant::DriftHeadingCentroid,
        ] {
            g.bench_function(format!("{v} {name}"), |b| b.iter(|| run(t, v)));
        }
    }
    g.finish();
}

criterion_group!(engine, benches);
criterion_main!(engine);
