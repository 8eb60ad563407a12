//! Calibration protocols: which movement label of a recording gives which axis
//! of which sensor's functional frame (FF), as TOML (`protocols/*.toml`).
//!
//! The paper's protocol (Ricci et al. 2014, thorax, upper arms, forearms) ships
//! as the built-in `ricci2014`; a lab writes its own file in the same format.

use super::error::CalibrationError;
use nalgebra::Vector3;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use toml::Spanned;

/// The protocols shipped with the program: (name, TOML text).
pub const BUILTIN_PROTOCOLS: &[(&str, &str)] =
    &[("ricci2014", include_str!("../../protocols/ricci2014.toml"))];

/// The protocol used when none is named.
pub const DEFAULT_PROTOCOL: &str = "ricci2014";

/// What a movement's readings measure.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MovementKind {
    /// A still posture: the accelerometer gives the direction of gravity (the
    /// specific force, pointing up); its sign is the mean reading's.
    Static,
    /// A mono-axial movement: the gyroscope gives the rotation axis; its sign is
    /// the angular velocity's during the first phase of the movement.
    Functional,
}

/// An axis of a functional frame with a sign, e.g. `-y`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SignedAxis {
    /// 0 = x, 1 = y, 2 = z.
    pub index: usize,
    /// +1.0 or -1.0.
    pub sign: f64,
}

impl SignedAxis {
    /// Parses `x`, `+x`, `-x` (y, z likewise; case-insensitive).
    pub fn parse(s: &str) -> Option<SignedAxis> {
        let t = s.trim().to_ascii_lowercase();
        let (sign, rest) = match t.strip_prefix('-') {
            Some(r) => (-1.0, r),
            None => (1.0, t.strip_prefix('+').unwrap_or(&t)),
        };
        let index = match rest {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return None,
        };
        Some(SignedAxis { index, sign })
    }

    /// The unit vector of this axis in the functional frame.
    pub fn vector(&self) -> Vector3<f64> {
        let mut v = Vector3::zeros();
        v[self.index] = self.sign;
        v
    }

    /// `+x`, `-z`, ...
    pub fn name(&self) -> String {
        format!(
            "{}{}",
            if self.sign < 0.0 { '-' } else { '+' },
            ['x', 'y', 'z'][self.index]
        )
    }
}

/// One movement of the protocol.
#[derive(Debug, Clone, PartialEq)]
pub struct Movement {
    /// The label of its rows in a recording (case-sensitive).
    pub label: String,
    pub kind: MovementKind,
    pub description: String,
    /// Functional-frame axis per IMU the movement calibrates.
    pub axes: BTreeMap<String, SignedAxis>,
}

/// A calibration protocol.
#[derive(Debug, Clone, PartialEq)]
pub struct Protocol {
    pub name: String,
    pub description: String,
    /// IMUs the protocol calibrates, in display order.
    pub segments: Vec<String>,
    /// Gyroscope readings slower than this are left out, degrees per second.
    pub min_rate_deg_s: f64,
    /// Movements in display order (the rows of the paper's Table 1).
    pub movements: Vec<Movement>,
    /// The protocol's TOML text as read (recorded with every calibration).
    pub text: String,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawProtocol {
    name: String,
    #[serde(default)]
    description: String,
    segments: Vec<Spanned<String>>,
    min_rate_deg_s: Option<Spanned<f64>>,
    #[serde(rename = "movement")]
    movements: Vec<RawMovement>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMovement {
    label: Spanned<String>,
    kind: MovementKind,
    #[serde(default)]
    description: String,
    axes: Spanned<BTreeMap<String, Spanned<String>>>,
}

impl Protocol {
    /// A built-in protocol by name.
    pub fn builtin(name: &str) -> Option<Protocol> {
        let (_, text) = BUILTIN_PROTOCOLS.iter().find(|(n, _)| *n == name)?;
        Some(
            Protocol::from_toml(text, &format!("<built-in {name}>"))
                .expect("built-in protocol is valid"),
        )
    }

    /// The default protocol (the paper's).
    pub fn default_protocol() -> Protocol {
        Protocol::builtin(DEFAULT_PROTOCOL).expect("default protocol exists")
    }

    /// A built-in name or a path to a TOML file.
    pub fn load(name_or_path: &str) -> Result<Protocol, CalibrationError> {
        if let Some(p) = Protocol::builtin(name_or_path) {
            return Ok(p);
        }
        let text = crate::input::read_text(std::path::Path::new(name_or_path)).map_err(|e| {
            CalibrationError::file(
                name_or_path,
                format!(
                    "cannot read protocol: {e} (built-in protocols: {})",
                    BUILTIN_PROTOCOLS
                        .iter()
                        .map(|(n, _)| *n)
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            )
        })?;
        Protocol::from_toml(&text, name_or_path)
    }

    /// Parses and checks a protocol; `origin` names it in errors.
    pub fn from_toml(text: &str, origin: &str) -> Result<Protocol, CalibrationError> {
        let raw: RawProtocol =
            toml::from_str(text).map_err(|e| CalibrationError::toml(origin, text, &e))?;
        let at = |span: std::ops::Range<usize>, msg: String| {
            let (l, c) = super::error::line_col(text, span.start);
            CalibrationError::at(origin, l, c, msg)
        };
        let mut segments: Vec<String> = Vec::new();
        for s in &raw.segments {
            if segments.iter().any(|x| x.eq_ignore_ascii_case(s.get_ref())) {
                return Err(at(
                    s.span(),
                    format!("IMU '{}' is listed twice", s.get_ref()),
                ));
            }
            segments.push(s.get_ref().clone());
        }
        let rate = raw.min_rate_deg_s.as_ref().map_or(0.0, |r| *r.get_ref());
        if !(rate.is_finite() && rate >= 0.0) {
            return Err(at(
                raw.min_rate_deg_s.as_ref().map_or(0..0, |r| r.span()),
                format!("min_rate_deg_s must be a finite number >= 0, found {rate}"),
            ));
        }
        let mut movements: Vec<Movement> = Vec::new();
        for m in raw.movements {
            let label = m.label.get_ref().trim().to_string();
            if label.is_empty() {
                return Err(at(
                    m.label.span(),
                    "a movement label must not be empty".into(),
                ));
            }
            if movements.iter().any(|x| x.label == label) {
                return Err(at(
                    m.label.span(),
                    format!("movement '{label}' is listed twice"),
                ));
            }
            if m.axes.get_ref().is_empty() {
                return Err(at(
                    m.axes.span(),
                    format!("movement '{label}': expected at least one IMU = axis"),
                ));
            }
            let mut axes = BTreeMap::new();
            for (imu, axis) in m.axes.get_ref() {
                let Some(seg) = segments.iter().find(|s| s.eq_ignore_ascii_case(imu)) else {
                    return Err(at(
                        axis.span(),
                        format!(
                            "movement '{label}': IMU '{imu}' is not in `segments` ({})",
                            segments.join(", ")
                        ),
                    ));
                };
                let a = SignedAxis::parse(axis.get_ref()).ok_or_else(|| {
                    at(
                        axis.span(),
                        format!(
                            "movement '{label}', IMU '{imu}': expected an axis such as +x, -y or z, found '{}'",
                            axis.get_ref()
                        ),
                    )
                })?;
                axes.insert(seg.clone(), a);
            }
            movements.push(Movement {
                label,
                kind: m.kind,
                description: m.description,
                axes,
            });
        }
        let p = Protocol {
            name: raw.name,
            description: raw.description,
            segments,
            min_rate_deg_s: rate,
            movements,
            text: text.to_string(),
        };
        if let Some((k, message)) = p.axes_problem() {
            return Err(at(raw.segments[k].span(), message));
        }
        Ok(p)
    }

    /// Every IMU needs two non-parallel axes to fix a rotation: the index in
    /// `segments` of the first IMU that has not, and why.
    fn axes_problem(&self) -> Option<(usize, String)> {
        for (k, seg) in self.segments.iter().enumerate() {
            let axes: Vec<usize> = self
                .movements
                .iter()
                .filter_map(|m| m.axes.get(seg).map(|a| a.index))
                .collect();
            if !axes.iter().any(|&a| a != axes[0]) {
                return Some((
                    k,
                    format!(
                        "IMU '{seg}': its movements give {} distinct functional axis; at least two non-parallel axes are needed to fix a rotation",
                        if axes.is_empty() { 0 } else { 1 }
                    ),
                ));
            }
        }
        None
    }

    /// The movement with this label.
    pub fn movement(&self, label: &str) -> Option<&Movement> {
        self.movements.iter().find(|m| m.label == label)
    }

    /// SHA-256 of the protocol's text.
    pub fn sha256(&self) -> String {
        crate::input::sha256_hex(self.text.as_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtin_protocol_is_the_papers_table_1() {
        let p = Protocol::default_protocol();
        assert_eq!(p.segments.len(), 5);
        let labels: Vec<&str> = p.movements.iter().map(|m| m.label.as_str()).collect();
        assert_eq!(
            labels,
            ["supine", "TR", "TFE", "FFEB", "FEB", "FE", "AA", "PS"]
        );
        // Table 1: the thorax has three movements, each arm segment five or six.
        let count = |seg: &str| {
            p.movements
                .iter()
                .filter(|m| m.axes.contains_key(seg))
                .count()
        };
        assert_eq!(count("upper_back"), 3);
        assert_eq!(count("l_upper_arm"), 5);
        assert_eq!(count("r_forearm"), 6);
        assert_eq!(p.movement("supine").unwrap().kind, MovementKind::Static);
        assert_eq!(p.movement("TR").unwrap().axes["upper_back"].name(), "+x");
    }

    #[test]
    fn signed_axes() {
        assert_eq!(SignedAxis::parse("-Y").unwrap().name(), "-y");
        assert_eq!(SignedAxis::parse("z").unwrap().vector(), Vector3::z());
        assert!(SignedAxis::parse("w").is_none());
        assert!(SignedAxis::parse("+-x").is_none());
    }

    fn err(text: &str) -> CalibrationError {
        Protocol::from_toml(text, "p.toml").unwrap_err()
    }

    const HEAD: &str = "name = \"t\"\nsegments = [\"a\"]\n";

    #[test]
    fn errors_name_line_and_column() {
        let e = err(&format!(
            "{HEAD}[[movement]]\nlabel = \"m\"\nkind = \"static\"\naxes = {{ a = \"+q\" }}\n"
        ));
        assert_eq!(
            (e.file.as_str(), e.line, e.column),
            ("p.toml", 6, 14),
            "{e}"
        );
        assert!(e.message.contains("expected an axis"), "{e}");
        let e = err(&format!(
            "{HEAD}[[movement]]\nlabel = \"m\"\nkind = \"wiggle\"\naxes = {{ a = \"x\" }}\n"
        ));
        assert_eq!(e.line, 5, "{e}");
        assert!(e.message.contains("static"), "{e}");
        let e = err(&format!(
            "{HEAD}[[movement]]\nlabel = \"m\"\nkind = \"static\"\naxes = {{ b = \"x\" }}\n"
        ));
        assert_eq!((e.line, e.column), (6, 14), "{e}");
        assert!(e.message.contains("not in `segments`"), "{e}");
        // One axis only: no rotation can be fitted.
        let e = err(&format!(
            "{HEAD}[[movement]]\nlabel = \"m\"\nkind = \"static\"\naxes = {{ a = \"x\" }}\n[[movement]]\nlabel = \"n\"\nkind = \"functional\"\naxes = {{ a = \"-x\" }}\n"
        ));
        assert!(e.message.contains("two non-parallel"), "{e}");
        // At the IMU's entry in `segments`.
        assert_eq!((e.line, e.column), (2, 13), "{e}");
        let e = err("name = 1\n");
        assert_eq!(e.line, 1, "{e}");
    }
}
