//! The source's analysis of joint angles over several trials (thesis 3.1.2 and
//! 3.3): histograms with the interval holding 90% of the samples, limit tables
//! suggested from those intervals, and centroid tables of mean angles.
//!
//! Angles are the joints' Z-Y-X Euler angles `[x, y, z]` in degrees (distal
//! relative to proximal, as [`crate::metrics::joint_angles`] gives them); times
//! are seconds from each trial's first sample.
//!
//! The views of one trial, as numbers (thesis 4.1-4.5, appendices B-C):
//!
//! * [`scatter`]: limit classes of joint angles and their 3-D scatter as three
//!   projections, reduced to a raster of the display's resolution;
//! * [`globe`]: the globographic mapping (the distal segment's direction on a
//!   sphere around the joint) and its limit band;
//! * [`applied`]: the applied correction over time;
//! * [`stick`]: the stick figure from segment orientations and lengths.

pub mod applied;
pub mod centroid;
pub mod globe;
pub mod histogram;
pub mod scatter;
pub mod stick;
pub mod suggest;
pub mod suggest_swing;

use crate::limits::LimitTable;
use crate::model::Model;
use crate::trial::Trial;
use std::collections::BTreeMap;
use std::ops::Range;

/// A time span of every trial, seconds from its first sample, half-open
/// `[start_s, end_s)`; `end_s = f64::INFINITY` runs to the end of the trial.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeSpan {
    pub start_s: f64,
    pub end_s: f64,
}

impl TimeSpan {
    /// The source's span: the first 30 s of each trial (thesis 3.1.2, 3.3).
    pub const FIRST_30_S: TimeSpan = TimeSpan {
        start_s: 0.0,
        end_s: 30.0,
    };

    /// The whole trial.
    pub const WHOLE: TimeSpan = TimeSpan {
        start_s: 0.0,
        end_s: f64::INFINITY,
    };

    /// Sample indices of `time_s` (ascending, as recorded) inside the span.
    pub fn indices(&self, time_s: &[f64]) -> Range<usize> {
        let origin = time_s.first().copied().unwrap_or(0.0);
        let a = time_s.partition_point(|&t| t - origin < self.start_s);
        let b = time_s.partition_point(|&t| t - origin < self.end_s);
        a..b.max(a)
    }

    /// `"0-30 s"`, or `"from 10 s"` for an open end.
    pub fn label(&self) -> String {
        if self.end_s.is_finite() {
            format!("{}-{} s", self.start_s, self.end_s)
        } else if self.start_s > 0.0 {
            format!("from {} s", self.start_s)
        } else {
            "whole trials".into()
        }
    }
}

/// The angles of one group of joints pooled over trials: a single joint, or
/// every joint that shares a row of the limit table (`hip` pools `l_hip` and
/// `r_hip`, as the thesis' Figure 3-6 does).
#[derive(Debug, Clone, PartialEq)]
pub struct JointSamples {
    /// The joint's name, or the limit table row's (`hip`) for a pooled group.
    pub name: String,
    /// Joint names pooled, in model order of first appearance.
    pub joints: Vec<String>,
    /// Number of trials that contributed samples.
    pub trials: usize,
    /// Z-Y-X angles `[x, y, z]`, degrees, one per sample.
    pub angles: Vec<[f64; 3]>,
}

/// One trial with the body model that reads it.
#[derive(Debug, Clone, Copy)]
pub struct TrialRef<'a> {
    pub trial: &'a Trial,
    pub model: &'a Model,
}

/// The trials, each read with `model`.
pub fn trial_refs<'a>(trials: &'a [Trial], model: &'a Model) -> Vec<TrialRef<'a>> {
    trials
        .iter()
        .map(|trial| TrialRef { trial, model })
        .collect()
}

/// Per joint, in model order of first appearance, the angles inside `span` of
/// every trial that has the joint's two IMUs. Joints without any sample in
/// the span are left out.
pub fn pool_by_joint(trials: &[TrialRef], span: TimeSpan) -> Vec<JointSamples> {
    pool(trials, span, |j| j.name.clone())
}

/// Like [`pool_by_joint`], but joints that share a row of `table` pool into
/// one group named after the row (a joint with rows of its own stays alone).
pub fn pool_by_table_row(
    trials: &[TrialRef],
    span: TimeSpan,
    table: &LimitTable,
) -> Vec<JointSamples> {
    pool(trials, span, |j| row_key(table, &j.name, &j.kind))
}

/// The `joint` column of the rows a joint reads: its own name if the table
/// has a row for it, else its kind.
pub fn row_key(table: &LimitTable, joint: &str, kind: &str) -> String {
    if table.rows.iter().any(|r| r.joint == joint) {
        joint.to_string()
    } else {
        kind.to_string()
    }
}

fn pool(
    trials: &[TrialRef],
    span: TimeSpan,
    key: impl Fn(&crate::model::Joint) -> String,
) -> Vec<JointSamples> {
    let mut order: Vec<String> = vec![];
    let mut groups: BTreeMap<String, JointSamples> = BTreeMap::new();
    for t in trials {
        let range = span.indices(&t.trial.time_s);
        let mut touched: Vec<String> = vec![];
        for j in &t.model.joints {
            let Some(angles) = joint_angles_in(t.trial, j, range.clone()) else {
                continue;
            };
            if angles.is_empty() {
                continue;
            }
            let k = key(j);
            let g = groups.entry(k.clone()).or_insert_with(|| {
                order.push(k.clone());
                JointSamples {
                    name: k.clone(),
                    joints: vec![],
                    trials: 0,
                    angles: vec![],
                }
            });
            if !g.joints.contains(&j.name) {
                g.joints.push(j.name.clone());
            }
            g.angles.extend(angles);
            if !touched.contains(&k) {
                touched.push(k.clone());
                g.trials += 1;
            }
        }
    }
    order
        .into_iter()
        .filter_map(|k| groups.remove(&k))
        .collect()
}

/// The angles (degrees, the table's convention) of `joint` for the samples in
/// `range`, if the trial has both IMUs.
fn joint_angles_in(
    trial: &Trial,
    joint: &crate::model::Joint,
    range: Range<usize>,
) -> Option<Vec<[f64; 3]>> {
    let p = &trial.imu(&joint.proximal)?.orientation;
    let d = &trial.imu(&joint.distal)?.orientation;
    let range = range.start.min(p.len())..range.end.min(p.len()).min(d.len());
    Some(range.map(|i| joint.angles(&p[i], &d[i])).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn span_indices_are_half_open_from_the_first_sample() {
        let t: Vec<f64> = (0..100).map(|i| 10.0 + i as f64 * 0.5).collect();
        let s = TimeSpan {
            start_s: 1.0,
            end_s: 3.0,
        };
        assert_eq!(s.indices(&t), 2..6);
        assert_eq!(TimeSpan::WHOLE.indices(&t), 0..100);
        assert_eq!(TimeSpan::FIRST_30_S.indices(&t), 0..60);
        let empty = TimeSpan {
            start_s: 80.0,
            end_s: 90.0,
        };
        assert!(empty.indices(&t).is_empty());
        assert_eq!(TimeSpan::FIRST_30_S.label(), "0-30 s");
    }

    #[test]
    fn pooling_by_row_merges_left_and_right() {
        use crate::simulate::{simulate, SimConfig};
        let mut cfg = SimConfig::full_body(5);
        cfg.duration_s = 40.0;
        let sim = simulate(&cfg).unwrap();
        let model = Model::infant13();
        let refs = [TrialRef {
            trial: &sim.trial,
            model: &model,
        }; 2];
        let table = LimitTable::default_table();
        let by_joint = pool_by_joint(&refs, TimeSpan::FIRST_30_S);
        assert_eq!(by_joint.len(), model.joints.len());
        assert!(by_joint
            .iter()
            .all(|g| g.angles.len() == 2 * 1500 && g.trials == 2));
        let by_row = pool_by_table_row(&refs, TimeSpan::FIRST_30_S, &table);
        let hip = by_row.iter().find(|g| g.name == "hip").unwrap();
        assert_eq!(hip.joints, ["l_hip", "r_hip"]);
        assert_eq!((hip.angles.len(), hip.trials), (4 * 1500, 2));
        // The samples are the joint angles of the metrics module.
        let l_hip = model.joint("l_hip").unwrap();
        let all = crate::metrics::joint_angles(&sim.trial, l_hip).unwrap();
        assert_eq!(hip.angles[..1500], all[..1500]);
    }
}
