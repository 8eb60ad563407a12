//! Centroid tables: the mean joint angles over a span of chosen trials, with
//! their spread (thesis 3.3: the source took the first 30 s of ten trials
//! with little drift for Table 3-3).
//!
//! A centroid table is a CSV file, one row per joint (or limit table row) and
//! axis: `joint,axis,centroid_deg,sd_deg,samples,trials`. Its `centroid_deg`
//! is the arithmetic mean of the Z-Y-X angle, degrees; `sd_deg` the standard
//! deviation of the samples about it.

use super::{JointSamples, TimeSpan};
use crate::limits::axis_name;
use std::fmt::Write as _;

/// The header of a centroid table.
pub const HEADER: &str = "joint,axis,centroid_deg,sd_deg,samples,trials";

/// The centroid of one axis of one joint or group.
#[derive(Debug, Clone, PartialEq)]
pub struct CentroidRow {
    /// Joint or limit table row name (see [`JointSamples::name`]).
    pub joint: String,
    /// 0 = X, 1 = Y, 2 = Z.
    pub axis: usize,
    /// Mean angle, degrees.
    pub centroid_deg: f64,
    /// Standard deviation of the samples (population), degrees.
    pub sd_deg: f64,
    pub samples: usize,
    pub trials: usize,
}

/// A whole centroid table.
#[derive(Debug, Clone, PartialEq)]
pub struct CentroidTable {
    /// Comment lines written above the header.
    pub preamble: Vec<String>,
    pub rows: Vec<CentroidRow>,
}

/// The centroids of every group of `samples` (three rows each) over `span`.
pub fn centroids(samples: &[JointSamples], span: TimeSpan) -> CentroidTable {
    let mut rows = vec![];
    for s in samples {
        let n = s.angles.len();
        if n == 0 {
            continue;
        }
        for axis in 0..3 {
            let mean = s.angles.iter().map(|a| a[axis]).sum::<f64>() / n as f64;
            let var = s
                .angles
                .iter()
                .map(|a| (a[axis] - mean).powi(2))
                .sum::<f64>()
                / n as f64;
            rows.push(CentroidRow {
                joint: s.name.clone(),
                axis,
                centroid_deg: mean,
                sd_deg: var.sqrt(),
                samples: n,
                trials: s.trials,
            });
        }
    }
    let trials = rows.iter().map(|r| r.trials).max().unwrap_or(0);
    CentroidTable {
        preamble: vec![format!(
            "# Centroids by acmw: mean Z-Y-X joint angles (deg) of {trials} trial(s), {} (thesis 3.3).",
            span.label()
        )],
        rows,
    }
}

impl CentroidTable {
    /// CSV text: comments, header, rows (angles to 0.01 deg).
    pub fn to_csv(&self) -> String {
        let mut out = String::new();
        for c in &self.preamble {
            out.push_str(c);
            out.push('\n');
        }
        out.push_str(HEADER);
        out.push('\n');
        for r in &self.rows {
            let _ = writeln!(
                out,
                "{},{},{:.2},{:.2},{},{}",
                r.joint,
                axis_name(r.axis),
                r.centroid_deg,
                r.sd_deg,
                r.samples,
                r.trials
            );
        }
        out
    }

    /// The rows of one joint or group, X, Y, Z.
    pub fn joint(&self, name: &str) -> Option<[&CentroidRow; 3]> {
        let find = |axis| self.rows.iter().find(|r| r.joint == name && r.axis == axis);
        Some([find(0)?, find(1)?, find(2)?])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mean_and_spread_by_hand() {
        let s = JointSamples {
            name: "hip".into(),
            joints: vec!["l_hip".into(), "r_hip".into()],
            trials: 2,
            angles: vec![[1.0, 10.0, -3.0], [3.0, 10.0, 5.0]],
        };
        let t = centroids(&[s], TimeSpan::FIRST_30_S);
        let [x, y, z] = t.joint("hip").unwrap();
        assert_eq!((x.centroid_deg, x.sd_deg), (2.0, 1.0));
        assert_eq!((y.centroid_deg, y.sd_deg), (10.0, 0.0));
        assert_eq!((z.centroid_deg, z.sd_deg), (1.0, 4.0));
        assert_eq!((z.samples, z.trials), (2, 2));
        let csv = t.to_csv();
        assert!(csv.starts_with("# Centroids by acmw"), "{csv}");
        assert!(
            csv.contains("\njoint,axis,centroid_deg,sd_deg,samples,trials\nhip,X,2.00,1.00,2,2\n")
        );
        assert!(centroids(&[], TimeSpan::WHOLE).rows.is_empty());
    }
}
