//! The sidecar JSON written beside every corrected trial: what was done, with
//! which settings and table, the per-window corrections and the figures, enough
//! to reproduce the output exactly.

use crate::acm::{Correction, JointResult, SkippedJoint, Variant};
use crate::limits::{LimitTable, Settings};
use crate::metrics::JointFigures;
use crate::model::Model;
use crate::trial::TrialFormat;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
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
    pub output_format: TrialFormat,
    pub variant: Variant,
    pub settings: Settings,
    pub model: Model,
    pub limits: TableRecord,
    pub joints: Vec<JointResult>,
    pub skipped: Vec<SkippedJoint>,
    pub figures: FiguresRecord,
    pub warnings: Vec<String>,
}

/// Hex SHA-256 of bytes.
pub fn sha256_hex(bytes: &[u8]) -> String {
    Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

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
            output_format,
            variant: correction.variant,
            settings: correction.settings,
            model: model.clone(),
            limits: TableRecord {
                source: limits_source.into(),
                sha256: limits.hash(),
                csv: limits.to_csv(),
            },
            joints: correction.joints.clone(),
            skipped: correction.skipped.clone(),
            figures,
            warnings: Vec::new(),
        }
    }

    /// The limit table recorded in the sidecar, checked against its hash.
    pub fn table(&self) -> anyhow::Result<LimitTable> {
        let t = LimitTable::parse(&self.limits.csv, "sidecar limits")?;
        anyhow::ensure!(
            t.hash() == self.limits.sha256,
            "the sidecar's limit table does not match its recorded hash"
        );
        Ok(t)
    }

    /// Pretty JSON text.
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).expect("sidecar serialises")
    }

    /// Reads a sidecar file.
    pub fn load(path: &Path) -> anyhow::Result<Sidecar> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| anyhow::anyhow!("{}: cannot read: {e}", path.display()))?;
        serde_json::from_str(&text).map_err(|e| {
            anyhow::anyhow!(
                "{}:{}:{}: not a sidecar: {e}",
                path.display(),
                e.line(),
                e.column()
            )
        })
    }

    /// The variant's name (for display).
    pub fn variant_name(&self) -> &'static str {
        Variant::name(self.variant)
    }
}
