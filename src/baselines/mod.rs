//! The single-joint methods the source compares the ACM against (docs/method.md
//! section 11): Rivest (2005) for knees, Mueller et al. (2017) for elbows.
//!
//! Each runs as a variant of the whole-trial correction (`rivest`, `mueller`):
//! the joints of its kind get the baseline, every other joint the ACM's
//! `drift-centroid` (the chain runs as usual, so a child of a baseline joint is
//! measured against the baseline's corrected orientation). Both methods correct
//! the proximal and the distal IMU of their joint; the proximal IMU is also the
//! distal IMU of its parent joint, whose angles must stay that joint's, so both
//! corrections are carried by the distal IMU: `G_R_dist' = G_R_prox' Rt'`, with
//! `Rt'` the baseline's corrected joint rotation. As a per-sample correction of
//! the distal IMU that is `C(t) = Rm(t)^-1 Rt'(t)`.
//!
//! Mueller needs angular rates: from the two IMUs' gyroscope readings when the
//! trial has them for both ([`JointGyros`]), else derived from the
//! orientations; the record says which ([`RateSource`]).

pub mod mueller;
pub mod rivest;

use crate::model::{Hinge, Joint, SignedAxis, TableAxes};
use crate::rotation::{angle_deg, canonical, euler_zyx_deg, quat_from_euler_zyx_deg, wxyz, Quat};
use crate::run::WindowSolution;
use crate::variant::Variant;
use crate::window::{between_centres, Window};
use mueller::{
    estimate_axes, rates_from_gyros, rates_from_orientations, MuellerFit, MuellerOptions,
};
use nalgebra::Vector3;
use rivest::RivestFit;
use serde::{Deserialize, Serialize};

/// A baseline method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Rivest (2005), for joints of kind `knee`, on the joint's angles in the
    /// table's convention (its `angle_axes`, docs/method.md section 2.5).
    Rivest {
        /// The joint's [`Joint::angle_axes`].
        angle_axes: [SignedAxis; 3],
        /// The joint's [`Joint::limit_box`] (degrees): of each rotation's two
        /// Z-Y-X triplets Rivest fits the one it reads (flexion beyond 90 deg
        /// on Y).
        limit_box: Option<[[f64; 2]; 3]>,
    },
    /// Mueller et al. (2017), for joints of kind `elbow`, turning about the
    /// two segment axes `axes` ([`Joint::two_axis_hinge`]).
    Mueller {
        /// The joint's proximal-fixed and distal-fixed segment axes.
        axes: Hinge,
    },
}

impl Method {
    /// The joint kind (limit-table row) the method is made for.
    pub fn joint_kind(self) -> &'static str {
        match self {
            Method::Rivest { .. } => "knee",
            Method::Mueller { .. } => "elbow",
        }
    }
}

/// The baseline that corrects `joint` in `variant`, if any (by its kind).
pub fn method_for(variant: Variant, joint: &Joint) -> Option<Method> {
    let m = match variant {
        Variant::Rivest => Method::Rivest {
            angle_axes: joint.angle_axes,
            limit_box: joint.limit_box(),
        },
        Variant::Mueller => Method::Mueller {
            axes: joint.two_axis_hinge(),
        },
        _ => return None,
    };
    (m.joint_kind() == joint.kind).then_some(m)
}

/// Where Mueller's angular rates came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RateSource {
    /// The two IMUs' gyroscope readings (each in its sensor frame).
    Gyroscopes,
    /// Central differences of the measured joint rotations (the only source
    /// before trials carried gyros, hence the default of older sidecars).
    #[default]
    Orientations,
}

/// The gyroscope readings of a joint's two IMUs, rad/s, one per sample:
/// `proximal` in the frame the measured joint rotations are taken from (the
/// proximal IMU as corrected by its parent joint), `distal` in the distal
/// IMU's sensor frame.
#[derive(Debug, Clone, Copy)]
pub struct JointGyros<'a> {
    pub proximal: &'a [Vector3<f64>],
    pub distal: &'a [Vector3<f64>],
}

/// What a baseline found for one joint (kept in the sidecar).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "kebab-case")]
pub enum BaselineRecord {
    /// Rivest's four corrections per window (degrees), in window order; between
    /// window centres they are interpolated linearly.
    Rivest { fits: Vec<RivestFit> },
    /// Mueller's axes (one estimate for the whole trial); `None` when the joint
    /// moved too little to estimate them (the joint is then left as measured).
    /// `rates` says where the angular rates came from (sidecars written before
    /// gyroscope support lack it and read as `orientations`).
    Mueller {
        fit: Option<MuellerFit>,
        #[serde(default)]
        rates: RateSource,
    },
}

/// A baseline's solution of one joint.
#[derive(Debug, Clone, PartialEq)]
pub struct BaselineSolution {
    /// Per window: `correction` is the mean of the applied correction `C(t)`
    /// over the window and `angle_deg` its angle; `cost` and
    /// `cost_uncorrected` are the method's own cost (Rivest: eq. 2.12 per
    /// sample, deg^2; Mueller: J of eq. 2.25) at the solution and with no
    /// correction; `evaluations` counts gradient-descent iterations (Mueller)
    /// or 1 (Rivest's closed form).
    pub windows: Vec<WindowSolution>,
    /// `C(t)` per sample (sensor frame of the distal IMU).
    pub series: Vec<Quat>,
    pub record: BaselineRecord,
    /// The distal IMU's gyroscope readings in its corrected frame (rad/s), when
    /// the method can tell them: Mueller from both IMUs' gyros. `None`
    /// otherwise: `C(t)` turns with the joint, so the recorded readings no
    /// longer describe the corrected orientation and are dropped.
    pub gyro: Option<Vec<Vector3<f64>>>,
}

/// Solves one joint with `method` from the measured joint rotations `Rm_i`
/// (parent' to child). Rivest fits each of `windows`; Mueller fits the whole
/// trial once (the axes are fixed in the sensors) and reports it per window,
/// with rates from `gyros` when given (one reading per sample for both IMUs),
/// else derived from `measured`. Rivest ignores `gyros`.
pub fn solve_joint(
    method: Method,
    time_s: &[f64],
    measured: &[Quat],
    gyros: Option<JointGyros>,
    windows: &[Window],
) -> BaselineSolution {
    match method {
        Method::Rivest {
            angle_axes,
            limit_box,
        } => solve_rivest(time_s, measured, windows, angle_axes, limit_box),
        Method::Mueller { axes } => solve_mueller(time_s, measured, gyros, windows, axes),
    }
}

/// Rivest on the table-convention angles of `measured` (docs/method.md
/// section 2.5): fitted, corrected, and turned back into joint rotations.
/// Rivest's model (eq. 2.10-2.11) couples rotation and ab/adduction with the
/// handedness of a right-handed frame, so where the table's axes are a
/// mirror image of the segment frames (`det(P) = -1`, a left knee of a model
/// whose left limbs mirror the right) it is fitted on `det(P)` times the
/// table's angles (the angles in the proper frame `Q`) and the correction
/// turned back; its fits are in that frame.
fn solve_rivest(
    time_s: &[f64],
    measured: &[Quat],
    windows: &[Window],
    angle_axes: [SignedAxis; 3],
    limit_box: Option<[[f64; 2]; 3]>,
) -> BaselineSolution {
    let axes = TableAxes::of(&angle_axes);
    let det = axes.map_or(1.0, |a| a.det);
    // The table's angles (read in its limit box), times det(P).
    let angles: Vec<[f64; 3]> = measured
        .iter()
        .map(|q| {
            let principal = match &axes {
                Some(a) => a.angles(q),
                None => euler_zyx_deg(q),
            };
            let table = match &limit_box {
                Some(b) => crate::rotation::read_in_box(principal, b),
                None => principal,
            };
            table.map(|v| det * v)
        })
        .collect();
    let rotation = |proper: [f64; 3]| {
        let t = proper.map(|v| det * v);
        match &axes {
            Some(a) => a.rotation(t),
            None => quat_from_euler_zyx_deg(t),
        }
    };
    let fits: Vec<RivestFit> = windows
        .iter()
        .map(|w| rivest::fit(&angles[w.first..w.end]))
        .collect();
    let centres: Vec<f64> = windows.iter().map(|w| w.centre_s).collect();
    let per_sample = between_centres(time_s, &centres, &fits, RivestFit::lerp);
    let series: Vec<Quat> = measured
        .iter()
        .zip(&angles)
        .zip(&per_sample)
        .map(|((rm, a), f)| rm.inverse() * rotation(f.correct(*a)))
        .collect();
    let windows_out = windows
        .iter()
        .zip(&fits)
        .map(|(w, f)| {
            let a = &angles[w.first..w.end];
            window_solution(w, &series, f.cost(a), RivestFit::default().cost(a), 1)
        })
        .collect();
    BaselineSolution {
        windows: windows_out,
        series,
        record: BaselineRecord::Rivest { fits },
        gyro: None,
    }
}

/// Relative rates (rad/s, proximal frame) for Mueller and where they came
/// from: the gyros when both IMUs have one per sample, else the orientations.
fn mueller_rates(
    time_s: &[f64],
    measured: &[Quat],
    gyros: Option<JointGyros>,
    opts: &MuellerOptions,
) -> (Vec<Vector3<f64>>, RateSource) {
    match gyros {
        Some(g) if g.proximal.len() == measured.len() && g.distal.len() == measured.len() => (
            rates_from_gyros(measured, g.proximal, g.distal),
            RateSource::Gyroscopes,
        ),
        _ => (
            rates_from_orientations(time_s, measured, opts.rate_half_span_s),
            RateSource::Orientations,
        ),
    }
}

/// The distal IMU's gyros after Mueller's correction: as recorded when no
/// axes were found (no correction), from both IMUs' gyros through
/// [`MuellerFit::corrected_distal_rates`] when they were, `None` without gyros.
fn mueller_corrected_gyro(
    fit: Option<&MuellerFit>,
    measured: &[Quat],
    gyros: Option<JointGyros>,
) -> Option<Vec<Vector3<f64>>> {
    let g = gyros?;
    if g.proximal.len() != measured.len() || g.distal.len() != measured.len() {
        return None;
    }
    Some(match fit {
        None => g.distal.to_vec(),
        Some(f) => f.corrected_distal_rates(measured, g.proximal, g.distal),
    })
}

fn solve_mueller(
    time_s: &[f64],
    measured: &[Quat],
    gyros: Option<JointGyros>,
    windows: &[Window],
    axes: Hinge,
) -> BaselineSolution {
    let opts = MuellerOptions::default();
    let (rates, source) = mueller_rates(time_s, measured, gyros, &opts);
    let (np, nd) = axes.segment_axes();
    let fit = estimate_axes(measured, &rates, (np.into(), nd.into()), &opts);
    let series: Vec<Quat> = match &fit {
        Some(f) => measured
            .iter()
            .map(|rm| rm.inverse() * f.correct(rm))
            .collect(),
        None => vec![Quat::identity(); measured.len()],
    };
    let (cost, cost_nominal, iterations) = fit
        .map(|f| (f.cost, f.cost_nominal, f.iterations))
        .unwrap_or((0.0, 0.0, 0));
    let windows_out = windows
        .iter()
        .map(|w| window_solution(w, &series, cost, cost_nominal, iterations))
        .collect();
    BaselineSolution {
        windows: windows_out,
        series,
        gyro: mueller_corrected_gyro(fit.as_ref(), measured, gyros),
        record: BaselineRecord::Mueller { fit, rates: source },
    }
}

/// A window's record: the mean applied correction over the window.
fn window_solution(
    w: &Window,
    series: &[Quat],
    cost: f64,
    cost_uncorrected: f64,
    evaluations: usize,
) -> WindowSolution {
    let mean = mean_rotation(&series[w.first..w.end]);
    WindowSolution {
        start_s: w.start_s,
        end_s: w.end_s,
        centre_s: w.centre_s,
        samples: w.len(),
        correction: wxyz(&mean),
        angle_deg: angle_deg(&mean),
        cost,
        cost_uncorrected,
        evaluations,
    }
}

/// The normalised sum of sign-aligned quaternions (identity when empty).
fn mean_rotation(qs: &[Quat]) -> Quat {
    let Some(first) = qs.first() else {
        return Quat::identity();
    };
    let r = first.into_inner();
    let sum = qs
        .iter()
        .fold(nalgebra::Quaternion::new(0.0, 0.0, 0.0, 0.0), |s, q| {
            let q = q.into_inner();
            if q.dot(&r) < 0.0 {
                s - q
            } else {
                s + q
            }
        });
    canonical(&Quat::from_quaternion(sum))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Axis, IDENTITY_AXES};
    use crate::rotation::quat_axis_angle_deg;
    use crate::window::{layout, whole_trial};

    #[test]
    fn mueller_records_say_where_the_rates_came_from_and_old_ones_still_load() {
        let new = BaselineRecord::Mueller {
            fit: None,
            rates: RateSource::Gyroscopes,
        };
        let json = serde_json::to_string(&new).unwrap();
        assert_eq!(
            json,
            r#"{"method":"mueller","fit":null,"rates":"gyroscopes"}"#
        );
        let back: BaselineRecord = serde_json::from_str(&json).unwrap();
        assert_eq!(back, new);
        // Written before gyroscope support: no "rates", which were orientations.
        let old: BaselineRecord =
            serde_json::from_str(r#"{"method":"mueller","fit":null}"#).unwrap();
        assert_eq!(
            old,
            BaselineRecord::Mueller {
                fit: None,
                rates: RateSource::Orientations
            }
        );
    }

    #[test]
    fn only_the_methods_joint_kind_gets_the_baseline() {
        let model = crate::model::Model::infant13();
        let (knee, elbow) = (
            model.joint("l_knee").unwrap(),
            model.joint("l_elbow").unwrap(),
        );
        // Prone frames: pronation about the arm's long axis y, flexion
        // about the forearm's x.
        let yx = Hinge::Two {
            proximal: Axis::Y,
            distal: Axis::X,
        };
        assert_eq!(
            method_for(Variant::Rivest, knee),
            Some(Method::Rivest {
                angle_axes: knee.angle_axes,
                limit_box: knee.limit_box(),
            })
        );
        assert_eq!(method_for(Variant::Rivest, elbow), None);
        assert_eq!(
            method_for(Variant::Mueller, elbow),
            Some(Method::Mueller { axes: yx })
        );
        assert_eq!(method_for(Variant::Mueller, knee), None);
        assert_eq!(method_for(Variant::DriftCentroid, knee), None);
    }

    #[test]
    fn mueller_turns_about_the_axes_of_the_models_frames() {
        // Standing frames put the elbow's carrying angle (the table's Y) on
        // the segments' X: flexion and pronation turn about Z and Y.
        for name in ["full_body16", "opensim"] {
            let model = crate::model::Model::builtin(name).unwrap();
            for side in ["l_elbow", "r_elbow"] {
                let elbow = model.joint(side).unwrap();
                assert_eq!(elbow.segment_axis(Axis::Y).axis, Axis::X, "{name} {side}");
                assert_eq!(
                    method_for(Variant::Mueller, elbow),
                    Some(Method::Mueller {
                        axes: Hinge::Two {
                            proximal: Axis::Z,
                            distal: Axis::Y
                        }
                    }),
                    "{name} {side}"
                );
            }
        }
    }

    #[test]
    fn rivest_series_carries_the_corrected_angles_and_interpolates_windows() {
        // Calf rotated 8 deg about X for the first half, 12 deg after: a
        // rotation offset Rivest removes per window.
        let n = 9000;
        let time_s: Vec<f64> = (0..n).map(|i| i as f64 / 50.0).collect();
        let measured: Vec<Quat> = time_s
            .iter()
            .map(|&t| {
                let flex = 45.0 - 30.0 * (t * 0.5).cos();
                let off = if t < 90.0 { 8.0 } else { 12.0 };
                quat_from_euler_zyx_deg([0.0, flex, 0.0])
                    * quat_axis_angle_deg([1.0, 0.0, 0.0], off)
            })
            .collect();
        let windows = layout(&time_s, 60.0, 30.0);
        let sol = solve_joint(
            Method::Rivest {
                angle_axes: IDENTITY_AXES,
                limit_box: None,
            },
            &time_s,
            &measured,
            None,
            &windows,
        );
        let BaselineRecord::Rivest { fits } = &sol.record else {
            panic!("rivest record")
        };
        assert_eq!(fits.len(), windows.len());
        assert!((fits[0].b2 - 8.0).abs() < 1e-6 && (fits.last().unwrap().b2 - 12.0).abs() < 1e-6);
        for i in [0, 1000, 8999] {
            let c = euler_zyx_deg(&(measured[i] * sol.series[i]));
            assert!(c[0].abs() < 1e-6 && c[2].abs() < 1e-6, "{i}: {c:?}");
            assert!((c[1] - euler_zyx_deg(&measured[i])[1]).abs() < 1e-9);
        }
        // Half-way between the centres of windows 2 and 3 (at 75 s and 105 s).
        let mid = fits[2].lerp(&fits[3], 0.5);
        assert!((mid.b2 - 0.5 * (fits[2].b2 + fits[3].b2)).abs() < 1e-12);
        let one = solve_joint(
            Method::Rivest {
                angle_axes: IDENTITY_AXES,
                limit_box: None,
            },
            &time_s,
            &measured,
            None,
            &whole_trial(&time_s),
        );
        assert_eq!(one.windows.len(), 1);
    }

    #[test]
    fn rivest_works_on_the_table_angles_of_a_standing_knee() {
        // full_body16's right knee counts flexion on the segments' y with
        // table X and Z on their -z and -x (a mirror image): a calf offset of
        // 8 deg about the table's X with up to 80 deg of flexion is removed
        // from X and Z and flexion stays as measured, all in table angles.
        let model = crate::model::Model::builtin("full_body16").unwrap();
        let knee = model.joint("r_knee").unwrap();
        assert_eq!(knee.table_axes().unwrap().det, -1.0);
        let time_s: Vec<f64> = (0..3000).map(|i| i as f64 / 50.0).collect();
        let flex = |t: f64| 45.0 - 35.0 * (t * 0.5).cos();
        let measured: Vec<Quat> = time_s
            .iter()
            .map(|&t| knee.rotation([0.0, flex(t), 0.0]) * knee.rotation([8.0, 0.0, 0.0]))
            .collect();
        let windows = whole_trial(&time_s);
        let method = method_for(Variant::Rivest, knee).unwrap();
        let sol = solve_joint(method, &time_s, &measured, None, &windows);
        let BaselineRecord::Rivest { fits } = &sol.record else {
            panic!("rivest record")
        };
        // The fit is in the knee's proper frame: det(P) times the table's
        // angles, so the 8 deg calf term reads -8.
        assert!((fits[0].b2 + 8.0).abs() < 1e-6, "{:?}", fits[0]);
        for i in (0..time_s.len()).step_by(101) {
            let a = knee.table_angles(&(measured[i] * sol.series[i]));
            assert!(a[0].abs() < 1e-6 && a[2].abs() < 1e-6, "{i}: {a:?}");
            assert!((a[1] - flex(time_s[i])).abs() < 1e-6, "{i}: {a:?}");
        }
    }
}
