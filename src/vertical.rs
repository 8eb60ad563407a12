//! The vertical axis of a recording's global frame G, about which a magnetometer
//! or gyroscope heading drift turns an IMU's reported orientation.
//!
//! Most fusion filters report orientations in a Z-up frame (east-north-up or
//! similar); north-east-down (NED) systems have Z pointing down, so their
//! vertical (up) is -Z. A heading angle is a right-handed rotation about the
//! up direction, so the same physical drift has opposite signs in the two
//! conventions.

use crate::rotation::{quat_axis_angle_deg, Quat};
use serde::{Deserialize, Serialize};

/// Which global axis points up.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Vertical {
    /// +Z is up (east-north-up and most fusion filters; the default).
    #[default]
    ZUp,
    /// -Z is up: north-east-down systems.
    ZDown,
}

impl Vertical {
    /// The unit up vector in the global frame.
    pub fn up(self) -> [f64; 3] {
        match self {
            Vertical::ZUp => [0.0, 0.0, 1.0],
            Vertical::ZDown => [0.0, 0.0, -1.0],
        }
    }

    /// The rotation by `heading_deg` degrees about the up direction (right-handed).
    pub fn heading_rotation(self, heading_deg: f64) -> Quat {
        quat_axis_angle_deg(self.up(), heading_deg)
    }

    /// The name used in settings files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Vertical::ZUp => "z-up",
            Vertical::ZDown => "z-down",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::angle_between_deg;

    #[test]
    fn z_down_turns_the_other_way() {
        let up = Vertical::ZUp.heading_rotation(20.0);
        let down = Vertical::ZDown.heading_rotation(-20.0);
        assert!(angle_between_deg(&up, &down) < 1e-12);
        let v = up * nalgebra::Vector3::new(1.0, 0.0, 0.0);
        assert!((v.y - 20f64.to_radians().sin()).abs() < 1e-12, "{v}");
    }
}
