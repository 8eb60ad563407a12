//! The minimiser against a dense multi-start search, on trials built here from a
//! known misalignment (`IMU = segment * M`): for every window, the engine's cost
//! must be no higher than the dense search's best point plus 1e-3; and on 200
//! windows drawn at random from simulated trials, the gradient solver's cost
//! from identity is within 1e-6 (relative) of a dense grid polished from its
//! best points.

use acm_workbench::acm::cost::WindowCost;
use acm_workbench::acm::minimise::Solver;
use acm_workbench::acm::minimise::{minimise, MinimiseOptions};
use acm_workbench::acm::window::layout;
use acm_workbench::acm::{solve_window, RunControl, Variant};
use acm_workbench::correct::correct_trial;
use acm_workbench::limits::{LimitTable, Settings};
use acm_workbench::model::Model;
use acm_workbench::rotation::{quat_from_wxyz, Quat};
use acm_workbench::simulate::{preset, simulate};
use nalgebra::Vector3;

/// Dense search: a grid of rotation vectors up to `radius_deg`, spacing
/// `step_deg`, then a Nelder-Mead polish from the eight best grid points.
fn dense_best(cost: &WindowCost, radius_deg: f64, step_deg: f64) -> f64 {
    let n = (radius_deg / step_deg).round() as i32;
    let mut grid: Vec<(f64, Quat)> = Vec::new();
    for i in -n..=n {
        for j in -n..=n {
            for k in -n..=n {
                let v = Vector3::new(i as f64, j as f64, k as f64) * step_deg;
                if v.norm() > radius_deg {
                    continue;
                }
                let q = Quat::from_scaled_axis(v.map(f64::to_radians));
                grid.push((cost.eval(&q), q));
            }
        }
    }
    grid.sort_by(|a, b| a.0.total_cmp(&b.0));
    let opts = MinimiseOptions {
        initial_step_rad: step_deg.to_radians(),
        ..MinimiseOptions::default()
    };
    grid.iter()
        .take(8)
        .map(|(_, q)| minimise(&|c| cost.eval(c), &[*q], &opts).cost)
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn every_window_reaches_the_dense_search_optimum() {
    let model = Model::infant13();
    let table = LimitTable::default_table();
    // 13 IMUs, 90 s (two windows), every non-base IMU misaligned 5-30 deg.
    let trial = simulate(&preset("full_body_clean").unwrap()).unwrap().trial;
    let settings = Settings::default();
    for variant in [Variant::Drift, Variant::DriftCentroid] {
        let run = correct_trial(
            &trial,
            &model,
            &table,
            &settings,
            variant,
            &RunControl::default(),
        )
        .unwrap();
        let windows = layout(&trial.time_s, settings.window_s, settings.hop_s);
        assert_eq!(windows.len(), 2);
        assert_eq!(run.joints.len(), 12);
        for jr in &run.joints {
            let joint = model.joint(&jr.joint).unwrap();
            let lim = table.cost_limits(joint, variant.centroid()).unwrap();
            let parent = &run.corrected.imu(&joint.proximal).unwrap().orientation;
            let child = &trial.imu(&joint.distal).unwrap().orientation;
            let measured: Vec<Quat> = parent
                .iter()
                .zip(child)
                .map(|(p, c)| p.inverse() * c)
                .collect();
            for (w, sol) in windows.iter().zip(&jr.windows) {
                let cost = WindowCost::new(&measured[w.first..w.end], &lim, settings.lambda1);
                let engine = cost.eval(&quat_from_wxyz(sol.correction));
                assert!((engine - sol.cost).abs() < 1e-9);
                let dense = dense_best(&cost, 45.0, 5.0);
                assert!(
                    engine <= dense + 1e-3,
                    "{variant} {} window {:.0}s: engine {engine} > dense {dense}",
                    jr.joint,
                    w.start_s
                );
            }
        }
    }
}

#[test]
fn random_windows_reach_the_dense_multi_start_optimum() {
    use rand::{Rng, SeedableRng};
    let model = Model::infant13();
    let table = LimitTable::default_table();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(19);
    let mut checked = 0;
    let mut worst: f64 = 0.0;
    let mut missed: Vec<String> = Vec::new();
    for seed in 0..4 {
        let mut cfg = acm_workbench::simulate::SimConfig::full_body(200 + seed);
        cfg.duration_s = 150.0;
        let trial = simulate(&cfg).unwrap().trial;
        let windows = layout(&trial.time_s, 60.0, 30.0);
        for _ in 0..50 {
            // A random joint, window, centroid term on or off, raw parent.
            let joint = &model.joints[rng.random_range(0..model.joints.len())];
            let w = &windows[rng.random_range(0..windows.len())];
            let centroid = rng.random_bool(0.5);
            let lim = table.cost_limits(joint, centroid).unwrap();
            let parent = &trial.imu(&joint.proximal).unwrap().orientation;
            let child = &trial.imu(&joint.distal).unwrap().orientation;
            let measured: Vec<Quat> = (w.first..w.end)
                .map(|i| parent[i].inverse() * child[i])
                .collect();
            let cost = WindowCost::new(&measured, &lim, 0.05);
            let engine = solve_window(&cost, &[Quat::identity()], Solver::Gradient).cost;
            let dense = dense_best(&cost, 45.0, 7.5);
            let rel = (engine - dense) / dense.abs().max(1e-12);
            if engine > dense + 1e-6 * dense.abs() + 1e-12 {
                missed.push(format!(
                    "seed {} {} window {:.0} s: gradient {engine} > dense {dense}",
                    200 + seed,
                    joint.name,
                    w.start_s
                ));
            } else {
                worst = worst.max(rel);
            }
            checked += 1;
        }
    }
    assert_eq!(checked, 200);
    eprintln!(
        "200 random windows: {} above the dense optimum {missed:?}; worst (gradient - dense) / dense of the others = {worst:e}",
        missed.len()
    );
    // A window's cost can have separate minima (a raw parent here, wide
    // elbow limits). From identity alone the descent stopped in another
    // basin on 6 of the 200 (seed 203's l_knee and r_elbow, 0.05-125% above)
    // until the X and Z excursions were read on the circle (the plain
    // formula made a wall where an elbow sample's flexion wrapped past 180)
    // and the descent's end was screened for lower basins; now none.
    assert!(missed.is_empty(), "{missed:?}");
}
