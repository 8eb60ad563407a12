//! Orientation glitches: jumps between neighbouring samples larger than a set
//! angle. They are found and reported, never smoothed: the data stay as recorded.
//!
//! A jump of one IMU's orientation `G_R_imu` between samples i-1 and i larger
//! than the threshold (degrees, the angle of `q[i-1]^-1 q[i]`) is a glitch at
//! sample i. When the next sample jumps back (it is again more than the threshold
//! from sample i but within it of sample i-1) the glitch is a single-sample spike
//! and the jump back is not counted again. Jumps across a gap
//! ([`super::timing`]) are not glitches: the body may move while no data come.

use super::timing::GAP_FACTOR;
use super::Trial;
use crate::rotation::angle_between_deg;
use serde::{Deserialize, Serialize};

/// Default threshold, degrees between neighbouring samples. Above the largest
/// per-sample change of vigorous real motion at 100 Hz (16 deg in the qmt
/// full-body example, thigh and shank near 1500 deg/s), far below the jumps of
/// a corrupted sample (tens to 180 deg).
pub const DEFAULT_GLITCH_DEG: f64 = 30.0;

/// One glitch.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Glitch {
    /// The IMU (canonical name).
    pub imu: String,
    /// Index of the sample after the jump.
    pub index: usize,
    /// Its time, seconds from the first sample.
    pub time_s: f64,
    /// The jump, degrees.
    pub jump_deg: f64,
    /// True when the next sample jumps back (a single-sample spike).
    pub spike: bool,
}

/// Every glitch of the trial's IMUs, larger than `threshold_deg`, by time then IMU order.
pub fn glitches(trial: &Trial, threshold_deg: f64) -> Vec<Glitch> {
    let t = &trial.time_s;
    let t0 = t.first().copied().unwrap_or(0.0);
    let gap = GAP_FACTOR * super::median_dt(t);
    let mut out = Vec::new();
    for imu in &trial.imus {
        let q = &imu.orientation;
        let n = q.len().min(t.len());
        let mut i = 1;
        while i < n {
            let jump = angle_between_deg(&q[i - 1], &q[i]);
            if jump > threshold_deg && t[i] - t[i - 1] <= gap {
                let spike = i + 1 < n
                    && angle_between_deg(&q[i], &q[i + 1]) > threshold_deg
                    && angle_between_deg(&q[i - 1], &q[i + 1]) <= threshold_deg;
                out.push(Glitch {
                    imu: imu.name.clone(),
                    index: i,
                    time_s: t[i] - t0,
                    jump_deg: jump,
                    spike,
                });
                if spike {
                    i += 1;
                }
            }
            i += 1;
        }
    }
    out.sort_by_key(|g| g.index);
    out
}

/// One line for reports: how many glitches, on which IMUs, the first few.
pub fn glitch_note(found: &[Glitch], threshold_deg: f64) -> Option<String> {
    if found.is_empty() {
        return None;
    }
    let list: Vec<String> = found
        .iter()
        .take(5)
        .map(|g| {
            format!(
                "{} at {:.3} s (sample {}, {:.0} deg{})",
                g.imu,
                g.time_s,
                g.index,
                g.jump_deg,
                if g.spike { ", single-sample" } else { "" }
            )
        })
        .collect();
    let more = if found.len() > 5 { ", ..." } else { "" };
    Some(format!(
        "{} orientation glitch{} (jump over {threshold_deg} deg between neighbouring samples; kept as recorded): {}{more}",
        found.len(),
        if found.len() == 1 { "" } else { "es" },
        list.join(", ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::quat_axis_angle_deg;
    use crate::trial::ImuSeries;

    fn trial(angles: &[f64], times: &[f64]) -> Trial {
        Trial {
            name: "g".into(),
            time_s: times.to_vec(),
            imus: vec![ImuSeries::new(
                "a",
                angles
                    .iter()
                    .map(|&a| quat_axis_angle_deg([0.0, 1.0, 0.0], a))
                    .collect(),
            )],
            warnings: vec![],
            orientation_decimals: None,
        }
    }

    #[test]
    fn spikes_steps_and_gaps() {
        let times: Vec<f64> = (0..8).map(|i| i as f64 * 0.01).collect();
        // A spike at 2, a step at 5 that stays.
        let g = glitches(
            &trial(&[0.0, 1.0, 90.0, 2.0, 3.0, 60.0, 61.0, 62.0], &times),
            30.0,
        );
        assert_eq!(g.len(), 2, "{g:?}");
        assert_eq!((g[0].index, g[0].spike), (2, true));
        assert!((g[0].jump_deg - 89.0).abs() < 1e-9);
        assert_eq!((g[1].index, g[1].spike), (5, false));
        assert!((g[1].time_s - 0.05).abs() < 1e-12);
        // Below the threshold: nothing.
        assert!(glitches(
            &trial(&[0.0, 20.0, 40.0, 60.0, 80.0, 100.0, 120.0, 140.0], &times),
            30.0
        )
        .is_empty());
        // The same step across a 1 s gap is not a glitch.
        let mut gap = times.clone();
        for t in &mut gap[5..] {
            *t += 1.0;
        }
        let g = glitches(
            &trial(&[0.0, 1.0, 2.0, 3.0, 4.0, 60.0, 61.0, 62.0], &gap),
            30.0,
        );
        assert!(g.is_empty(), "{g:?}");
        assert!(glitch_note(&[], 30.0).is_none());
    }
}
