//! The correction variants: one table ([`VARIANTS`]) that the command line,
//! files (serde), sidecars, reports and every screen label read. A variant
//! is added by adding its enum value and its row here; the engine picks its
//! solver from the row's [`Kind`] and flags.

use serde::{Deserialize, Deserializer, Serialize, Serializer};

/// A correction variant (its properties live in its [`VariantInfo`] row).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Variant {
    Basic,
    Drift,
    DriftCentroid,
    Rivest,
    Mueller,
    DriftHeading,
    DriftHeadingCentroid,
    Ik,
    Hinge,
    /// `hinge` after removing the heading drift `drift-heading-centroid` finds.
    HingeHeading,
    /// Per joint, the ACM variant its own figures favour (`acm::auto`).
    Auto,
    None,
    /// `basic` with the centroid term: registered only with the
    /// `demo-variant` feature, to show that this file is the one place a
    /// variant is added (`tests/variant_registry.rs`).
    #[cfg(feature = "demo-variant")]
    BasicCentroid,
}

/// Which solver corrects a variant's joints.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// The Anatomical Constraint Method, one correction per distal IMU.
    Acm,
    /// The ACM with drift modelled as a heading about the global vertical.
    Heading,
    /// A published baseline method for some joints, the ACM elsewhere.
    Baseline,
    /// IMU inverse kinematics: joint coordinates within hard limits.
    Ik,
    /// Per joint, one of several ACM variants, chosen without truth.
    Auto,
    /// No correction.
    None,
}

/// One row of the variant table.
#[derive(Debug, Clone, Copy)]
pub struct VariantInfo {
    pub variant: Variant,
    /// The name on the command line, in files and on screen.
    pub name: &'static str,
    /// At most five characters, for the trial list's columns.
    pub short: &'static str,
    /// At most fourteen characters, for the compare screen's columns.
    pub column: &'static str,
    pub kind: Kind,
    /// Solves per window (true) or once for the whole trial (false).
    pub windowed: bool,
    /// Uses the table's centroid term.
    pub centroid: bool,
    /// Estimates the hinge joints' axes and corrects both of their IMUs with them.
    pub hinge: bool,
    /// Removes each IMU's heading drift since its first window, as
    /// `drift-heading-centroid` estimates it, from the trial before
    /// correcting it.
    pub headings_first: bool,
    /// One line for `--help` and the help screen.
    pub description: &'static str,
}

const fn row(
    variant: Variant,
    name: &'static str,
    short: &'static str,
    column: &'static str,
    kind: Kind,
    (windowed, centroid, hinge, headings_first): (bool, bool, bool, bool),
    description: &'static str,
) -> VariantInfo {
    VariantInfo {
        variant,
        name,
        short,
        column,
        kind,
        windowed,
        centroid,
        hinge,
        headings_first,
        description,
    }
}

/// Every variant, in the order screens and reports list them.
pub const VARIANTS: &[VariantInfo] = &[
    row(
        Variant::Basic,
        "basic",
        "basic",
        "basic",
        Kind::Acm,
        (false, false, false, false),
        "One correction per joint for the whole trial, no centroid term.",
    ),
    row(
        Variant::Drift,
        "drift",
        "drift",
        "drift",
        Kind::Acm,
        (true, false, false, false),
        "Windows + slerp to follow drift, no centroid term (lambda2 = 0).",
    ),
    row(
        Variant::DriftCentroid,
        "drift-centroid",
        "d+c",
        "drift-centroid",
        Kind::Acm,
        (true, true, false, false),
        "Windows + slerp + the centroid term (lambda2 from the table).",
    ),
    row(
        Variant::DriftHeading,
        "drift-heading",
        "d+h",
        "drift-heading",
        Kind::Heading,
        (true, false, false, false),
        "One constant correction per IMU plus a heading correction about the \
         global vertical per window: `G_R' = R_up(-h(t)) G_R C`; no centroid term.",
    ),
    row(
        Variant::DriftHeadingCentroid,
        "drift-heading-centroid",
        "d+h+c",
        "drift-hdg-cent",
        Kind::Heading,
        (true, true, false, false),
        "As `drift-heading`, with the centroid term.",
    ),
    row(
        Variant::Rivest,
        "rivest",
        "rivest",
        "rivest",
        Kind::Baseline,
        (true, true, false, false),
        "Rivest (2005) for the knees, per drift window; `drift-centroid` elsewhere.",
    ),
    row(
        Variant::Mueller,
        "mueller",
        "muell",
        "mueller",
        Kind::Baseline,
        (true, true, false, false),
        "Mueller et al. (2017) axes for the elbows; `drift-centroid` elsewhere.",
    ),
    row(
        Variant::Ik,
        "ik",
        "ik",
        "ik",
        Kind::Ik,
        (false, false, false, false),
        "IMU inverse kinematics: joint coordinates with the model's degrees of \
         freedom and hard limits; not the ACM.",
    ),
    row(
        Variant::Hinge,
        "hinge",
        "hinge",
        "hinge",
        Kind::Acm,
        (true, true, true, false),
        "As `drift-centroid`, with the hinge axes of the model's hinge joints \
         estimated in both IMUs' frames: they fix two degrees of freedom of \
         the distal IMU's correction and of the proximal one's.",
    ),
    row(
        Variant::HingeHeading,
        "hinge-heading",
        "hng+h",
        "hinge-heading",
        Kind::Acm,
        (true, true, true, true),
        "`hinge` on the trial with each IMU's heading drift since its first \
         window removed as `drift-heading-centroid` estimates it: \
         `G_R' = R_up(-h(t)) G_R C(t)`, for hinges whose IMUs drift in heading.",
    ),
    row(
        Variant::Auto,
        "auto",
        "auto",
        "auto",
        Kind::Auto,
        (true, false, false, false),
        "Per joint in chain order, the joint rotation of the one of \
         hinge-heading, drift-heading-centroid, drift-heading, \
         drift-centroid, drift and none that keeps the joint inside its limits \
         (docs/method.md section 19); the choice and its figures are in the sidecar.",
    ),
    row(
        Variant::None,
        "none",
        "none",
        "none",
        Kind::None,
        (false, false, false, false),
        "No correction: the trial as read, after any pose or functional \
         calibration (the step before every other variant).",
    ),
    #[cfg(feature = "demo-variant")]
    row(
        Variant::BasicCentroid,
        "basic-centroid",
        "b+c",
        "basic-centroid",
        Kind::Acm,
        (false, true, false, false),
        "As `basic`, with the centroid term (a demonstration variant).",
    ),
];

impl Variant {
    /// Every variant, in the order screens and reports list them.
    pub const ALL: [Variant; VARIANTS.len()] = {
        let mut all = [Variant::None; VARIANTS.len()];
        let mut k = 0;
        while k < VARIANTS.len() {
            all[k] = VARIANTS[k].variant;
            k += 1;
        }
        all
    };

    /// This variant's row of the table.
    pub fn info(self) -> &'static VariantInfo {
        VARIANTS
            .iter()
            .find(|r| r.variant == self)
            .expect("every variant has a row")
    }

    /// The name used on the command line, in files and on screen.
    pub fn name(self) -> &'static str {
        self.info().name
    }

    /// Parses a variant name.
    pub fn from_name(name: &str) -> Option<Variant> {
        VARIANTS.iter().find(|r| r.name == name).map(|r| r.variant)
    }

    /// The solver that corrects this variant's joints.
    pub fn kind(self) -> Kind {
        self.info().kind
    }

    /// Solves per window (true) or once for the whole trial (false).
    pub fn windowed(self) -> bool {
        self.info().windowed
    }

    /// Uses the table's centroid term.
    pub fn centroid(self) -> bool {
        self.info().centroid
    }

    /// Models drift as a heading rotation about the global vertical.
    pub fn heading(self) -> bool {
        self.kind() == Kind::Heading
    }

    /// Estimates the hinge joints' axes and corrects both of their IMUs with them.
    pub fn hinge(self) -> bool {
        self.info().hinge
    }

    /// Removes each IMU's estimated heading drift before correcting.
    pub fn headings_first(self) -> bool {
        self.info().headings_first
    }

    /// Reports a heading drift per IMU (the heading kind, and the variants
    /// that remove it first).
    pub fn fits_headings(self) -> bool {
        self.heading() || self.headings_first()
    }
}

impl std::fmt::Display for Variant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A name that is no variant's.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown variant '{0}': expected one of {names}", names = names().join(", "))]
pub struct UnknownVariant(pub String);

/// Every variant's name, in table order.
pub fn names() -> Vec<&'static str> {
    VARIANTS.iter().map(|r| r.name).collect()
}

impl std::str::FromStr for Variant {
    type Err = UnknownVariant;
    fn from_str(s: &str) -> Result<Variant, UnknownVariant> {
        Variant::from_name(s).ok_or_else(|| UnknownVariant(s.to_string()))
    }
}

impl Serialize for Variant {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for Variant {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Variant, D::Error> {
        let name = String::deserialize(d)?;
        name.parse().map_err(serde::de::Error::custom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_round_trip() {
        for v in Variant::ALL {
            assert_eq!(Variant::from_name(v.name()), Some(v));
            let json = serde_json::to_string(&v).unwrap();
            assert_eq!(json, format!("\"{}\"", v.name()));
            assert_eq!(serde_json::from_str::<Variant>(&json).unwrap(), v);
        }
        let mut names = names();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), VARIANTS.len());
    }

    #[test]
    fn labels_fit_their_columns() {
        for r in VARIANTS {
            assert!(r.short.len() <= 6 && r.column.len() <= 14, "{}", r.name);
        }
    }

    #[test]
    fn an_unknown_name_lists_the_known_ones() {
        let e = "drift-centroids".parse::<Variant>().unwrap_err();
        assert!(e.to_string().contains("drift, drift-centroid"), "{e}");
    }
}
