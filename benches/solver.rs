//! The gradient solver against Nelder-Mead (the previous solver), measured in
//! one run on 2 threads, computation only (trials simulated beforehand):
//!
//! - a 5-minute 13-IMU trial with `drift-centroid`, each solver;
//! - one joint (the left knee, and the ankle below it) re-corrected after a
//!   limit edit, each solver;
//! - `drift-heading-centroid` with each solver (the C steps and the heading
//!   steps; Nelder-Mead's are the previous ones), and against
//!   `drift-centroid`: the gradient solver's (now) and Nelder-Mead's heading
//!   fit against the gradient `drift-centroid` (before);
//! - a 2-hour trial against 24 times the 5-minute one, gradient solver;
//! - peak heap during a `drift-centroid` correction of 5 min, 30 min and
//!   2 h, as a multiple of the decoded orientations (samples x IMUs x 32 bytes).
//!
//! Run with `cargo bench --bench solver`. The ratios are printed at the end,
//! from the mean time per iteration of criterion's own samples.

use acm_workbench::acm::minimise::Solver;
use acm_workbench::acm::{Correction, RunControl, Variant};
use acm_workbench::correct::{correct_trial, recorrect};
use acm_workbench::limits::{LimitRow, LimitTable, Settings};
use acm_workbench::model::Model;
use acm_workbench::rotation::Quat;
use acm_workbench::simulate::{simulate, SimConfig};
use acm_workbench::trial::Trial;
use criterion::{criterion_group, criterion_main, Bencher, Criterion};
use std::alloc::{GlobalAlloc, Layout, System};
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

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

/// Mean seconds per iteration of each benchmark, as measured.
static MEANS: Mutex<BTreeMap<String, (f64, u64)>> = Mutex::new(BTreeMap::new());

/// Runs `f` under criterion and records its mean time per iteration.
fn timed(b: &mut Bencher, name: &str, mut f: impl FnMut()) {
    b.iter_custom(|iters| {
        let start = Instant::now();
        for _ in 0..iters {
            f();
        }
        let took = start.elapsed();
        let mut means = MEANS.lock().unwrap();
        let e = means.entry(name.to_string()).or_insert((0.0, 0));
        e.0 += took.as_secs_f64();
        e.1 += iters;
        took
    });
}

fn mean_s(name: &str) -> f64 {
    let means = MEANS.lock().unwrap();
    let (s, n) = means[name];
    s / n as f64
}

/// A 13-IMU, 50 Hz trial with random 5-30 deg misalignments and 0.3 deg noise.
fn trial(minutes: f64) -> Trial {
    let mut cfg = SimConfig::full_body(5);
    cfg.duration_s = minutes * 60.0;
    simulate(&cfg).unwrap().trial
}

fn settings(solver: Solver) -> Settings {
    Settings {
        solver,
        ..Settings::default()
    }
}

fn run(t: &Trial, variant: Variant, table: &LimitTable, solver: Solver) -> Correction {
    correct_trial(
        t,
        &Model::infant13(),
        table,
        &settings(solver),
        variant,
        &RunControl::default(),
    )
    .unwrap()
}

/// The default table with the left knee's flexion range narrowed to 20-60 deg.
fn edited_table() -> LimitTable {
    let mut table = LimitTable::default_table();
    for axis in [0, 2] {
        let mut r = table.row("knee", "knee", axis).unwrap().clone();
        r.joint = "l_knee".into();
        table.rows.push(r);
    }
    table.rows.push(LimitRow {
        joint: "l_knee".into(),
        axis: 1,
        movement: "flexion/extension".into(),
        lower_deg: 20.0,
        upper_deg: 60.0,
        centroid_deg: None,
        lambda2: 0.0,
    });
    table
}

fn peak_memory_ratio(t: &Trial) -> f64 {
    let decoded = t.len() * t.imus.len() * std::mem::size_of::<Quat>() + t.len() * 8;
    let base = LIVE.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    let table = LimitTable::default_table();
    run(t, Variant::DriftCentroid, &table, Solver::Gradient);
    (PEAK.load(Ordering::Relaxed) - base) as f64 / decoded as f64
}

fn benches(c: &mut Criterion) {
    // Two worker threads, as on the machine the figures are for.
    rayon::ThreadPoolBuilder::new()
        .num_threads(2)
        .build_global()
        .expect("the global pool is built once");
    let five = trial(5.0);
    let two_hours = trial(120.0);
    let table = LimitTable::default_table();
    let edited = edited_table();
    let mut memory = Vec::new();
    for (name, minutes) in [("5 min", 5.0), ("30 min", 30.0), ("2 h", 120.0)] {
        let t = if minutes == 120.0 {
            two_hours.clone()
        } else {
            trial(minutes)
        };
        memory.push((name, peak_memory_ratio(&t)));
    }

    let mut g = c.benchmark_group("solver");
    g.sample_size(10).measurement_time(Duration::from_secs(10));
    for solver in [Solver::NelderMead, Solver::Gradient] {
        let name = format!("{solver:?} drift-centroid 5 min");
        g.bench_function(&name, |b| {
            timed(b, &name, || {
                run(&five, Variant::DriftCentroid, &table, solver);
            })
        });
        let previous = run(&five, Variant::DriftCentroid, &table, solver);
        let name = format!("{solver:?} re-correct l_knee 5 min");
        g.bench_function(&name, |b| {
            timed(b, &name, || {
                recorrect(
                    &five,
                    &Model::infant13(),
                    &edited,
                    &settings(solver),
                    &previous,
                    &["l_knee"],
                    &RunControl::default(),
                )
                .unwrap();
            })
        });
    }
    for solver in [Solver::NelderMead, Solver::Gradient] {
        let name = format!("{solver:?} drift-heading-centroid 5 min");
        g.bench_function(&name, |b| {
            timed(b, &name, || {
                run(&five, Variant::DriftHeadingCentroid, &table, solver);
            })
        });
    }
    let name = "Gradient drift-centroid 2 h";
    g.bench_function(name, |b| {
        timed(b, name, || {
            run(&two_hours, Variant::DriftCentroid, &table, Solver::Gradient);
        })
    });
    g.finish();

    let ratio = |a: &str, b: &str| mean_s(a) / mean_s(b);
    eprintln!("\n== solver ratios (mean seconds per run, 2 threads)");
    for what in [
        "drift-centroid 5 min",
        "re-correct l_knee 5 min",
        "drift-heading-centroid 5 min",
    ] {
        let (nm, gr) = (format!("NelderMead {what}"), format!("Gradient {what}"));
        eprintln!(
            "{what}: Nelder-Mead {:.3} s, gradient {:.3} s: {:.2}x faster",
            mean_s(&nm),
            mean_s(&gr),
            ratio(&nm, &gr)
        );
    }
    for solver in ["Gradient", "NelderMead"] {
        eprintln!(
            "drift-heading-centroid ({solver} heading fit) / drift-centroid (gradient), 5 min: {:.2}",
            ratio(
                &format!("{solver} drift-heading-centroid 5 min"),
                "Gradient drift-centroid 5 min"
            )
        );
    }
    eprintln!(
        "2 h / (24 x 5 min) (drift-centroid, gradient): {:.2}",
        mean_s("Gradient drift-centroid 2 h") / (24.0 * mean_s("Gradient drift-centroid 5 min"))
    );
    for (name, m) in memory {
        eprintln!("peak heap during drift-centroid, {name}: {m:.2} x the decoded orientations");
    }
}

criterion_group!(solver, benches);
criterion_main!(solver);
