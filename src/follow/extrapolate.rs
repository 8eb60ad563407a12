//! The correction of samples past the end of the last solved prefix.

use crate::acm::Correction;
use crate::rotation::Quat;
use crate::trial::{ImuSeries, Trial};
use crate::vertical::Vertical;

/// How the correction is carried past the samples it was solved on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Extrapolation {
    /// Each IMU keeps the correction of the last solved sample: `C(t) = C(t_end)`;
    /// the heading variants keep their last heading `h_N` and `C`.
    Hold,
    /// As `Hold`, but the heading variants continue each IMU's heading drift at
    /// its last window-to-window rate: `h(t) = h_N + r_N (t - c_N)` with `c_N`
    /// the last window centre.
    #[default]
    HeadingRate,
}

impl crate::names::Named for Extrapolation {
    const CHOICES: &'static [Self] = &[Extrapolation::HeadingRate, Extrapolation::Hold];
    fn name(self) -> &'static str {
        match self {
            Extrapolation::Hold => "hold",
            Extrapolation::HeadingRate => "rate",
        }
    }
    fn help(self) -> &'static str {
        match self {
            Extrapolation::Hold => "hold the last correction (and the last heading)",
            Extrapolation::HeadingRate => {
                "hold the last correction; heading variants continue the heading at its last rate"
            }
        }
    }
}

/// The sensor-frame correction `c` of `raw`'s last sample in a correction
/// that removed the heading `heading_deg` first: `G_R' = R_up(-h) G_R c`
/// (identity when the IMU was not corrected).
fn held_after_heading(
    correction: &Correction,
    raw: &ImuSeries,
    vertical: Vertical,
    heading_deg: f64,
) -> Quat {
    let last = raw.orientation.len().checked_sub(1);
    let corrected = correction.corrected.imu(&raw.name);
    match (
        raw.orientation.last(),
        corrected.and_then(|c| c.orientation.get(last?)),
    ) {
        (Some(r), Some(c)) => Quat::new_normalize(
            ((vertical.heading_rotation(-heading_deg) * r).inverse() * c).into_inner(),
        ),
        _ => Quat::identity(),
    }
}

/// How one IMU's orientations past the solved samples are corrected.
#[derive(Debug, Clone, PartialEq)]
pub enum ImuExtrapolation {
    /// Not corrected: the orientation is written as read.
    Identity,
    /// `G_R' = G_R * c` (sensor frame correction held).
    Hold { c: Quat },
    /// `G_R' = R_up(-h(t)) * G_R * c`, `h(t) = heading_deg + rate_deg_s * (t - centre_s)`
    /// degrees, `t` and `centre_s` seconds from the first sample.
    Heading {
        c: Quat,
        heading_deg: f64,
        rate_deg_s: f64,
        centre_s: f64,
        vertical: Vertical,
    },
}

/// What a solve of the first `samples` samples lets the follower do with
/// the samples after them.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// Samples the solve saw (a prefix of the trial).
    pub samples: usize,
    /// Trial time of the last sample it saw, seconds from the first sample.
    pub last_s: f64,
    /// One entry per IMU of the trial, in trial order.
    pub imus: Vec<ImuExtrapolation>,
}

impl Solution {
    /// The extrapolation of `correction`, solved on `trial` (the prepared
    /// trial the pipeline corrected: same IMUs and samples).
    pub fn new(trial: &Trial, correction: &Correction, how: Extrapolation) -> Solution {
        let n = trial.len();
        let t0 = trial.time_s.first().copied().unwrap_or(0.0);
        let last_s = trial.time_s.last().map_or(0.0, |t| t - t0);
        let heading_kind = correction.variant.fits_headings();
        let imus = trial
            .imus
            .iter()
            .map(|raw| {
                if heading_kind {
                    if let Some(h) = correction.heading(&raw.name) {
                        if let Some(last) = h.windows.last() {
                            let c = if correction.variant.headings_first() {
                                // The correction after the heading's removal
                                // is the windows' C(t), held at its last value.
                                held_after_heading(correction, raw, h.vertical, last.heading_deg)
                            } else {
                                let [w, x, y, z] = h.correction;
                                Quat::new_normalize(nalgebra::Quaternion::new(w, x, y, z))
                            };
                            let rate = match how {
                                Extrapolation::Hold => 0.0,
                                Extrapolation::HeadingRate => last.rate_deg_s.unwrap_or(0.0),
                            };
                            return ImuExtrapolation::Heading {
                                c,
                                heading_deg: last.heading_deg,
                                rate_deg_s: rate,
                                centre_s: last.centre_s,
                                vertical: h.vertical,
                            };
                        }
                    }
                }
                let corrected = correction.corrected.imu(&raw.name);
                match (
                    raw.orientation.last(),
                    corrected.and_then(|c| c.orientation.get(n - 1)),
                ) {
                    (Some(r), Some(c)) if r != c => ImuExtrapolation::Hold {
                        c: Quat::new_normalize((r.inverse() * c).into_inner()),
                    },
                    _ => ImuExtrapolation::Identity,
                }
            })
            .collect();
        Solution {
            samples: n,
            last_s,
            imus,
        }
    }

    /// The uncorrected extrapolation (before anything was solved).
    pub fn identity(imus: usize) -> Solution {
        Solution {
            samples: 0,
            last_s: 0.0,
            imus: vec![ImuExtrapolation::Identity; imus],
        }
    }

    /// Samples `range` of `trial` corrected with this solution, as a trial of
    /// those samples (gyroscope readings turned into the corrected sensor
    /// frames, `w' = c^-1 w`). `t0` is the trial's first sample time.
    pub fn apply(&self, trial: &Trial, range: std::ops::Range<usize>, t0: f64) -> Trial {
        let time_s = trial.time_s[range.clone()].to_vec();
        let imus = trial
            .imus
            .iter()
            .enumerate()
            .map(|(k, s)| {
                let how = self.imus.get(k).unwrap_or(&ImuExtrapolation::Identity);
                let raw = &s.orientation[range.clone()];
                let orientation: Vec<Quat> = match how {
                    ImuExtrapolation::Identity => raw.to_vec(),
                    ImuExtrapolation::Hold { c } => raw
                        .iter()
                        .map(|q| Quat::new_normalize((q * c).into_inner()))
                        .collect(),
                    ImuExtrapolation::Heading {
                        c,
                        heading_deg,
                        rate_deg_s,
                        centre_s,
                        vertical,
                    } => raw
                        .iter()
                        .zip(&time_s)
                        .map(|(q, &t)| {
                            let h = heading_deg + rate_deg_s * (t - t0 - centre_s);
                            Quat::new_normalize(
                                (vertical.heading_rotation(-h) * q * c).into_inner(),
                            )
                        })
                        .collect(),
                };
                let mut out = ImuSeries::new(s.name.clone(), orientation)
                    .with_gyro(s.gyro.as_ref().map(|g| g[range.clone()].to_vec()));
                match how {
                    ImuExtrapolation::Identity => {}
                    ImuExtrapolation::Hold { c } | ImuExtrapolation::Heading { c, .. } => {
                        out.turn_gyro(c)
                    }
                }
                out
            })
            .collect();
        Trial {
            name: trial.name.clone(),
            time_s,
            imus,
            warnings: Vec::new(),
            orientation_decimals: trial.orientation_decimals,
        }
    }
}
