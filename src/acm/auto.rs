//! The `auto` variant: per joint, in chain order, one of the variants
//! [`CANDIDATES`] chosen from figures the trial itself gives, without truth
//! (docs/method.md section 19).
//!
//! Every candidate corrects the whole trial on its own and each joint takes
//! the joint rotation of the run it chose ([`super::auto_run`]); this module
//! only judges a joint's candidates. All angles are degrees; joint angles
//! are the limit table's convention ([`crate::model::Joint::angles`]); a
//! correction `C(t)` is the distal IMU's sensor-frame rotation
//! `G_R_measured(t)^-1 G_R_corrected(t)`.
//!
//! The judgement of a candidate is its **score**, in degrees:
//!
//! ```text
//! score = excursion + PULL_WEIGHT * max(0, pull - PULL_FREE)
//! ```
//!
//! - `excursion`: the joint's mean excursion beyond the table's limits (the
//!   figure of section 16, without the centroid term), in the table's own
//!   model (Euler box or swing-twist), with the candidate run's own proximal
//!   and distal IMUs;
//! - `pull`: for `drift-centroid` and `drift-heading-centroid`, how far the
//!   mean angles sit from those of the same model without the centroid
//!   term, as a fraction of the limits' half-width on the worst axis.
//!
//! Recorded, not scored: `wobble`, how far the correction moves between
//! windows beyond what its model explains (the RMS angle of the window
//! corrections about their mean; for the heading variants the RMS of the
//! window headings about their least-squares line), and the heading trend.
//! Scoring it (weight 0.1, as before the hinge candidates) made the choice
//! worse on the tuning trials (median joint error 3.29 against 2.91 deg).
//!
//! `none` scores its excursion alone, so the choice is never worse than
//! leaving the joint uncorrected by the score. Candidates within
//! [`MARGIN_DEG`] of the lowest score (and not above `none`'s) count as
//! tied, and the first of them in [`CANDIDATES`] order is taken.

use super::cost::excursion;
use super::{ImuHeading, WindowSolution};
use crate::limits::JointLimits;
use crate::model::Joint;
use crate::rotation::{angle_deg, quat_from_wxyz, wrap180, Quat};
use crate::variant::Variant;
use serde::{Deserialize, Serialize};

/// The variants `auto` chooses among, in order of preference on a tie:
/// the best single variants on simulated trials first, `none` (the joint as
/// measured) last. `hinge` is not among them: on trials without heading
/// drift `hinge-heading` gives its corrections to a few hundredths of a
/// degree, and offering both changed no figure on the 36 tuning trials
/// while it cost a third of the run.
pub const CANDIDATES: &[Variant] = &[
    Variant::HingeHeading,
    Variant::DriftHeadingCentroid,
    Variant::DriftHeading,
    Variant::DriftCentroid,
    Variant::Drift,
    Variant::None,
];

/// Weight of the centroid pull beyond [`PULL_FREE`] in the score, degrees per
/// unit of half-width.
pub const PULL_WEIGHT: f64 = 0.25;
/// The centroid pull, as a fraction of the limits' half-width, that costs nothing.
pub const PULL_FREE: f64 = 0.1;
/// Scores closer than this to the lowest count as tied, degrees.
pub const MARGIN_DEG: f64 = 0.005;
/// Two tied candidates whose joint angles differ by more than this (RMS over
/// samples and axes, degrees) leave the joint undecided (flagged).
pub const UNDECIDED_DEG: f64 = 3.0;

/// One candidate solution of a joint, as the chain engine solved it.
pub struct Candidate<'a> {
    pub variant: Variant,
    /// The proximal IMU as the candidate's own run corrected it (global
    /// frame), per sample.
    pub parent: &'a [Quat],
    /// The distal IMU's corrected orientations (global frame), per sample.
    pub distal: &'a [Quat],
    /// The per-window solutions (window corrections: sensor frame).
    pub windows: &'a [WindowSolution],
    /// The heading fit (heading variants).
    pub heading: Option<&'a ImuHeading>,
}

/// A joint with its candidates, for [`choose`].
pub struct JointCandidates<'a> {
    pub joint: &'a Joint,
    /// The joint's limits in the table's convention, with its centroid
    /// (None when the table has no row: then every candidate scores 0).
    pub limits: Option<JointLimits>,
    /// The distal IMU as measured, per sample.
    pub raw: &'a [Quat],
    /// In [`CANDIDATES`] order.
    pub candidates: Vec<Candidate<'a>>,
}

/// The figures `auto` judged one candidate by (degrees).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CandidateFigures {
    pub variant: Variant,
    /// Mean joint excursion beyond the limits per sample (sum over axes).
    pub excursion_deg: f64,
    /// Mean rotation angle of the correction `C(t)`.
    pub correction_deg: f64,
    /// Movement of the correction its model does not explain (see the module).
    pub wobble_deg: f64,
    /// Heading drift over the trial (heading variants): the least-squares
    /// slope of the window headings times the span of their centres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub heading_trend_deg: Option<f64>,
    /// Centroid pull as a fraction of the limits' half-width (centroid variants).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub centroid_pull: Option<f64>,
    /// The score the choice minimises.
    pub score: f64,
}

/// How `auto` chose a joint's correction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AutoChoice {
    /// The variant whose correction the joint took.
    pub chosen: Variant,
    /// The candidate with the next lowest score.
    pub runner_up: Option<Variant>,
    /// One line: why the chosen one won.
    pub reason: String,
    /// What the user should look at: `undecided`, `centroid-pull`,
    /// `uncorrected` (with a word of explanation each).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub flags: Vec<String>,
    /// Every candidate's figures, in [`CANDIDATES`] order.
    pub candidates: Vec<CandidateFigures>,
    /// Set when the user chose `chosen` over `auto`'s own choice, which
    /// this names (the workbench's compare screen).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub overridden: Option<Variant>,
}

/// The choice: the index of the chosen candidate and its record.
pub struct Choice {
    pub chosen_index: usize,
    pub record: AutoChoice,
}

/// The figures of every candidate and the choice among them (see the
/// module); `forced` is the user's choice when they overrode `auto`'s.
pub fn choose(j: &JointCandidates, forced: Option<Variant>) -> Choice {
    let angles: Vec<Vec<[f64; 3]>> = j
        .candidates
        .iter()
        .map(|c| {
            c.parent
                .iter()
                .zip(c.distal)
                .map(|(p, d)| j.joint.angles(p, d))
                .collect()
        })
        .collect();
    let figures: Vec<CandidateFigures> = j
        .candidates
        .iter()
        .enumerate()
        .map(|(i, c)| figures_of(j, i, c, &angles))
        .collect();
    let mut choice = decide(&figures, &angles);
    let forced = forced.and_then(|v| Some((v, figures.iter().position(|f| f.variant == v)?)));
    if let Some((v, index)) = forced.filter(|(v, _)| *v != choice.record.chosen) {
        let own = choice.record.chosen;
        choice.record.reason = format!(
            "chosen by the user (score {:.2} deg) over auto's {own}: {}",
            figures[index].score, choice.record.reason
        );
        choice.record.chosen = v;
        choice.record.overridden = Some(own);
        choice.chosen_index = index;
    }
    choice
}

/// The choice from the candidates' figures and joint angles.
fn decide(figures: &[CandidateFigures], angles: &[Vec<[f64; 3]>]) -> Choice {
    let best = figures
        .iter()
        .map(|f| f.score)
        .fold(f64::INFINITY, f64::min);
    // A tie never lifts the choice above the joint left uncorrected.
    let cap = (figures.iter())
        .find(|f| f.variant == Variant::None)
        .map_or(f64::INFINITY, |f| f.score);
    let chosen_index = figures
        .iter()
        .position(|f| f.score <= (best + MARGIN_DEG).min(cap))
        .unwrap_or(figures.len() - 1);
    let chosen = &figures[chosen_index];
    let runner = (0..figures.len())
        .filter(|&i| i != chosen_index)
        .min_by(|&a, &b| {
            figures[a]
                .score
                .total_cmp(&figures[b].score)
                .then(a.cmp(&b))
        });
    let mut flags = Vec::new();
    if let Some(r) = runner {
        let gap = figures[r].score - chosen.score;
        let apart = rms_apart(&angles[chosen_index], &angles[r]);
        if gap <= MARGIN_DEG && apart > UNDECIDED_DEG {
            flags.push(format!(
                "undecided: {} scores within {MARGIN_DEG} deg yet its angles differ by {apart:.1} deg RMS",
                figures[r].variant
            ));
        }
    }
    if let Some(p) = chosen.centroid_pull.filter(|p| *p > PULL_FREE) {
        flags.push(format!(
            "centroid-pull: the centroid term moves the mean angles by {:.0}% of the limits' half-width",
            100.0 * p
        ));
    }
    if chosen.variant == Variant::None {
        flags.push("uncorrected: no candidate scored below the joint as measured".to_string());
    }
    let reason = match runner {
        Some(r) => format!(
            "score {:.2} deg (excursion {:.2}{}) against {} {:.2} deg",
            chosen.score,
            chosen.excursion_deg,
            chosen
                .centroid_pull
                .map_or(String::new(), |p| format!(", centroid pull {p:.2}")),
            figures[r].variant,
            figures[r].score
        ),
        None => format!("the only candidate, score {:.2} deg", chosen.score),
    };
    Choice {
        chosen_index,
        record: AutoChoice {
            chosen: chosen.variant,
            runner_up: runner.map(|r| figures[r].variant),
            reason,
            flags,
            candidates: figures.to_vec(),
            overridden: None,
        },
    }
}

/// Mean over samples of the summed excursion beyond `range_deg` of the three
/// angles, degrees (summed per axis first, as the report's figure is).
fn joint_mean_excursion_deg(angles: &[[f64; 3]], range_deg: &[[f64; 2]; 3]) -> f64 {
    let mut sum = [0.0; 3];
    for a in angles {
        let a = crate::rotation::read_in_box(*a, range_deg);
        for (s, e) in sum.iter_mut().zip(excursion(a, range_deg)) {
            *s += e;
        }
    }
    sum.iter().sum::<f64>() / angles.len().max(1) as f64
}

fn figures_of(
    j: &JointCandidates,
    i: usize,
    c: &Candidate,
    angles: &[Vec<[f64; 3]>],
) -> CandidateFigures {
    // By the table's own model: a swing-twist table's excursion is the
    // swing's beyond its region plus the twist's beyond its range.
    let excursion_deg = j.limits.as_ref().map_or(0.0, |l| {
        let rotations = c.parent.iter().zip(c.distal).map(|(p, d)| p.inverse() * d);
        match l.swing_twist_parts(j.joint, rotations) {
            Some(parts) => {
                parts.iter().map(|p| p.swing_deg + p.twist_deg).sum::<f64>()
                    / parts.len().max(1) as f64
            }
            None => joint_mean_excursion_deg(&angles[i], &l.range_deg),
        }
    });
    let n = j.raw.len().max(1) as f64;
    let correction_deg = j
        .raw
        .iter()
        .zip(c.distal)
        .map(|(r, d)| angle_deg(&(r.inverse() * d)))
        .sum::<f64>()
        / n;
    let (wobble_deg, heading_trend_deg) = match c.heading {
        Some(h) => heading_wobble(h),
        None => (window_wobble(c.windows), None),
    };
    let plain =
        without_centroid(c.variant).and_then(|v| j.candidates.iter().position(|o| o.variant == v));
    let centroid_pull = match (plain, &j.limits) {
        (Some(p), Some(l)) => Some(pull(&angles[i], &angles[p], l)),
        _ => None,
    };
    let score =
        excursion_deg + PULL_WEIGHT * centroid_pull.map_or(0.0, |p| (p - PULL_FREE).max(0.0));
    CandidateFigures {
        variant: c.variant,
        excursion_deg,
        correction_deg,
        wobble_deg,
        heading_trend_deg,
        centroid_pull,
        score,
    }
}

/// The same model without the centroid term, for the centroid candidates
/// whose pull is measured (the hinge variants' angles differ from
/// `drift`'s by their axes too, so they have none).
fn without_centroid(v: Variant) -> Option<Variant> {
    match v {
        Variant::DriftHeadingCentroid => Some(Variant::DriftHeading),
        Variant::DriftCentroid => Some(Variant::Drift),
        _ => None,
    }
}

/// RMS angle of the window corrections about their mean rotation, degrees.
fn window_wobble(windows: &[WindowSolution]) -> f64 {
    if windows.len() < 2 {
        return 0.0;
    }
    let qs: Vec<Quat> = windows
        .iter()
        .map(|w| quat_from_wxyz(w.correction))
        .collect();
    let mean = mean_rotation(&qs);
    let sq: f64 = qs
        .iter()
        .map(|q| angle_deg(&(mean.inverse() * q)).powi(2))
        .sum();
    (sq / qs.len() as f64).sqrt()
}

/// The chordal mean of rotations (quaternions sign-aligned with the first).
fn mean_rotation(qs: &[Quat]) -> Quat {
    let first = qs[0].coords;
    let sum = qs.iter().fold(nalgebra::Vector4::zeros(), |acc, q| {
        let c = q.coords;
        if c.dot(&first) < 0.0 {
            acc - c
        } else {
            acc + c
        }
    });
    Quat::new_normalize(nalgebra::Quaternion::from(sum))
}

/// The heading fit's wobble (RMS of the window headings about their
/// least-squares line) and its trend over the trial, degrees.
fn heading_wobble(h: &ImuHeading) -> (f64, Option<f64>) {
    let n = h.windows.len();
    if n < 2 {
        return (0.0, Some(0.0));
    }
    let slope = h.mean_rate_deg_s();
    let mt = h.windows.iter().map(|w| w.centre_s).sum::<f64>() / n as f64;
    let mh = h.windows.iter().map(|w| w.heading_deg).sum::<f64>() / n as f64;
    let sq: f64 = h
        .windows
        .iter()
        .map(|w| (w.heading_deg - mh - slope * (w.centre_s - mt)).powi(2))
        .sum();
    let span = h.windows[n - 1].centre_s - h.windows[0].centre_s;
    ((sq / n as f64).sqrt(), Some(slope * span))
}

/// How far the mean angles of `with` sit from those of `without`, as a
/// fraction of the limits' half-width, on the worst axis.
fn pull(with: &[[f64; 3]], without: &[[f64; 3]], limits: &JointLimits) -> f64 {
    let n = with.len().max(1) as f64;
    (0..3)
        .map(|k| {
            let d: f64 = with
                .iter()
                .zip(without)
                .map(|(a, b)| wrap180(a[k] - b[k]))
                .sum::<f64>()
                / n;
            let half = 0.5 * (limits.range_deg[k][1] - limits.range_deg[k][0]);
            d.abs() / half.max(1.0)
        })
        .fold(0.0, f64::max)
}

/// RMS over samples and axes of the wrapped difference of two angle series.
fn rms_apart(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    let n = (3 * a.len()).max(1) as f64;
    let sq: f64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (0..3).map(|k| wrap180(x[k] - y[k]).powi(2)).sum::<f64>())
        .sum();
    (sq / n).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{quat_axis_angle_deg, wxyz};

    fn fig(
        variant: Variant,
        excursion_deg: f64,
        wobble_deg: f64,
        pull: Option<f64>,
    ) -> CandidateFigures {
        let score = excursion_deg + PULL_WEIGHT * pull.map_or(0.0, |p| (p - PULL_FREE).max(0.0));
        CandidateFigures {
            variant,
            excursion_deg,
            correction_deg: 0.0,
            wobble_deg,
            heading_trend_deg: None,
            centroid_pull: pull,
            score,
        }
    }

    fn flat(n: usize, a: f64) -> Vec<[f64; 3]> {
        vec![[a, 0.0, 0.0]; n]
    }

    #[test]
    fn the_lowest_score_wins_and_ties_go_to_the_earlier_candidate() {
        let f = [
            fig(Variant::DriftHeadingCentroid, 1.0, 0.0, Some(0.05)),
            fig(Variant::DriftHeading, 1.0, 0.0, None),
            fig(Variant::DriftCentroid, 0.5, 2.0, Some(0.1)),
            fig(Variant::Drift, 0.7, 0.0, None),
            fig(Variant::None, 3.0, 0.0, None),
        ];
        let angles: Vec<Vec<[f64; 3]>> = (0..5).map(|k| flat(4, k as f64)).collect();
        let c = decide(&f, &angles);
        // drift-centroid's 0.5 (its wobble is recorded, not scored; its pull
        // is free) beats drift's 0.7.
        assert_eq!(c.record.chosen, Variant::DriftCentroid);
        assert_eq!(c.chosen_index, 2);
        assert_eq!(c.record.runner_up, Some(Variant::Drift));
        assert!(c.record.flags.is_empty(), "{:?}", c.record.flags);
        assert!(
            c.record.reason.contains("against drift 0.70 deg"),
            "{}",
            c.record.reason
        );
        // A tie within the margin goes to the earlier candidate, flagged
        // undecided when their angles are far apart.
        let tied = [
            fig(Variant::DriftHeadingCentroid, 1.0, 0.0, None),
            fig(Variant::DriftHeading, 1.0 - 0.5 * MARGIN_DEG, 0.0, None),
            fig(Variant::None, 9.0, 0.0, None),
        ];
        let far = vec![flat(4, 0.0), flat(4, 10.0), flat(4, 0.0)];
        let c = decide(&tied, &far);
        assert_eq!(c.record.chosen, Variant::DriftHeadingCentroid);
        assert!(
            c.record.flags[0].starts_with("undecided"),
            "{:?}",
            c.record.flags
        );
        let near = vec![flat(4, 0.0), flat(4, 1.0), flat(4, 0.0)];
        assert!(decide(&tied, &near).record.flags.is_empty());
    }

    #[test]
    fn never_worse_than_uncorrected_by_the_score() {
        // Every correction removes excursion but pulls more than it
        // removes: the joint is left as measured, and flagged.
        let f = [
            fig(Variant::DriftHeadingCentroid, 0.5, 1.0, Some(3.0)),
            fig(Variant::DriftCentroid, 0.1, 30.0, Some(4.1)),
            fig(Variant::None, 1.0, 0.0, None),
        ];
        let angles: Vec<Vec<[f64; 3]>> = (0..3).map(|_| flat(2, 0.0)).collect();
        let c = decide(&f, &angles);
        assert_eq!(c.record.chosen, Variant::None);
        assert!(c.record.flags.iter().any(|f| f.starts_with("uncorrected")));
    }

    #[test]
    fn a_tie_never_lifts_the_choice_above_uncorrected() {
        let f = [
            fig(
                Variant::DriftHeadingCentroid,
                1.0 + 0.5 * MARGIN_DEG,
                0.0,
                None,
            ),
            fig(Variant::None, 1.0, 0.0, None),
        ];
        let angles: Vec<Vec<[f64; 3]>> = (0..2).map(|_| flat(2, 0.0)).collect();
        assert_eq!(decide(&f, &angles).record.chosen, Variant::None);
    }

    #[test]
    fn wobble_of_constant_and_turning_corrections() {
        let w = |deg: f64| WindowSolution {
            start_s: 0.0,
            end_s: 1.0,
            centre_s: 0.5,
            samples: 1,
            correction: wxyz(&quat_axis_angle_deg([0.0, 0.0, 1.0], deg)),
            angle_deg: deg.abs(),
            cost: 0.0,
            cost_uncorrected: 0.0,
            evaluations: 0,
        };
        // A constant 20-degree correction does not wobble.
        assert!(window_wobble(&[w(20.0), w(20.0), w(20.0)]) < 1e-9);
        // 10 and 30 degrees about one axis: 10 degrees either side of 20.
        assert!((window_wobble(&[w(10.0), w(30.0)]) - 10.0).abs() < 1e-6);
    }

    #[test]
    fn a_heading_trend_does_not_wobble_and_a_zigzag_does() {
        let fit = |headings: &[f64]| ImuHeading {
            imu: "calf".into(),
            joint: "knee".into(),
            vertical: crate::vertical::Vertical::default(),
            correction: [1.0, 0.0, 0.0, 0.0],
            correction_angle_deg: 0.0,
            windows: headings
                .iter()
                .enumerate()
                .map(|(k, &h)| super::super::HeadingWindow {
                    centre_s: 30.0 * k as f64,
                    heading_deg: h,
                    rate_deg_s: None,
                })
                .collect(),
            rounds: 0,
            c_evaluations: 0,
        };
        let (wobble, trend) = heading_wobble(&fit(&[0.0, 3.0, 6.0, 9.0]));
        assert!(wobble < 1e-9);
        assert!((trend.unwrap() - 9.0).abs() < 1e-9);
        let (wobble, trend) = heading_wobble(&fit(&[2.0, -2.0, 2.0, -2.0]));
        assert!(wobble > 1.5, "{wobble}");
        assert!(trend.unwrap().abs() < 3.0);
    }
}
