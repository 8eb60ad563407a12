//! The model as a kinematic tree for inverse kinematics: one segment per IMU,
//! each joint's moving Z-Y-X axes as coordinates with their hard limits.
//!
//! Segment orientations (segment frame to global frame G):
//! `S_base = B` (a free rotation), `S_distal = S_proximal * Rz(z) Ry(y) Rx(x)`,
//! where each of `x, y, z` is a coordinate when the joint declares it in `dof`
//! and its `default_pose_deg` value otherwise (coordinates, `dof`, hard limits
//! and the default pose are in the table's convention, each landing on the
//! segment axis the joint's `angle_axes` names, with its sign). Coordinates are radians inside
//! the solver, degrees in every output.

use crate::model::{Axis, Model};
use crate::run::SkippedJoint;

/// One joint coordinate: an Euler axis of a joint that moves.
#[derive(Debug, Clone, PartialEq)]
pub struct Coordinate {
    pub joint: String,
    pub axis: Axis,
    /// Hard limits, radians (infinite when the model declares none).
    pub lower: f64,
    pub upper: f64,
    /// The value in the model's default pose, radians.
    pub default: f64,
}

impl Coordinate {
    /// `<joint>_<axis>`, e.g. `l_knee_y`: the column name in output files.
    pub fn label(&self) -> String {
        format!("{}_{}", self.joint, self.axis.name())
    }

    /// Whether the coordinate has any hard limit.
    pub fn limited(&self) -> bool {
        self.lower.is_finite() || self.upper.is_finite()
    }
}

/// One segment (one IMU) of the tree.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// The IMU's canonical name.
    pub imu: String,
    /// Index of the parent segment (None for the base).
    pub parent: Option<usize>,
    /// Per Z-Y-X angle `[x, y, z]` of the segment frames: the coordinate
    /// index, or None when fixed. A coordinate is a joint angle in the table's
    /// convention (`angle_axes`), so it lands on its segment axis with `sign`.
    pub coordinate: [Option<usize>; 3],
    /// Per segment axis: -1 where the coordinate counts the other way.
    pub sign: [f64; 3],
    /// Values of the segment-frame angles, radians (from `default_pose_deg`).
    pub fixed: [f64; 3],
    /// Weight of this IMU's orientation error.
    pub weight: f64,
    /// Solver columns that move this segment: the base's three, then the
    /// coordinates of every joint from the base down to this segment.
    pub columns: Vec<usize>,
}

/// The base's rotation takes the first three solver columns.
pub const BASE_COLUMNS: usize = 3;

/// The tree: segments in model order (base first, parents before children).
#[derive(Debug, Clone, PartialEq)]
pub struct Skeleton {
    pub segments: Vec<Segment>,
    pub coordinates: Vec<Coordinate>,
    /// Joints of the model left out, and why.
    pub skipped: Vec<SkippedJoint>,
}

impl Skeleton {
    /// The tree of `model`'s joints whose IMUs are `present` (and whose parent
    /// segment is in the tree). `None` when the base IMU is absent.
    pub fn new(model: &Model, present: impl Fn(&str) -> bool) -> Option<Skeleton> {
        if !present(&model.base) {
            return None;
        }
        let mut segments = vec![Segment {
            imu: model.base.clone(),
            parent: None,
            coordinate: [None; 3],
            sign: [1.0; 3],
            fixed: [0.0; 3],
            weight: model.weight(&model.base),
            columns: (0..BASE_COLUMNS).collect(),
        }];
        let mut coordinates: Vec<Coordinate> = Vec::new();
        let mut skipped = Vec::new();
        for j in &model.joints {
            let parent = segments.iter().position(|s| s.imu == j.proximal);
            let reason = if !present(&j.distal) {
                Some(format!("IMU '{}' is not in the trial", j.distal))
            } else if parent.is_none() {
                Some(format!(
                    "its proximal segment '{}' is not in the tree",
                    j.proximal
                ))
            } else {
                None
            };
            if let Some(reason) = reason {
                skipped.push(SkippedJoint {
                    joint: j.name.clone(),
                    reason,
                });
                continue;
            }
            let parent = parent.expect("checked above");
            let mut columns = segments[parent].columns.clone();
            let mut coordinate = [None; 3];
            let mut sign = [1.0; 3];
            for axis in Axis::ALL.into_iter().filter(|a| j.moves(*a)) {
                let [lower, upper] = j
                    .hard_limits_deg
                    .get(axis)
                    .map(|l| l.map(f64::to_radians))
                    .unwrap_or([f64::NEG_INFINITY, f64::INFINITY]);
                let on = j.segment_axis(axis);
                coordinate[on.axis.index()] = Some(coordinates.len());
                if on.negative {
                    sign[on.axis.index()] = -1.0;
                }
                columns.push(BASE_COLUMNS + coordinates.len());
                coordinates.push(Coordinate {
                    joint: j.name.clone(),
                    axis,
                    lower,
                    upper,
                    default: j.default_pose_deg[axis.index()].to_radians(),
                });
            }
            segments.push(Segment {
                imu: j.distal.clone(),
                parent: Some(parent),
                coordinate,
                sign,
                fixed: j.segment_angles(j.default_pose_deg).map(f64::to_radians),
                weight: model.weight(&j.distal),
                columns,
            });
        }
        Some(Skeleton {
            segments,
            coordinates,
            skipped,
        })
    }

    /// Solver unknowns: the base's three plus one per coordinate.
    pub fn columns(&self) -> usize {
        BASE_COLUMNS + self.coordinates.len()
    }

    /// The segment frames' Z-Y-X angles `[x, y, z]` of a segment's joint
    /// (radians) for coordinates `q`.
    pub fn joint_angles(&self, segment: usize, q: &[f64]) -> [f64; 3] {
        let s = &self.segments[segment];
        let mut a = s.fixed;
        for (k, c) in s.coordinate.iter().enumerate() {
            if let Some(c) = c {
                a[k] = s.sign[k] * q[*c];
            }
        }
        a
    }

    /// `q` moved inside the hard limits.
    pub fn clamp(&self, q: &mut [f64]) {
        for (v, c) in q.iter_mut().zip(&self.coordinates) {
            *v = v.clamp(c.lower, c.upper);
        }
    }
}
