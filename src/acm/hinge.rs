//! Hinge axes that inform both IMUs (the `hinge` variant, docs/method.md
//! section 18).
//!
//! A hinge joint turns about axes fixed in its segments, so its measured
//! rotations `Rm_i` (distal to proximal IMU frame) reveal those axes in both
//! sensor frames: `a` in the proximal IMU's and `b` in the distal IMU's.
//!
//! - One-axis hinge (`hinge = "y"`, the knee): `Rm_i = M_p^-1 R_n(theta_i) M_d`,
//!   so every relative rate, in the proximal frame, is parallel to
//!   `a = M_p^-1 n`, and in the distal frame (`Rm_i^-1 w_i`) parallel to
//!   `b = M_d^-1 n`. Each is the principal direction of the rates' scatter
//!   `sum w w^T`; isotropic noise adds a multiple of the identity to it and
//!   leaves the direction alone.
//! - Two-axis hinge (`hinge = "z-x"`, the elbow): Z fixed in the proximal
//!   segment, X in the distal one (`"z-y"` and `"y-x"` in frames whose
//!   constant angle is X or Z), found by the Mueller estimator
//!   ([`crate::baselines::mueller::estimate_axes`]).
//!
//! An estimated axis fixes two of the three degrees of freedom of its IMU's
//! correction: `C(phi) = S R_n(phi)`, with `S` the least rotation taking the
//! segment axis `n` onto the estimated one and `phi` the turn about `n` that
//! no axis can show. The limits decide `phi` by a one-dimensional search of
//! the usual window cost ([`minimise_about_axis`]) whose size term counts
//! `|phi|` instead of the angle of `C`: the swing is the axis' to decide, and
//! beside a large swing the angle of `C` hardly changes with `phi`, so any
//! noise at the limits would turn `phi` freely. An axis is used only where
//! the joint turned about it by at least [`MIN_RANGE_DEG`] in the window (and,
//! for a one-axis hinge, mostly about one axis); elsewhere the window falls
//! back to the unconstrained correction and its record says why.
//!
//! Rates are rad/s, axes unit vectors in sensor frames, angles degrees in
//! records.

use super::window::Window;
use crate::baselines::mueller::{
    angle_between_axes_deg, estimate_axes, rates_from_gyros, rates_from_orientations, swing,
    MuellerOptions,
};
use crate::baselines::{JointGyros, RateSource};
use crate::model::Hinge;
use crate::rotation::{wrap180, Quat};
use nalgebra::{Matrix3, Unit, Vector3};
use serde::{Deserialize, Serialize};

/// Least turn about an axis within a window, degrees, for the axis to count
/// as observed.
pub const MIN_RANGE_DEG: f64 = 10.0;
/// Largest ratio of the second to the first principal rate (RMS) of a
/// one-axis hinge: beyond it the joint did not turn about one axis.
pub const MAX_OFF_AXIS_RATIO: f64 = 0.5;
/// Half the span (seconds) of the central difference that derives a one-axis
/// hinge's rates from orientations: long enough that a slow knee turns by
/// several degrees, so per-sample noise stays small beside it.
pub const SINGLE_AXIS_HALF_SPAN_S: f64 = 0.25;
/// Step of the scan over the turn about the axis, degrees.
const SCAN_STEP_DEG: f64 = 2.0;
/// Golden-section steps after the scan (the bracket shrinks to about 1e-8 deg).
const REFINE_STEPS: usize = 60;

/// The estimated axes of one window of one hinge joint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HingeWindow {
    /// Window centre, seconds from the first sample.
    pub centre_s: f64,
    /// The hinge axis in the proximal IMU's sensor frame (unit), when observed.
    pub proximal_axis: Option<[f64; 3]>,
    /// The hinge axis in the distal IMU's sensor frame (unit), when observed.
    pub distal_axis: Option<[f64; 3]>,
    /// Angle of each estimated axis from the IMU's own segment axis, degrees
    /// (how far the sensor sat off the hinge).
    pub proximal_tilt_deg: Option<f64>,
    pub distal_tilt_deg: Option<f64>,
    /// How far the joint turned about the proximal and the distal axis over the
    /// window (max minus min), degrees.
    pub proximal_range_deg: f64,
    pub distal_range_deg: f64,
    /// True when the window took the axes fitted on all the windows that
    /// agree with them (a two-axis hinge; see `pool_two_axes`).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub pooled: bool,
    /// Why an axis was not used in this window (none: both were).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fallback: Option<String>,
}

/// What the `hinge` variant found for one hinge joint (kept in the sidecar).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HingeRecord {
    /// The hinge as the model declares it (`y`, `z-x`, ...).
    pub hinge: String,
    /// Where the angular rates came from.
    pub rates: RateSource,
    /// Per window, in window order.
    pub windows: Vec<HingeWindow>,
    /// True when no joint above corrects the proximal IMU (its joint is
    /// skipped or absent): the axis alone turned it, by the least rotation
    /// taking the estimated axis onto the segment's.
    #[serde(default)]
    pub proximal_turned_by_axis: bool,
}

impl HingeRecord {
    /// Windows where the proximal / the distal axis was used.
    pub fn windows_used(&self) -> (usize, usize) {
        let p = self.windows.iter().filter(|w| w.proximal_axis.is_some());
        let d = self.windows.iter().filter(|w| w.distal_axis.is_some());
        (p.count(), d.count())
    }
}

/// The hinge axes of one window as vectors (sensor frames), when observed.
#[derive(Debug, Clone, Copy)]
pub struct WindowAxes {
    pub proximal: Option<Vector3<f64>>,
    pub distal: Option<Vector3<f64>>,
}

/// A joint's hinge estimate: the record and the axes per window.
#[derive(Debug, Clone)]
pub struct HingeFits {
    pub hinge: Hinge,
    pub record: HingeRecord,
    pub axes: Vec<WindowAxes>,
}

/// Estimates a hinge joint's axes in every window from its measured rotations
/// `Rm_i` (raw distal to raw proximal IMU frame), with rates from both IMUs'
/// gyros when given (one reading per sample each), else from orientations.
pub fn estimate_windows(
    hinge: Hinge,
    time_s: &[f64],
    rm: &[Quat],
    gyros: Option<JointGyros>,
    windows: &[Window],
) -> HingeFits {
    let half_span = match hinge {
        Hinge::Single(_) => SINGLE_AXIS_HALF_SPAN_S,
        Hinge::Two { .. } => MuellerOptions::default().rate_half_span_s,
    };
    let (rates, source) = match gyros {
        Some(g) if g.proximal.len() == rm.len() && g.distal.len() == rm.len() => (
            rates_from_gyros(rm, g.proximal, g.distal),
            RateSource::Gyroscopes,
        ),
        _ => (
            rates_from_orientations(time_s, rm, half_span),
            RateSource::Orientations,
        ),
    };
    let (fits, axes): (Vec<HingeWindow>, Vec<WindowAxes>) = windows
        .iter()
        .map(|w| {
            let span = w.first..w.end;
            estimate_window(hinge, w.centre_s, &rm[span.clone()], &rates[span])
        })
        .unzip();
    let (mut fits, mut axes) = (fits, axes);
    if let Hinge::Two { .. } = hinge {
        pool_two_axes(hinge, rm, &rates, windows, (&mut fits, &mut axes));
    }
    HingeFits {
        hinge,
        record: HingeRecord {
            hinge: hinge.name().to_string(),
            rates: source,
            windows: fits,
            proximal_turned_by_axis: false,
        },
        axes,
    }
}

/// Most samples of a pooled two-axis fit (evenly spaced).
const POOL_MAX_SAMPLES: usize = 6000;
/// How much larger a window's sum of squared plane residuals may be at the
/// pooled axes than at its own for the window to join the pool.
pub const POOL_TOLERANCE: f64 = 0.1;

/// A two-axis hinge's axes: proximal frame, distal frame (unit).
type AxisPair = (Vector3<f64>, Vector3<f64>);

/// One window's own two-axis fit: its axes, its samples and their sum of
/// squared residuals at those axes.
struct OwnFit {
    axes: AxisPair,
    samples: PlaneSamples,
    sum_sq: f64,
}

/// Pools a two-axis hinge's windows: an IMU that stays put on its segment
/// has the same axes in every window, and one window's plane fit (a minute
/// of elbow movement whose held angle is not quite held) scatters by several
/// degrees about them. Consecutive windows where both axes were observed are
/// gathered into runs, a run growing by the next window as long as the axes
/// fitted on all of the run's samples fit each of its windows within
/// [`POOL_TOLERANCE`] of that window's own fit; every window of a run of two
/// or more takes the run's axes. Where the axes move (a strap slips, a
/// heading drifts) runs stay short and windows keep axes of their own time.
fn pool_two_axes(
    hinge: Hinge,
    rm: &[Quat],
    rates: &[Vector3<f64>],
    windows: &[Window],
    (records, axes): (&mut [HingeWindow], &mut [WindowAxes]),
) {
    let opts = MuellerOptions::default();
    let own: Vec<Option<OwnFit>> = (axes.iter())
        .zip(windows)
        .map(|(ax, w)| {
            let own = (ax.proximal?, ax.distal?);
            let span = w.first..w.end;
            let samples =
                PlaneSamples::new(&rm[span.clone()], &rates[span], &opts, REFINE_MAX_SAMPLES)?;
            let sum_sq = samples.sum_sq(&own.0, &own.1);
            Some(OwnFit {
                axes: own,
                samples,
                sum_sq,
            })
        })
        .collect();
    let fit_run = |run: &[usize], start: AxisPair| {
        let (first, end) = (windows[run[0]].first, windows[*run.last()?].end);
        let all = PlaneSamples::new(&rm[first..end], &rates[first..end], &opts, POOL_MAX_SAMPLES)?;
        let (a, b, _) = all.fit(start);
        let agree = run.iter().all(|&k| {
            let mine = own[k].as_ref().expect("observed");
            mine.samples.sum_sq(&a, &b) <= (1.0 + POOL_TOLERANCE) * mine.sum_sq
        });
        agree.then_some((a, b))
    };
    let mut runs: Vec<(Vec<usize>, AxisPair)> = Vec::new();
    let mut run: Vec<usize> = Vec::new();
    let mut pooled = None;
    for (k, mine) in own.iter().enumerate() {
        let Some(mine) = mine else {
            runs.extend(pooled.take().map(|p| (std::mem::take(&mut run), p)));
            run.clear();
            continue;
        };
        run.push(k);
        if run.len() == 1 {
            continue;
        }
        let start = pooled.unwrap_or(mine.axes);
        match fit_run(&run, start) {
            Some(p) => pooled = Some(p),
            None => {
                run.pop();
                runs.extend(pooled.take().map(|p| (std::mem::take(&mut run), p)));
                run = vec![k];
            }
        }
    }
    runs.extend(pooled.map(|p| (run, p)));
    let (np, nd) = hinge.segment_axes();
    let (np, nd) = (Vector3::from(np), Vector3::from(nd));
    for (run, (a, b)) in runs {
        let a = if a.dot(&np) < 0.0 { -a } else { a };
        let b = if b.dot(&nd) < 0.0 { -b } else { b };
        for k in run {
            axes[k] = WindowAxes {
                proximal: Some(a),
                distal: Some(b),
            };
            let r = &mut records[k];
            r.proximal_axis = Some(a.into());
            r.distal_axis = Some(b.into());
            r.proximal_tilt_deg = Some(angle_between_axes_deg(&a, &np));
            r.distal_tilt_deg = Some(angle_between_axes_deg(&b, &nd));
            r.pooled = true;
        }
    }
}

/// The axes of one window from its joint rotations and relative rates
/// (proximal frame).
pub fn estimate_window(
    hinge: Hinge,
    centre_s: f64,
    rm: &[Quat],
    rates: &[Vector3<f64>],
) -> (HingeWindow, WindowAxes) {
    let (np, nd) = hinge.segment_axes();
    let (np, nd) = (Vector3::from(np), Vector3::from(nd));
    let estimate = match hinge {
        Hinge::Single(_) => single_axis(rm, rates, &np, &nd),
        Hinge::Two { .. } => two_axes(rm, rates, (np, nd)),
    };
    let Some((a, b, off_axis)) = estimate else {
        let record = HingeWindow {
            centre_s,
            proximal_axis: None,
            distal_axis: None,
            proximal_tilt_deg: None,
            distal_tilt_deg: None,
            proximal_range_deg: 0.0,
            distal_range_deg: 0.0,
            fallback: Some("the joint hardly moved: no axis to estimate".into()),
            pooled: false,
        };
        let none = WindowAxes {
            proximal: None,
            distal: None,
        };
        return (record, none);
    };
    let (range_p, range_d) = turn_ranges(hinge, rm, &a, &b);
    let mut reasons = Vec::new();
    if let Some(r) = off_axis.filter(|r| *r > MAX_OFF_AXIS_RATIO) {
        reasons.push(format!(
            "the joint did not turn about one axis (second principal rate {r:.2} of the first, over {MAX_OFF_AXIS_RATIO})"
        ));
    }
    let p_ok = reasons.is_empty() && range_p >= MIN_RANGE_DEG;
    let d_ok = reasons.is_empty() && range_d >= MIN_RANGE_DEG;
    if reasons.is_empty() && !(p_ok && d_ok) {
        reasons.push(format!(
            "the joint turned {range_p:.1} deg about the proximal axis and {range_d:.1} deg about the distal one (at least {MIN_RANGE_DEG} needed)"
        ));
    }
    let axes = WindowAxes {
        proximal: p_ok.then_some(a),
        distal: d_ok.then_some(b),
    };
    let record = HingeWindow {
        centre_s,
        proximal_axis: axes.proximal.map(Into::into),
        distal_axis: axes.distal.map(Into::into),
        proximal_tilt_deg: axes.proximal.map(|a| angle_between_axes_deg(&a, &np)),
        distal_tilt_deg: axes.distal.map(|b| angle_between_axes_deg(&b, &nd)),
        proximal_range_deg: range_p,
        distal_range_deg: range_d,
        fallback: (!reasons.is_empty()).then(|| reasons.join("; ")),
        pooled: false,
    };
    (record, axes)
}

/// Principal direction of `vs` (sign towards `nominal`) and the RMS ratio of
/// the second principal component to the first; none without movement.
fn principal_axis(
    vs: impl Iterator<Item = Vector3<f64>>,
    nominal: &Vector3<f64>,
) -> Option<(Vector3<f64>, f64)> {
    let s = vs.fold(Matrix3::zeros(), |s, v| s + v * v.transpose());
    let eig = s.symmetric_eigen();
    let mut order = [0, 1, 2];
    order.sort_by(|&i, &j| eig.eigenvalues[j].total_cmp(&eig.eigenvalues[i]));
    let l1 = eig.eigenvalues[order[0]];
    if !(l1.is_finite() && l1 > 0.0) {
        return None;
    }
    let mut axis: Vector3<f64> = eig.eigenvectors.column(order[0]).normalize();
    if axis.dot(nominal) < 0.0 {
        axis = -axis;
    }
    let ratio = (eig.eigenvalues[order[1]].max(0.0) / l1).sqrt();
    Some((axis, ratio))
}

/// One-axis hinge: the rates' principal direction in each frame.
fn single_axis(
    rm: &[Quat],
    rates: &[Vector3<f64>],
    np: &Vector3<f64>,
    nd: &Vector3<f64>,
) -> Option<(Vector3<f64>, Vector3<f64>, Option<f64>)> {
    let (a, ratio) = principal_axis(rates.iter().copied(), np)?;
    let distal = rm.iter().zip(rates).map(|(r, w)| r.inverse() * w);
    let (b, _) = principal_axis(distal, nd)?;
    Some((a, b, Some(ratio)))
}

/// Two-axis hinge: the Mueller estimate, starting from the segment axes
/// `nominal` (proximal, distal), refined by [`refine_two_axes`].
fn two_axes(
    rm: &[Quat],
    rates: &[Vector3<f64>],
    nominal: (Vector3<f64>, Vector3<f64>),
) -> Option<(Vector3<f64>, Vector3<f64>, Option<f64>)> {
    let opts = MuellerOptions {
        max_samples: 1500,
        ..MuellerOptions::default()
    };
    let fit = estimate_axes(rm, rates, nominal, &opts)?;
    let (mut a, mut b) = refine_two_axes(
        rm,
        rates,
        (fit.proximal_axis.into(), fit.distal_axis.into()),
        &opts,
    );
    if a.dot(&nominal.0) < 0.0 {
        a = -a;
    }
    if b.dot(&nominal.1) < 0.0 {
        b = -b;
    }
    Some((a, b, None))
}

/// Most samples the two-axis refinement takes (evenly spaced).
const REFINE_MAX_SAMPLES: usize = 3000;
/// Weight of the held angle's prior in the two-axis refinement, relative to
/// the RMS relative rate: the model's two segment axes are perpendicular, so
/// `a . Rm_k b` is the sine of the held angle, which the prior pulls to zero.
pub const HELD_ANGLE_WEIGHT: f64 = 0.3;
/// Levenberg-Marquardt iterations of the two-axis refinement.
const REFINE_ITERATIONS: usize = 60;

/// Unit vectors spanning the plane perpendicular to the unit vector `a`.
fn tangent_basis(a: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let helper = if a.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let u = helper.cross(a).normalize();
    (u, a.cross(&u))
}

/// The two-axis constraint's residuals: the component of each relative rate
/// `w_k` (rad/s, proximal frame) normal to the plane of `a` and `Rm_k b`.
fn plane_residuals(
    samples: &[(Matrix3<f64>, Vector3<f64>)],
    held_weight: f64,
    a: &Vector3<f64>,
    b: &Vector3<f64>,
    out: &mut Vec<f64>,
) {
    out.clear();
    out.extend(samples.iter().map(|(m, w)| {
        let n = a.cross(&(m * b));
        let len = n.norm();
        if len > 1e-9 {
            w.dot(&n) / len
        } else {
            0.0
        }
    }));
    out.extend(samples.iter().map(|(m, _)| held_weight * a.dot(&(m * b))));
}

/// Refines a two-axis hinge's axes `start` (proximal frame, distal frame) by
/// Gauss-Newton with Levenberg-Marquardt damping over the four tangent
/// angles of the two unit axes, minimising `sum_k (w_k . n_k)^2` with
/// `n_k` the unit normal of the plane of `a` and `Rm_k b`: every relative rate
/// of a two-axis joint lies in that plane (Seel et al. 2014, Mueller et al.
/// 2017). Unlike Mueller's `J`, the residuals are not divided by `|w_k|`:
/// a small turn about the third axis (the elbow's Y, which the model holds
/// constant) is a zero-mean rate that the sum averages out, and dividing by
/// `|w_k|` would give the samples where it dominates (the joint slowing down
/// about both hinge axes) the largest say. Samples under the minimum rate
/// are left out as for Mueller's estimate.
pub fn refine_two_axes(
    rm: &[Quat],
    rates: &[Vector3<f64>],
    start: (Vector3<f64>, Vector3<f64>),
    opts: &MuellerOptions,
) -> (Vector3<f64>, Vector3<f64>) {
    let start = (start.0.normalize(), start.1.normalize());
    match PlaneSamples::new(rm, rates, opts, REFINE_MAX_SAMPLES) {
        Some(samples) => {
            let (a, b, _) = samples.fit(start);
            (a, b)
        }
        None => start,
    }
}

/// The samples of a two-axis fit: per moving sample (relative rate above the
/// minimum, evenly spaced) the joint rotation as a matrix and the relative
/// rate (rad/s, proximal frame), with the weight of the held angle's prior.
struct PlaneSamples {
    samples: Vec<(Matrix3<f64>, Vector3<f64>)>,
    held_weight: f64,
}

impl PlaneSamples {
    /// At most `max` of the moving samples; none when fewer than 10 move.
    fn new(
        rm: &[Quat],
        rates: &[Vector3<f64>],
        opts: &MuellerOptions,
        max: usize,
    ) -> Option<PlaneSamples> {
        let min_rate = opts.min_rate_deg_s.to_radians();
        let moving: Vec<usize> = (0..rm.len().min(rates.len()))
            .filter(|&k| rates[k].norm() > min_rate)
            .collect();
        if moving.len() < 10 {
            return None;
        }
        let stride = moving.len().div_ceil(max);
        let samples: Vec<(Matrix3<f64>, Vector3<f64>)> = (moving.iter().step_by(stride))
            .map(|&k| (*rm[k].to_rotation_matrix().matrix(), rates[k]))
            .collect();
        // The held angle's prior: `a . Rm b` (the cosine of the angle between
        // the axes, zero when the held angle is) as one residual per sample,
        // scaled to the RMS rate.
        let rms_rate = (samples.iter().map(|(_, w)| w.norm_squared()).sum::<f64>()
            / samples.len() as f64)
            .sqrt();
        Some(PlaneSamples {
            samples,
            held_weight: HELD_ANGLE_WEIGHT * rms_rate,
        })
    }

    /// The sum of squared residuals at axes `a`, `b` (see [`plane_residuals`]).
    fn sum_sq(&self, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
        let mut r = Vec::new();
        plane_residuals(&self.samples, self.held_weight, a, b, &mut r);
        r.iter().map(|x| x * x).sum()
    }

    /// Gauss-Newton with Levenberg-Marquardt damping from unit axes `start`
    /// (see [`refine_two_axes`]): the axes and their sum of squares.
    fn fit(&self, start: (Vector3<f64>, Vector3<f64>)) -> (Vector3<f64>, Vector3<f64>, f64) {
        let (samples, held_weight) = (&self.samples, self.held_weight);
        let (mut a, mut b) = start;
        let step = |a: &Vector3<f64>, b: &Vector3<f64>, d: &nalgebra::Vector4<f64>| {
            let (ua, va) = tangent_basis(a);
            let (ub, vb) = tangent_basis(b);
            (
                (a + ua * d[0] + va * d[1]).normalize(),
                (b + ub * d[2] + vb * d[3]).normalize(),
            )
        };
        let (mut r, mut moved) = (Vec::new(), Vec::new());
        plane_residuals(samples, held_weight, &a, &b, &mut r);
        let sum_sq = |r: &[f64]| r.iter().map(|x| x * x).sum::<f64>();
        let mut f = sum_sq(&r);
        let mut mu = 1e-3;
        let h = 1e-7;
        for _ in 0..REFINE_ITERATIONS {
            // Forward-difference Jacobian, one column per tangent angle.
            let mut jac = vec![nalgebra::Vector4::<f64>::zeros(); r.len()];
            for p in 0..4 {
                let mut d = nalgebra::Vector4::zeros();
                d[p] = h;
                let (a2, b2) = step(&a, &b, &d);
                plane_residuals(samples, held_weight, &a2, &b2, &mut moved);
                for (j, (m, r0)) in jac.iter_mut().zip(moved.iter().zip(&r)) {
                    j[p] = (m - r0) / h;
                }
            }
            let mut jtj = nalgebra::Matrix4::<f64>::zeros();
            let mut jtr = nalgebra::Vector4::<f64>::zeros();
            for (j, r0) in jac.iter().zip(&r) {
                jtj += j * j.transpose();
                jtr += j * *r0;
            }
            let mut improved = false;
            for _ in 0..30 {
                let mut m = jtj;
                for p in 0..4 {
                    m[(p, p)] += mu * jtj[(p, p)] + 1e-12;
                }
                let Some(inv) = m.try_inverse() else {
                    mu *= 10.0;
                    continue;
                };
                let (a2, b2) = step(&a, &b, &(-(inv * jtr)));
                plane_residuals(samples, held_weight, &a2, &b2, &mut moved);
                let f2 = sum_sq(&moved);
                if f2 < f {
                    improved = f - f2 > 1e-12 * f;
                    (a, b, f) = (a2, b2, f2);
                    std::mem::swap(&mut r, &mut moved);
                    mu = (mu * 0.3).max(1e-9);
                    break;
                }
                mu *= 10.0;
            }
            if !improved {
                break;
            }
        }
        (a, b, f)
    }
}

/// Turn of `q` about the unit axis `u` (its twist), degrees in [-180, 180).
fn twist_deg(q: &Quat, u: &Vector3<f64>) -> f64 {
    wrap180(2f64.to_degrees() * q.imag().dot(u).atan2(q.w))
}

/// How far the joint turned about each axis over the window (max minus min),
/// degrees. One-axis hinge: the twist about `a` of `Rm_i Rm_0^-1` (proximal
/// frame) and about `b` of `Rm_0^-1 Rm_i` (distal frame). Two-axis hinge: the
/// ranges of its two angles (Z and X for `z-x`) once both axes are put onto
/// the segments'.
fn turn_ranges(hinge: Hinge, rm: &[Quat], a: &Vector3<f64>, b: &Vector3<f64>) -> (f64, f64) {
    let range = |it: &mut dyn Iterator<Item = f64>| {
        let (lo, hi) = it.fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
        if hi >= lo {
            hi - lo
        } else {
            0.0
        }
    };
    let Some(first) = rm.first() else {
        return (0.0, 0.0);
    };
    match hinge {
        Hinge::Single(_) => (
            range(&mut rm.iter().map(|r| twist_deg(&(r * first.inverse()), a))),
            range(&mut rm.iter().map(|r| twist_deg(&(first.inverse() * r), b))),
        ),
        Hinge::Two { proximal, distal } => {
            let (np, nd) = hinge.segment_axes();
            let cp = swing(a, &Vector3::from(np));
            let cd_inv = swing(b, &Vector3::from(nd)).inverse();
            // `R_p(x) R_d(y)` read as Z-Y-X angles: of the segment frames when
            // `p` comes first in that order, else in the frame `M` whose Z is
            // `p` and X is `d` (`M^T R M = Rz(x) Ry(0) Rx(y)`).
            let zyx_first = proximal.index() > distal.index();
            let m = two_axis_frame(np, nd);
            let angles: Vec<[f64; 3]> = rm
                .iter()
                .map(|r| {
                    let r = cp * r * cd_inv;
                    let r = if zyx_first { r } else { m.inverse() * r * m };
                    crate::rotation::euler_zyx_deg(&r)
                })
                .collect();
            let (kp, kd) = if zyx_first {
                (proximal.index(), distal.index())
            } else {
                (2, 0)
            };
            (
                range(&mut angles.iter().map(|e| e[kp])),
                range(&mut angles.iter().map(|e| e[kd])),
            )
        }
    }
}

/// The rotation `M` with columns `d`, `p x d`, `p` (unit segment axes `p`
/// fixed in the proximal and `d` in the distal segment, orthogonal).
fn two_axis_frame(p: [f64; 3], d: [f64; 3]) -> Quat {
    let (p, d) = (Vector3::from(p), Vector3::from(d));
    let m = Matrix3::from_columns(&[d, p.cross(&d), p]);
    Quat::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(m))
}

/// The corrections of an IMU whose hinge axis is known:
/// `C(phi) = S R_n(phi)`, where `S` takes the segment axis `n` onto the
/// estimated sensor-frame axis, so the corrected frame's `n` is the hinge axis.
#[derive(Debug, Clone, Copy)]
pub struct AxisFamily {
    swing: Quat,
    axis: Unit<Vector3<f64>>,
}

impl AxisFamily {
    /// The family for segment axis `segment` (unit) and estimated `sensor` axis.
    pub fn new(segment: &Vector3<f64>, sensor: &Vector3<f64>) -> AxisFamily {
        AxisFamily {
            swing: swing(segment, sensor),
            axis: Unit::new_normalize(*segment),
        }
    }

    /// The least rotation of the family (`phi = 0`).
    pub fn swing(&self) -> Quat {
        self.swing
    }

    /// `C(phi)`, `phi` in degrees.
    pub fn at(&self, phi_deg: f64) -> Quat {
        self.swing * Quat::from_axis_angle(&self.axis, phi_deg.to_radians())
    }
}

/// The best correction of a family and what it cost.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AxisSolution {
    pub c: Quat,
    /// The turn about the axis, degrees in [-180, 180).
    pub phi_deg: f64,
    pub cost: f64,
    pub evaluations: usize,
}

/// Minimises `cost(C(phi), phi)` (`phi` in degrees) over the family: the
/// lowest point of the 2-deg grid over the whole turn ([`minimise_turn`]),
/// then a golden-section search in the steps either side of it (the first
/// best on ties, so the result is deterministic).
pub fn minimise_about_axis(cost: &dyn Fn(&Quat, f64) -> f64, family: &AxisFamily) -> AxisSolution {
    let (phi, v, evaluations) = minimise_turn(&|phi: f64| cost(&family.at(phi), wrap180(phi)));
    AxisSolution {
        c: family.at(phi),
        phi_deg: phi,
        cost: v,
        evaluations,
    }
}

/// The turn `phi` (degrees, in (-180, 180]) minimising `f` over the whole
/// circle: the lowest point of the grid every [`SCAN_STEP_DEG`], looked for
/// coarse to fine as the heading fit's scan is (every 3rd point, then the
/// points around the coarse grid's three lowest local minima: at most 72
/// evaluations where the whole grid takes 180), `phi = 0` kept on a tie;
/// then a golden-section search around it. Returns `(phi, f(phi),
/// evaluations)`.
pub fn minimise_turn(f: &dyn Fn(f64) -> f64) -> (f64, f64, usize) {
    let mut evaluations = 1;
    let mut best = (0.0, f(0.0));
    let mut counted = |phi: f64| {
        evaluations += 1;
        f(phi)
    };
    if let Some(found) = super::circle_grid::refined_grid_minimum(&mut counted, SCAN_STEP_DEG) {
        if found.1 < best.1 {
            best = found;
        }
    }
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut lo, mut hi) = (best.0 - SCAN_STEP_DEG, best.0 + SCAN_STEP_DEG);
    let mut x1 = hi - g * (hi - lo);
    let mut x2 = lo + g * (hi - lo);
    let (mut f1, mut f2) = (f(x1), f(x2));
    evaluations += 2;
    for _ in 0..REFINE_STEPS {
        if f1 <= f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - g * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + g * (hi - lo);
            f2 = f(x2);
        }
        evaluations += 1;
    }
    let (phi, v) = [(x1, f1), (x2, f2)]
        .into_iter()
        .fold(best, |b, c| if c.1 < b.1 { c } else { b });
    (wrap180(phi), v, evaluations)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{quat_axis_angle_deg, quat_from_euler_zyx_deg};

    /// A knee flexing 15-75 deg about Y with both sensors off the hinge.
    fn knee(n: usize, dt: f64, mp: Quat, md: Quat) -> (Vec<f64>, Vec<Quat>) {
        let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
        let rm = t
            .iter()
            .map(|&s| {
                let flex = 45.0 - 30.0 * (0.5 * s).cos();
                mp.inverse() * quat_from_euler_zyx_deg([0.0, flex, 0.0]) * md
            })
            .collect();
        (t, rm)
    }

    #[test]
    fn one_axis_hinge_is_found_in_both_frames() {
        let mp = quat_axis_angle_deg([1.0, 0.0, 0.3], 20.0);
        let md = quat_axis_angle_deg([0.0, 0.2, 1.0], 25.0);
        let (t, rm) = knee(3000, 0.02, mp, md);
        let w = crate::acm::window::whole_trial(&t);
        let fits = estimate_windows(Hinge::Single(crate::model::Axis::Y), &t, &rm, None, &w);
        let ax = fits.axes[0];
        let want_a = mp.inverse() * Vector3::y();
        let want_b = md.inverse() * Vector3::y();
        assert!(angle_between_axes_deg(&ax.proximal.unwrap(), &want_a) < 1e-6);
        assert!(angle_between_axes_deg(&ax.distal.unwrap(), &want_b) < 1e-6);
        let rec = &fits.record.windows[0];
        assert!(rec.fallback.is_none());
        assert!((rec.proximal_range_deg - 60.0).abs() < 0.1, "{rec:?}");
        // The family's least rotation undoes the tilt: C y = a.
        let fam = AxisFamily::new(&Vector3::y(), &ax.proximal.unwrap());
        assert!((fam.at(17.0) * Vector3::y() - want_a).norm() < 1e-9);
    }

    #[test]
    fn a_joint_that_barely_moves_falls_back() {
        let n = 3000;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.02).collect();
        let rm: Vec<Quat> = t
            .iter()
            .map(|&s| quat_from_euler_zyx_deg([0.0, 30.0 + 2.0 * s.sin(), 0.0]))
            .collect();
        let w = crate::acm::window::whole_trial(&t);
        let fits = estimate_windows(Hinge::Single(crate::model::Axis::Y), &t, &rm, None, &w);
        assert!(fits.axes[0].proximal.is_none() && fits.axes[0].distal.is_none());
        let why = fits.record.windows[0].fallback.as_deref().unwrap();
        assert!(why.contains("4.0 deg about the proximal axis"), "{why}");
        // Not moving at all: no estimate.
        let still = vec![Quat::identity(); n];
        let fits = estimate_windows(Hinge::Single(crate::model::Axis::Y), &t, &still, None, &w);
        assert!(fits.record.windows[0]
            .fallback
            .as_deref()
            .unwrap()
            .contains("hardly moved"));
    }

    #[test]
    fn two_axes_are_refined_past_a_small_turn_about_the_third() {
        // An elbow (pronation Z in the upper arm, flexion X in the forearm)
        // whose Y also turns +-5 deg with zero mean, both sensors tilted.
        let ma = quat_axis_angle_deg([1.0, 1.0, 0.0], 20.0);
        let mb = quat_axis_angle_deg([0.0, 1.0, -1.0], 20.0);
        let t: Vec<f64> = (0..3000).map(|i| f64::from(i) * 0.02).collect();
        let rm: Vec<Quat> = (t.iter())
            .map(|&s| {
                let flex = 70.0 + 60.0 * (1.3 * s).sin();
                let pro = 25.0 * (0.7 * s + 1.0).sin();
                let y = 5.0 * (2.3 * s + 0.4).sin();
                ma.inverse() * quat_from_euler_zyx_deg([flex, y, pro]) * mb
            })
            .collect();
        let rates = rates_from_orientations(&t, &rm, 0.05);
        let (want_a, want_b) = (ma.inverse() * Vector3::z(), mb.inverse() * Vector3::x());
        let opts = MuellerOptions::default();
        let (a, b) = refine_two_axes(&rm, &rates, (Vector3::z(), Vector3::x()), &opts);
        let (ea, eb) = (
            angle_between_axes_deg(&a, &want_a),
            angle_between_axes_deg(&b, &want_b),
        );
        assert!(ea < 1.0 && eb < 1.0, "{ea} / {eb}");
        // The window estimate the variant uses gives the same axes.
        let (rec, axes) = estimate_window(
            Hinge::two_axes_holding(crate::model::Axis::Y),
            30.0,
            &rm,
            &rates,
        );
        assert!(rec.fallback.is_none(), "{rec:?}");
        let ap = axes.proximal.unwrap();
        assert!(angle_between_axes_deg(&ap, &want_a) < 1.0);
        assert!(angle_between_axes_deg(&axes.distal.unwrap(), &want_b) < 1.0);
    }

    /// An elbow over `t` whose Y turns +-5 deg with zero mean, the upper
    /// arm's sensor `ma(s)` and the forearm's `mb` off their hinge axes.
    fn elbow(t: &[f64], ma: &dyn Fn(f64) -> Quat, mb: Quat) -> Vec<Quat> {
        (t.iter())
            .map(|&s| {
                let flex = 70.0 + 60.0 * (1.3 * s).sin();
                let pro = 25.0 * (0.7 * s + 1.0).sin();
                let y = 5.0 * (2.3 * s + 0.4).sin() * (0.11 * s).cos();
                ma(s).inverse() * quat_from_euler_zyx_deg([flex, y, pro]) * mb
            })
            .collect()
    }

    #[test]
    fn windows_that_agree_take_the_axes_fitted_on_all_of_them() {
        // 5 min, 60-s windows every 30 s, both sensors fixed: every window
        // pools, and the pooled axes are closer to the truth than the worst
        // window's own.
        let ma = quat_axis_angle_deg([1.0, 1.0, 0.0], 20.0);
        let mb = quat_axis_angle_deg([0.0, 1.0, -1.0], 20.0);
        let t: Vec<f64> = (0..15000).map(|i| f64::from(i) * 0.02).collect();
        let rm = elbow(&t, &|_| ma, mb);
        let rates = rates_from_orientations(&t, &rm, 0.05);
        let w = crate::window::layout(&t, 60.0, 30.0);
        let hinge = Hinge::two_axes_holding(crate::model::Axis::Y);
        let fits = estimate_windows(hinge, &t, &rm, None, &w);
        let (want_a, want_b) = (ma.inverse() * Vector3::z(), mb.inverse() * Vector3::x());
        let own_worst = (w.iter())
            .map(|w| {
                let (_, ax) =
                    estimate_window(hinge, 0.0, &rm[w.first..w.end], &rates[w.first..w.end]);
                angle_between_axes_deg(&ax.proximal.unwrap(), &want_a)
                    .max(angle_between_axes_deg(&ax.distal.unwrap(), &want_b))
            })
            .fold(0.0, f64::max);
        assert!(fits.record.windows.iter().all(|r| r.pooled));
        let ax = fits.axes[0];
        let pooled = angle_between_axes_deg(&ax.proximal.unwrap(), &want_a)
            .max(angle_between_axes_deg(&ax.distal.unwrap(), &want_b));
        assert!(
            pooled < 0.5 && pooled < own_worst,
            "{pooled} vs {own_worst}"
        );
        assert!(fits.axes.iter().all(|a| a.proximal == ax.proximal));
    }

    #[test]
    fn a_strap_that_slips_splits_the_pool() {
        // The upper arm's sensor turns by 15 deg about its long axis's
        // normal half way through: no window before the slip shares axes
        // with one after it, and the windows on each side keep axes of their
        // own side (those before within 2.4 deg: the window across the slip
        // joins their run and brings some of the new axes).
        let before = quat_axis_angle_deg([1.0, 1.0, 0.0], 20.0);
        let after = quat_axis_angle_deg([1.0, 0.0, 0.0], 15.0) * before;
        let ma = move |s: f64| if s < 150.0 { before } else { after };
        let mb = quat_axis_angle_deg([0.0, 1.0, -1.0], 20.0);
        let t: Vec<f64> = (0..15000).map(|i| f64::from(i) * 0.02).collect();
        let rm = elbow(&t, &ma, mb);
        let w = crate::window::layout(&t, 60.0, 30.0);
        let hinge = Hinge::two_axes_holding(crate::model::Axis::Y);
        let fits = estimate_windows(hinge, &t, &rm, None, &w);
        for (win, ax) in w.iter().zip(&fits.axes) {
            let a = ax.proximal.unwrap();
            if win.end_s <= 150.0 {
                let e = angle_between_axes_deg(&a, &(before.inverse() * Vector3::z()));
                assert!(e < 3.0, "before the slip, window at {}: {e}", win.centre_s);
            } else if win.start_s >= 150.0 {
                let e = angle_between_axes_deg(&a, &(after.inverse() * Vector3::z()));
                assert!(e < 1.0, "after the slip, window at {}: {e}", win.centre_s);
            }
        }
        let first = fits.axes[0].proximal.unwrap();
        let last = fits.axes[w.len() - 1].proximal.unwrap();
        assert!(angle_between_axes_deg(&first, &last) > 10.0);
    }

    #[test]
    fn the_scan_finds_the_turn_a_cost_asks_for() {
        let fam = AxisFamily::new(&Vector3::y(), &Vector3::new(0.1, 1.0, 0.0).normalize());
        let target = fam.at(-123.4);
        let cost = |c: &Quat, _: f64| crate::rotation::angle_between_deg(c, &target);
        let s = minimise_about_axis(&cost, &fam);
        assert!((s.phi_deg + 123.4).abs() < 1e-6, "{s:?}");
        assert!(s.cost < 1e-6);
    }

    #[test]
    fn two_axis_turn_ranges_in_any_order_of_the_axes() {
        use crate::model::Axis;
        // R = R_p(a) R_d(b): a over 0..40, b over -10..60, for each pair of
        // axes, the proximal one earlier or later in Z-Y-X order.
        for (p, d) in [
            (Axis::Z, Axis::X),
            (Axis::Z, Axis::Y),
            (Axis::Y, Axis::X),
            (Axis::X, Axis::Z),
            (Axis::Y, Axis::Z),
            (Axis::X, Axis::Y),
        ] {
            let hinge = Hinge::Two {
                proximal: p,
                distal: d,
            };
            let (np, nd) = hinge.segment_axes();
            let rm: Vec<Quat> = (0..=20)
                .map(|i| {
                    let s = f64::from(i) / 20.0;
                    let a = 40.0 * s;
                    let b = -10.0 + 70.0 * (1.0 - s) * (1.0 - s);
                    quat_axis_angle_deg(np, a) * quat_axis_angle_deg(nd, b)
                })
                .collect();
            let (ra, rb) = turn_ranges(hinge, &rm, &Vector3::from(np), &Vector3::from(nd));
            assert!(
                (ra - 40.0).abs() < 1e-9 && (rb - 70.0).abs() < 1e-9,
                "{}: {ra} {rb}",
                hinge.name()
            );
        }
    }
}
