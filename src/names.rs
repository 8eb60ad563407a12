//! Names of the library's small choice types, as settings files, sidecars and
//! the command line spell them.
//!
//! The core carries each choice's name and one line of help; the command line
//! (the binary) builds its parsers from them, so the library needs no
//! command-line crate and a name is spelled in one place per type (serde's
//! `rename_all` must agree, which the tests below check).

use crate::limits::Solver;
use crate::plot::PlotKind;
use crate::simulate::{KneeAxis, KneeImu};
use crate::trial::TrialFormat;
use crate::vertical::Vertical;

/// A choice type with a fixed set of named values.
pub trait Named: Sized + Copy + 'static {
    /// The values a user may choose, in the order help texts list them.
    const CHOICES: &'static [Self];

    /// The value's name (kebab- or snake-case, as in settings files).
    fn name(self) -> &'static str;

    /// One line saying what the value means, for help texts.
    fn help(self) -> &'static str;

    /// The value with this exact name, if it is one of [`Named::CHOICES`].
    fn from_name(name: &str) -> Option<Self> {
        Self::CHOICES.iter().copied().find(|c| c.name() == name)
    }
}

impl Named for Vertical {
    const CHOICES: &'static [Self] = &[Vertical::ZUp, Vertical::ZDown];
    fn name(self) -> &'static str {
        Vertical::name(self)
    }
    fn help(self) -> &'static str {
        match self {
            Vertical::ZUp => "+Z is up (east-north-up and most fusion filters)",
            Vertical::ZDown => "-Z is up: north-east-down systems",
        }
    }
}

impl Named for Solver {
    const CHOICES: &'static [Self] = &[Solver::Gradient, Solver::NelderMead];
    fn name(self) -> &'static str {
        match self {
            Solver::Gradient => "gradient",
            Solver::NelderMead => "nelder-mead",
        }
    }
    fn help(self) -> &'static str {
        match self {
            Solver::Gradient => "value and gradient in one pass, quasi-Newton steps",
            Solver::NelderMead => "Nelder-Mead with restarts on values only (the reference)",
        }
    }
}

impl Named for KneeImu {
    const CHOICES: &'static [Self] = &[KneeImu::None, KneeImu::Thigh, KneeImu::Calf];
    fn name(self) -> &'static str {
        match self {
            KneeImu::None => "none",
            KneeImu::Thigh => "thigh",
            KneeImu::Calf => "calf",
        }
    }
    fn help(self) -> &'static str {
        match self {
            KneeImu::None => "both IMUs sit exactly on their segments",
            KneeImu::Thigh => "the thigh IMU is misaligned",
            KneeImu::Calf => "the calf IMU is misaligned",
        }
    }
}

impl Named for KneeAxis {
    const CHOICES: &'static [Self] = &[KneeAxis::X, KneeAxis::Z];
    fn name(self) -> &'static str {
        match self {
            KneeAxis::X => "x",
            KneeAxis::Z => "z",
        }
    }
    fn help(self) -> &'static str {
        match self {
            KneeAxis::X => "about the sensor's X axis",
            KneeAxis::Z => "about the sensor's Z axis",
        }
    }
}

impl Named for PlotKind {
    const CHOICES: &'static [Self] = &[
        PlotKind::Traces,
        PlotKind::Histogram,
        PlotKind::Scatter,
        PlotKind::Globe,
    ];
    fn name(self) -> &'static str {
        match self {
            PlotKind::Traces => "traces",
            PlotKind::Histogram => "histogram",
            PlotKind::Scatter => "scatter",
            PlotKind::Globe => "globe",
        }
    }
    fn help(self) -> &'static str {
        match self {
            PlotKind::Traces => "a joint's X, Y and Z angles over time with limit lines",
            PlotKind::Histogram => "histograms of a joint's angles over trials",
            PlotKind::Scatter => "a joint's angles as three projections",
            PlotKind::Globe => "the distal segment's direction on a sphere",
        }
    }
}

/// Only the formats a corrected trial can be written in: Xsens exports are
/// read only, so they are not offered.
impl Named for TrialFormat {
    const CHOICES: &'static [Self] = &[
        TrialFormat::QuatCsv,
        TrialFormat::EulerCsv,
        TrialFormat::Sto,
    ];
    fn name(self) -> &'static str {
        self.row().name
    }
    fn help(self) -> &'static str {
        self.row().help
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Serialize;

    /// The name serde writes for `value` (settings files, sidecars).
    fn serde_name<T: Serialize>(value: T) -> String {
        serde_json::to_value(value)
            .unwrap()
            .as_str()
            .unwrap()
            .to_string()
    }

    fn check<T: Named + Serialize>() {
        for &c in T::CHOICES {
            assert_eq!(c.name(), serde_name(c), "serde and Named disagree");
            assert_eq!(T::from_name(c.name()).map(|v| v.name()), Some(c.name()));
            assert!(!c.help().is_empty());
        }
        assert!(T::from_name("no-such-name").is_none());
    }

    #[test]
    fn names_agree_with_serde() {
        check::<Vertical>();
        check::<Solver>();
        check::<KneeImu>();
        check::<KneeAxis>();
        check::<TrialFormat>();
        assert_eq!(serde_name(TrialFormat::Xsens), TrialFormat::Xsens.name());
        let writable: Vec<TrialFormat> = (crate::trial::format::FORMATS.iter())
            .filter(|r| r.writable)
            .map(|r| r.format)
            .collect();
        assert_eq!(
            TrialFormat::CHOICES,
            writable,
            "the choices are the writable formats"
        );
    }

    #[test]
    fn plot_kinds_round_trip() {
        for &k in PlotKind::CHOICES {
            assert_eq!(PlotKind::from_name(k.name()), Some(k));
        }
    }
}
