//! Body models as data (METHOD.md section 2): IMUs, joints, correction order, aliases.
//!
//! A model is a TOML file. Two ship inside the binary (`infant13`, the source
//! study's 13-IMU suit, and `opensim`, the OpenSim full-body IMU set); a lab can
//! point `--model` at its own file. See `models/README.md` for the format.

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

/// One joint: the rotation of the distal IMU relative to the proximal one.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct Joint {
    /// Joint name, e.g. `l_knee`.
    pub name: String,
    /// Row name in the limit tables, e.g. `knee` (left and right share a row).
    pub kind: String,
    /// IMU above the joint (its frame is the reference).
    pub proximal: String,
    /// IMU below the joint (the one the ACM corrects).
    pub distal: String,
}

/// A body model: which IMUs exist, how they form joints, in which order to correct.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
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
    /// Optional direction of each segment in its IMU's frame, in the zero pose
    /// (every joint angle 0), from the end nearer the base to the far end; for
    /// stick figures. Unit-free (normalised on use).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub segment_direction: BTreeMap<String, [f64; 3]>,
}

/// Why a model file was rejected.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    #[error("{path}: cannot read: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("{path}: {message}")]
    Parse { path: String, message: String },
    #[error("{path}: {message}")]
    Invalid { path: String, message: String },
    #[error(
        "unknown built-in model '{0}' (known: infant13, opensim, opensense_lower, full_body16)"
    )]
    Unknown(String),
}

impl Model {
    /// A built-in model by name (see [`BUILTIN_MODELS`]).
    pub fn builtin(name: &str) -> Result<Model, ModelError> {
        let text = BUILTIN_MODELS
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, t)| *t)
            .ok_or_else(|| ModelError::Unknown(name.to_string()))?;
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
        let text = std::fs::read_to_string(path).map_err(|source| ModelError::Io {
            path: name_or_path.to_string(),
            source,
        })?;
        Model::from_toml(&text, name_or_path)
    }

    /// Parses and validates a model from TOML text; `origin` names it in errors.
    pub fn from_toml(text: &str, origin: &str) -> Result<Model, ModelError> {
        let model: Model = toml::from_str(text).map_err(|e| ModelError::Parse {
            path: origin.to_string(),
            message: e.to_string(),
        })?;
        model.validate().map_err(|message| ModelError::Invalid {
            path: origin.to_string(),
            message,
        })?;
        Ok(model)
    }

    fn validate(&self) -> Result<(), String> {
        let imus: HashSet<&str> = self.imus.iter().map(String::as_str).collect();
        if imus.len() != self.imus.len() {
            return Err("an IMU is listed twice in `imus`".into());
        }
        if !imus.contains(self.base.as_str()) {
            return Err(format!("base IMU '{}' is not in `imus`", self.base));
        }
        let mut corrected: HashSet<&str> = HashSet::from([self.base.as_str()]);
        let mut names = HashSet::new();
        for j in &self.joints {
            if !names.insert(j.name.as_str()) {
                return Err(format!("joint '{}' is listed twice", j.name));
            }
            for imu in [&j.proximal, &j.distal] {
                if !imus.contains(imu.as_str()) {
                    return Err(format!("joint '{}': IMU '{imu}' is not in `imus`", j.name));
                }
            }
            if !corrected.contains(j.proximal.as_str()) {
                return Err(format!(
                    "joint '{}': proximal IMU '{}' must be the base or the distal IMU of an earlier joint (correction order)",
                    j.name, j.proximal
                ));
            }
            if !corrected.insert(j.distal.as_str()) {
                return Err(format!(
                    "joint '{}': IMU '{}' is already corrected by another joint or is the base",
                    j.name, j.distal
                ));
            }
        }
        for (alias, canon) in &self.aliases {
            if !imus.contains(canon.as_str()) {
                return Err(format!("alias '{alias}' points to unknown IMU '{canon}'"));
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
        assert!(e.contains("m.toml") && e.contains("line 1"), "{e}");
    }
}
