//! The manifest of a batch run: one row per trial and variant, written as JSON
//! (read back to resume and to merge shards) and as CSV (for spreadsheets),
//! each atomically after every finished trial.

use super::Shard;
use crate::limits::Settings;
use crate::metrics::JointFigures;
use crate::save::{atomic_write, WriteError};
use crate::variant::Variant;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// How a trial and variant ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Corrected and saved (in this run, or in an earlier one it resumed).
    Ok,
    /// Could not be read, prepared, corrected or saved; `error` says why.
    Failed,
}

impl Status {
    /// The name in the CSV and JSON.
    pub fn name(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Failed => "failed",
        }
    }
}

/// The figures of docs/method.md section 16 of one joint, before and after.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JointRow {
    pub joint: String,
    /// Joint mean excursion beyond the limits, uncorrected, degrees.
    pub excursion_before_deg: f64,
    /// Joint mean excursion beyond the limits, corrected, degrees.
    pub excursion_after_deg: f64,
    /// Samples outside the limits on any axis, uncorrected, percent.
    pub outside_before_pct: f64,
    /// Samples outside the limits on any axis, corrected, percent.
    pub outside_after_pct: f64,
    /// Mean rotation angle of the distal IMU's applied correction, degrees.
    pub correction_deg: f64,
    /// How `auto` chose this joint's correction (the `auto` variant only).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub auto: Option<AutoRow>,
}

/// `auto`'s choice for one joint, as the manifest records it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AutoRow {
    pub chosen: Variant,
    pub runner_up: Option<Variant>,
    /// The figures that decided, in one line.
    pub reason: String,
    pub flags: Vec<String>,
}

impl AutoRow {
    /// `joint=chosen(runner-up)`, with `!` when flagged: the CSV's cell part.
    fn cell(&self, joint: &str) -> String {
        format!(
            "{joint}={}({}){}",
            self.chosen,
            self.runner_up.map_or("-".to_string(), |v| v.to_string()),
            if self.flags.is_empty() { "" } else { "!" }
        )
    }
}

/// One trial corrected with one variant.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Row {
    /// The trial's path as found (a folder's entry or a pattern's match).
    pub trial: String,
    pub variant: Variant,
    pub status: Status,
    /// SHA-256 of the input's bytes (empty when it could not be read).
    pub input_sha256: String,
    /// SHA-256 of what else decides the output: settings, model, output
    /// format and the preparation (see [`super::Batch::settings_sha256`]).
    pub settings_sha256: String,
    /// SHA-256 of the limit table's rows.
    pub table_sha256: String,
    /// The program version that made the output.
    pub version: String,
    /// The corrected trial's path.
    pub output: String,
    /// SHA-256 of the corrected trial as written.
    pub output_sha256: String,
    /// The sidecar's path.
    pub sidecar: String,
    /// Mean over joints of the joint mean excursion, uncorrected, degrees.
    pub excursion_before_deg: Option<f64>,
    /// Mean over joints of the joint mean excursion, corrected, degrees.
    pub excursion_after_deg: Option<f64>,
    /// Mean over joints of the samples outside on any axis, uncorrected, percent.
    pub outside_before_pct: Option<f64>,
    /// Mean over joints of the samples outside on any axis, corrected, percent.
    pub outside_after_pct: Option<f64>,
    /// The joint with the largest mean excursion after correction.
    pub worst_joint: Option<String>,
    /// That joint's mean excursion after correction, degrees.
    pub worst_after_deg: Option<f64>,
    /// Mean over joints of the mean correction angle, degrees.
    pub correction_deg: Option<f64>,
    /// Per joint figures (JSON only).
    pub joints: Vec<JointRow>,
    /// Warnings about the trial (conventions, calibration, skipped joints).
    pub warnings: Vec<String>,
    /// Why the trial failed.
    pub error: Option<String>,
    /// Seconds spent on this trial and variant (reading and preparing the
    /// trial counted in each of its variants' rows).
    pub wall_s: f64,
}

impl Row {
    /// A row for a trial that failed before or while correcting.
    pub fn failed(trial: &Path, variant: Variant, error: String) -> Row {
        Row {
            trial: trial.display().to_string(),
            variant,
            status: Status::Failed,
            input_sha256: String::new(),
            settings_sha256: String::new(),
            table_sha256: String::new(),
            version: env!("CARGO_PKG_VERSION").to_string(),
            output: String::new(),
            output_sha256: String::new(),
            sidecar: String::new(),
            excursion_before_deg: None,
            excursion_after_deg: None,
            outside_before_pct: None,
            outside_after_pct: None,
            worst_joint: None,
            worst_after_deg: None,
            correction_deg: None,
            joints: Vec::new(),
            warnings: Vec::new(),
            error: Some(error),
            wall_s: 0.0,
        }
    }

    /// Fills the figures from the uncorrected and corrected joints' figures.
    pub fn set_figures(&mut self, before: &[JointFigures], after: &[JointFigures]) {
        let joints: Vec<JointRow> = after
            .iter()
            .filter_map(|a| {
                let b = before.iter().find(|b| b.joint == a.joint)?;
                Some(JointRow {
                    joint: a.joint.clone(),
                    excursion_before_deg: b.excursion.joint_mean_excursion_deg,
                    excursion_after_deg: a.excursion.joint_mean_excursion_deg,
                    outside_before_pct: b.excursion.pct_outside_any,
                    outside_after_pct: a.excursion.pct_outside_any,
                    correction_deg: a.shift.map_or(0.0, |s| s.mean_correction_angle_deg),
                    auto: None,
                })
            })
            .collect();
        let mean = |f: fn(&JointRow) -> f64| {
            (!joints.is_empty()).then(|| joints.iter().map(f).sum::<f64>() / joints.len() as f64)
        };
        self.excursion_before_deg = mean(|j| j.excursion_before_deg);
        self.excursion_after_deg = mean(|j| j.excursion_after_deg);
        self.outside_before_pct = mean(|j| j.outside_before_pct);
        self.outside_after_pct = mean(|j| j.outside_after_pct);
        self.correction_deg = mean(|j| j.correction_deg);
        let worst = joints
            .iter()
            .max_by(|a, b| a.excursion_after_deg.total_cmp(&b.excursion_after_deg));
        self.worst_joint = worst.map(|j| j.joint.clone());
        self.worst_after_deg = worst.map(|j| j.excursion_after_deg);
        self.joints = joints;
    }

    /// Records `auto`'s choice per joint from its correction's joint results.
    pub fn set_auto(&mut self, joints: &[crate::acm::JointResult]) {
        for row in &mut self.joints {
            row.auto = joints
                .iter()
                .find(|j| j.joint == row.joint)
                .and_then(|j| j.auto.as_ref())
                .map(|a| AutoRow {
                    chosen: a.chosen,
                    runner_up: a.runner_up,
                    reason: a.reason.clone(),
                    flags: a.flags.clone(),
                });
        }
    }

    /// The order of rows in a manifest: by trial, then variant.
    fn key(&self) -> (&str, Variant) {
        (&self.trial, self.variant)
    }
}

/// The manifest of one run (or of one shard of it, or of merged shards).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Manifest {
    pub program: String,
    pub version: String,
    /// The shard this manifest covers; `None` for the whole list.
    pub shard: Option<Shard>,
    pub variants: Vec<Variant>,
    pub settings: Settings,
    /// Where the limit table came from (a path or `<built-in NAME>`).
    pub limits_source: String,
    pub limits_sha256: String,
    /// Sorted by trial, then variant.
    pub rows: Vec<Row>,
}

/// A manifest that cannot be read or merged.
#[derive(Debug, thiserror::Error)]
pub enum ManifestError {
    #[error("{path}: cannot read: {message}")]
    Read { path: String, message: String },
    #[error("{path}:{line}:{column}: not a batch manifest: {message}")]
    Parse {
        path: String,
        line: usize,
        column: usize,
        message: String,
    },
    #[error("{0}")]
    Merge(String),
    #[error(transparent)]
    Write(#[from] WriteError),
}

impl Manifest {
    /// The file name of the manifest of `shard` (`manifest.json` for the
    /// whole list, `manifest.shard-K-of-N.json` for a shard); the CSV has
    /// the same stem.
    pub fn file_name(shard: Option<Shard>, ext: &str) -> String {
        match shard {
            None => format!("manifest.{ext}"),
            Some(s) => format!("manifest.shard-{}-of-{}.{ext}", s.index, s.count),
        }
    }

    /// Sorts the rows into manifest order.
    pub fn sort(&mut self) {
        self.rows.sort_by(|a, b| a.key().cmp(&b.key()));
    }

    /// Reads a manifest JSON.
    pub fn load(path: &Path) -> Result<Manifest, ManifestError> {
        let text = crate::input::read_text(path).map_err(|e| ManifestError::Read {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        serde_json::from_str(&text).map_err(|e| ManifestError::Parse {
            path: path.display().to_string(),
            line: e.line(),
            column: e.column(),
            message: e.to_string(),
        })
    }

    /// Writes `<dir>/<name>.json` then `<dir>/<name>.csv`, each atomically.
    pub fn save(&self, dir: &Path) -> Result<(PathBuf, PathBuf), WriteError> {
        let json = dir.join(Manifest::file_name(self.shard, "json"));
        let csv = dir.join(Manifest::file_name(self.shard, "csv"));
        let text = serde_json::to_string_pretty(self).expect("a manifest serialises");
        atomic_write(&json, text.as_bytes()).map_err(|e| WriteError::io(&json, &e))?;
        atomic_write(&csv, self.to_csv().as_bytes()).map_err(|e| WriteError::io(&csv, &e))?;
        Ok((json, csv))
    }

    /// The rows as CSV: one line per trial and variant, the figures as means
    /// over joints (the JSON has them per joint).
    pub fn to_csv(&self) -> String {
        let mut w = csv::Writer::from_writer(Vec::new());
        let header = [
            "trial",
            "variant",
            "status",
            "input_sha256",
            "settings_sha256",
            "table_sha256",
            "version",
            "output",
            "output_sha256",
            "sidecar",
            "excursion_before_deg",
            "excursion_after_deg",
            "outside_before_pct",
            "outside_after_pct",
            "worst_joint",
            "worst_after_deg",
            "correction_deg",
            "auto_choice",
            "warnings",
            "error",
            "wall_s",
        ];
        w.write_record(header).expect("writing to memory");
        let num = |v: Option<f64>| v.map(|v| format!("{v:.4}")).unwrap_or_default();
        for r in &self.rows {
            w.write_record([
                r.trial.clone(),
                r.variant.to_string(),
                r.status.name().to_string(),
                r.input_sha256.clone(),
                r.settings_sha256.clone(),
                r.table_sha256.clone(),
                r.version.clone(),
                r.output.clone(),
                r.output_sha256.clone(),
                r.sidecar.clone(),
                num(r.excursion_before_deg),
                num(r.excursion_after_deg),
                num(r.outside_before_pct),
                num(r.outside_after_pct),
                r.worst_joint.clone().unwrap_or_default(),
                num(r.worst_after_deg),
                num(r.correction_deg),
                r.joints
                    .iter()
                    .filter_map(|j| j.auto.as_ref().map(|a| a.cell(&j.joint)))
                    .collect::<Vec<_>>()
                    .join(" "),
                r.warnings.join("; "),
                r.error.clone().unwrap_or_default(),
                format!("{:.3}", r.wall_s),
            ])
            .expect("writing to memory");
        }
        String::from_utf8(w.into_inner().expect("writing to memory")).expect("UTF-8 fields")
    }

    /// Joins the manifests of the shards of one run, checking that they
    /// are `count` shards of one list with the same settings and table, each
    /// present once, and that no trial appears twice.
    pub fn merge(parts: Vec<Manifest>) -> Result<Manifest, ManifestError> {
        let merge_err = |m: String| ManifestError::Merge(m);
        let first = parts
            .first()
            .ok_or_else(|| merge_err("no shard manifests to merge".into()))?;
        let count = first
            .shard
            .ok_or_else(|| merge_err("a manifest to merge covers no shard".into()))?
            .count;
        let mut seen = vec![false; count];
        for p in &parts {
            let s = p
                .shard
                .ok_or_else(|| merge_err("a manifest to merge covers no shard".into()))?;
            if s.count != count {
                return Err(merge_err(format!(
                    "shard {s} is not one of {count} shards like the others"
                )));
            }
            if std::mem::replace(&mut seen[s.index - 1], true) {
                return Err(merge_err(format!("shard {s} appears twice")));
            }
            if p.settings != first.settings
                || p.limits_sha256 != first.limits_sha256
                || p.variants != first.variants
                || p.version != first.version
            {
                return Err(merge_err(format!(
                    "shard {s} was run with other settings, table, variants or program version than shard {}",
                    first.shard.expect("checked")
                )));
            }
        }
        let missing: Vec<String> = (1..=count)
            .filter(|k| !seen[k - 1])
            .map(|k| format!("{k}/{count}"))
            .collect();
        if !missing.is_empty() {
            return Err(merge_err(format!(
                "shard manifests missing for {} (expected {})",
                missing.join(", "),
                Manifest::file_name(Some(Shard { index: 1, count }), "json")
                    .replace("-1-of-", "-K-of-")
            )));
        }
        let mut merged = Manifest {
            shard: None,
            rows: parts.iter().flat_map(|p| p.rows.clone()).collect(),
            ..first.clone()
        };
        merged.sort();
        if let Some(w) = merged.rows.windows(2).find(|w| w[0].key() == w[1].key()) {
            return Err(merge_err(format!(
                "{} ({}) appears in two shards",
                w[0].trial, w[0].variant
            )));
        }
        Ok(merged)
    }

    /// Reads every shard manifest in `dir` (`manifest.shard-K-of-N.json`).
    pub fn load_shards(dir: &Path) -> Result<Vec<Manifest>, ManifestError> {
        let rd = std::fs::read_dir(dir).map_err(|e| ManifestError::Read {
            path: dir.display().to_string(),
            message: e.to_string(),
        })?;
        let shard_file = |p: &Path, end: &str| {
            p.file_name()
                .map(|n| n.to_string_lossy())
                .is_some_and(|n| n.starts_with("manifest.shard-") && n.ends_with(end))
        };
        let all: Vec<PathBuf> = rd.filter_map(|e| e.ok()).map(|e| e.path()).collect();
        // A shard's journal outlives its run only when the run was killed (or
        // still runs): its manifest then lacks trials the journal holds.
        if let Some(j) = all.iter().find(|p| shard_file(p, ".journal.jsonl")) {
            return Err(ManifestError::Merge(format!(
                "{} exists: that shard was stopped before its end or is still running; \
                 run it again (it resumes) before merging",
                j.display()
            )));
        }
        let mut paths: Vec<PathBuf> = all.into_iter().filter(|p| shard_file(p, ".json")).collect();
        paths.sort();
        paths.iter().map(|p| Manifest::load(p)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::acm::auto::AutoChoice;
    use crate::acm::JointResult;

    fn joint(name: &str, auto: Option<AutoChoice>) -> JointResult {
        JointResult {
            joint: name.into(),
            proximal: "a".into(),
            distal: "b".into(),
            lambda2: 0.0,
            parent_corrected: false,
            windows: vec![],
            baseline: None,
            hinge: None,
            axis_from: None,
            auto,
        }
    }

    #[test]
    fn auto_choices_go_to_the_json_rows_and_one_csv_cell() {
        let choice = |chosen, runner_up, flags: Vec<String>| AutoChoice {
            chosen,
            runner_up,
            reason: "score 0.10 deg".into(),
            flags,
            candidates: vec![],
            overridden: None,
        };
        let mut row = Row::failed(Path::new("t.csv"), Variant::Auto, String::new());
        row.joints = ["back", "l_knee", "neck"]
            .iter()
            .map(|j| JointRow {
                joint: j.to_string(),
                excursion_before_deg: 1.0,
                excursion_after_deg: 0.5,
                outside_before_pct: 10.0,
                outside_after_pct: 5.0,
                correction_deg: 3.0,
                auto: None,
            })
            .collect();
        row.set_auto(&[
            joint(
                "back",
                Some(choice(
                    Variant::DriftHeadingCentroid,
                    Some(Variant::DriftHeading),
                    vec![],
                )),
            ),
            joint(
                "l_knee",
                Some(choice(
                    Variant::None,
                    Some(Variant::Drift),
                    vec!["uncorrected".into()],
                )),
            ),
            joint("neck", None),
        ]);
        assert_eq!(row.joints[1].auto.as_ref().unwrap().chosen, Variant::None);
        assert!(row.joints[2].auto.is_none());
        let m = Manifest {
            program: "acmw".into(),
            version: "0".into(),
            shard: None,
            variants: vec![Variant::Auto],
            settings: Settings::default(),
            limits_source: String::new(),
            limits_sha256: String::new(),
            rows: vec![row],
        };
        let csv = m.to_csv();
        let mut r = csv::Reader::from_reader(csv.as_bytes());
        let column = r
            .headers()
            .unwrap()
            .iter()
            .position(|h| h == "auto_choice")
            .unwrap();
        let rec = r.records().next().unwrap().unwrap();
        assert_eq!(
            &rec[column],
            "back=drift-heading-centroid(drift-heading) l_knee=none(drift)!"
        );
        let json = serde_json::to_string(&m).unwrap();
        let back: Manifest = serde_json::from_str(&json).unwrap();
        assert_eq!(back, m);
    }

    #[test]
    fn shards_are_not_merged_while_one_has_a_journal() {
        let dir = tempfile::tempdir().unwrap();
        let journal = dir.path().join("manifest.shard-2-of-4.journal.jsonl");
        std::fs::write(&journal, "").unwrap();
        let e = Manifest::load_shards(dir.path()).unwrap_err().to_string();
        assert!(
            e.contains("manifest.shard-2-of-4.journal.jsonl exists"),
            "{e}"
        );
        std::fs::remove_file(&journal).unwrap();
        assert!(Manifest::load_shards(dir.path()).unwrap().is_empty());
    }
}
