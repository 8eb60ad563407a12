//! Joint limit tables (docs/method.md section 4) and correction settings.
//!
//! A limit table is a CSV file, one row per joint and axis:
//!
//! ```text
//! joint,axis,movement,lower_deg,upper_deg,centroid_deg,lambda2
//! knee,Y,flexion/extension,0,130,,0
//! ```
//!
//! `joint` is a joint kind of the model (`knee` covers `l_knee` and `r_knee`) or a
//! single joint's name (`l_knee`), which then overrides the kind's rows. Angles are
//! Z-Y-X Euler angles of the joint rotation in degrees. `centroid_deg` is empty when
//! the joint has no centroid; `lambda2` weighs the centroid term and is the same on
//! the joint's three rows. The global settings (`lambda1`, window and hop) live in
//! `joint_limits/settings.toml` (see [`Settings`]).
//!
//! A table may instead be in the swing-twist model ([`swing_twist`]): its
//! header, `joint,twist_axis,...`, says so, and the loader decides by it.

pub mod swing_twist;

use crate::model::Model;
use crate::trial::precision::Precision;
use crate::vertical::Vertical;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

/// The tables shipped with the program: (file name, CSV text).
pub const BUILTIN_TABLES: &[(&str, &str)] = &[
    (
        "table_3_2.csv",
        include_str!("../joint_limits/table_3_2.csv"),
    ),
    (
        "table_3_1.csv",
        include_str!("../joint_limits/table_3_1.csv"),
    ),
    (
        "swing_twist.csv",
        include_str!("../joint_limits/swing_twist.csv"),
    ),
];

/// The settings shipped with the program.
pub const BUILTIN_SETTINGS: &str = include_str!("../joint_limits/settings.toml");

/// The CSV header every limit table starts with.
pub const HEADER: [&str; 7] = [
    "joint",
    "axis",
    "movement",
    "lower_deg",
    "upper_deg",
    "centroid_deg",
    "lambda2",
];

/// One row: the limits of one axis of one joint (kind), degrees.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LimitRow {
    pub joint: String,
    /// 0 = X, 1 = Y, 2 = Z.
    pub axis: usize,
    pub movement: String,
    pub lower_deg: f64,
    pub upper_deg: f64,
    pub centroid_deg: Option<f64>,
    pub lambda2: f64,
}

/// Limits, centroid and weight of one joint, ready for the cost function.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointLimits {
    /// `[lower, upper]` per axis X, Y, Z, degrees.
    pub range_deg: [[f64; 2]; 3],
    /// Centroid Z-Y-X angles, degrees, when the table sets one.
    pub centroid_deg: Option<[f64; 3]>,
    /// Weight of the centroid term (docs/method.md section 5).
    pub lambda2: f64,
    /// The frame the ranges apply in: `None` for the Z-Y-X angles of the joint
    /// rotation itself (the table's convention of a joint with identity
    /// `angle_axes`, and every use outside the engine); `Some(axes)` for those
    /// of `Q^T R Q` (the engine's costs, [`JointLimits::in_table_axes`]).
    pub axes: Option<crate::model::TableAxes>,
    /// The swing-twist limits when the table is of that model
    /// ([`swing_twist`]): the costs then use them instead of `range_deg`
    /// (which holds their box in Z-Y-X angles, for views and checks).
    pub swing_twist: Option<swing_twist::SwingTwistLimits>,
}

impl JointLimits {
    /// The same limits as the engine's costs apply them to a joint rotation
    /// `R` of `joint`'s segment frames (docs/method.md section 2.5): on the
    /// Z-Y-X angles of `Q^T R Q`, which are the table's angles times
    /// `det(P)`. So the ranges and the centroid are kept (`det(P) = 1`) or
    /// negated (`det(P) = -1`: `[lo, hi]` becomes `[-hi, -lo]`), and `axes`
    /// set. With identity `angle_axes` the limits are returned unchanged.
    pub fn in_table_axes(&self, joint: &crate::model::Joint) -> JointLimits {
        let Some(axes) = joint.table_axes() else {
            return *self;
        };
        let flip = axes.det < 0.0;
        JointLimits {
            range_deg: self
                .range_deg
                .map(|[lo, hi]| if flip { [-hi, -lo] } else { [lo, hi] }),
            centroid_deg: self
                .centroid_deg
                .map(|c| if flip { c.map(|a| -a) } else { c }),
            lambda2: self.lambda2,
            axes: Some(axes),
            swing_twist: self
                .swing_twist
                .map(|s| if flip { s.mirrored() } else { s }),
        }
    }

    /// Per joint rotation of `rotations` (segment frames, distal in
    /// proximal), its excursion beyond these limits in the swing-twist model
    /// when they are of it ([`swing_twist`]; `None` for an Euler box). The
    /// limits are the table's own (not [`JointLimits::in_table_axes`]); the
    /// rotations are read in the table's axes as the ACM's cost reads them
    /// (docs/method.md section 5.1), in degrees.
    pub fn swing_twist_parts(
        &self,
        joint: &crate::model::Joint,
        rotations: impl Iterator<Item = crate::rotation::Quat>,
    ) -> Option<Vec<swing_twist::ExcursionParts>> {
        self.swing_twist?;
        let lim = self.in_table_axes(joint);
        let st = lim.swing_twist?;
        Some(
            rotations
                .map(|r| st.excursion_parts(crate::rotation::wxyz(&lim.to_axes(&r))))
                .collect(),
        )
    }

    /// Whether these limits read the joint rotation `r` (segment frames) in
    /// two Z-Y-X triplets (a Y range beyond +-90 deg) and its middle angle
    /// lies within [`TWO_READINGS_ZONE_DEG`] of +-90: there the ACM cost has
    /// one basin per reading (docs/method.md section 2.5).
    pub fn near_the_other_triplet(&self, r: &crate::rotation::Quat) -> bool {
        crate::rotation::y_beyond_90(&self.range_deg)
            && crate::rotation::euler_zyx_deg(&self.to_axes(r))[1].abs()
                >= 90.0 - TWO_READINGS_ZONE_DEG
    }

    /// A joint rotation `r` (segment frames) as the ranges see it: `Q^T R Q`,
    /// or `r` itself without `axes`.
    pub fn to_axes(&self, r: &crate::rotation::Quat) -> crate::rotation::Quat {
        match &self.axes {
            Some(a) => a.to_table(r),
            None => *r,
        }
    }
}

/// A whole limit table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LimitTable {
    /// Comment lines (starting `#`) above the header, kept when saving.
    #[serde(default)]
    pub preamble: Vec<String>,
    pub rows: Vec<LimitRow>,
    /// The swing-twist rows when the table is of that model; `rows` then
    /// holds their boxes in Z-Y-X angles ([`swing_twist::SwingTwistRow::euler_rows`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub swing_twist: Option<Vec<swing_twist::SwingTwistRow>>,
}

/// A limit table or settings problem, located in its file (line 0 when the
/// file as a whole is meant; column = field index).
pub type LimitsError = crate::located::LocatedError;

/// Half-width of the zone about a middle Z-Y-X angle of +-90 deg where a
/// joint read in two triplets has one cost basin per reading
/// ([`JointLimits::near_the_other_triplet`]), degrees.
pub const TWO_READINGS_ZONE_DEG: f64 = 15.0;

/// Settings of a correction that are not per joint.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Settings {
    /// Weight of the correction's rotation angle in the cost (per degree).
    pub lambda1: f64,
    /// Window length, seconds (docs/method.md section 7).
    pub window_s: f64,
    /// Hop between window starts, seconds.
    pub hop_s: f64,
    /// The global frame's up axis (heading-drift variants turn about it).
    #[serde(default)]
    pub vertical: Vertical,
    /// The minimiser of the window costs (the previous one stays selectable,
    /// to compare against).
    #[serde(default, skip_serializing_if = "Solver::is_default")]
    pub solver: Solver,
    /// The decimals orientation numbers are written with (`--precision`;
    /// does not change the correction). Left out when `auto`.
    #[serde(default, skip_serializing_if = "Precision::is_auto")]
    pub precision: Precision,
}

impl Default for Settings {
    fn default() -> Self {
        Settings {
            lambda1: 0.05,
            window_s: 60.0,
            hop_s: 30.0,
            vertical: Vertical::ZUp,
            solver: Solver::default(),
            precision: Precision::Auto,
        }
    }
}

/// `joint_limits/settings.toml`: the settings plus the name of the default table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SettingsFile {
    /// File name of the default limit table in the same folder.
    pub table: String,
    pub lambda1: f64,
    pub window_s: f64,
    pub hop_s: f64,
    /// `z-up` (default) or `z-down` (north-east-down recordings).
    #[serde(default)]
    pub vertical: Vertical,
    /// An orientation jump between neighbouring samples larger than this,
    /// degrees, is flagged as a glitch (reported and shown, never smoothed).
    #[serde(default = "default_glitch_deg")]
    pub glitch_deg: f64,
    /// Decimals of the orientation numbers written: `auto` (as read), `full`
    /// or a count (`--precision` overrides it).
    #[serde(default, deserialize_with = "precision_in_toml")]
    pub precision: Precision,
}

/// `precision = "auto" | "full" | N` in the settings file, the count also
/// as a bare integer (`precision = 6`).
fn precision_in_toml<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Precision, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Written {
        Count(i64),
        Word(String),
    }
    let text = match Written::deserialize(d)? {
        Written::Count(n) => n.to_string(),
        Written::Word(w) => w,
    };
    Precision::parse(&text).map_err(serde::de::Error::custom)
}

fn default_glitch_deg() -> f64 {
    crate::trial::glitch::DEFAULT_GLITCH_DEG
}

impl SettingsFile {
    /// Parses and validates the settings TOML; `origin` names the file in errors.
    pub fn parse(text: &str, origin: &str) -> Result<SettingsFile, LimitsError> {
        let s: SettingsFile = toml::from_str(text).map_err(|e| {
            let (line, column) = e
                .span()
                .map(|sp| crate::input::line_col(text, sp.start))
                .unwrap_or((0, 0));
            LimitsError {
                file: origin.into(),
                line,
                column,
                message: e.message().to_string(),
            }
        })?;
        match s.problem() {
            None => Ok(s),
            Some(p) => Err(p.in_toml(text, origin)),
        }
    }

    /// The first value out of bounds, if any: [`Settings::problem`], then
    /// `glitch_deg` in (0, 180] degrees.
    pub fn problem(&self) -> Option<SettingsProblem> {
        self.settings().problem().or_else(|| {
            let g = self.glitch_deg;
            (!(g.is_finite() && g > 0.0 && g <= 180.0)).then(|| SettingsProblem {
                key: "glitch_deg",
                message: format!("expected a number of degrees in (0, 180], found {g}"),
            })
        })
    }

    /// The correction settings it holds.
    pub fn settings(&self) -> Settings {
        Settings {
            lambda1: self.lambda1,
            window_s: self.window_s,
            hop_s: self.hop_s,
            vertical: self.vertical,
            solver: Solver::default(),
            precision: self.precision,
        }
    }

    /// TOML text for saving.
    pub fn to_toml(&self) -> String {
        format!(
            "# Correction settings (docs/method.md sections 4-7); the limit table is a CSV in this folder.\ntable = {}\n# weight of the correction's rotation angle in the cost, per degree\nlambda1 = {}\n# drift windows: length and hop, seconds\nwindow_s = {}\nhop_s = {}\n# the global frame's up axis: z-up, or z-down for north-east-down recordings\nvertical = \"{}\"\n# an orientation jump between neighbouring samples beyond this, degrees, is flagged as a glitch\nglitch_deg = {}\n# decimals of the orientation numbers written: auto (as the input had them), full, or a count\nprecision = \"{}\"\n",
            // A TOML string (Rust's `{:?}` escapes control characters as `\u{1b}`, not TOML).
            toml::Value::String(self.table.clone()),
            self.lambda1, self.window_s, self.hop_s, self.vertical.name(), self.glitch_deg, self.precision
        )
    }
}

/// The limits of a folder such as `joint_limits/`: its `settings.toml` and the
/// table that names, each from disk when present there, else the built-in copy.
#[derive(Debug, Clone, PartialEq)]
pub struct LimitsDir {
    pub settings: SettingsFile,
    pub table: LimitTable,
    /// Where the table came from: its path, or `<built-in NAME>`.
    pub table_source: String,
}

impl LimitsDir {
    /// Resolves `dir/settings.toml` and the table it names, falling back to the
    /// built-in files for whichever is absent. Malformed files are errors.
    pub fn load(dir: &Path) -> Result<LimitsDir, LimitsError> {
        let settings_path = dir.join("settings.toml");
        let origin = settings_path.display().to_string();
        // Finish a save of table and settings that a kill interrupted (a
        // read-only folder has none to finish).
        let _ = crate::save::recover(dir);
        let (settings, text) = if settings_path.exists() {
            let text =
                crate::input::read_text_located(&settings_path).map_err(|e| LimitsError {
                    file: origin.clone(),
                    line: e.line,
                    column: e.column,
                    message: format!("cannot read: {}", e.error),
                })?;
            (SettingsFile::parse(&text, &origin)?, Some(text))
        } else {
            let builtin = SettingsFile::parse(BUILTIN_SETTINGS, "<built-in settings.toml>")?;
            (builtin, None)
        };
        let path = dir.join(&settings.table);
        let (table, table_source) = if path.exists() {
            (LimitTable::load(&path)?, path.display().to_string())
        } else {
            let builtin = BUILTIN_TABLES.iter().find(|(n, _)| *n == settings.table);
            if let (None, Some(text)) = (builtin, &text) {
                // A table the lab named but that is nowhere: a typo must not
                // silently correct with another table.
                let (line, column) = crate::input::locate::toml_key(text, &["table"])
                    .unwrap_or((key_line(text, "table"), 0));
                return Err(LimitsError {
                    file: origin,
                    line,
                    column,
                    message: format!(
                        "expected a limit table in {} or a built-in one, found no '{}'",
                        dir.display(),
                        settings.table
                    ),
                });
            }
            let (name, text) = builtin.unwrap_or(&BUILTIN_TABLES[0]);
            let source = format!("<built-in {name}>");
            (LimitTable::parse(text, &source)?, source)
        };
        Ok(LimitsDir {
            settings,
            table,
            table_source,
        })
    }
}

/// A setting out of bounds: which key, and what was expected and found.
#[derive(Debug, Clone, PartialEq)]
pub struct SettingsProblem {
    /// The key as `settings.toml` and sidecars spell it (`hop_s`).
    pub key: &'static str,
    /// `expected ..., found ...`.
    pub message: String,
}

impl SettingsProblem {
    /// The error in a settings TOML `text` read from `origin`, at the key's
    /// line and column (line 1 when the key is absent: a default is at fault).
    pub fn in_toml(&self, text: &str, origin: &str) -> LimitsError {
        let (line, column) = crate::input::locate::toml_key(text, &[self.key])
            .unwrap_or((key_line(text, self.key), 0));
        self.at(origin, line, column)
    }

    /// The error at a place in `file` (`key: message`).
    pub fn at(&self, file: &str, line: u64, column: usize) -> LimitsError {
        LimitsError {
            file: file.into(),
            line,
            column,
            message: format!("{}: {}", self.key, self.message),
        }
    }
}

impl Settings {
    /// The first value that is not usable, wherever it came from (a settings
    /// file, flags, a sidecar): each must be finite, with
    /// `0 <= lambda1 <= MAX_LAMBDA1`, `0 < window_s <= MAX_SPAN_S` and
    /// `window_s / MAX_OVERLAP <= hop_s <= window_s`. Whether the windows suit
    /// a given trial is [`crate::acm::window::check_layout`]'s.
    pub fn problem(&self) -> Option<SettingsProblem> {
        use crate::trial::timing::MAX_SPAN_S;
        let problem = |key, message| Some(SettingsProblem { key, message });
        if !(self.lambda1.is_finite() && (0.0..=MAX_LAMBDA1).contains(&self.lambda1)) {
            return problem(
                "lambda1",
                format!(
                    "expected a finite weight per degree in [0, {MAX_LAMBDA1}], found {}",
                    self.lambda1
                ),
            );
        }
        if !(self.window_s.is_finite() && self.window_s > 0.0 && self.window_s <= MAX_SPAN_S) {
            return problem(
                "window_s",
                format!(
                    "expected a positive number of seconds, at most {MAX_SPAN_S:e}, found {}",
                    self.window_s
                ),
            );
        }
        let least = self.window_s / MAX_OVERLAP;
        if !(self.hop_s.is_finite() && self.hop_s >= least && self.hop_s <= self.window_s) {
            return problem(
                "hop_s",
                format!(
                    "expected a number of seconds between window_s / {MAX_OVERLAP} ({least}) and window_s ({}), found {}",
                    self.window_s, self.hop_s
                ),
            );
        }
        None
    }

    /// [`Settings::problem`] as an error about `origin` as a whole.
    pub fn validate(&self, origin: &str) -> Result<(), LimitsError> {
        match self.problem() {
            None => Ok(()),
            Some(p) => Err(p.at(origin, 0, 0)),
        }
    }
}

/// Largest `lambda1` (per degree): beyond it the correction angle is all the
/// cost sees and the limits nothing.
pub const MAX_LAMBDA1: f64 = 1e6;

/// Most windows that may overlap any instant (`window_s / hop_s`).
pub const MAX_OVERLAP: f64 = 1000.0;

/// Parses an axis name `X`, `Y` or `Z` (case-insensitive) into 0, 1, 2.
pub fn parse_axis(s: &str) -> Option<usize> {
    match s.trim().to_ascii_uppercase().as_str() {
        "X" => Some(0),
        "Y" => Some(1),
        "Z" => Some(2),
        _ => None,
    }
}

/// The name of axis 0, 1, 2.
pub fn axis_name(axis: usize) -> &'static str {
    ["X", "Y", "Z"][axis.min(2)]
}

impl LimitTable {
    /// The default table (Table 3-2, "adjusted") as shipped.
    pub fn default_table() -> LimitTable {
        LimitTable::parse(BUILTIN_TABLES[0].1, "table_3_2.csv").expect("built-in table is valid")
    }

    /// Reads and parses a limit table file.
    pub fn load(path: &Path) -> Result<LimitTable, LimitsError> {
        let origin = path.display().to_string();
        let text = crate::input::read_text_located(path).map_err(|e| LimitsError {
            file: origin.clone(),
            line: e.line,
            column: e.column,
            message: format!("cannot read: {}", e.error),
        })?;
        LimitTable::parse(&text, &origin)
    }

    /// Parses CSV text (see the module docs); `origin` names the file in errors.
    pub fn parse(text: &str, origin: &str) -> Result<LimitTable, LimitsError> {
        let err = |line: u64, column: usize, message: String| LimitsError {
            file: origin.into(),
            line,
            column,
            message,
        };
        let mut rdr = csv::ReaderBuilder::new()
            .has_headers(true)
            .comment(Some(b'#'))
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let header = rdr
            .headers()
            .map_err(|e| err(1, 0, format!("cannot read the header: {e}")))?
            .clone();
        let found: Vec<&str> = header.iter().collect();
        if found.get(1) == Some(&"twist_axis") {
            return parse_swing_twist(text, rdr, &found, &err);
        }
        if found != HEADER {
            return Err(header_error(&found, &HEADER, "header", &err));
        }
        let preamble = comment_preamble(text);
        let mut rows = Vec::new();
        let mut lines = Vec::new();
        for rec in rdr.records() {
            let rec = rec.map_err(|e| {
                let line = e.position().map_or(0, |p| p.line());
                // The first field missing, or the first one too many.
                let column = match e.kind() {
                    csv::ErrorKind::UnequalLengths { len, .. } => {
                        (*len as usize).min(HEADER.len()) + 1
                    }
                    _ => 1,
                };
                err(line, column, format!("expected 7 fields per row: {e}"))
            })?;
            let line = rec.position().map_or(0, |p| p.line());
            rows.push(parse_row(&rec, line, &err)?);
            lines.push(line);
        }
        let table = LimitTable {
            preamble,
            rows,
            swing_twist: None,
        };
        table.check_consistency(origin, &lines)?;
        Ok(table)
    }

    fn check_consistency(&self, origin: &str, lines: &[u64]) -> Result<(), LimitsError> {
        let mut seen: BTreeMap<(&str, usize), usize> = BTreeMap::new();
        for (i, r) in self.rows.iter().enumerate() {
            if let Some(prev) = seen.insert((r.joint.as_str(), r.axis), i) {
                return Err(LimitsError {
                    file: origin.into(),
                    line: lines[i],
                    column: 2,
                    message: format!(
                        "joint '{}' axis {} appears twice (first on line {})",
                        r.joint,
                        axis_name(r.axis),
                        lines[prev]
                    ),
                });
            }
        }
        for (i, r) in self.rows.iter().enumerate() {
            let siblings: Vec<&LimitRow> =
                self.rows.iter().filter(|s| s.joint == r.joint).collect();
            if siblings.iter().any(|s| s.lambda2 != r.lambda2) {
                return Err(LimitsError {
                    file: origin.into(),
                    line: lines[i],
                    column: 7,
                    message: format!(
                        "lambda2 of joint '{}' differs between its rows; expected one value per joint",
                        r.joint
                    ),
                });
            }
            if siblings.len() == 3
                && siblings.iter().any(|s| s.centroid_deg.is_some())
                && siblings.iter().any(|s| s.centroid_deg.is_none())
            {
                return Err(LimitsError {
                    file: origin.into(),
                    line: lines[i],
                    column: 6,
                    message: format!(
                        "joint '{}' has a centroid on some axes only; expected all three or none",
                        r.joint
                    ),
                });
            }
        }
        Ok(())
    }

    /// Checks that every joint of `model` has all three axes.
    pub fn check_covers(&self, model: &Model, origin: &str) -> Result<(), LimitsError> {
        self.check_covers_in(model, origin, None)
    }

    /// [`LimitTable::check_covers`], locating a missing row in `text`, the
    /// CSV the table was parsed from: at the axis column of the joint's (or
    /// its kind's) first row when it has some rows, else at the header's
    /// `joint` column. Without the text the table as a whole is meant.
    pub fn check_covers_in(
        &self,
        model: &Model,
        origin: &str,
        text: Option<&str>,
    ) -> Result<(), LimitsError> {
        for j in &model.joints {
            for axis in 0..3 {
                if self.row(&j.name, &j.kind, axis).is_some() {
                    continue;
                }
                let (line, column) = text.map_or((0, 0), |t| joint_rows_at(t, &j.name, &j.kind));
                return Err(LimitsError {
                    file: origin.into(),
                    line,
                    column,
                    message: format!(
                        "no row for joint '{}' (kind '{}') axis {} of model '{}': expected a row `{},{},...`",
                        j.name,
                        j.kind,
                        axis_name(axis),
                        model.name,
                        j.kind,
                        axis_name(axis),
                    ),
                });
            }
        }
        Ok(())
    }

    /// The row for a joint's axis: the joint's own row if present, else its kind's.
    pub fn row(&self, joint: &str, kind: &str, axis: usize) -> Option<&LimitRow> {
        let find = |name: &str| self.rows.iter().find(|r| r.joint == name && r.axis == axis);
        find(joint).or_else(|| find(kind))
    }

    /// The limits of `joint` as the engine's costs apply them to its joint
    /// rotations in segment frames: its [`LimitTable::joint_limits`] in the
    /// joint's table axes ([`JointLimits::in_table_axes`]). Every cost built
    /// from measured rotations takes these; `with_centroid = false` sets
    /// lambda2 to 0.
    pub fn cost_limits(
        &self,
        joint: &crate::model::Joint,
        with_centroid: bool,
    ) -> Option<JointLimits> {
        self.joint_limits(&joint.name, &joint.kind, with_centroid)
            .map(|l| l.in_table_axes(joint))
    }

    /// The limits of one joint; `with_centroid = false` sets lambda2 to 0.
    pub fn joint_limits(
        &self,
        joint: &str,
        kind: &str,
        with_centroid: bool,
    ) -> Option<JointLimits> {
        let rows = [
            self.row(joint, kind, 0)?,
            self.row(joint, kind, 1)?,
            self.row(joint, kind, 2)?,
        ];
        let centroid = match (
            rows[0].centroid_deg,
            rows[1].centroid_deg,
            rows[2].centroid_deg,
        ) {
            (Some(x), Some(y), Some(z)) => Some([x, y, z]),
            _ => None,
        };
        let lambda2 = if with_centroid && centroid.is_some() {
            rows[0].lambda2
        } else {
            0.0
        };
        let swing_twist = match &self.swing_twist {
            None => None,
            Some(st) => {
                let find = |name: &str| st.iter().find(|r| r.joint == name);
                Some(find(joint).or_else(|| find(kind))?.limits)
            }
        };
        Some(JointLimits {
            range_deg: rows.map(|r| [r.lower_deg, r.upper_deg]),
            centroid_deg: centroid,
            lambda2,
            axes: None,
            swing_twist,
        })
    }

    /// The table's limit model: `euler-zyx` (a box on Z-Y-X angles) or
    /// `swing-twist` ([`swing_twist`]), as reports and sidecars name it.
    pub fn model_name(&self) -> &'static str {
        if self.swing_twist.is_some() {
            "swing-twist"
        } else {
            "euler-zyx"
        }
    }

    /// The table as CSV text, comments first, as saved.
    pub fn to_csv(&self) -> String {
        let mut out = String::new();
        for c in &self.preamble {
            out.push_str(c);
            out.push('\n');
        }
        out.push_str(&self.rows_csv());
        out
    }

    /// Header and rows only, in canonical form: what [`LimitTable::hash`] covers.
    pub fn rows_csv(&self) -> String {
        if let Some(st) = &self.swing_twist {
            let mut out = swing_twist::HEADER.join(",");
            out.push('\n');
            for r in st {
                out.push_str(&r.to_csv());
                out.push('\n');
            }
            return out;
        }
        let mut out = HEADER.join(",");
        out.push('\n');
        for r in &self.rows {
            let _ = writeln!(
                out,
                "{},{},{},{},{},{},{}",
                csv_field(&r.joint),
                axis_name(r.axis),
                csv_field(&r.movement),
                r.lower_deg,
                r.upper_deg,
                r.centroid_deg.map(|c| c.to_string()).unwrap_or_default(),
                r.lambda2
            );
        }
        out
    }

    /// SHA-256 of [`LimitTable::rows_csv`], hex: identifies the table's content.
    pub fn hash(&self) -> String {
        let digest = Sha256::digest(self.rows_csv().as_bytes());
        digest.iter().map(|b| format!("{b:02x}")).collect()
    }
}

/// A text cell as CSV: quoted (quotes doubled) when it holds a separator, a
/// quote or a line break, or starts with the comment sign, so that it reads back as is.
pub(crate) fn csv_field(text: &str) -> std::borrow::Cow<'_, str> {
    if text.contains([',', '"', '\n', '\r']) || text.starts_with('#') {
        format!("\"{}\"", text.replace('"', "\"\"")).into()
    } else {
        text.into()
    }
}

fn parse_row(
    rec: &csv::StringRecord,
    line: u64,
    err: &dyn Fn(u64, usize, String) -> LimitsError,
) -> Result<LimitRow, LimitsError> {
    if rec.len() != HEADER.len() {
        return Err(err(
            line,
            0,
            format!("expected {} fields, found {}", HEADER.len(), rec.len()),
        ));
    }
    let joint = rec[0].to_string();
    if joint.is_empty() {
        return Err(err(line, 1, "expected a joint name, found nothing".into()));
    }
    let axis = parse_axis(&rec[1])
        .ok_or_else(|| err(line, 2, format!("expected X, Y or Z, found '{}'", &rec[1])))?;
    let angle = |col: usize| -> Result<f64, LimitsError> {
        let s = &rec[col];
        let v: f64 = s.parse().map_err(|_| {
            err(
                line,
                col + 1,
                format!("expected {} in degrees, found '{s}'", HEADER[col]),
            )
        })?;
        if !v.is_finite() || !(-180.0..=180.0).contains(&v) {
            return Err(err(
                line,
                col + 1,
                format!(
                    "expected {} within -180..180 degrees, found {s}",
                    HEADER[col]
                ),
            ));
        }
        Ok(v)
    };
    let lower_deg = angle(3)?;
    let upper_deg = angle(4)?;
    if lower_deg >= upper_deg {
        return Err(err(
            line,
            5,
            format!("expected upper_deg > lower_deg, found {upper_deg} <= {lower_deg}"),
        ));
    }
    let centroid_deg = if rec[5].is_empty() {
        None
    } else {
        Some(angle(5)?)
    };
    let lambda2: f64 = rec[6].parse().map_err(|_| {
        err(
            line,
            7,
            format!("expected lambda2 as a number >= 0, found '{}'", &rec[6]),
        )
    })?;
    if !lambda2.is_finite() || lambda2 < 0.0 {
        return Err(err(
            line,
            7,
            format!("expected lambda2 as a finite number >= 0, found {lambda2}"),
        ));
    }
    Ok(LimitRow {
        joint,
        axis,
        movement: rec[2].to_string(),
        lower_deg,
        upper_deg,
        centroid_deg,
        lambda2,
    })
}

/// The rest of [`LimitTable::parse`] for a table whose header names the
/// swing-twist model (`found`): its rows, each joint once, and their boxes as
/// the Euler rows.
/// The error of a header `found` that is not `want`, located at its first
/// field that differs (1-based), or the first one missing.
fn header_error(
    found: &[&str],
    want: &[&str],
    what: &str,
    err: &dyn Fn(u64, usize, String) -> LimitsError,
) -> LimitsError {
    let column = found
        .iter()
        .zip(want)
        .position(|(f, h)| f != h)
        .unwrap_or(found.len().min(want.len()))
        + 1;
    err(
        1,
        column,
        format!(
            "expected the {what} `{}`, found `{}`",
            want.join(","),
            found.join(",")
        ),
    )
}

/// The `#` comment lines a table file starts with (kept when it is saved).
fn comment_preamble(text: &str) -> Vec<String> {
    text.lines()
        .take_while(|l| l.trim_start().starts_with('#'))
        .map(str::to_string)
        .collect()
}

fn parse_swing_twist(
    text: &str,
    mut rdr: csv::Reader<&[u8]>,
    found: &[&str],
    err: &dyn Fn(u64, usize, String) -> LimitsError,
) -> Result<LimitTable, LimitsError> {
    let want = swing_twist::HEADER;
    if found != want {
        return Err(header_error(found, &want, "swing-twist header", err));
    }
    let preamble = comment_preamble(text);
    let mut st: Vec<swing_twist::SwingTwistRow> = Vec::new();
    let mut lines: Vec<u64> = Vec::new();
    for rec in rdr.records() {
        let rec = rec.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line());
            let column = match e.kind() {
                csv::ErrorKind::UnequalLengths { len, .. } => (*len as usize).min(want.len()) + 1,
                _ => 1,
            };
            err(
                line,
                column,
                format!("expected {} fields per row: {e}", want.len()),
            )
        })?;
        let line = rec.position().map_or(0, |p| p.line());
        let row = swing_twist::parse_row(&rec, line, err)?;
        if let Some(i) = st.iter().position(|r| r.joint == row.joint) {
            return Err(err(
                line,
                1,
                format!(
                    "joint '{}' appears twice (first on line {}); expected one row per joint",
                    row.joint, lines[i]
                ),
            ));
        }
        st.push(row);
        lines.push(line);
    }
    Ok(LimitTable {
        preamble,
        rows: st.iter().flat_map(|r| r.euler_rows()).collect(),
        swing_twist: Some(st),
    })
}

/// 1-based line of the TOML key `key` in `text` (1 when it is not found).
/// Where the rows of a joint (by name, else by kind) start in a limit table's
/// CSV text: line and axis column of the first, or the header's line and
/// `joint` column when there are none.
fn joint_rows_at(text: &str, joint: &str, kind: &str) -> (u64, usize) {
    let header = text
        .lines()
        .position(|l| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .map_or(1, |i| i as u64 + 1);
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(true)
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .flexible(true)
        .from_reader(text.as_bytes());
    let mut by_kind = None;
    for rec in rdr.records().map_while(Result::ok) {
        let line = rec.position().map_or(header, |p| p.line());
        match rec.get(0) {
            Some(n) if n == joint => return (line, 2),
            Some(n) if n == kind && by_kind.is_none() => by_kind = Some(line),
            _ => {}
        }
    }
    by_kind.map_or((header, 1), |line| (line, 2))
}

fn key_line(text: &str, key: &str) -> u64 {
    text.lines()
        .position(|l| {
            l.trim_start()
                .strip_prefix(key)
                .is_some_and(|rest| rest.trim_start().starts_with('='))
        })
        .map_or(1, |i| i as u64 + 1)
}

/// Which minimiser solves the ACM's window costs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Solver {
    /// Value and gradient in one pass, quasi-Newton steps ([`crate::acm::minimise::minimise_shaped`]).
    #[default]
    Gradient,
    /// Nelder-Mead with restarts on values only ([`crate::acm::minimise::minimise`]): the previous
    /// solver, kept as the reference.
    NelderMead,
}

impl Solver {
    /// True for the default solver (settings files leave it out).
    pub fn is_default(&self) -> bool {
        *self == Solver::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The boxes `Joint::limit_box` reads (`builtin_box`, parsed apart from
    /// this module) are the default table's, for every joint of every
    /// built-in model.
    #[test]
    fn builtin_boxes_equal_the_default_table() {
        let table = LimitTable::default_table();
        let mut checked = 0;
        for (name, _) in crate::model::BUILTIN_MODELS {
            let model = crate::model::Model::builtin(name).unwrap();
            for j in &model.joints {
                let want = table
                    .joint_limits(&j.name, &j.kind, false)
                    .map(|l| l.range_deg);
                assert_eq!(j.limit_box(), want, "{name} {}", j.name);
                checked += usize::from(want.is_some());
            }
        }
        assert!(checked > 30, "{checked}");
        assert_eq!(crate::builtin_box::table_3_2_box("nowhere", "none"), None);
    }

    #[test]
    fn shipped_tables_match_method_section_5() {
        let t = LimitTable::default_table();
        let m = Model::infant13();
        t.check_covers(&m, "t").unwrap();
        let sh = t.joint_limits("l_shoulder", "shoulder", true).unwrap();
        assert_eq!(sh.range_deg, [[-10.0, 100.0], [-40.0, 60.0], [-70.0, 70.0]]);
        assert_eq!(sh.centroid_deg, Some([47.0, -1.0, -31.0]));
        assert_eq!(sh.lambda2, 30.0);
        let knee = t.joint_limits("r_knee", "knee", true).unwrap();
        assert_eq!(knee.range_deg, [[-5.0, 5.0], [0.0, 130.0], [-5.0, 5.0]]);
        assert_eq!((knee.centroid_deg, knee.lambda2), (None, 0.0));
        let no_c = t.joint_limits("l_hip", "hip", false).unwrap();
        assert_eq!(no_c.lambda2, 0.0);
        let t1 = LimitTable::parse(BUILTIN_TABLES[1].1, "table_3_1.csv").unwrap();
        let sh1 = t1.joint_limits("l_shoulder", "shoulder", true).unwrap();
        assert_eq!(
            sh1.range_deg,
            [[-45.0, 135.0], [-60.0, 60.0], [-90.0, 90.0]]
        );
        let back1 = t1.joint_limits("back", "back", true).unwrap();
        assert_eq!(back1.range_deg[1], [-30.0, 10.0]);
        let s = SettingsFile::parse(BUILTIN_SETTINGS, "settings.toml").unwrap();
        assert_eq!(s.settings(), Settings::default());
        assert_eq!(s.table, "table_3_2.csv");
    }

    #[test]
    fn csv_round_trip_and_hash() {
        let t = LimitTable::default_table();
        let again = LimitTable::parse(&t.to_csv(), "x").unwrap();
        assert_eq!(t, again);
        assert_eq!(t.hash(), again.hash());
        let mut changed = t.clone();
        changed.rows[0].upper_deg += 1.0;
        assert_ne!(t.hash(), changed.hash());
    }

    #[test]
    fn joint_row_overrides_kind() {
        let mut t = LimitTable::default_table();
        let mut r = t.row("knee", "knee", 1).unwrap().clone();
        r.joint = "l_knee".into();
        r.upper_deg = 100.0;
        t.rows.push(r);
        assert_eq!(
            t.joint_limits("l_knee", "knee", true).unwrap().range_deg[1][1],
            100.0
        );
        assert_eq!(
            t.joint_limits("r_knee", "knee", true).unwrap().range_deg[1][1],
            130.0
        );
    }

    fn parse_err(body: &str) -> LimitsError {
        let text = format!("{}\n{body}", HEADER.join(","));
        LimitTable::parse(&text, "bad.csv").unwrap_err()
    }

    #[test]
    fn errors_name_file_line_and_column() {
        let e = parse_err("knee,Y,flexion,0,130,,0\nknee,W,x,0,1,,0\n");
        assert_eq!((e.line, e.column), (3, 2), "{e}");
        let e = parse_err("knee,Y,flexion,abc,130,,0\n");
        assert_eq!((e.line, e.column), (2, 4));
        assert!(e.to_string().starts_with("bad.csv:2:4:"), "{e}");
        let e = parse_err("knee,Y,flexion,30,10,,0\n");
        assert!(e.message.contains("upper_deg > lower_deg"), "{e}");
        let e = parse_err("knee,Y,flexion,0,200,,0\n");
        assert_eq!(e.column, 5);
        let e = parse_err("knee,Y,flexion,0,NaN,,0\n");
        assert_eq!(e.column, 5);
        let e = parse_err("knee,Y,flexion,0,100,,-1\n");
        assert_eq!(e.column, 7);
        let e = parse_err("knee,Y,flexion,0,100\n");
        assert_eq!(e.line, 2, "{e}");
        let e = parse_err("knee,Y,f,0,100,,0\nknee,Y,f,0,100,,0\n");
        assert!(e.message.contains("twice"), "{e}");
        let e = LimitTable::parse("a,b\n", "h.csv").unwrap_err();
        assert_eq!(e.line, 1);
        let t = LimitTable::parse(&format!("{}\nknee,Y,f,0,1,,0\n", HEADER.join(",")), "s.csv")
            .unwrap();
        let e = t.check_covers(&Model::infant13(), "s.csv").unwrap_err();
        assert!(e.message.contains("no row for joint 'back'"), "{e}");
    }

    #[test]
    fn glitch_threshold_is_a_setting_in_degrees() {
        let base = "table = \"t.csv\"\nlambda1 = 0.05\nwindow_s = 60.0\nhop_s = 30.0\n";
        let s = SettingsFile::parse(&format!("{base}glitch_deg = 12.5\n"), "s.toml").unwrap();
        assert_eq!(s.glitch_deg, 12.5);
        let again = SettingsFile::parse(&s.to_toml(), "again.toml").unwrap();
        assert_eq!(again, s);
        for bad in ["0", "-3", "200", "nan"] {
            let e =
                SettingsFile::parse(&format!("{base}glitch_deg = {bad}\n"), "s.toml").unwrap_err();
            assert!(e.message.contains("glitch_deg"), "{bad}: {e}");
        }
    }

    #[test]
    fn limits_dir_falls_back_to_built_ins_and_reads_files() {
        let dir = tempfile::tempdir().unwrap();
        let d = LimitsDir::load(dir.path()).unwrap();
        assert_eq!(d.table, LimitTable::default_table());
        assert_eq!(d.table_source, "<built-in table_3_2.csv>");
        std::fs::write(
            dir.path().join("settings.toml"),
            "table = \"mine.csv\"\nlambda1 = 0.1\nwindow_s = 40.0\nhop_s = 20.0\n",
        )
        .unwrap();
        let mut mine = LimitTable::default_table();
        mine.rows[0].upper_deg = 31.0;
        std::fs::write(dir.path().join("mine.csv"), mine.to_csv()).unwrap();
        let d = LimitsDir::load(dir.path()).unwrap();
        assert_eq!((d.settings.lambda1, d.table.rows[0].upper_deg), (0.1, 31.0));
        // glitch_deg defaults to 30 deg when absent.
        assert_eq!(d.settings.glitch_deg, 30.0);
        assert!(d.table_source.ends_with("mine.csv"));
        std::fs::write(dir.path().join("mine.csv"), "joint,axis\n").unwrap();
        let e = LimitsDir::load(dir.path()).unwrap_err();
        assert!(e.file.ends_with("mine.csv") && e.line == 1, "{e}");
        // A table named in settings.toml that is neither in the folder nor
        // built in is an error at the `table` line, not a silent fallback.
        std::fs::remove_file(dir.path().join("mine.csv")).unwrap();
        std::fs::write(
            dir.path().join("settings.toml"),
            "lambda1 = 0.1\nwindow_s = 40.0\n  table = \"mine.csv\"\nhop_s = 20.0\n",
        )
        .unwrap();
        let e = LimitsDir::load(dir.path()).unwrap_err();
        assert!(e.file.ends_with("settings.toml") && e.line == 3, "{e}");
        assert!(e.message.contains("'mine.csv'"), "{e}");
        // A built-in name missing from the folder is the built-in table.
        std::fs::write(
            dir.path().join("settings.toml"),
            "table = \"table_3_1.csv\"\nlambda1 = 0.1\nwindow_s = 40.0\nhop_s = 20.0\n",
        )
        .unwrap();
        let d = LimitsDir::load(dir.path()).unwrap();
        assert_eq!(d.table_source, "<built-in table_3_1.csv>");
    }

    #[test]
    fn settings_errors_are_located() {
        let e = SettingsFile::parse(
            "table = \"t.csv\"\nlambda1 = \"x\"\nwindow_s = 60.0\nhop_s = 30.0\n",
            "s.toml",
        )
        .unwrap_err();
        assert_eq!(e.line, 2, "{e}");
        let e = SettingsFile::parse(
            "table = \"t.csv\"\nlambda1 = 0.05\nwindow_s = 60.0\nhop_s = 90.0\n",
            "s.toml",
        )
        .unwrap_err();
        assert!(e.message.contains("hop_s"), "{e}");
    }

    /// `precision` in the settings file: a word or a count (quoted or bare),
    /// carried into the settings; a bad value is located on its line.
    #[test]
    fn settings_precision_key() {
        let base = "table = \"t.csv\"\nlambda1 = 0.05\nwindow_s = 60.0\nhop_s = 30.0\n";
        for (value, want) in [
            ("\"full\"", Precision::Full),
            ("\"auto\"", Precision::Auto),
            ("6", Precision::Decimals(6)),
            ("\"4\"", Precision::Decimals(4)),
        ] {
            let s = SettingsFile::parse(&format!("{base}precision = {value}\n"), "s.toml").unwrap();
            assert_eq!(s.settings().precision, want, "{value}");
            let back = SettingsFile::parse(&s.to_toml(), "s.toml").unwrap();
            assert_eq!(back, s, "{value}");
        }
        assert_eq!(
            SettingsFile::parse(base, "s.toml").unwrap().precision,
            Precision::Auto
        );
        for bad in ["\"some\"", "18", "-1", "2.5"] {
            let e =
                SettingsFile::parse(&format!("{base}precision = {bad}\n"), "s.toml").unwrap_err();
            assert_eq!(e.line, 5, "{bad}: {e}");
        }
    }
}
