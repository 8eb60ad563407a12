//! Body models as data (docs/method.md section 3): IMUs, joints, correction order, aliases.
//!
//! A model is a TOML file. Four ship inside the binary (`infant13`, the source
//! study's 13-IMU suit, `opensim`, `opensense_lower` and `full_body16`); a lab can
//! point `--model` at its own file. The README's "Body models" gives the format.

use serde::{Deserialize, Serialize};
use std::collections::{BTreeMap, HashSet};
use std::path::Path;

/// The models shipped with the program: (name, TOML text).
pub const BUILTIN_MODELS: &[(&str, &str)] = &[
    ("infant13", include_str!("../models/infant13.toml")),
    ("opensim", include_str!("../models/opensim.toml")),
    (
        "opensense_lower",
        include_str!("../models/opensense_lower.toml"),
    ),
    ("full_body16", include_str!("../models/full_body16.toml")),
];

/// An axis of a joint's Z-Y-X Euler angles (docs/method.md section 2.3).
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub enum Axis {
    #[serde(rename = "x", alias = "X")]
    X,
    #[serde(rename = "y", alias = "Y")]
    Y,
    #[serde(rename = "z", alias = "Z")]
    Z,
}

impl Axis {
    /// All three, in the order of the angle triples `[x, y, z]`.
    pub const ALL: [Axis; 3] = [Axis::X, Axis::Y, Axis::Z];

    /// Index into `[x, y, z]`.
    pub fn index(self) -> usize {
        self as usize
    }

    /// `x`, `y` or `z`.
    pub fn name(self) -> &'static str {
        ["x", "y", "z"][self.index()]
    }
}

/// Hard limits of a joint's coordinates, degrees, `[lower, upper]` per axis
/// (absent = unlimited). Inverse kinematics never leaves them.
#[derive(Debug, Clone, Copy, Default, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct HardLimits {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub x: Option<[f64; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub y: Option<[f64; 2]>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub z: Option<[f64; 2]>,
}

impl HardLimits {
    /// The limits of one axis, degrees.
    pub fn get(&self, axis: Axis) -> Option<[f64; 2]> {
        [self.x, self.y, self.z][axis.index()]
    }

    fn is_empty(&self) -> bool {
        *self == HardLimits::default()
    }
}

/// A sensor axis with a sign, e.g. `+x` or `-z`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct SignedAxis {
    pub axis: Axis,
    pub negative: bool,
}

impl SignedAxis {
    /// `+x`.
    pub const PLUS_X: SignedAxis = SignedAxis {
        axis: Axis::X,
        negative: false,
    };

    /// The unit vector `[x, y, z]`.
    pub fn vector(self) -> [f64; 3] {
        let mut v = [0.0; 3];
        v[self.axis.index()] = if self.negative { -1.0 } else { 1.0 };
        v
    }
}

impl std::str::FromStr for SignedAxis {
    type Err = String;
    fn from_str(s: &str) -> Result<SignedAxis, String> {
        let t = s.trim().to_ascii_lowercase();
        let (negative, rest) = match t.as_bytes().first() {
            Some(b'-') => (true, &t[1..]),
            Some(b'+') => (false, &t[1..]),
            _ => (false, t.as_str()),
        };
        let axis = match rest {
            "x" => Axis::X,
            "y" => Axis::Y,
            "z" => Axis::Z,
            _ => {
                return Err(format!(
                    "'{s}' is not an axis (expected +x, -x, +y, -y, +z or -z)"
                ))
            }
        };
        Ok(SignedAxis { axis, negative })
    }
}

impl TryFrom<String> for SignedAxis {
    type Error = String;
    fn try_from(s: String) -> Result<SignedAxis, String> {
        s.parse()
    }
}

impl From<SignedAxis> for String {
    fn from(a: SignedAxis) -> String {
        a.to_string()
    }
}

impl std::fmt::Display for SignedAxis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}{}",
            if self.negative { "-" } else { "+" },
            self.axis.name()
        )
    }
}

/// How pose calibration finds the subject's heading (docs/method.md section 14).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PoseSetup {
    /// The base IMU's sensor axis that points forward in the calibration pose.
    #[serde(default = "plus_x")]
    pub base_forward: SignedAxis,
    /// The model's forward direction in the (horizontal) global frame; the
    /// vertical is global +Z.
    #[serde(default = "plus_x")]
    pub forward: SignedAxis,
}

fn plus_x() -> SignedAxis {
    SignedAxis::PLUS_X
}

impl Default for PoseSetup {
    fn default() -> PoseSetup {
        PoseSetup {
            base_forward: SignedAxis::PLUS_X,
            forward: SignedAxis::PLUS_X,
        }
    }
}

fn is_default<T: Default + PartialEq>(v: &T) -> bool {
    *v == T::default()
}

fn all_axes() -> Vec<Axis> {
    Axis::ALL.to_vec()
}

fn is_all_axes(v: &[Axis]) -> bool {
    v == Axis::ALL
}

/// How a hinge joint turns, in its Z-Y-X angles (docs/method.md section 18):
/// the axes the `hinge` variant estimates in both IMUs' frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum Hinge {
    /// One axis, fixed in both segments (`"y"` for a knee: flexion only).
    Single(Axis),
    /// Two segment axes: `proximal` fixed in the proximal segment and `distal`
    /// in the distal one, `R = R_proximal(a) R_distal(b)` (`"z-x"` for the
    /// elbow of frames whose carrying angle is Y: pronation and flexion;
    /// `"z-y"` where it is X). When `proximal` is the earlier of the two in
    /// Z-Y-X order (`z-y`, `z-x`, `y-x`), the third Z-Y-X angle of the
    /// segment frames is the constant one.
    Two {
        /// The segment axis fixed in the proximal segment.
        proximal: Axis,
        /// The segment axis fixed in the distal segment.
        distal: Axis,
    },
}

/// The unit vector of a segment axis.
fn unit(axis: Axis) -> [f64; 3] {
    let mut v = [0.0; 3];
    v[axis.index()] = 1.0;
    v
}

impl Hinge {
    /// The two-axis hinge whose constant Z-Y-X angle is `held`: of the other
    /// two axes, the earlier in Z-Y-X order is fixed in the proximal segment
    /// (`R = R_1(a) R_2(b)` turns about the proximal frame's axis 1 and the
    /// distal frame's axis 2).
    pub fn two_axes_holding(held: Axis) -> Hinge {
        let [proximal, distal] = match held {
            Axis::X => [Axis::Z, Axis::Y],
            Axis::Y => [Axis::Z, Axis::X],
            Axis::Z => [Axis::Y, Axis::X],
        };
        Hinge::Two { proximal, distal }
    }

    /// The segment axis fixed in the proximal and the one fixed in the
    /// distal segment (the same axis twice for a one-axis hinge).
    pub fn axes(self) -> (Axis, Axis) {
        match self {
            Hinge::Single(a) => (a, a),
            Hinge::Two { proximal, distal } => (proximal, distal),
        }
    }

    /// The hinge axis in the proximal and in the distal segment frame (unit).
    pub fn segment_axes(self) -> ([f64; 3], [f64; 3]) {
        let (p, d) = self.axes();
        (unit(p), unit(d))
    }

    /// The name in model files: `x`, `y`, `z`, or `<proximal>-<distal>`
    /// (`z-y`, `z-x`, `y-x`, `y-z`, `x-z`, `x-y`).
    pub fn name(self) -> &'static str {
        const TWO: [[&str; 3]; 3] = [
            ["x-x", "x-y", "x-z"],
            ["y-x", "y-y", "y-z"],
            ["z-x", "z-y", "z-z"],
        ];
        match self {
            Hinge::Single(a) => a.name(),
            Hinge::Two { proximal, distal } => TWO[proximal.index()][distal.index()],
        }
    }
}

impl TryFrom<String> for Hinge {
    type Error = String;
    fn try_from(s: String) -> Result<Hinge, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "x" => Ok(Hinge::Single(Axis::X)),
            "y" => Ok(Hinge::Single(Axis::Y)),
            "z" => Ok(Hinge::Single(Axis::Z)),
            "z-y" => Ok(Hinge::two_axes_holding(Axis::X)),
            "z-x" => Ok(Hinge::two_axes_holding(Axis::Y)),
            "y-x" => Ok(Hinge::two_axes_holding(Axis::Z)),
            "y-z" | "x-z" | "x-y" => {
                let axis = |c: &str| c.parse::<SignedAxis>().map(|a| a.axis);
                let t = s.trim().to_ascii_lowercase();
                Ok(Hinge::Two {
                    proximal: axis(&t[..1])?,
                    distal: axis(&t[2..])?,
                })
            }
            _ => Err(format!(
                "hinge = '{s}': expected x, y or z (one axis fixed in both segments) or two different axes, the first fixed in the proximal segment, the second in the distal (z-y, z-x, y-x, y-z, x-z, x-y)"
            )),
        }
    }
}

impl From<Hinge> for String {
    fn from(h: Hinge) -> String {
        h.name().to_string()
    }
}

/// One joint: the rotation of the distal IMU relative to the proximal one.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Joint {
    /// Joint name, e.g. `l_knee`.
    pub name: String,
    /// Row name in the limit tables, e.g. `knee` (left and right share a row).
    pub kind: String,
    /// IMU above the joint (its frame is the reference).
    pub proximal: String,
    /// IMU below the joint (the one the ACM corrects).
    pub distal: String,
    /// Degrees of freedom for inverse kinematics: the axes of the joint's
    /// angles (table convention) that move (`["y"]` for a hinge knee); all
    /// three when absent.
    /// The others stay at their `default_pose_deg` value.
    #[serde(default = "all_axes", skip_serializing_if = "is_all_axes")]
    pub dof: Vec<Axis>,
    /// Hard limits of the moving axes, degrees (inverse kinematics only; the
    /// ACM uses the limit tables).
    #[serde(default, skip_serializing_if = "HardLimits::is_empty")]
    pub hard_limits_deg: HardLimits,
    /// The joint's angles `[x, y, z]` in the model's default pose, degrees,
    /// in the table's convention (`angle_axes`; pose calibration takes the
    /// IMUs to show this pose).
    #[serde(default, skip_serializing_if = "is_default")]
    pub default_pose_deg: [f64; 3],
    /// Marks a hinge joint: the `hinge` variant estimates these axes in both
    /// IMUs' frames and corrects the proximal IMU with them too. Absent: not a
    /// hinge.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hinge: Option<Hinge>,
    /// The limit table's axes (docs/method.md section 2.5): entry k names the
    /// segment-frame axis, with its sign, that is the table's axis k
    /// (`["-z", "-y", "-x"]`: the table's X is the segment frames' -z, and so
    /// on). The joint's angles are the Z-Y-X angles of
    /// `(G_R_prox)^T G_R_dist` expressed in these axes ([`TableAxes`]), so a
    /// small turn about segment axis `a_k` reads on table axis k with sign
    /// `s_k`, and any turn reads in the table's own Z-Y-X order. `["+x", "+y",
    /// "+z"]` (the default) takes the segment frames' angles as they are.
    /// Every joint angle the program shows, writes or limits is in the table's
    /// convention.
    #[serde(default = "identity_axes", skip_serializing_if = "is_identity_axes")]
    pub angle_axes: [SignedAxis; 3],
}

/// `["+x", "+y", "+z"]`: the table's angles are the segment frames' own.
pub const IDENTITY_AXES: [SignedAxis; 3] = [
    SignedAxis {
        axis: Axis::X,
        negative: false,
    },
    SignedAxis {
        axis: Axis::Y,
        negative: false,
    },
    SignedAxis {
        axis: Axis::Z,
        negative: false,
    },
];

fn identity_axes() -> [SignedAxis; 3] {
    IDENTITY_AXES
}

fn is_identity_axes(a: &[SignedAxis; 3]) -> bool {
    *a == IDENTITY_AXES
}

/// The limit table's axes in a joint's segment frames (docs/method.md section
/// 2.5): `P`, the signed permutation whose column k is table axis k in segment
/// coordinates (`angle_axes[k]`), kept as the proper rotation `Q = det(P) P`
/// and the sign `det(P)`. The table's angles of a joint rotation `R` (segment
/// frames) are `det(P) * ZYX(Q^T R Q)`, degrees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TableAxes {
    /// `Q = det(P) P` as a unit quaternion (a proper rotation).
    pub q: crate::rotation::Quat,
    /// `det(P)`: `1.0`, or `-1.0` when the table's axes are a mirror image of
    /// the segment frames' (the table's angles then count the other way).
    pub det: f64,
}

impl TableAxes {
    /// The axes of `angle_axes`; `None` for the identity (`["+x", "+y", "+z"]`),
    /// where the table's angles are the segment frames' own.
    pub fn of(angle_axes: &[SignedAxis; 3]) -> Option<TableAxes> {
        if is_identity_axes(angle_axes) {
            return None;
        }
        let cols = angle_axes.map(|a| nalgebra::Vector3::from(a.vector()));
        let p = nalgebra::Matrix3::from_columns(&cols);
        let det = p.determinant().signum();
        let rot = nalgebra::Rotation3::from_matrix_unchecked(p * det);
        Some(TableAxes {
            q: crate::rotation::Quat::from_rotation_matrix(&rot),
            det,
        })
    }

    /// `Q^T R Q`: a joint rotation `r` (segment frames) in the table's axes.
    pub fn to_table(&self, r: &crate::rotation::Quat) -> crate::rotation::Quat {
        self.q.inverse() * r * self.q
    }

    /// `Q R Q^T`: the inverse of [`TableAxes::to_table`].
    pub fn from_table(&self, r: &crate::rotation::Quat) -> crate::rotation::Quat {
        self.q * r * self.q.inverse()
    }

    /// The table's angles `[x, y, z]` (degrees) of the joint rotation `r`.
    pub fn angles(&self, r: &crate::rotation::Quat) -> [f64; 3] {
        crate::rotation::euler_zyx_deg(&self.to_table(r)).map(|a| self.det * a)
    }

    /// The joint rotation (segment frames) whose table angles are `table`
    /// (degrees): `Q Rzyx(det(P) table) Q^T`.
    pub fn rotation(&self, table: [f64; 3]) -> crate::rotation::Quat {
        self.from_table(&crate::rotation::quat_from_euler_zyx_deg(
            table.map(|a| self.det * a),
        ))
    }
}

impl Joint {
    /// The table's axes in the segment frames; `None` when they are the
    /// segment frames' own (`angle_axes` the identity).
    pub fn table_axes(&self) -> Option<TableAxes> {
        TableAxes::of(&self.angle_axes)
    }

    /// Degrees `[x, y, z]` in the limit table's convention of the joint
    /// rotation `r` (distal segment frame in the proximal one): the Z-Y-X
    /// angles of `r` expressed in the table's axes (see [`TableAxes`]). With
    /// identity `angle_axes`, the Z-Y-X angles of `r` itself.
    ///
    /// Of the rotation's two Z-Y-X triplets it is the one the joint's limit
    /// box reads ([`crate::rotation::read_in_box`], docs/method.md section 2.5):
    /// where the box's Y range reaches beyond +-90 (hip and knee flexion), a
    /// knee flexed 120 deg reads 120 on Y. The box is the built-in table's
    /// (Table 3-2) row of the joint ([`Joint::limit_box`]); figures against
    /// another table read the angles in its box again.
    pub fn table_angles(&self, r: &crate::rotation::Quat) -> [f64; 3] {
        let principal = self.principal_table_angles(r);
        match self.limit_box() {
            Some(b) => crate::rotation::read_in_box(principal, &b),
            None => principal,
        }
    }

    /// The principal Z-Y-X triplet (middle angle in [-90, 90]) of the joint
    /// rotation `r` in the table's axes, degrees: [`Joint::table_angles`]
    /// before the limit box picks a triplet.
    pub fn principal_table_angles(&self, r: &crate::rotation::Quat) -> [f64; 3] {
        match self.table_axes() {
            Some(t) => t.angles(r),
            None => crate::rotation::euler_zyx_deg(r),
        }
    }

    /// The limit box `[[lo, hi]; 3]` (degrees, table convention) the joint's
    /// angles are read in: its row (by name, else kind) of the built-in table
    /// (Table 3-2), `None` when that table has no row for it.
    pub fn limit_box(&self) -> Option<[[f64; 2]; 3]> {
        crate::builtin_box::table_3_2_box(&self.name, &self.kind)
    }

    /// The two axes a two-degree-of-freedom joint (the elbow) turns about, in
    /// segment frames: the model's `hinge` when it names two axes, else those
    /// of table angles `[x, 0, z]` (the elbow's carrying angle Y constant):
    /// `Q Rz Rx Q^T` turns about the segment axis of the table's Z, fixed in
    /// the proximal segment, and that of its X, fixed in the distal one.
    pub fn two_axis_hinge(&self) -> Hinge {
        match self.hinge {
            Some(h @ Hinge::Two { .. }) => h,
            _ => Hinge::Two {
                proximal: self.segment_axis(Axis::Z).axis,
                distal: self.segment_axis(Axis::X).axis,
            },
        }
    }

    /// The segment axis, with its sign, that is the table's `axis`
    /// (`angle_axes[axis]`): a small turn about it reads positive there.
    pub fn segment_axis(&self, axis: Axis) -> SignedAxis {
        self.angle_axes[axis.index()]
    }

    /// The joint's angles (degrees, table convention) for the segment
    /// orientations `proximal` and `distal` (segment frame to global).
    pub fn angles(
        &self,
        proximal: &crate::rotation::Quat,
        distal: &crate::rotation::Quat,
    ) -> [f64; 3] {
        self.table_angles(&(proximal.inverse() * distal))
    }

    /// The joint rotation (distal segment frame in the proximal one) whose
    /// angles in the table's convention are `table` (degrees).
    pub fn rotation(&self, table: [f64; 3]) -> crate::rotation::Quat {
        match self.table_axes() {
            Some(t) => t.rotation(table),
            None => crate::rotation::quat_from_euler_zyx_deg(table),
        }
    }

    /// Whether inverse kinematics moves this axis.
    pub fn moves(&self, axis: Axis) -> bool {
        self.dof.contains(&axis)
    }

    /// Checks the joint's own values; the error names the key at fault.
    fn validate(&self) -> Result<(), (&'static str, String)> {
        let name = &self.name;
        for (k, a) in self.angle_axes.iter().enumerate() {
            if self.angle_axes[..k].iter().any(|b| b.axis == a.axis) {
                return Err((
                    "angle_axes",
                    format!(
                        "joint '{name}': angle_axes names the segment axis '{}' twice (expected each of x, y, z once, e.g. [\"-z\", \"-y\", \"-x\"])",
                        a.axis.name()
                    ),
                ));
            }
        }
        for (k, a) in self.dof.iter().enumerate() {
            if self.dof[..k].contains(a) {
                return Err((
                    "dof",
                    format!(
                        "joint '{name}': axis '{}' is listed twice in `dof`",
                        a.name()
                    ),
                ));
            }
        }
        for axis in Axis::ALL {
            let pose = self.default_pose_deg[axis.index()];
            if !(pose.is_finite() && (-180.0..=180.0).contains(&pose)) {
                return Err((
                    "default_pose_deg",
                    format!(
                        "joint '{name}': default_pose_deg.{} = {pose} is not within -180..180",
                        axis.name()
                    ),
                ));
            }
            let Some([lo, hi]) = self.hard_limits_deg.get(axis) else {
                continue;
            };
            if !self.moves(axis) {
                return Err((
                    "hard_limits_deg",
                    format!(
                        "joint '{name}': hard_limits_deg.{0} limits an axis that is not in `dof`",
                        axis.name()
                    ),
                ));
            }
            if !(lo.is_finite() && hi.is_finite() && -180.0 <= lo && lo < hi && hi <= 180.0) {
                return Err((
                    "hard_limits_deg",
                    format!(
                        "joint '{name}': hard_limits_deg.{} = [{lo}, {hi}]: expected lower < upper within -180..180",
                        axis.name()
                    ),
                ));
            }
            if !(lo..=hi).contains(&pose) {
                return Err((
                    "default_pose_deg",
                    format!(
                        "joint '{name}': default_pose_deg.{} = {pose} is outside its hard limits [{lo}, {hi}]",
                        axis.name()
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// A body model: which IMUs exist, how they form joints, in which order to correct.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Model {
    /// Short name, e.g. `infant13`.
    pub name: String,
    #[serde(default)]
    pub description: String,
    /// The IMU assumed correct (the root of the chain).
    pub base: String,
    /// Every IMU of the model, canonical names.
    pub imus: Vec<String>,
    /// Joints in correction order: a joint's proximal IMU is the base or the
    /// distal IMU of an earlier joint.
    #[serde(rename = "joint")]
    pub joints: Vec<Joint>,
    /// Accepted alternative IMU names (as found in files) -> canonical name.
    #[serde(default)]
    pub aliases: BTreeMap<String, String>,
    /// Optional segment lengths in metres, keyed by IMU (for stick figures).
    #[serde(default)]
    pub segment_length_m: BTreeMap<String, f64>,
    /// Weight of each IMU's orientation error in inverse kinematics (1 when absent).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub imu_weight: BTreeMap<String, f64>,
    /// Heading axes for pose calibration.
    #[serde(default, skip_serializing_if = "is_default")]
    pub pose: PoseSetup,
    /// Optional direction of each segment in its IMU's frame, in the zero pose
    /// (every joint angle 0), from the end nearer the base to the far end; for
    /// stick figures. Unit-free (normalised on use).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub segment_direction: BTreeMap<String, [f64; 3]>,
    /// Coordinates of an optical reference mapped to joint axes: key an
    /// OpenSim `.mot` column (`knee_angle_r`) or a C3D point's component
    /// (`RKneeAngles.x`), value `[-]<joint>.<axis>` (`r_knee.y`; `-` when the
    /// reference counts the other way). Degrees either side.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub reference_coordinates: BTreeMap<String, String>,
}

/// Where a reference coordinate goes: a joint's axis, and the sign that turns
/// the reference's value into the joint angle.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReferenceTarget {
    pub joint: String,
    pub axis: Axis,
    /// True when the joint angle is minus the reference's value.
    pub negated: bool,
}

impl std::str::FromStr for ReferenceTarget {
    type Err = String;
    /// `[-|+]<joint>.<x|y|z>`.
    fn from_str(s: &str) -> Result<ReferenceTarget, String> {
        let t = s.trim();
        let (negated, rest) = match t.as_bytes().first() {
            Some(b'-') => (true, &t[1..]),
            Some(b'+') => (false, &t[1..]),
            _ => (false, t),
        };
        let (joint, axis) = rest
            .rsplit_once('.')
            .ok_or_else(|| format!("'{s}': expected [-]<joint>.<x|y|z>, e.g. -r_hip.y"))?;
        let axis = match axis.to_ascii_lowercase().as_str() {
            "x" => Axis::X,
            "y" => Axis::Y,
            "z" => Axis::Z,
            _ => return Err(format!("'{s}': the axis must be x, y or z")),
        };
        Ok(ReferenceTarget {
            joint: joint.to_string(),
            axis,
            negated,
        })
    }
}

/// Why a model was rejected: a file that cannot be read, parsed or validated,
/// or an unknown built-in name (the file is then the name itself).
pub type ModelError = crate::located::LocatedError;

/// What is wrong with a model, and where: the path of the key at fault from
/// the model's top (`["joint", "2", "proximal"]`: the third joint's
/// `proximal`), for locating it in the file the model came from.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelProblem {
    pub path: Vec<String>,
    pub message: String,
}

impl Model {
    /// A built-in model by name (see [`BUILTIN_MODELS`]).
    pub fn builtin(name: &str) -> Result<Model, ModelError> {
        let text = BUILTIN_MODELS
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, t)| *t)
            .ok_or_else(|| {
                let known: Vec<&str> = BUILTIN_MODELS.iter().map(|(n, _)| *n).collect();
                ModelError::file(
                    name,
                    format!(
                        "unknown built-in model (known: {}; or a path to a model TOML)",
                        known.join(", ")
                    ),
                )
            })?;
        Model::from_toml(text, &format!("<built-in {name}>"))
    }

    /// The source study's 13-IMU infant model.
    pub fn infant13() -> Model {
        Model::builtin("infant13").expect("built-in model is valid")
    }

    /// Loads a model: a built-in name or a path to a TOML file.
    pub fn load(name_or_path: &str) -> Result<Model, ModelError> {
        if BUILTIN_MODELS.iter().any(|(n, _)| *n == name_or_path) {
            return Model::builtin(name_or_path);
        }
        let path = Path::new(name_or_path);
        let text = crate::input::read_text_located(path).map_err(|e| {
            let message = if e.line > 0 {
                e.error.to_string()
            } else {
                format!("cannot read: {}", e.error)
            };
            ModelError::at(name_or_path, e.line, e.column, message)
        })?;
        Model::from_toml(&text, name_or_path)
    }

    /// Parses and validates a model from TOML text; `origin` names it in errors.
    pub fn from_toml(text: &str, origin: &str) -> Result<Model, ModelError> {
        let model: Model = toml::from_str(text).map_err(|e| ModelError::toml(origin, text, &e))?;
        model.validate().map_err(|p| {
            let keys: Vec<&str> = p.path.iter().map(String::as_str).collect();
            let (line, column) = crate::input::locate::toml_key(text, &keys).unwrap_or((0, 0));
            ModelError::at(origin, line, column, p.message)
        })?;
        Ok(model)
    }

    /// Checks a model that did not come from a file (a sidecar's) as
    /// [`Model::from_toml`] checks one that did; `origin` names it in errors.
    pub fn check(&self, origin: &str) -> Result<(), ModelError> {
        self.validate()
            .map_err(|p| ModelError::file(origin, p.message))
    }

    /// The first thing wrong with the model, if any, with the key it is
    /// about: what [`Model::from_toml`] and [`Model::check`] refuse.
    pub fn problem(&self) -> Option<ModelProblem> {
        self.validate().err()
    }

    fn validate(&self) -> Result<(), ModelProblem> {
        let err = |path: &[&str], message: String| ModelProblem {
            path: path.iter().map(|s| s.to_string()).collect(),
            message,
        };
        let imus: HashSet<&str> = self.imus.iter().map(String::as_str).collect();
        if let Some(k) = (1..self.imus.len()).find(|&k| self.imus[..k].contains(&self.imus[k])) {
            return Err(err(
                &["imus", &k.to_string()],
                format!("IMU '{}' is listed twice in `imus`", self.imus[k]),
            ));
        }
        if !imus.contains(self.base.as_str()) {
            return Err(err(
                &["base"],
                format!("base IMU '{}' is not in `imus`", self.base),
            ));
        }
        let mut corrected: HashSet<&str> = HashSet::from([self.base.as_str()]);
        let mut names = HashSet::new();
        for (i, j) in self.joints.iter().enumerate() {
            let at = |key: &str, message: String| err(&["joint", &i.to_string(), key], message);
            if !names.insert(j.name.as_str()) {
                return Err(at("name", format!("joint '{}' is listed twice", j.name)));
            }
            for (key, imu) in [("proximal", &j.proximal), ("distal", &j.distal)] {
                if !imus.contains(imu.as_str()) {
                    return Err(at(
                        key,
                        format!("joint '{}': IMU '{imu}' is not in `imus`", j.name),
                    ));
                }
            }
            if !corrected.contains(j.proximal.as_str()) {
                return Err(at("proximal", format!(
                    "joint '{}': proximal IMU '{}' must be the base or the distal IMU of an earlier joint (correction order)",
                    j.name, j.proximal
                )));
            }
            if !corrected.insert(j.distal.as_str()) {
                return Err(at(
                    "distal",
                    format!(
                        "joint '{}': IMU '{}' is already corrected by another joint or is the base",
                        j.name, j.distal
                    ),
                ));
            }
        }
        for (i, j) in self.joints.iter().enumerate() {
            j.validate()
                .map_err(|(key, message)| err(&["joint", &i.to_string(), key], message))?;
        }
        if self.pose.forward.axis == Axis::Z {
            return Err(err(&["pose", "forward"], format!(
                "pose.forward = {}: the model's forward axis must be horizontal (x or y; +z is vertical)",
                self.pose.forward
            )));
        }
        for (imu, w) in &self.imu_weight {
            if !imus.contains(imu.as_str()) {
                return Err(err(
                    &["imu_weight", imu],
                    format!("imu_weight: IMU '{imu}' is not in `imus`"),
                ));
            }
            if !(w.is_finite() && *w > 0.0) {
                return Err(err(
                    &["imu_weight", imu],
                    format!("imu_weight.{imu} = {w}: expected a positive number"),
                ));
            }
        }
        for (coordinate, target) in &self.reference_coordinates {
            let at = &["reference_coordinates", coordinate.as_str()];
            let t: ReferenceTarget = target
                .parse()
                .map_err(|e| err(at, format!("reference_coordinates.{coordinate}: {e}")))?;
            if self.joint(&t.joint).is_none() {
                return Err(err(
                    at,
                    format!(
                        "reference_coordinates.{coordinate}: joint '{}' is not in the model",
                        t.joint
                    ),
                ));
            }
        }
        for (alias, canon) in &self.aliases {
            if !imus.contains(canon.as_str()) {
                return Err(err(
                    &["aliases", alias],
                    format!("alias '{alias}' points to unknown IMU '{canon}'"),
                ));
            }
        }
        Ok(())
    }

    /// The canonical IMU name for a name found in a file (exact, alias, or case-insensitive).
    pub fn canonical_imu(&self, name: &str) -> Option<&str> {
        if let Some(n) = self.imus.iter().find(|n| *n == name) {
            return Some(n);
        }
        if let Some(c) = self.aliases.get(name) {
            return Some(c);
        }
        let lower = name.to_ascii_lowercase();
        self.imus
            .iter()
            .find(|n| n.to_ascii_lowercase() == lower)
            .or_else(|| {
                self.aliases
                    .iter()
                    .find(|(a, _)| a.to_ascii_lowercase() == lower)
                    .map(|(_, c)| c)
            })
            .map(String::as_str)
    }

    /// The joint axis a reference coordinate maps to (see
    /// [`Model::reference_coordinates`]); exact name, else any case.
    pub fn reference_target(&self, coordinate: &str) -> Option<ReferenceTarget> {
        let target = self.reference_coordinates.get(coordinate).or_else(|| {
            self.reference_coordinates
                .iter()
                .find(|(k, _)| k.eq_ignore_ascii_case(coordinate))
                .map(|(_, v)| v)
        })?;
        target.parse().ok()
    }

    /// The inverse-kinematics weight of an IMU (1 unless the model says otherwise).
    pub fn weight(&self, imu: &str) -> f64 {
        self.imu_weight.get(imu).copied().unwrap_or(1.0)
    }

    /// The joint with this name.
    pub fn joint(&self, name: &str) -> Option<&Joint> {
        self.joints.iter().find(|j| j.name == name)
    }

    /// The joint whose distal IMU is `imu`.
    pub fn joint_of_distal(&self, imu: &str) -> Option<&Joint> {
        self.joints.iter().find(|j| j.distal == imu)
    }

    /// Depth of each joint in the chain (joints on the base are depth 0).
    /// Joints of equal depth never depend on each other.
    pub fn joint_depths(&self) -> Vec<usize> {
        let mut depth_of_imu: BTreeMap<&str, usize> = BTreeMap::new();
        depth_of_imu.insert(&self.base, 0);
        self.joints
            .iter()
            .map(|j| {
                let d = depth_of_imu.get(j.proximal.as_str()).copied().unwrap_or(0);
                depth_of_imu.insert(&j.distal, d + 1);
                d
            })
            .collect()
    }

    /// Indices of the joints that depend on joint `idx` (its descendants), in order.
    pub fn descendants(&self, idx: usize) -> Vec<usize> {
        let mut affected: HashSet<&str> = HashSet::from([self.joints[idx].distal.as_str()]);
        let mut out = Vec::new();
        for (k, j) in self.joints.iter().enumerate().skip(idx + 1) {
            if affected.contains(j.proximal.as_str()) {
                affected.insert(&j.distal);
                out.push(k);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtin_models_load_and_follow_method_order() {
        let m = Model::infant13();
        assert_eq!(m.imus.len(), 13);
        let order: Vec<&str> = m.joints.iter().map(|j| j.distal.as_str()).collect();
        assert_eq!(
            order,
            [
                "upper_back",
                "head",
                "l_upper_arm",
                "r_upper_arm",
                "l_forearm",
                "r_forearm",
                "l_thigh",
                "r_thigh",
                "l_calf",
                "r_calf",
                "l_foot",
                "r_foot"
            ]
        );
        let knee = m.joint("l_knee").unwrap();
        assert_eq!(
            (knee.proximal.as_str(), knee.kind.as_str()),
            ("l_thigh", "knee")
        );
        let o = Model::builtin("opensim").unwrap();
        assert_eq!(o.joints.len(), 11); // no head IMU, no neck
        assert_eq!(o.joint("r_knee").unwrap().distal, "tibia_r_imu");
    }

    #[test]
    fn chain_depths_and_descendants() {
        let m = Model::infant13();
        let d = m.joint_depths();
        let depth = |n: &str| d[m.joints.iter().position(|j| j.name == n).unwrap()];
        assert_eq!(depth("back"), 0);
        assert_eq!(depth("l_hip"), 0);
        assert_eq!(depth("l_shoulder"), 1);
        assert_eq!(depth("l_elbow"), 2);
        assert_eq!(depth("r_ankle"), 2);
        let hip = m.joints.iter().position(|j| j.name == "l_hip").unwrap();
        let names: Vec<&str> = m
            .descendants(hip)
            .iter()
            .map(|&k| m.joints[k].name.as_str())
            .collect();
        assert_eq!(names, ["l_knee", "l_ankle"]);
    }

    #[test]
    fn aliases_and_case() {
        let m = Model::infant13();
        assert_eq!(m.canonical_imu("L_Calf"), Some("l_calf"));
        assert_eq!(m.canonical_imu("lower_back"), Some("base"));
        assert_eq!(m.canonical_imu("tail"), None);
    }

    #[test]
    fn invalid_models_are_rejected_with_reason() {
        let bad_order = r#"
name = "x"
base = "a"
imus = ["a", "b", "c"]
[[joint]]
name = "j2"
kind = "knee"
proximal = "b"
distal = "c"
[[joint]]
name = "j1"
kind = "hip"
proximal = "a"
distal = "b"
"#;
        let e = Model::from_toml(bad_order, "m.toml")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("m.toml") && e.contains("correction order"),
            "{e}"
        );
        let e = Model::from_toml("name = 3", "m.toml")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("m.toml:1:8: invalid type"), "{e}");
        // A misspelt key is an error at its line, not silently ignored.
        let e = Model::from_toml("name = \"m\"\nbasee = \"a\"\n", "m.toml")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("m.toml:2:1: unknown field `basee`"), "{e}");
    }

    #[test]
    fn dof_limits_and_pose_declarations() {
        let m = Model::infant13();
        let knee = m.joint("l_knee").unwrap();
        assert_eq!(knee.dof, [Axis::Y]);
        assert_eq!(knee.hard_limits_deg.get(Axis::Y), Some([-10.0, 150.0]));
        assert!(!knee.moves(Axis::X));
        let hip = m.joint("l_hip").unwrap();
        assert_eq!(hip.dof, Axis::ALL);
        assert_eq!(hip.hard_limits_deg, HardLimits::default());
        assert_eq!(m.pose, PoseSetup::default());
        assert_eq!(m.weight("head"), 1.0);
        let o = Model::builtin("opensim").unwrap();
        assert_eq!(o.pose.base_forward.to_string(), "-z");
        assert_eq!(o.pose.base_forward.vector(), [0.0, 0.0, -1.0]);
        // A model without the new keys serialises as before (sidecars stay the same).
        let plain = r#"
name = "x"
base = "a"
imus = ["a", "b"]
[[joint]]
name = "j"
kind = "knee"
proximal = "a"
distal = "b"
"#;
        let m = Model::from_toml(plain, "m.toml").unwrap();
        let json = serde_json::to_string(&m).unwrap();
        assert!(!json.contains("dof") && !json.contains("pose"), "{json}");
        // Round trip with everything declared.
        let full = format!(
            "{plain}dof = [\"Y\", \"z\"]\nhard_limits_deg = {{ y = [0, 140] }}\ndefault_pose_deg = [0, 10, 0]\n[imu_weight]\nb = 2.0\n[pose]\nbase_forward = \"-y\"\n"
        );
        let m = Model::from_toml(&full, "m.toml").unwrap();
        assert_eq!(m.joints[0].dof, [Axis::Y, Axis::Z]);
        assert_eq!(m.weight("b"), 2.0);
        assert_eq!(m.pose.base_forward.vector(), [0.0, -1.0, 0.0]);
        let back: Model = serde_json::from_str(&serde_json::to_string(&m).unwrap()).unwrap();
        assert_eq!(back, m);
    }

    #[test]
    fn bad_dof_and_limits_are_rejected_with_reason() {
        let base = "name = \"x\"\nbase = \"a\"\nimus = [\"a\", \"b\"]\n[[joint]]\nname = \"j\"\nkind = \"knee\"\nproximal = \"a\"\ndistal = \"b\"\n";
        let cases = [
            ("dof = [\"y\", \"y\"]", "listed twice"),
            ("dof = [\"w\"]", "m.toml:9:8: unknown variant"),
            ("doff = [\"y\"]", "m.toml:9:1: unknown field `doff`"),
            (
                "dof = [\"y\"]\nhard_limits_deg = { x = [0, 10] }",
                "not in `dof`",
            ),
            ("hard_limits_deg = { y = [10, 0] }", "lower < upper"),
            ("hard_limits_deg = { y = [0, 200] }", "within -180..180"),
            (
                "hard_limits_deg = { y = [0, 100] }\ndefault_pose_deg = [0, -5, 0]",
                "outside its hard limits",
            ),
            ("hard_limits_deg = { q = [0, 100] }", "unknown field"),
            ("[imu_weight]\nb = -1", "positive"),
            ("[imu_weight]\nc = 1", "'c' is not in"),
            ("[pose]\nbase_forward = \"up\"", "not an axis"),
            ("[pose]\nforward = \"-z\"", "must be horizontal"),
        ];
        for (extra, want) in cases {
            let e = Model::from_toml(&format!("{base}{extra}\n"), "m.toml")
                .unwrap_err()
                .to_string();
            assert!(e.contains("m.toml") && e.contains(want), "{extra}: {e}");
        }
    }

    /// The joints of `full_body16` with a proper (`r_hip`) and improper
    /// (`r_elbow`, `r_knee`) signed permutation, and every other non-identity
    /// `angle_axes` of the built-in models.
    fn framed_joints() -> Vec<Joint> {
        let mut out: Vec<Joint> = Vec::new();
        for (name, _) in BUILTIN_MODELS {
            for j in Model::builtin(name).unwrap().joints {
                let new = !out.iter().any(|o| o.angle_axes == j.angle_axes);
                if new && !is_identity_axes(&j.angle_axes) {
                    out.push(j);
                }
            }
        }
        out
    }

    #[test]
    fn table_axes_of_the_standing_elbow_hip_and_knee() {
        let m = Model::builtin("full_body16").unwrap();
        let det = |n: &str| m.joint(n).unwrap().table_axes().unwrap().det;
        assert_eq!(
            m.joint("r_elbow")
                .unwrap()
                .angle_axes
                .map(|a| a.to_string()),
            ["-y", "-x", "+z"]
        );
        assert_eq!(
            m.joint("r_hip").unwrap().angle_axes.map(|a| a.to_string()),
            ["-z", "-y", "-x"]
        );
        assert_eq!(
            m.joint("r_knee").unwrap().angle_axes.map(|a| a.to_string()),
            ["-z", "+y", "-x"]
        );
        assert_eq!(
            (det("r_elbow"), det("r_hip"), det("r_knee")),
            (-1.0, 1.0, -1.0)
        );
        assert_eq!(TableAxes::of(&IDENTITY_AXES), None);
        // Q takes each segment axis onto its table axis (times det(P)).
        for j in framed_joints() {
            let t = j.table_axes().unwrap();
            for (k, a) in j.angle_axes.iter().enumerate() {
                let col = t.q * nalgebra::Vector3::from(unit(Axis::ALL[k])) * t.det;
                let want = nalgebra::Vector3::from(a.vector());
                assert!((col - want).norm() < 1e-15, "{} {k}", j.name);
            }
        }
    }

    #[test]
    fn table_angles_round_trip_for_proper_and_improper_axes() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let joints = framed_joints();
        assert!(joints.len() > 5);
        for j in &joints {
            for _ in 0..500 {
                let t = [
                    rng.random_range(-179.9..179.9),
                    rng.random_range(-89.0..89.0),
                    rng.random_range(-179.9..179.9),
                ];
                let back = j.principal_table_angles(&j.rotation(t));
                for k in 0..3 {
                    assert!(
                        (back[k] - t[k]).abs() < 1e-9,
                        "{} {t:?} -> {back:?}",
                        j.name
                    );
                }
                // The triplet shown is the one the joint's limit box reads.
                let shown = j.table_angles(&j.rotation(t));
                let want = j
                    .limit_box()
                    .map_or(t, |b| crate::rotation::read_in_box(t, &b));
                for k in 0..3 {
                    let d = crate::rotation::wrap180(shown[k] - want[k]);
                    assert!(d.abs() < 1e-9, "{} {t:?} -> {shown:?}", j.name);
                }
            }
        }
    }

    #[test]
    fn small_rotations_read_as_the_signed_permutation_of_the_segment_angles() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(6);
        for j in framed_joints() {
            for _ in 0..200 {
                let e = 0.01; // degrees
                let seg: [f64; 3] = std::array::from_fn(|_| rng.random_range(-e..e));
                let r = crate::rotation::quat_from_euler_zyx_deg(seg);
                // The mapping before section 2.5 took the Z-Y-X angles of the
                // segment frames, permuted and signed.
                let old = j.angle_axes.map(|a| {
                    let v = seg[a.axis.index()];
                    if a.negative {
                        -v
                    } else {
                        v
                    }
                });
                let new = j.table_angles(&r);
                for k in 0..3 {
                    // Equal to first order: they differ by O(e^2) (in degrees,
                    // e^2 * pi / 180 per product of two angles).
                    assert!(
                        (new[k] - old[k]).abs() < 3.0 * e * e * 0.02,
                        "{}: {new:?} vs {old:?}",
                        j.name
                    );
                }
            }
        }
    }

    #[test]
    fn identity_axes_give_the_segment_frames_angles_exactly() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let m = Model::infant13();
        // The back and the neck keep the segment axes.
        let identity: Vec<&Joint> = m
            .joints
            .iter()
            .filter(|j| j.angle_axes == IDENTITY_AXES)
            .collect();
        assert_eq!(identity.len(), 2);
        for j in identity {
            for _ in 0..100 {
                let t: [f64; 3] = std::array::from_fn(|_| rng.random_range(-170.0..170.0));
                let p = crate::rotation::quat_from_euler_zyx_deg(t.map(|a| 0.5 * a));
                let d = crate::rotation::quat_from_euler_zyx_deg(t);
                let r = p.inverse() * d;
                let zyx = crate::rotation::euler_zyx_deg(&r);
                assert_eq!(j.principal_table_angles(&r), zyx);
                let want = j
                    .limit_box()
                    .map_or(zyx, |b| crate::rotation::read_in_box(zyx, &b));
                assert_eq!(j.angles(&p, &d), want);
                assert_eq!(j.rotation(t), crate::rotation::quat_from_euler_zyx_deg(t));
            }
        }
    }

    /// Hip and knee flexion beyond 90 deg (Table 3-2: hip Y -30..100, knee
    /// Y 0..130) read as flexion on the table's Y in every built-in model: a
    /// turn by `y` about the segment axis `angle_axes[1]` names (the sense
    /// the table counts positive) reads `[0, y, 0]`, where the principal
    /// Z-Y-X triplet would read `[180, 180 - y, 180]`.
    #[test]
    fn hip_and_knee_flexion_beyond_90_read_on_y_in_every_model() {
        let mut checked = 0;
        for (name, _) in BUILTIN_MODELS {
            let m = Model::builtin(name).unwrap();
            for j in m
                .joints
                .iter()
                .filter(|j| j.kind == "hip" || j.kind == "knee")
            {
                let flexions: &[f64] = if j.kind == "knee" {
                    &[100.0, 120.0, 140.0]
                } else {
                    &[95.0]
                };
                let axis = j.angle_axes[1].vector();
                for &flex in flexions {
                    let r = crate::rotation::quat_axis_angle_deg(axis, flex);
                    let a = j.table_angles(&r);
                    assert!(
                        a[0].abs() < 1e-9 && (a[1] - flex).abs() < 1e-9 && a[2].abs() < 1e-9,
                        "{name} {} {flex}: {a:?}",
                        j.name
                    );
                    let p = j.principal_table_angles(&r);
                    assert!((p[1] - (180.0 - flex)).abs() < 1e-9, "{p:?}");
                    // The segments' angles go through the same reading.
                    let prox = crate::rotation::quat_axis_angle_deg([0.3, -1.0, 0.2], 37.0);
                    let b = j.angles(&prox, &(prox * r));
                    assert!((b[1] - flex).abs() < 1e-9, "{b:?}");
                    checked += 1;
                }
            }
        }
        assert!(checked >= 4 * 8, "{checked}");
    }

    #[test]
    fn standing_elbow_reads_flexion_beyond_90_degrees() {
        let m = Model::builtin("full_body16").unwrap();
        for side in ["r_elbow", "l_elbow"] {
            let elbow = m.joint(side).unwrap();
            // Table X (flexion) is the segment axis angle_axes[0] names.
            let axis = elbow.angle_axes[0].vector();
            for flex in [30.0, 90.0, 150.0, 160.0] {
                let r = crate::rotation::quat_axis_angle_deg(axis, flex);
                let a = elbow.table_angles(&r);
                assert!(
                    (a[0] - flex).abs() < 1e-9 && a[1].abs() < 1e-9 && a[2].abs() < 1e-9,
                    "{side} {flex}: {a:?}"
                );
            }
        }
    }

    #[test]
    fn two_axis_hinge_turns_about_the_table_z_then_x() {
        for (name, _) in BUILTIN_MODELS {
            let m = Model::builtin(name).unwrap();
            for j in m.joints.iter().filter(|j| j.kind == "elbow") {
                let Hinge::Two { proximal, distal } = j.two_axis_hinge() else {
                    panic!("two axes")
                };
                let r = j.rotation([40.0, 0.0, 25.0]);
                let rz = crate::rotation::quat_axis_angle_deg(j.angle_axes[2].vector(), 25.0);
                let rx = crate::rotation::quat_axis_angle_deg(j.angle_axes[0].vector(), 40.0);
                assert!(
                    crate::rotation::angle_between_deg(&r, &(rz * rx)) < 1e-9,
                    "{name} {}",
                    j.name
                );
                assert_eq!(
                    (proximal, distal),
                    (j.angle_axes[2].axis, j.angle_axes[0].axis)
                );
            }
        }
        for n in ["z-y", "z-x", "y-x", "y-z", "x-z", "x-y"] {
            let h = Hinge::try_from(n.to_string()).unwrap();
            assert_eq!(h.name(), n);
        }
    }
}
