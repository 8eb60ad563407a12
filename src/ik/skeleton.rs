//! The model as a kinematic tree for inverse kinematics: one segment per IMU,
//! each joint's moving Z-Y-X axes as coordinates with their hard limits.
//!
//! Segment orientations (segment frame to global frame G):
//! `S_base = B` (a free rotation),
//! `S_distal = S_proximal * Q Rz(d z) Ry(d y) Rx(d x) Q^T` (the joint's
//! [`crate::model::Joint::rotation`]: `Q` and `d = det(P)` are its table axes,
//! docs/method.md section 2.5; `Q = I`, `d = 1` for identity `angle_axes`),
//! where each of `x, y, z` is a coordinate when the joint declares it in `dof`
//! and its `default_pose_deg` value otherwise (coordinates, `dof`, hard limits
//! and the default pose are in the table's convention). Coordinates are
//! radians inside the solver, degrees in every output.

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
    /// Per table-convention angle `[x, y, z]` of the joint: the coordinate
    /// index, or None when fixed.
    pub coordinate: [Option<usize>; 3],
    /// The joint's table axes `Q` in its segment frames (identity for the
    /// base and for identity `angle_axes`).
    pub frame: crate::rotation::Quat,
    /// `det(P)` of the table axes: -1 where they are a mirror image of the
    /// segment frames (the Z-Y-X angles of `Q^T R Q` count the other way).
    pub det: f64,
    /// Values of the table-convention angles, radians (from `default_pose_deg`).
    pub fixed: [f64; 3],
    /// The joint's limit box (degrees, table convention; [`crate::model::Joint::limit_box`]):
    /// of a rotation's two Z-Y-X triplets the one it reads starts the solve
    /// (a hinge knee flexed 120 deg starts at 120, not 60). None for the base.
    pub limit_box: Option<[[f64; 2]; 3]>,
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
            frame: crate::rotation::Quat::identity(),
            det: 1.0,
            fixed: [0.0; 3],
            limit_box: None,
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
            for axis in Axis::ALL.into_iter().filter(|a| j.moves(*a)) {
                let [lower, upper] = j
                    .hard_limits_deg
                    .get(axis)
                    .map(|l| l.map(f64::to_radians))
                    .unwrap_or([f64::NEG_INFINITY, f64::INFINITY]);
                coordinate[axis.index()] = Some(coordinates.len());
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
                frame: j
                    .table_axes()
                    .map_or_else(crate::rotation::Quat::identity, |a| a.q),
                det: j.table_axes().map_or(1.0, |a| a.det),
                fixed: j.default_pose_deg.map(f64::to_radians),
                limit_box: j.limit_box(),
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

    /// The table-convention angles `[x, y, z]` of a segment's joint (radians)
    /// for coordinates `q`.
    pub fn joint_angles(&self, segment: usize, q: &[f64]) -> [f64; 3] {
        let s = &self.segments[segment];
        let mut a = s.fixed;
        for (k, c) in s.coordinate.iter().enumerate() {
            if let Some(c) = c {
                a[k] = q[*c];
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
