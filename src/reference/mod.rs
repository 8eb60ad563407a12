//! Joint angles from an optical system, as a reference for the IMU angles.
//!
//! A reference is a set of channels, each one joint axis (`r_knee`, Y) in
//! degrees on the reference's own time base (seconds from its first sample).
//! [`read`] reads it from a CSV, an OpenSim `.mot` or a C3D file; [`compare`]
//! resamples it onto a trial's times, finds the time lag between the two
//! clocks by cross-correlation, and scores each variant's angles against it.

mod compare;
mod read;

pub use compare::{
    compare, format_text, trace, AxisScore, CompareError, CompareOptions, ReferenceReport,
    ReferenceTrace, VariantScores,
};
pub use read::{
    read_reference, reference_beside, write_c3d, write_csv, write_mot, REFERENCE_BESIDE,
};

use crate::model::Axis;

/// One joint axis of the reference, degrees at `Reference::time_s`.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// The model's joint name.
    pub joint: String,
    pub axis: Axis,
    /// Where it came from (a column or C3D point component, with its sign).
    pub source: String,
    /// Degrees, in the tool's sign convention for this joint axis; NaN where
    /// the reference has no value (a gap in the optical data).
    pub values_deg: Vec<f64>,
}

/// An optical reference: channels on one time base.
#[derive(Debug, Clone, PartialEq)]
pub struct Reference {
    /// The file as the user named it.
    pub origin: String,
    /// Seconds, strictly increasing.
    pub time_s: Vec<f64>,
    pub channels: Vec<Channel>,
    /// Columns or points that map to no joint axis (listed in the report).
    pub ignored: Vec<String>,
}
