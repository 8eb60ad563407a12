//! The sidecar JSON written beside every corrected trial: what was done, with
//! which settings and table, the per-window corrections and the figures, enough
//! to reproduce the output exactly.

use crate::acm::{Correction, ImuHeading, JointResult, SkippedJoint, Variant};
use crate::ik::output::{coordinates_path, write_coordinates};
use crate::ik::IkSummary;
use crate::limits::{LimitTable, Settings};
use crate::metrics::{trial_figures, JointFigures};
use crate::model::Model;
use crate::pose::PoseRecord;
use crate::save::{atomic_write, OutputLock};
use crate::trial::precision::{AngleNumbers, Fixed};
use crate::trial::{write_trial_hashed, Trial, TrialFormat};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The limit table a correction used: where from, its content and hash.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TableRecord {
    /// The file it was read from, or `<built-in NAME>`.
    pub source: String,
    /// SHA-256 of the table's rows (see [`LimitTable::hash`]).
    pub sha256: String,
    /// The table itself, as CSV text.
    pub csv: String,
    /// The table's limit model when it is not the Euler box (`swing-twist`,
    /// as its CSV header also says); absent for Euler tables.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<String>,
}

/// The input trial of a correction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InputRecord {
    pub file: String,
    pub format: TrialFormat,
    /// SHA-256 of the file's bytes as read (compressed when gzip).
    pub sha256: String,
    pub samples: usize,
    pub imus: Vec<String>,
}

/// Figures before and after correction.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FiguresRecord {
    pub before: Vec<JointFigures>,
    pub after: Vec<JointFigures>,
}

/// Everything about one correction run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sidecar {
    pub program: String,
    pub version: String,
    pub input: InputRecord,
    pub output: String,
    /// SHA-256 of the output file's bytes as written: a reader of the output
    /// can tell whether this sidecar describes it (a save cut short between
    /// the trial and its sidecar leaves them apart).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output_sha256: Option<String>,
    pub output_format: TrialFormat,
    /// How the output's orientation numbers were written, from
    /// `settings.precision` and the input's decimals: fixed decimals, or
    /// absent for full precision (shortest round-trip digits).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub output_precision: Option<Fixed>,
    pub variant: Variant,
    pub settings: Settings,
    pub model: Model,
    pub limits: TableRecord,
    pub joints: Vec<JointResult>,
    pub skipped: Vec<SkippedJoint>,
    /// Estimated heading drift per IMU over time (heading-drift variants only).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub headings: Vec<ImuHeading>,
    pub figures: FiguresRecord,
    pub warnings: Vec<String>,
    /// A functional calibration applied to the trial before the correction.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub calibration: Option<crate::calibration::AppliedCalibration>,
    /// The pose calibration applied before the correction, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pose_calibration: Option<PoseRecord>,
    /// The `ik` variant's figures and its joint-coordinates file.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ik: Option<IkRecord>,
}

/// What an `ik` run wrote besides the orientations.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IkRecord {
    /// The joint-coordinates CSV.
    pub coordinates_file: String,
    pub summary: IkSummary,
}

pub use crate::input::sha256_hex;

/// The sidecar path of an output trial: `<output>.acmw.json`.
pub fn sidecar_path(output: &Path) -> PathBuf {
    let mut name = output.file_name().unwrap_or_default().to_os_string();
    name.push(".acmw.json");
    output.with_file_name(name)
}

impl Sidecar {
    /// Builds the record of a finished correction.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        input: InputRecord,
        output: &Path,
        output_format: TrialFormat,
        model: &Model,
        limits: &LimitTable,
        limits_source: &str,
        correction: &Correction,
        figures: FiguresRecord,
    ) -> Sidecar {
        Sidecar {
            program: "acmw".into(),
            version: env!("CARGO_PKG_VERSION").into(),
            input,
            output: output.display().to_string(),
            output_sha256: None,
            output_format,
            output_precision: correction.settings.precision.style(
                correction.corrected.orientation_decimals,
                AngleNumbers::written_in(output_format),
            ),
            variant: correction.variant,
            settings: correction.settings,
            model: model.clone(),
            limits: TableRecord {
                source: limits_source.into(),
                sha256: limits.hash(),
                csv: limits.to_csv(),
                model: limits
                    .swing_twist
                    .as_ref()
                    .map(|_| limits.model_name().to_string()),
            },
            joints: correction.joints.clone(),
            skipped: correction.skipped.clone(),
            headings: correction.headings.clone(),
            figures,
            warnings: Vec::new(),
            calibration: None,
            pose_calibration: None,
            ik: None,
        }
    }

    /// The limit table recorded in the sidecar, checked against its hash;
    /// `origin` (the sidecar's path) names it in errors.
    pub fn table(&self, origin: &str) -> anyhow::Result<LimitTable> {
        let t = LimitTable::parse(&self.limits.csv, &format!("{origin} (limits.csv)"))?;
        anyhow::ensure!(
            t.hash() == self.limits.sha256,
            "{origin}: limits.csv does not match limits.sha256 (the sidecar was edited?)"
        );
        Ok(t)
    }

    /// Checks what the sidecar would run with as if it came from files:
    /// settings ([`Settings::problem`]), model ([`Model::problem`]) and the
    /// limit table (its rows, its hash, and rows for every joint kind of the
    /// model). `text` is the sidecar's JSON as read from `origin`: errors
    /// point at the key at fault there (`origin:line:column: settings.hop_s: ...`);
    /// a problem inside the recorded table also names its line in `limits.csv`.
    pub fn check(&self, origin: &str, text: &str) -> Result<(), crate::limits::LimitsError> {
        let at = |path: &[&str], message: String| {
            let (line, column) = crate::input::locate::json_key(text, path).unwrap_or((0, 0));
            crate::limits::LimitsError {
                file: origin.to_string(),
                line,
                column,
                message,
            }
        };
        if let Some(p) = self.settings.problem() {
            return Err(at(
                &["settings", p.key],
                format!("settings.{}: {}", p.key, p.message),
            ));
        }
        if let Some(p) = self.model.problem() {
            let mut path = vec!["model"];
            path.extend(p.path.iter().map(String::as_str));
            return Err(at(&path, format!("model: {}", p.message)));
        }
        let in_table = |e: crate::limits::LimitsError| {
            let place = match (e.line, e.column) {
                (0, _) => String::new(),
                (l, 0) => format!(" line {l}"),
                (l, c) => format!(" line {l} column {c}"),
            };
            at(
                &["limits", "csv"],
                format!("limits.csv{place}: {}", e.message),
            )
        };
        let table = LimitTable::parse(&self.limits.csv, "limits.csv").map_err(in_table)?;
        if table.hash() != self.limits.sha256 {
            return Err(at(
                &["limits", "sha256"],
                "limits.csv does not match limits.sha256 (the sidecar was edited?)".into(),
            ));
        }
        let recorded = self.limits.model.as_deref().unwrap_or("euler-zyx");
        if recorded != table.model_name() {
            return Err(at(
                &["limits", "model"],
                format!(
                    "expected the model of limits.csv ('{}'), found '{recorded}'",
                    table.model_name()
                ),
            ));
        }
        table
            .check_covers_in(&self.model, "limits.csv", Some(&self.limits.csv))
            .map_err(in_table)?;
        Ok(())
    }

    /// Reads a sidecar file and [checks](Sidecar::check) it.
    pub fn load_checked(path: &Path) -> anyhow::Result<Sidecar> {
        let text = crate::input::read_text(path)
            .map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", path.display()))?;
        let sidecar = Sidecar::parse(&text, path)?;
        sidecar.check(&path.display().to_string(), &text)?;
        Ok(sidecar)
    }

    /// `None` when an input whose SHA-256 is `found` (hex) is the one
    /// recorded, else `found`.
    pub fn check_input<'a>(&self, found: &'a str) -> Option<&'a str> {
        (found != self.input.sha256).then_some(found)
    }

    /// Pretty JSON text.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("sidecar serialises")
    }

    /// Reads a sidecar file.
    pub fn load(path: &Path) -> anyhow::Result<Sidecar> {
        let text = crate::input::read_text(path)
            .map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", path.display()))?;
        Sidecar::parse(&text, path)
    }

    fn parse(text: &str, path: &Path) -> anyhow::Result<Sidecar> {
        serde_json::from_str(text).map_err(|e| {
            anyhow::anyhow!(
                "{}:{}:{}: not a sidecar: {e}",
                path.display(),
                e.line(),
                e.column()
            )
        })
    }
}

/// A warning when the sidecar beside the trial file `path` does not describe
/// the bytes of it read, whose SHA-256 is `sha256` (hex): the file was
/// replaced after the sidecar was written, or a save was cut short between
/// them. `None` when it does, or there is no sidecar or it records no output hash.
pub fn mismatch_warning(path: &Path, sha256: &str) -> Option<String> {
    let sc_path = sidecar_path(path);
    if !sc_path.is_file() {
        return None;
    }
    let recorded = match Sidecar::load(&sc_path) {
        Ok(s) => s.output_sha256?,
        Err(e) => return Some(format!("sidecar beside it is unreadable: {e}")),
    };
    (sha256 != recorded).then(|| {
        format!(
            "{} does not describe this file (output SHA-256 differs): the file changed after that correction was saved",
            sc_path.display()
        )
    })
}

/// The default output path of a corrected trial:
/// `corrected/<stem>.<variant>.<ext>[.gz]` in the input's folder.
pub fn default_output(input: &Path, variant: Variant, format: TrialFormat, gzip: bool) -> PathBuf {
    let stem = crate::file_names::stem_without(input, &crate::file_names::TRIAL_SUFFIXES);
    let ext = format.extension();
    let gz = if gzip { ".gz" } else { "" };
    input
        .parent()
        .unwrap_or(Path::new("."))
        .join("corrected")
        .join(format!("{stem}.{variant}.{ext}{gz}"))
}

/// What to save: a finished correction of the trial read from `input`.
pub struct SaveRequest<'a> {
    /// The file the raw trial was read from.
    pub input: &'a Path,
    pub input_format: TrialFormat,
    /// SHA-256 (hex) of the input's bytes as the trial was read from them.
    pub input_sha256: &'a str,
    /// The trial as the correction saw it: as read, or pose-calibrated.
    pub trial: &'a Trial,
    /// The pose calibration that made `trial` from the file, if any.
    pub pose: Option<&'a PoseRecord>,
    pub correction: &'a Correction,
    pub model: &'a Model,
    pub limits: &'a LimitTable,
    /// Where the table came from (a path or `<built-in NAME>`).
    pub limits_source: &'a str,
    /// The corrected trial's path and format.
    pub output: &'a Path,
    pub output_format: TrialFormat,
    /// The sidecar's path; `None` for [`sidecar_path`] of the output.
    pub sidecar: Option<&'a Path>,
}

impl SaveRequest<'_> {
    /// The sidecar record of this correction.
    pub fn sidecar(&self) -> Sidecar {
        let input = InputRecord {
            file: self.input.display().to_string(),
            format: self.input_format,
            sha256: self.input_sha256.to_string(),
            samples: self.trial.len(),
            imus: self.trial.imus.iter().map(|i| i.name.clone()).collect(),
        };
        let figures = FiguresRecord {
            before: trial_figures(self.trial, None, None, self.model, self.limits),
            after: trial_figures(
                &self.correction.corrected,
                Some(self.trial),
                None,
                self.model,
                self.limits,
            ),
        };
        let mut s = Sidecar::new(
            input,
            self.output,
            self.output_format,
            self.model,
            self.limits,
            self.limits_source,
            self.correction,
            figures,
        );
        s.warnings = self.trial.warnings.clone();
        s.pose_calibration = self.pose.cloned();
        s.ik = self.correction.ik.as_ref().map(|run| IkRecord {
            coordinates_file: coordinates_path(self.output).display().to_string(),
            summary: run.summary(),
        });
        s
    }

    /// Writes the corrected trial and its sidecar, each atomically (previous
    /// files are kept as `.bak`). Returns the sidecar's path.
    pub fn save(&self) -> anyhow::Result<PathBuf> {
        self.save_with(self.sidecar())
    }

    /// Writes the corrected trial and the given sidecar (built by
    /// [`SaveRequest::sidecar`], perhaps amended), as [`SaveRequest::save`] does.
    /// The output and its sidecar are written under an [`OutputLock`]: a
    /// second run writing the same output waits, then refuses.
    pub fn save_with(&self, sidecar: Sidecar) -> anyhow::Result<PathBuf> {
        self.save_building(move || sidecar)
    }

    /// As [`SaveRequest::save_with`], the sidecar built by `build` while the
    /// corrected trial is formatted and written (the same files as building
    /// it first).
    pub fn save_building(&self, build: impl FnOnce() -> Sidecar + Send) -> anyhow::Result<PathBuf> {
        if let Some(dir) = self.output.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .map_err(|e| anyhow::anyhow!("{}: cannot create folder: {e}", dir.display()))?;
        }
        let _lock = OutputLock::acquire(self.output)
            .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", self.output.display()))?;
        let (written, mut sidecar) = rayon::join(
            || {
                write_trial_hashed(
                    &self.correction.corrected,
                    self.output,
                    self.output_format,
                    self.correction.settings.precision,
                )
            },
            build,
        );
        sidecar.output_sha256 = Some(written?);
        if let Some(run) = &self.correction.ik {
            write_coordinates(run, &coordinates_path(self.output))?;
        }
        let path = self
            .sidecar
            .map(Path::to_path_buf)
            .unwrap_or_else(|| sidecar_path(self.output));
        atomic_write(&path, sidecar.to_json().as_bytes())
            .map_err(|e| anyhow::anyhow!("{}: cannot write: {e}", path.display()))?;
        Ok(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_output_names() {
        let p = default_output(
            Path::new("d/walk.CSV.gz"),
            Variant::Drift,
            TrialFormat::QuatCsv,
            true,
        );
        assert_eq!(p, Path::new("d/corrected/walk.drift.csv.gz"));
        let p = default_output(Path::new("w.sto"), Variant::Basic, TrialFormat::Sto, false);
        assert_eq!(p, Path::new("corrected/w.basic.sto"));
        assert_eq!(
            sidecar_path(Path::new("a/b.csv")),
            Path::new("a/b.csv.acmw.json")
        );
    }
}
