//! OpenSense's sensor-to-body mapping (`myIMUMappings.xml`).
//!
//! ```xml
//! <OpenSimDocument Version="40000">
//!   <XsensDataReaderSettings>
//!     <trial_prefix>MT_012005D6_009-001</trial_prefix>
//!     <ExperimentalSensors>
//!       <ExperimentalSensor name="_00B42268">
//!         <name_in_model>torso_imu</name_in_model>
//!       </ExperimentalSensor>
//!     </ExperimentalSensors>
//!   </XsensDataReaderSettings>
//! </OpenSimDocument>
//! ```
//!
//! Sensor `name` is appended to the prefix to give the export's file name
//! (`MT_012005D6_009-001_00B42268.txt`). An optional
//! `<sensor_to_opensim_rotations>rx ry rz</sensor_to_opensim_rotations>` (radians,
//! as in OpenSense's IMU placer and IK setup files) anywhere in the document
//! rotates the data from the Xsens global frame into OpenSim's ground frame.

use super::TrialError;
use crate::rotation::Quat;
use nalgebra::Vector3;

/// One sensor of the mapping.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MappedSensor {
    /// The `name` attribute, e.g. `_00B42268` (appended to the trial prefix).
    pub file_suffix: String,
    /// The IMU name in the model, e.g. `torso_imu`.
    pub name_in_model: String,
    /// Line of the `ExperimentalSensor` element (1-based).
    pub line: u64,
}

/// A parsed mapping file.
#[derive(Debug, Clone, PartialEq)]
pub struct Mapping {
    /// Common prefix of the export file names.
    pub trial_prefix: String,
    pub sensors: Vec<MappedSensor>,
    /// `sensor_to_opensim_rotations`, radians about X, Y, Z (space-fixed), if given.
    pub sensor_to_opensim_rad: Option<[f64; 3]>,
}

/// True when `text` looks like an OpenSense Xsens mapping (cheap check, no parse).
pub fn looks_like_mapping(text: &str) -> bool {
    text.contains("<XsensDataReaderSettings")
}

/// The rotation OpenSense applies for `sensor_to_opensim_rotations = [rx, ry, rz]`
/// (radians): space-fixed X, then Y, then Z, i.e. `Rz * Ry * Rx`. Data become
/// `R * G_R_sensor` (OpenSense `rotateOrientationTable`).
pub fn sensor_to_opensim(rad: [f64; 3]) -> Quat {
    let qx = Quat::from_axis_angle(&Vector3::x_axis(), rad[0]);
    let qy = Quat::from_axis_angle(&Vector3::y_axis(), rad[1]);
    let qz = Quat::from_axis_angle(&Vector3::z_axis(), rad[2]);
    qz * qy * qx
}

fn at(doc: &roxmltree::Document, node: roxmltree::Node, origin: &str, msg: String) -> TrialError {
    let p = doc.text_pos_at(node.range().start);
    TrialError::at(origin, p.row as u64, p.col as usize, msg)
}

fn child<'a, 'i>(node: roxmltree::Node<'a, 'i>, name: &str) -> Option<roxmltree::Node<'a, 'i>> {
    node.children()
        .find(|c| c.is_element() && c.tag_name().name() == name)
}

/// Parses a mapping file; `origin` names it in errors (line and column of the element).
pub fn parse_mapping(text: &str, origin: &str) -> Result<Mapping, TrialError> {
    let doc = roxmltree::Document::parse(text).map_err(|e| {
        let p = e.pos();
        TrialError::at(
            origin,
            p.row as u64,
            p.col as usize,
            format!("invalid XML: {e}"),
        )
    })?;
    let root = doc.root_element();
    let settings = root
        .descendants()
        .find(|n| n.has_tag_name("XsensDataReaderSettings"))
        .ok_or_else(|| {
            at(
                &doc,
                root,
                origin,
                "expected an <XsensDataReaderSettings> element (OpenSense sensor mapping)".into(),
            )
        })?;
    let prefix = child(settings, "trial_prefix")
        .and_then(|n| n.text())
        .map(|t| t.trim().to_string())
        .filter(|t| !t.is_empty())
        .ok_or_else(|| {
            at(
                &doc,
                settings,
                origin,
                "expected a non-empty <trial_prefix> (common start of the export file names)"
                    .into(),
            )
        })?;
    let list = child(settings, "ExperimentalSensors").ok_or_else(|| {
        at(
            &doc,
            settings,
            origin,
            "expected <ExperimentalSensors> listing the sensors".into(),
        )
    })?;
    let mut sensors: Vec<MappedSensor> = Vec::new();
    for s in list
        .children()
        .filter(|c| c.has_tag_name("ExperimentalSensor"))
    {
        let line = doc.text_pos_at(s.range().start).row as u64;
        let suffix = s
            .attribute("name")
            .map(str::trim)
            .filter(|n| !n.is_empty())
            .ok_or_else(|| {
                at(
                    &doc,
                    s,
                    origin,
                    "expected a name=\"_<serial>\" attribute".into(),
                )
            })?;
        let model_name = child(s, "name_in_model")
            .and_then(|n| n.text())
            .map(str::trim)
            .filter(|n| !n.is_empty())
            .ok_or_else(|| {
                at(
                    &doc,
                    s,
                    origin,
                    format!("sensor '{suffix}': expected a non-empty <name_in_model>"),
                )
            })?;
        if let Some(prev) = sensors
            .iter()
            .find(|p| p.file_suffix == suffix || p.name_in_model == model_name)
        {
            return Err(at(
                &doc,
                s,
                origin,
                format!(
                    "sensor '{suffix}' ({model_name}) repeats a sensor or model name of line {}; expected each once",
                    prev.line
                ),
            ));
        }
        sensors.push(MappedSensor {
            file_suffix: suffix.to_string(),
            name_in_model: model_name.to_string(),
            line,
        });
    }
    if sensors.is_empty() {
        return Err(at(
            &doc,
            list,
            origin,
            "expected at least one <ExperimentalSensor>".into(),
        ));
    }
    let rotation = match root
        .descendants()
        .find(|n| n.has_tag_name("sensor_to_opensim_rotations"))
    {
        None => None,
        Some(n) => Some(parse_rotation(&doc, n, origin)?),
    };
    Ok(Mapping {
        trial_prefix: prefix,
        sensors,
        sensor_to_opensim_rad: rotation,
    })
}

fn parse_rotation(
    doc: &roxmltree::Document,
    n: roxmltree::Node,
    origin: &str,
) -> Result<[f64; 3], TrialError> {
    let text = n.text().unwrap_or("");
    let v: Vec<Option<f64>> = text
        .split_whitespace()
        .map(|t| t.parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect();
    match v.as_slice() {
        [Some(x), Some(y), Some(z)] => Ok([*x, *y, *z]),
        _ => Err(at(
            doc,
            n,
            origin,
            format!(
                "expected three angles in radians 'rx ry rz' in <sensor_to_opensim_rotations>, found '{}'",
                text.trim()
            ),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rotation::{angle_between_deg, quat_axis_angle_deg};

    #[test]
    fn opensense_rotation_is_space_fixed_xyz() {
        // OpenSense's tutorial value: -pi/2 about X turns Z-up into Y-up.
        let r = sensor_to_opensim([-std::f64::consts::FRAC_PI_2, 0.0, 0.0]);
        let up = r * Vector3::z();
        assert!((up - Vector3::y()).norm() < 1e-12);
        let r = sensor_to_opensim([0.3, 0.0, 0.5]);
        let want = quat_axis_angle_deg([0.0, 0.0, 1.0], 0.5f64.to_degrees())
            * quat_axis_angle_deg([1.0, 0.0, 0.0], 0.3f64.to_degrees());
        assert!(angle_between_deg(&r, &want) < 1e-12);
    }

    #[test]
    fn mapping_errors_are_located() {
        let e = parse_mapping("<a><b></a>", "m.xml").unwrap_err();
        assert!(e.line == 1 && e.message.contains("invalid XML"), "{e}");
        let e = parse_mapping("<OpenSimDocument>\n<XsensDataReaderSettings>\n<trial_prefix>p</trial_prefix>\n<ExperimentalSensors>\n<ExperimentalSensor name=\"_1\"></ExperimentalSensor>\n</ExperimentalSensors></XsensDataReaderSettings></OpenSimDocument>", "m.xml").unwrap_err();
        assert_eq!((e.line, e.column), (5, 1), "{e}");
        assert!(e.message.contains("name_in_model"), "{e}");
        let e = parse_mapping("<X><XsensDataReaderSettings><trial_prefix>p</trial_prefix><ExperimentalSensors><ExperimentalSensor name=\"_1\"><name_in_model>a</name_in_model></ExperimentalSensor></ExperimentalSensors></XsensDataReaderSettings>\n<sensor_to_opensim_rotations>1 2</sensor_to_opensim_rotations></X>", "m.xml").unwrap_err();
        assert_eq!(e.line, 2, "{e}");
    }
}
