//! The kinematic stick figure (thesis Figure 2-3, 4.5): the body's segments
//! placed from the IMU orientations, the model's segment lengths and
//! directions, to compare uncorrected and corrected poses with video.
//!
//! Frames and units: positions are metres in the global frame G (+Z up), the
//! base segment starting at the origin. A segment's direction is given in its
//! IMU's frame (model `segment_direction`, the zero pose), so its direction in
//! G is `G_R_imu d`. A segment starts at the far end of its proximal segment,
//! or at its start when that is the base segment and the two point in
//! opposite directions in the zero pose (legs leave the pelvis where the spine
//! starts, while arms hanging in a standing pose leave the top of the trunk).

use crate::model::Model;
use crate::rotation::Quat;
use crate::trial::Trial;
use nalgebra::Vector3;

/// One drawn segment.
#[derive(Debug, Clone, PartialEq)]
pub struct Bone {
    /// The IMU on the segment.
    pub imu: String,
    /// The proximal segment (index into [`Skeleton::bones`]); None for the base.
    pub parent: Option<usize>,
    /// Starts at the far end of the parent (true) or at the parent's start.
    pub at_parent_end: bool,
    /// Unit direction in the IMU frame, zero pose.
    pub direction: [f64; 3],
    /// Length, metres.
    pub length_m: f64,
}

/// The segments of a model, base first, then each joint's distal segment in
/// the model's order.
#[derive(Debug, Clone, PartialEq)]
pub struct Skeleton {
    pub bones: Vec<Bone>,
}

/// Start and end of a segment, global frame, metres.
pub type Segment = [[f64; 3]; 2];

fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
    (n.is_finite() && n > 1e-9).then(|| v.map(|x| x / n))
}

/// What a model lacks for a stick figure ([`Skeleton::of`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("model {model}: {what} '{imu}'")]
pub struct SkeletonError {
    pub model: String,
    /// The IMU whose segment is at fault.
    pub imu: String,
    pub what: Missing,
}

/// The part of a segment a model lacks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Missing {
    /// No positive `segment_length_m`.
    Length,
    /// No non-zero `segment_direction`.
    Direction,
    /// A joint's proximal IMU has no segment of its own.
    Segment,
}

impl std::fmt::Display for Missing {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Missing::Length => "no positive segment_length_m for",
            Missing::Direction => "no segment_direction (a non-zero [x, y, z]) for",
            Missing::Segment => "no segment for",
        })
    }
}

impl Skeleton {
    /// The skeleton of a model; an error names the first IMU whose length
    /// (`[segment_length_m]`) or direction (`[segment_direction]`) is missing
    /// or unusable.
    pub fn of(model: &Model) -> Result<Skeleton, SkeletonError> {
        let missing = |imu: &str, what: Missing| SkeletonError {
            model: model.name.clone(),
            imu: imu.to_string(),
            what,
        };
        let bone = |imu: &str| -> Result<([f64; 3], f64), SkeletonError> {
            let len = model.segment_length_m.get(imu).copied();
            let dir = model.segment_direction.get(imu).copied();
            match (len, dir.and_then(unit)) {
                (Some(l), Some(d)) if l.is_finite() && l > 0.0 => Ok((d, l)),
                (None, _) | (Some(_), Some(_)) => Err(missing(imu, Missing::Length)),
                (_, None) => Err(missing(imu, Missing::Direction)),
            }
        };
        let (d, l) = bone(&model.base)?;
        let mut bones = vec![Bone {
            imu: model.base.clone(),
            parent: None,
            at_parent_end: true,
            direction: d,
            length_m: l,
        }];
        for j in &model.joints {
            let (d, l) = bone(&j.distal)?;
            let parent = bones
                .iter()
                .position(|b| b.imu == j.proximal)
                .ok_or_else(|| missing(&j.proximal, Missing::Segment))?;
            let p = bones[parent].direction;
            let against = p[0] * d[0] + p[1] * d[1] + p[2] * d[2] < 0.0;
            bones.push(Bone {
                imu: j.distal.clone(),
                parent: Some(parent),
                at_parent_end: parent != 0 || !against,
                direction: d,
                length_m: l,
            });
        }
        Ok(Skeleton { bones })
    }

    /// The segments for the given IMU orientations (`G_R_imu`); a segment whose
    /// IMU, or whose parent, has none is `None`, except that the first segment
    /// placed starts at the origin whether its parent is placed or not.
    pub fn pose(&self, orientation: impl Fn(&str) -> Option<Quat>) -> Vec<Option<Segment>> {
        let mut out: Vec<Option<Segment>> = Vec::with_capacity(self.bones.len());
        for b in &self.bones {
            // A segment whose parent is not placed starts at the origin when
            // nothing is placed yet (a trial without its base IMU, say).
            let first = out.iter().all(Option::is_none);
            let start = match b.parent {
                None => Some([0.0; 3]),
                Some(p) => out[p]
                    .map(|s| if b.at_parent_end { s[1] } else { s[0] })
                    .or(first.then_some([0.0; 3])),
            };
            let seg = start.zip(orientation(&b.imu)).map(|(s, q)| {
                let v = q * Vector3::from(b.direction) * b.length_m;
                [s, [s[0] + v[0], s[1] + v[1], s[2] + v[2]]]
            });
            out.push(seg);
        }
        out
    }

    /// The segments at sample `i` of a trial.
    pub fn pose_at(&self, trial: &Trial, i: usize) -> Vec<Option<Segment>> {
        self.pose(|imu| trial.imu(imu).and_then(|s| s.orientation.get(i)).copied())
    }

    /// The farthest any point of the figure can be from the origin, metres
    /// (the longest chain of lengths): fixed bounds for drawing.
    pub fn reach_m(&self) -> f64 {
        let mut reach = vec![0.0; self.bones.len()];
        for (k, b) in self.bones.iter().enumerate() {
            reach[k] = b.parent.map_or(0.0, |p| reach[p]) + b.length_m;
        }
        reach.into_iter().fold(0.0, f64::max)
    }
}

/// Horizontal axes that follow the body's heading: `forward` is the horizontal
/// part of the base segment's direction (global X if it points straight up or
/// down), `left = up x forward`, `up` the global +Z.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyFrame {
    pub forward: [f64; 3],
    pub left: [f64; 3],
}

impl BodyFrame {
    /// The frame of a pose, from its first placed segment (the base when present).
    pub fn of(pose: &[Option<Segment>]) -> BodyFrame {
        let f = pose
            .iter()
            .flatten()
            .next()
            .and_then(|&[s, e]| unit([e[0] - s[0], e[1] - s[1], 0.0]))
            .unwrap_or([1.0, 0.0, 0.0]);
        BodyFrame {
            forward: f,
            left: [-f[1], f[0], 0.0],
        }
    }

    /// Top view (from above): (forward, left), metres.
    pub fn top(&self, p: [f64; 3]) -> (f64, f64) {
        (
            p[0] * self.forward[0] + p[1] * self.forward[1],
            p[0] * self.left[0] + p[1] * self.left[1],
        )
    }

    /// Side view (from the body's right): (forward, up), metres.
    pub fn side(&self, p: [f64; 3]) -> (f64, f64) {
        (p[0] * self.forward[0] + p[1] * self.forward[1], p[2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{quat_axis_angle_deg, quat_from_euler_zyx_deg};
    use std::collections::HashMap;

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        (0..3).all(|k| (a[k] - b[k]).abs() < 1e-9)
    }

    #[test]
    fn zero_pose_is_the_calibration_figure() {
        let m = Model::infant13();
        let s = Skeleton::of(&m).unwrap();
        assert_eq!(s.bones.len(), 13);
        let pose = s.pose(|_| Some(Quat::identity()));
        let seg = |imu: &str| pose[s.bones.iter().position(|b| b.imu == imu).unwrap()].unwrap();
        // Spine and head forward along X from the origin.
        assert!(close(seg("base")[1], [0.10, 0.0, 0.0]));
        assert!(close(seg("head")[1], [0.37, 0.0, 0.0]));
        // Arms out from the top of the upper back, left along +Y.
        assert!(close(seg("l_upper_arm")[0], [0.25, 0.0, 0.0]));
        assert!(close(seg("l_forearm")[1], [0.25, 0.22, 0.0]));
        assert!(close(seg("r_forearm")[1], [0.25, -0.22, 0.0]));
        // Legs from the pelvis (the base's start), straight back.
        assert!(close(seg("l_thigh")[0], [0.0; 3]));
        assert!(close(seg("l_foot")[1], [-0.33, 0.0, 0.0]));
        assert!((s.reach_m() - 0.47).abs() < 1e-9); // base + back + arm + forearm
    }

    #[test]
    fn segments_follow_orientations_down_the_chain() {
        let m = Model::infant13();
        let s = Skeleton::of(&m).unwrap();
        // Base turned 90 deg about vertical; thigh flexed 90 deg about its Y
        // (knee rotation chain: calf and foot follow the thigh).
        let base = quat_axis_angle_deg([0.0, 0.0, 1.0], 90.0);
        let thigh = base * quat_from_euler_zyx_deg([0.0, 90.0, 0.0]);
        let q: HashMap<&str, Quat> = [("base", base), ("l_thigh", thigh), ("l_calf", thigh)].into();
        let pose = s.pose(|imu| q.get(imu).copied());
        let idx = |imu: &str| s.bones.iter().position(|b| b.imu == imu).unwrap();
        assert!(close(pose[idx("base")].unwrap()[1], [0.0, 0.10, 0.0]));
        // -X of the thigh frame after Ry(90) is +Z, turned about Z: still +Z.
        assert!(close(pose[idx("l_thigh")].unwrap()[1], [0.0, 0.0, 0.14]));
        assert!(close(pose[idx("l_calf")].unwrap()[1], [0.0, 0.0, 0.26]));
        // Missing IMUs drop their segment and everything below it.
        assert!(pose[idx("l_foot")].is_none() && pose[idx("head")].is_none());
        // Without the base, the first segment present starts at the origin.
        let q: HashMap<&str, Quat> =
            [("l_thigh", Quat::identity()), ("l_calf", Quat::identity())].into();
        let knee = s.pose(|imu| q.get(imu).copied());
        assert!(close(knee[idx("l_thigh")].unwrap()[0], [0.0; 3]));
        assert!(close(knee[idx("l_calf")].unwrap()[1], [-0.26, 0.0, 0.0]));
        assert_eq!(knee.iter().filter(|p| p.is_some()).count(), 2);
        // The body frame turns with the base: forward is +Y.
        let f = BodyFrame::of(&pose);
        assert!(close(f.forward, [0.0, 1.0, 0.0]) && close(f.left, [-1.0, 0.0, 0.0]));
        let (a, b) = f.top([0.0, 0.10, 0.0]);
        assert!((a - 0.10).abs() < 1e-12 && b.abs() < 1e-12);
        let (a, b) = f.side([0.0, 0.0, 0.26]);
        assert!(a.abs() < 1e-12 && (b - 0.26).abs() < 1e-12);
    }

    #[test]
    fn models_without_geometry_say_what_is_missing() {
        let mut m = Model::infant13();
        m.segment_direction.remove("l_calf");
        let e = Skeleton::of(&m).unwrap_err();
        assert_eq!((e.what, e.imu.as_str()), (Missing::Direction, "l_calf"));
        let e = e.to_string();
        assert!(
            e.contains("segment_direction") && e.contains("l_calf"),
            "{e}"
        );
        let mut m = Model::infant13();
        m.segment_length_m.remove("head");
        let e = Skeleton::of(&m).unwrap_err().to_string();
        assert!(e.contains("segment_length_m") && e.contains("head"), "{e}");
        assert!(Skeleton::of(&Model::builtin("opensim").unwrap()).is_ok());
    }

    #[test]
    fn standing_models_stand_in_their_pose() {
        // In the standing pose (x forward, y left, z up; arms hanging) the
        // head is the highest point, the feet the lowest and forward, and the
        // hands hang from the shoulders beside the hips.
        for name in ["opensim", "full_body16", "opensense_lower"] {
            let m = Model::builtin(name).unwrap();
            let s = Skeleton::of(&m).unwrap();
            let pose = s.pose(|_| Some(Quat::identity()));
            let ends: Vec<[f64; 3]> = pose.iter().map(|p| p.unwrap()[1]).collect();
            let top = ends.iter().map(|e| e[2]).fold(f64::MIN, f64::max);
            let low = ends.iter().map(|e| e[2]).fold(f64::MAX, f64::min);
            assert!(top > 0.3 && low < -0.7, "{name}: {low}..{top}");
            for (b, e) in s.bones.iter().zip(&ends) {
                let d = b.direction;
                if d == [1.0, 0.0, 0.0] {
                    // A foot: from the ankle, forward, at the bottom.
                    assert!(e[2] < -0.7 && e[0] > 0.1, "{name} {}: {e:?}", b.imu);
                } else if d == [0.0, 0.0, -1.0] && b.parent.is_some_and(|p| p != 0) {
                    // Arms and shanks hang below their parent's far end.
                    let parent_end = ends[b.parent.unwrap()];
                    assert!(e[2] < parent_end[2], "{name} {}", b.imu);
                }
            }
            let mut arms = 0;
            for (k, b) in s.bones.iter().enumerate() {
                let Some(p) = b.parent.filter(|&p| p != 0) else {
                    continue;
                };
                if b.direction == [0.0, 0.0, -1.0] && s.bones[p].direction == [0.0, 0.0, 1.0] {
                    // An upper arm hangs from the top of the trunk, not the pelvis.
                    let start = pose[k].unwrap()[0];
                    assert!(start[2] > 0.2, "{name} {}: {start:?}", b.imu);
                    arms += 1;
                }
            }
            assert_eq!(
                arms,
                if name == "opensense_lower" { 0 } else { 2 },
                "{name}"
            );
        }
    }
}
