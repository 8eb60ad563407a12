//! IMU inverse kinematics (docs/method.md section 15; Lavikainen et al.).
//!
//! Per frame, the base rotation and joint coordinates (the moving Z-Y-X axes
//! each joint declares, inside its hard limits) that minimise the weighted sum
//! of squared orientation-error angles of all IMUs, warm-started from the
//! previous frame ([`solver`]). The output is the coordinates over time and the
//! segment orientations they imply, which stand in for the IMU orientations of
//! a corrected trial: the `ik` variant. Frames run in order on one thread
//! (each starts from the last), so the result does not depend on thread count.

pub mod output;
pub mod sim;
pub mod skeleton;
pub mod solver;

pub use skeleton::{Coordinate, Skeleton};
pub use solver::{Pose, Solver, SolverOptions};

use crate::model::Model;
use crate::rotation::Quat;
use crate::run::{Cancelled, RunControl, SkippedJoint};
use crate::trial::{ImuSeries, Trial};
use serde::{Deserialize, Serialize};
use std::sync::atomic::Ordering;

/// Frames between progress reports and cancellation checks.
const PROGRESS_FRAMES: usize = 500;

/// The coordinates of one run over time.
#[derive(Debug, Clone, PartialEq)]
pub struct IkRun {
    pub coordinates: Vec<Coordinate>,
    /// Sample times, seconds (the trial's).
    pub time_s: Vec<f64>,
    /// Coordinate values, degrees: frame after frame, `coordinates.len()` each.
    pub values_deg: Vec<f64>,
    /// The base segment's orientation per frame (segment to global).
    pub base: Vec<Quat>,
    /// Per frame, `sqrt(sum w_i x_i^2 / sum w_i)`: the weighted RMS
    /// orientation error of the IMUs, degrees.
    pub rms_error_deg: Vec<f64>,
    /// Gauss-Newton steps per frame.
    pub iterations: Vec<u32>,
    /// Joints left out of the tree, and why.
    pub skipped: Vec<SkippedJoint>,
}

impl IkRun {
    /// The coordinates of frame `i`, degrees.
    pub fn frame(&self, i: usize) -> &[f64] {
        let n = self.coordinates.len();
        &self.values_deg[i * n..(i + 1) * n]
    }

    /// The values of coordinate `c` over time, degrees.
    pub fn series(&self, c: usize) -> Vec<f64> {
        (0..self.time_s.len()).map(|i| self.frame(i)[c]).collect()
    }

    /// Figures of the run, for sidecars and reports.
    pub fn summary(&self) -> IkSummary {
        let frames = self.time_s.len();
        let n = frames.max(1) as f64;
        let at_limit = self
            .coordinates
            .iter()
            .enumerate()
            .filter(|(_, c)| c.limited())
            .map(|(k, c)| {
                let hits = (0..frames)
                    .filter(|&i| {
                        let v = self.frame(i)[k].to_radians();
                        v <= c.lower + 1e-9 || v >= c.upper - 1e-9
                    })
                    .count();
                (c.label(), 100.0 * hits as f64 / n)
            })
            .filter(|(_, pct)| *pct > 0.0)
            .collect();
        IkSummary {
            frames,
            coordinates: self.coordinates.iter().map(Coordinate::label).collect(),
            mean_rms_error_deg: self.rms_error_deg.iter().sum::<f64>() / n,
            max_rms_error_deg: self.rms_error_deg.iter().copied().fold(0.0, f64::max),
            mean_iterations: self.iterations.iter().map(|&i| f64::from(i)).sum::<f64>() / n,
            max_iterations: self.iterations.iter().copied().max().unwrap_or(0),
            pct_at_limit: at_limit,
        }
    }
}

/// Figures of an IK run (recorded in the sidecar).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IkSummary {
    pub frames: usize,
    /// Column names of the coordinates file, `<joint>_<axis>`.
    pub coordinates: Vec<String>,
    /// Mean and largest per-frame weighted RMS orientation error, degrees.
    pub mean_rms_error_deg: f64,
    pub max_rms_error_deg: f64,
    /// Gauss-Newton steps per frame.
    pub mean_iterations: f64,
    pub max_iterations: u32,
    /// Coordinates that sat on a hard limit, with the percentage of frames.
    pub pct_at_limit: Vec<(String, f64)>,
}

/// An IK run and the segment orientations it implies.
#[derive(Debug, Clone, PartialEq)]
pub struct IkSolution {
    pub run: IkRun,
    /// Per segment of the tree (base first, model order): the orientation
    /// `S_i` (segment to global) per frame, named by its IMU.
    pub segments: Vec<ImuSeries>,
}

/// Runs inverse kinematics over every frame of `trial`. `None` when the base
/// IMU is missing (there is no tree to fit).
pub fn solve_trial(
    trial: &Trial,
    model: &Model,
    options: &SolverOptions,
    control: &RunControl,
) -> Result<Option<IkSolution>, Cancelled> {
    let Some(sk) = Skeleton::new(model, |imu| trial.imu(imu).is_some()) else {
        return Ok(None);
    };
    let series: Vec<&[Quat]> = sk
        .segments
        .iter()
        .map(|s| trial.imu(&s.imu).expect("present").orientation.as_slice())
        .collect();
    let frames = trial.len();
    let nc = sk.coordinates.len();
    let mut solver = Solver::new(&sk, *options);
    let mut measured = vec![Quat::identity(); sk.segments.len()];
    let mut orientations = vec![Vec::with_capacity(frames); sk.segments.len()];
    let mut run = IkRun {
        coordinates: sk.coordinates.clone(),
        time_s: trial.time_s.clone(),
        values_deg: Vec::with_capacity(frames * nc),
        base: Vec::with_capacity(frames),
        rms_error_deg: Vec::with_capacity(frames),
        iterations: Vec::with_capacity(frames),
        skipped: sk.skipped.clone(),
    };
    let weight: f64 = sk.segments.iter().map(|s| s.weight).sum();
    let mut pose: Option<Pose> = None;
    for i in 0..frames {
        if i % PROGRESS_FRAMES == 0 {
            if control.cancel.is_some_and(|c| c.load(Ordering::Relaxed)) {
                return Err(Cancelled);
            }
            if let Some(p) = control.progress {
                p(i, frames);
            }
        }
        for (m, s) in measured.iter_mut().zip(&series) {
            *m = s[i];
        }
        let mut p = match pose.take() {
            Some(p) => p,
            None => solver.initial_pose(&measured),
        };
        let stats = solver.solve(&measured, &mut p);
        wrap_unlimited(&sk, &mut p.q);
        run.values_deg.extend(p.q.iter().map(|v| v.to_degrees()));
        run.base.push(p.base);
        run.rms_error_deg
            .push((stats.cost / weight).sqrt().to_degrees());
        run.iterations.push(stats.iterations);
        for (o, q) in orientations.iter_mut().zip(solver.orientations()) {
            o.push(*q);
        }
        pose = Some(p);
    }
    if let Some(p) = control.progress {
        p(frames, frames);
    }
    let segments = sk
        .segments
        .iter()
        .zip(orientations)
        .map(|(s, orientation)| ImuSeries::new(s.imu.clone(), orientation))
        .collect();
    Ok(Some(IkSolution { run, segments }))
}

/// Unlimited coordinates back into `[-pi, pi)` (the same rotation).
fn wrap_unlimited(sk: &Skeleton, q: &mut [f64]) {
    use std::f64::consts::{PI, TAU};
    for (v, c) in q.iter_mut().zip(&sk.coordinates) {
        if !c.limited() && !(-PI..PI).contains(v) {
            *v = (*v + PI).rem_euclid(TAU) - PI;
        }
    }
}

#[cfg(test)]
mod tests;
