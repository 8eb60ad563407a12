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
//! - the basin screen alone: every window cost of the 5-minute trial
//!   solved from the identity with and without it, one after the other;
//! - a 2-hour trial against 24 times the 5-minute one, gradient solver;
//! - peak heap during a `drift-centroid` correction of 5 min, 30 min and
//!   2 h, as a multiple of the decoded orientations (samples x IMUs x 32 bytes).
//!
//! Run with `cargo bench --bench solver`. The ratios are printed at the end,
//! from the mean time per iteration of criterion's own samples; with a
//! filter (`cargo bench --bench solver -- 'Gradient drift-(heading-)?centroid 5'`)
//! only the ratios of what ran. `SOLVER_BENCH_NO_MEMORY=1` leaves out the
//! peak-heap figures (three more corrections, one of a 2-hour trial).

use acm_workbench::acm::chain::solve_window_screened;
use acm_workbench::acm::cost::WindowCost;
use acm_workbench::acm::minimise::Solver;
use acm_workbench::acm::{Correction, RunControl, Variant};
use acm_workbench::correct::{correct_trial, recorrect};
use acm_workbench::limits::{LimitRow, LimitTable, Settings};
use acm_workbench::model::Model;
use acm_workbench::rotation::Quat;
use acm_workbench::simulate::{simulate, SimConfig};
use acm_workbench::trial::Trial;
use acm_workbench::window::layout;
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

/// CPU seconds of every thread of this process so far (user and system).
fn cpu_s() -> f64 {
    // SAFETY: getrusage fills the struct it is given.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    let s = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    s(u.ru_utime) + s(u.ru_stime)
}

/// CPU seconds per iteration of each benchmark, as measured: less sensitive
/// than wall time to other work on a shared machine.
static CPU: Mutex<BTreeMap<String, (f64, u64)>> = Mutex::new(BTreeMap::new());

/// Runs `f` under criterion and records its mean time per iteration.
fn timed(b: &mut Bencher, name: &str, mut f: impl FnMut()) {
    b.iter_custom(|iters| {
        let (start, cpu) = (Instant::now(), cpu_s());
        for _ in 0..iters {
            f();
        }
        let took = start.elapsed();
        let used = cpu_s() - cpu;
        let mut means = MEANS.lock().unwrap();
        let e = means.entry(name.to_string()).or_insert((0.0, 0));
        e.0 += took.as_secs_f64();
        e.1 += iters;
        let mut cpu = CPU.lock().unwrap();
        let e = cpu.entry(name.to_string()).or_insert((0.0, 0));
        e.0 += used;
        e.1 += iters;
        took
    });
}

/// The mean CPU seconds per iteration of benchmark `name`, if it ran.
fn cpu_mean_s(name: &str) -> Option<f64> {
    let cpu = CPU.lock().unwrap();
    cpu.get(name).map(|&(s, n)| s / n as f64)
}

/// The mean seconds per iteration of benchmark `name`, if it ran.
fn mean_s(name: &str) -> Option<f64> {
    let means = MEANS.lock().unwrap();
    means.get(name).map(|&(s, n)| s / n as f64)
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

/// The window costs of every joint of `t` on its measured joint rotations
/// (`infant13`'s joints with their centroids, the default layout and
/// `lambda1`).
fn window_costs(t: &Trial, table: &LimitTable) -> Vec<WindowCost> {
    let model = Model::infant13();
    let s = Settings::default();
    let windows = layout(&t.time_s, s.window_s, s.hop_s);
    let mut costs = Vec::new();
    for joint in &model.joints {
        let (Some(p), Some(d), Some(limits)) = (
            t.imu(&joint.proximal),
            t.imu(&joint.distal),
            table.cost_limits(joint, true),
        ) else {
            continue;
        };
        let rm: Vec<Quat> = (p.orientation.iter().zip(&d.orientation))
            .map(|(p, d)| p.inverse() * d)
            .collect();
        for w in &windows {
            costs.push(WindowCost::new(&rm[w.first..w.end], &limits, s.lambda1));
        }
    }
    costs
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
    // Simulated when first needed (the 2-hour bench, the peak-heap figures).
    let two_hours = std::sync::OnceLock::new();
    let two_hours = || two_hours.get_or_init(|| trial(120.0));
    let table = LimitTable::default_table();
    let edited = edited_table();
    let mut memory = Vec::new();
    if std::env::var_os("SOLVER_BENCH_NO_MEMORY").is_none() {
        for (name, minutes) in [("5 min", 5.0), ("30 min", 30.0), ("2 h", 120.0)] {
            let t = if minutes == 120.0 {
                two_hours().clone()
            } else {
                trial(minutes)
            };
            memory.push((name, peak_memory_ratio(&t)));
        }
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
    // The basin screen alone: every window of every joint of the 5-minute
    // trial (measured joint rotations, default table), solved one after the
    // other from the identity, with and without the screen.
    let costs = window_costs(&five, &table);
    for screen in [false, true] {
        let name = format!(
            "window solves, screen {}",
            if screen { "on" } else { "off" }
        );
        g.bench_function(&name, |b| {
            timed(b, &name, || {
                for cost in &costs {
                    std::hint::black_box(solve_window_screened(
                        cost,
                        &[Quat::identity()],
                        Solver::Gradient,
                        screen,
                    ));
                }
            })
        });
    }
    let name = "Gradient drift-centroid 2 h";
    g.bench_function(name, |b| {
        let t = two_hours();
        timed(b, name, || {
            run(t, Variant::DriftCentroid, &table, Solver::Gradient);
        })
    });
    g.finish();

    // Only what ran (a filter may leave benchmarks out).
    let ratio = |a: &str, b: &str| Some(mean_s(a)? / mean_s(b)?);
    eprintln!("\n== solver ratios (mean seconds per run, 2 threads)");
    for what in [
        "drift-centroid 5 min",
        "re-correct l_knee 5 min",
        "drift-heading-centroid 5 min",
    ] {
        let (nm, gr) = (format!("NelderMead {what}"), format!("Gradient {what}"));
        if let (Some(a), Some(b), Some(r)) = (mean_s(&nm), mean_s(&gr), ratio(&nm, &gr)) {
            eprintln!("{what}: Nelder-Mead {a:.3} s, gradient {b:.3} s: {r:.2}x faster");
        }
    }
    if let (Some(on), Some(off)) = (
        mean_s("window solves, screen on"),
        mean_s("window solves, screen off"),
    ) {
        eprintln!(
            "window solves of the 5-min trial ({} windows), with / without the basin screen: {on:.3} s / {off:.3} s = {:.2}",
            window_costs(&five, &table).len(),
            on / off
        );
    }
    for solver in ["Gradient", "NelderMead"] {
        let heading = format!("{solver} drift-heading-centroid 5 min");
        if let (Some(h), Some(c), Some(r)) = (
            mean_s(&heading),
            mean_s("Gradient drift-centroid 5 min"),
            ratio(&heading, "Gradient drift-centroid 5 min"),
        ) {
            eprintln!(
                "drift-heading-centroid ({solver} heading fit) / drift-centroid (gradient), 5 min: {h:.3} s / {c:.3} s = {r:.2}"
            );
        }
        if let (Some(h), Some(c)) = (
            cpu_mean_s(&heading),
            cpu_mean_s("Gradient drift-centroid 5 min"),
        ) {
            eprintln!(
                "  the same in CPU time (both threads): {h:.3} s / {c:.3} s = {:.2}",
                h / c
            );
        }
    }
    if let (Some(long), Some(five)) = (
        mean_s("Gradient drift-centroid 2 h"),
        mean_s("Gradient drift-centroid 5 min"),
    ) {
        eprintln!(
            "2 h / (24 x 5 min) (drift-centroid, gradient): {:.2}",
            long / (24.0 * five)
        );
    }
    for (name, m) in memory {
        eprintln!("peak heap during drift-centroid, {name}: {m:.2} x the decoded orientations");
    }
}

criterion_group!(solver, benches);
criterion_main!(solver);
