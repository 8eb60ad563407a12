//! Correcting an archive of trials unattended: finding the trials in folders
//! and patterns, splitting the list into shards for a cluster, running the
//! one pipeline ([`crate::correct::pipeline`]) over them on a pool of
//! workers, and recording every trial's outcome in a manifest
//! ([`manifest::Manifest`]) that a re-run resumes from.
//!
//! A trial that fails (unreadable, malformed, too short for the windows, a
//! save refused) is recorded as failed and the batch goes on. Outputs do
//! not depend on the number of workers, nor on how the list is sharded.
//! Nothing here prints: progress comes back through [`Event`]s.

pub mod journal;
pub mod manifest;

use crate::acm::RunControl;
use crate::correct::pipeline::{self, Preparation, Setup};
use crate::input::sha256_hex;
use crate::limits::{LimitTable, Settings};
use crate::model::Model;
use crate::sidecar::sidecar_path;
use crate::trial::{detect_format, is_trial_path, TrialFormat};
use crate::variant::Variant;
use journal::Journal;
use manifest::{Manifest, Row, Status};
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::Instant;

/// The manifest being built by a run: its header, its rows by trial and
/// variant (kept in manifest order), and when it is next rewritten whole.
struct Record {
    header: Manifest,
    rows: std::collections::BTreeMap<(String, Variant), Row>,
    pace: journal::SavePace,
}

impl Record {
    /// Replaces the rows of `trial` by `rows`, rewriting the manifest when
    /// its pace says so.
    fn insert(
        &mut self,
        trial: &Path,
        rows: &[Row],
        out_dir: &Path,
    ) -> Result<(), crate::save::WriteError> {
        let name = trial.display().to_string();
        for &v in &self.header.variants {
            self.rows.remove(&(name.clone(), v));
        }
        for r in rows {
            self.rows.insert((r.trial.clone(), r.variant), r.clone());
        }
        if self.pace.due() {
            self.save(out_dir)?;
        }
        Ok(())
    }

    /// The manifest as it stands.
    fn manifest(&self) -> Manifest {
        Manifest {
            rows: self.rows.values().cloned().collect(),
            ..self.header.clone()
        }
    }

    /// Writes the manifest (JSON and CSV) atomically.
    fn save(&mut self, out_dir: &Path) -> Result<(), crate::save::WriteError> {
        let started = Instant::now();
        self.manifest().save(out_dir)?;
        self.pace.saved(started);
        Ok(())
    }
}

/// One of `count` parts of a trial list (`index` from 1 to `count`).
///
/// A trial belongs to the shard picked by the SHA-256 of its file name, so
/// every machine that lists the same folder agrees on the split, and a trial
/// keeps its shard when others are added to the folder.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl Shard {
    /// Whether the trial at `path` belongs to this shard.
    pub fn holds(&self, path: &Path) -> bool {
        shard_of(path, self.count) == self.index
    }
}

/// The shard (1 to `count`) of the trial at `path`.
pub fn shard_of(path: &Path, count: usize) -> usize {
    let name = path.file_name().unwrap_or(path.as_os_str());
    let digest = <sha2::Sha256 as sha2::Digest>::digest(name.as_encoded_bytes());
    let mut head = [0u8; 8];
    head.copy_from_slice(&digest[..8]);
    (u64::from_be_bytes(head) % count.max(1) as u64) as usize + 1
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Shard, String> {
        let bad = || format!("expected K/N with 1 <= K <= N (shard K of N), found '{s}'");
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let index: usize = k.trim().parse().map_err(|_| bad())?;
        let count: usize = n.trim().parse().map_err(|_| bad())?;
        if index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl Serialize for Shard {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.to_string())
    }
}

impl<'de> Deserialize<'de> for Shard {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Shard, D::Error> {
        String::deserialize(d)?
            .parse()
            .map_err(serde::de::Error::custom)
    }
}

/// Why a batch cannot start or had to stop.
#[derive(Debug, thiserror::Error)]
pub enum BatchError {
    /// An input names no file or folder and matches nothing as a pattern.
    #[error("{0}: no such file or folder, and no trial matches it as a pattern")]
    NotFound(String),
    /// An input is not a valid glob pattern.
    #[error("{pattern}: bad pattern: {message}")]
    Pattern { pattern: String, message: String },
    #[error("{path}: cannot list: {message}")]
    List { path: String, message: String },
    /// Two trials would write the same output.
    #[error("{first} and {second} would both be written to {output}: rename one or correct them in separate runs")]
    Collision {
        first: String,
        second: String,
        output: String,
    },
    /// The worker pool could not be made.
    #[error("cannot start {jobs} workers: {message}")]
    Pool { jobs: usize, message: String },
    #[error(transparent)]
    Manifest(#[from] manifest::ManifestError),
    #[error("{0}")]
    Lock(String),
}

/// The trials named by `inputs`, sorted by path, each once: a file as it is,
/// a folder's trials (not recursive: trial files, OpenSense mappings, folders
/// of Xsens exports that no listed mapping reads), and the trials matching a
/// glob pattern (`archive/*/walk*.csv.gz`, for shells that do not expand it
/// or lists too long for a command line).
pub fn discover(inputs: &[String]) -> Result<Vec<PathBuf>, BatchError> {
    let mut found = Vec::new();
    for input in inputs {
        let path = Path::new(input);
        if path.is_dir() && !is_trial_path(path) {
            found.extend(folder_trials(path)?);
        } else if path.exists() {
            found.push(path.to_path_buf());
        } else {
            let matches = glob::glob(input).map_err(|e| BatchError::Pattern {
                pattern: input.clone(),
                message: e.to_string(),
            })?;
            let before = found.len();
            found.extend(matches.filter_map(Result::ok).filter(|p| is_trial_path(p)));
            if found.len() == before {
                return Err(BatchError::NotFound(input.clone()));
            }
        }
    }
    found.sort();
    found.dedup();
    Ok(found)
}

/// The trials in folder `dir` (not recursive), as the workbench lists them.
fn folder_trials(dir: &Path) -> Result<Vec<PathBuf>, BatchError> {
    crate::trial::folder_trials(dir).map_err(|e| BatchError::List {
        path: dir.display().to_string(),
        message: e.to_string(),
    })
}

/// What a batch does to every trial, and where it writes.
#[derive(Clone, Copy)]
pub struct Batch<'a> {
    /// The body model of every trial; `None` detects it per trial from its
    /// IMU names.
    pub model: Option<&'a Model>,
    pub limits: &'a LimitTable,
    /// Where the table came from (a path or `<built-in NAME>`).
    pub limits_source: &'a str,
    pub settings: &'a Settings,
    pub preparation: &'a Preparation,
    /// Each trial is corrected with each of these; one output per variant.
    pub variants: &'a [Variant],
    /// Output format [`None`: the input format's default].
    pub format: Option<TrialFormat>,
    /// Outputs (`<stem>.<variant>.<ext>`, their sidecars) and the manifest go here.
    pub out_dir: &'a Path,
    /// Trials corrected at once (each on one worker; a worker's correction
    /// runs on the same pool).
    pub jobs: usize,
    /// Only this shard of the list.
    pub shard: Option<Shard>,
}

/// What a running batch reports.
pub enum Event<'r> {
    /// The batch starts with `trials` trials (of its shard).
    Started { trials: usize },
    /// A trial is finished: its rows, and whether an earlier run had already
    /// done all of them (then nothing was redone).
    Finished { rows: &'r [Row], resumed: bool },
}

impl Batch<'_> {
    /// The output of `trial` with `variant`: `<out_dir>/<stem>.<variant>.<ext>`
    /// (reads the trial's header for its format).
    pub fn output_path(&self, trial: &Path, variant: Variant) -> PathBuf {
        let (format, gzip) = match detect_format(trial) {
            Ok((f, g)) => (f, g),
            // A trial that cannot be read fails before its output is named.
            Err(_) => (TrialFormat::QuatCsv, false),
        };
        self.output_of(trial, format, gzip, variant)
    }

    /// [`Batch::output_path`] of a trial read as `format`, gzip-compressed or not.
    fn output_of(
        &self,
        trial: &Path,
        format: TrialFormat,
        gzip: bool,
        variant: Variant,
    ) -> PathBuf {
        let format = self.format.unwrap_or(format.output_default());
        let name = crate::sidecar::default_output(trial, variant, format, gzip);
        self.out_dir.join(name.file_name().unwrap_or_default())
    }

    /// SHA-256 of what, besides the input, the table and the program,
    /// decides a trial's outputs: the settings, the model, the output format
    /// and the functional and pose calibrations.
    pub fn settings_sha256(&self, model: &Model) -> String {
        let record = serde_json::json!({
            "settings": self.settings,
            "model": model,
            "format": self.format,
            "calibration": self.preparation.calibration.as_ref().map(|c| &c.sha256),
            "pose": self.preparation.pose,
        });
        sha256_hex(record.to_string().as_bytes())
    }

    /// The trials of `trials` that this batch's shard holds.
    pub fn select(&self, trials: &[PathBuf]) -> Vec<PathBuf> {
        trials
            .iter()
            .filter(|p| self.shard.is_none_or(|s| s.holds(p)))
            .cloned()
            .collect()
    }

    /// Checks that no two trials would write the same output. Outputs are
    /// named by the trial's stem, so only trials that share a stem can
    /// collide, and only their headers are read (for the extension).
    pub fn check_outputs(&self, trials: &[PathBuf]) -> Result<(), BatchError> {
        use crate::file_names::{stem_without, TRIAL_SUFFIXES};
        let mut stems: HashMap<String, usize> = HashMap::new();
        for t in trials {
            *stems.entry(stem_without(t, &TRIAL_SUFFIXES)).or_default() += 1;
        }
        let shared = trials
            .iter()
            .filter(|t| stems[&stem_without(t, &TRIAL_SUFFIXES)] > 1);
        let mut seen: HashMap<PathBuf, &Path> = HashMap::new();
        for t in shared {
            let out = self.output_path(t, Variant::None);
            if let Some(first) = seen.insert(out.clone(), t) {
                return Err(BatchError::Collision {
                    first: first.display().to_string(),
                    second: t.display().to_string(),
                    output: out.display().to_string(),
                });
            }
        }
        Ok(())
    }

    /// Corrects every trial of `trials` in this batch's shard that the
    /// manifest in `out_dir` does not already record as done with the same
    /// input, settings, table and program version (and whose output is
    /// still there as written), writing the manifest after each trial.
    /// Returns the manifest of the run.
    pub fn run(
        &self,
        trials: &[PathBuf],
        observe: &(dyn Fn(Event) + Sync),
    ) -> Result<Manifest, BatchError> {
        let trials = self.select(trials);
        self.check_outputs(&trials)?;
        std::fs::create_dir_all(self.out_dir).map_err(|e| BatchError::List {
            path: self.out_dir.display().to_string(),
            message: format!("cannot create folder: {e}"),
        })?;
        let json = self.out_dir.join(Manifest::file_name(self.shard, "json"));
        let _lock = crate::save::OutputLock::acquire(&json)
            .map_err(|e| BatchError::Lock(format!("{}: {e}", json.display())))?;
        let journal_path = Journal::path_for(&json);
        let mut earlier: HashMap<(String, Variant), Row> = HashMap::new();
        if json.is_file() {
            for r in Manifest::load(&json)?.rows {
                earlier.insert((r.trial.clone(), r.variant), r);
            }
        }
        // The journal holds what was done after the manifest was last
        // written; its rows are the newer ones.
        let journaled = journal::read(&journal_path)?;
        let had_journal = journal_path.exists();
        for r in journaled {
            earlier.insert((r.trial.clone(), r.variant), r);
        }
        let names: std::collections::HashSet<String> =
            trials.iter().map(|t| t.display().to_string()).collect();
        let mut record = Record {
            header: Manifest {
                program: "acmw".into(),
                version: env!("CARGO_PKG_VERSION").into(),
                shard: self.shard,
                variants: self.variants.to_vec(),
                settings: *self.settings,
                limits_source: self.limits_source.to_string(),
                limits_sha256: self.limits.hash(),
                rows: Vec::new(),
            },
            // Until a trial is looked at again, its earlier rows stand (a run
            // killed early loses nothing an earlier run recorded).
            rows: (earlier.values())
                .filter(|r| names.contains(&r.trial))
                .filter(|r| self.variants.contains(&r.variant))
                .map(|r| ((r.trial.clone(), r.variant), r.clone()))
                .collect(),
            pace: journal::SavePace::new(),
        };
        let manifest_error = |e: crate::save::WriteError| BatchError::Manifest(e.into());
        let journal_error = |e: std::io::Error| {
            BatchError::Manifest(crate::save::WriteError::io(&journal_path, &e).into())
        };
        if had_journal {
            // Fold the journal into the manifest, then start a fresh one (no
            // line is ever appended after one a kill cut short).
            record.save(self.out_dir).map_err(manifest_error)?;
        }
        let _ = std::fs::remove_file(&journal_path);
        let journal = Journal::open(&journal_path).map_err(journal_error)?;
        let shared = Mutex::new((record, journal));
        observe(Event::Started {
            trials: trials.len(),
        });
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.jobs.max(1))
            .build()
            .map_err(|e| BatchError::Pool {
                jobs: self.jobs,
                message: e.to_string(),
            })?;
        let write_error: Mutex<Option<BatchError>> = Mutex::new(None);
        pool.install(|| {
            use rayon::prelude::*;
            trials.par_iter().with_max_len(1).for_each(|trial| {
                if write_error.lock().expect("not poisoned").is_some() {
                    return;
                }
                let (rows, resumed) = self.trial(trial, &earlier);
                let mut guard = shared.lock().expect("not poisoned");
                let (record, journal) = &mut *guard;
                let written = journal.append(&rows).map_err(journal_error).and_then(|()| {
                    record
                        .insert(trial, &rows, self.out_dir)
                        .map_err(manifest_error)
                });
                if let Err(e) = written {
                    *write_error.lock().expect("not poisoned") = Some(e);
                    return;
                }
                drop(guard);
                observe(Event::Finished {
                    rows: &rows,
                    resumed,
                });
            });
        });
        if let Some(e) = write_error.into_inner().expect("not poisoned") {
            return Err(e);
        }
        let (mut record, journal) = shared.into_inner().expect("not poisoned");
        record.save(self.out_dir).map_err(manifest_error)?;
        journal.remove().map_err(journal_error)?;
        Ok(record.manifest())
    }

    /// One trial: its rows, and whether all were taken from `earlier`.
    fn trial(&self, path: &Path, earlier: &HashMap<(String, Variant), Row>) -> (Vec<Row>, bool) {
        let start = Instant::now();
        let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            self.trial_inner(path, earlier, start)
        }));
        match result {
            Ok(r) => r,
            Err(panic) => {
                let what = panic
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| panic.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_else(|| "unknown".into());
                let rows = self
                    .variants
                    .iter()
                    .map(|&v| {
                        let mut r = Row::failed(
                            path,
                            v,
                            format!("{}: internal error (panic: {what})", path.display()),
                        );
                        r.wall_s = start.elapsed().as_secs_f64();
                        r
                    })
                    .collect();
                (rows, false)
            }
        }
    }

    fn trial_inner(
        &self,
        path: &Path,
        earlier: &HashMap<(String, Variant), Row>,
        start: Instant,
    ) -> (Vec<Row>, bool) {
        let fail_all = |e: String| {
            let rows = self
                .variants
                .iter()
                .map(|&v| {
                    let mut r = Row::failed(path, v, e.clone());
                    r.wall_s = start.elapsed().as_secs_f64();
                    r
                })
                .collect();
            (rows, false)
        };
        // The one read of the input: its hash, its model and its trial.
        let file = match pipeline::read(path) {
            Ok(f) => f,
            Err(e) => return fail_all(e.to_string()),
        };
        let model = match self.model {
            Some(m) => m.clone(),
            None => file.detect_model(),
        };
        let (format, gzip) = (file.format, file.gzip);
        let output = |v: Variant| self.output_of(path, format, gzip, v);
        let base = Row {
            input_sha256: file.sha256.clone(),
            settings_sha256: self.settings_sha256(&model),
            table_sha256: self.limits.hash(),
            status: Status::Ok,
            error: None,
            ..Row::failed(path, Variant::None, String::new())
        };
        let done = self.earlier_rows(&base, earlier, &output);
        if done.iter().all(Option::is_some) {
            return (done.into_iter().flatten().collect(), true);
        }
        let setup = Setup {
            model: &model,
            limits: self.limits,
            limits_source: self.limits_source,
            settings: self.settings,
        };
        let prepared = (|| -> anyhow::Result<_> {
            self.limits.check_covers(&model, self.limits_source)?;
            let loaded = pipeline::load_file(&file, &model)?;
            let prepared = pipeline::prepare(loaded.trial, setup, self.preparation)
                .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
            Ok((loaded.source, prepared))
        })();
        // The text read is parsed: only the trial is kept from here on.
        drop(file);
        let (source, prepared) = match prepared {
            Ok(p) => p,
            Err(e) => return fail_all(format!("{e:#}")),
        };
        let shared_s = start.elapsed().as_secs_f64();
        let mut warnings = prepared.trial.warnings.clone();
        warnings.extend(prepared.calibration_warnings.iter().cloned());
        let mut rows = Vec::with_capacity(self.variants.len());
        for (&variant, done) in self.variants.iter().zip(done) {
            if let Some(r) = done {
                rows.push(r);
                continue;
            }
            let t0 = Instant::now();
            let mut row = Row {
                variant,
                warnings: warnings.clone(),
                ..base.clone()
            };
            let output = output(variant);
            row.output = output.display().to_string();
            row.sidecar = sidecar_path(&output).display().to_string();
            let result = self.correct_one(&source, &prepared, setup, output, &mut row);
            if let Err(e) = result {
                row.status = Status::Failed;
                row.error = Some(format!("{e:#}"));
            }
            row.wall_s = shared_s + t0.elapsed().as_secs_f64();
            rows.push(row);
        }
        (rows, false)
    }

    /// Per variant, the row an earlier run finished with the same input
    /// (`base`'s hashes), settings, table and program version, whose output
    /// (named by `output`) and sidecar are still there as written.
    fn earlier_rows(
        &self,
        base: &Row,
        earlier: &HashMap<(String, Variant), Row>,
        output: &dyn Fn(Variant) -> PathBuf,
    ) -> Vec<Option<Row>> {
        (self.variants.iter())
            .map(|&v| {
                let r = earlier.get(&(base.trial.clone(), v))?;
                let same = r.status == Status::Ok
                    && r.input_sha256 == base.input_sha256
                    && r.settings_sha256 == base.settings_sha256
                    && r.table_sha256 == base.table_sha256
                    && r.version == base.version
                    && r.output == output(v).display().to_string()
                    && Path::new(&r.sidecar).is_file()
                    && std::fs::read(&r.output).is_ok_and(|b| sha256_hex(&b) == r.output_sha256);
                same.then(|| r.clone())
            })
            .collect()
    }

    /// Corrects the prepared trial with `row.variant`, saves it to `output`
    /// (with its sidecar) and fills the row's figures, warnings and output hash.
    fn correct_one(
        &self,
        source: &pipeline::Source,
        prepared: &pipeline::Prepared,
        setup: Setup,
        output: PathBuf,
        row: &mut Row,
    ) -> anyhow::Result<()> {
        let variant = row.variant;
        let c = pipeline::correct(&prepared.trial, setup, variant, &RunControl::default())?;
        let report = pipeline::report(prepared, setup, None, [&c]);
        row.set_figures(&report.uncorrected, &report.variants[0].joints);
        row.set_auto(&c.joints);
        row.warnings.extend(
            c.skipped
                .iter()
                .map(|s| format!("skipped {}: {}", s.joint, s.reason)),
        );
        let mut out = source.default_output(variant, self.format);
        out.path = output;
        pipeline::save(source, prepared, &c, setup, &out)?;
        let written = std::fs::read(&out.path)
            .map_err(|e| anyhow::anyhow!("{}: cannot read back: {e}", out.path.display()))?;
        row.output_sha256 = sha256_hex(&written);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_split_a_list_into_disjoint_parts() {
        assert_eq!("2/4".parse(), Ok(Shard { index: 2, count: 4 }));
        for bad in ["0/4", "5/4", "2", "a/4", "1/0"] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
        let names: Vec<PathBuf> = (0..200)
            .map(|k| PathBuf::from(format!("archive/t{k:04}.csv.gz")))
            .collect();
        let mut seen = vec![0usize; names.len()];
        for index in 1..=4 {
            for (k, n) in names.iter().enumerate() {
                if (Shard { index, count: 4 }).holds(n) {
                    seen[k] += 1;
                }
            }
        }
        assert!(seen.iter().all(|&c| c == 1), "every trial in one shard");
        // Balanced within binomial spread, and independent of the folder.
        for index in 1..=4 {
            let n = names
                .iter()
                .filter(|p| (Shard { index, count: 4 }).holds(p))
                .count();
            assert!((30..=70).contains(&n), "shard {index}: {n}");
        }
        assert_eq!(
            shard_of(Path::new("a/t0001.csv.gz"), 4),
            shard_of(Path::new("/mnt/b/t0001.csv.gz"), 4)
        );
    }

    #[test]
    fn a_batch_reads_each_input_once_and_records_the_hash_of_what_it_read() {
        use crate::simulate::{simulate, SimConfig};
        let dir = tempfile::tempdir().unwrap();
        let mut cfg = SimConfig::full_body(7);
        cfg.duration_s = 70.0;
        let sim = simulate(&cfg).unwrap();
        let trial = dir.path().join("walk.csv.gz");
        crate::trial::write_trial(&sim.trial, &trial, TrialFormat::QuatCsv).unwrap();
        let (limits, settings) = (LimitTable::default_table(), Settings::default());
        let prep = Preparation::default();
        let variants = [Variant::None, Variant::Basic, Variant::Drift];
        let batch = Batch {
            model: None,
            limits: &limits,
            limits_source: "<built-in>",
            settings: &settings,
            preparation: &prep,
            variants: &variants,
            format: None,
            out_dir: &dir.path().join("out"),
            jobs: 1,
            shard: None,
        };
        let before = crate::input::times_opened(&trial);
        let manifest = batch.run(std::slice::from_ref(&trial), &|_| {}).unwrap();
        // Unique stems: listing, model detection, hashing, parsing and the
        // three saves all use the one read.
        assert_eq!(crate::input::times_opened(&trial) - before, 1);
        let sha256 = sha256_hex(&std::fs::read(&trial).unwrap());
        assert_eq!(manifest.rows.len(), 3);
        for row in &manifest.rows {
            assert_eq!(row.status, Status::Ok, "{:?}", row.error);
            assert_eq!(row.input_sha256, sha256);
            let sidecar = crate::sidecar::Sidecar::load(Path::new(&row.sidecar)).unwrap();
            assert_eq!(sidecar.input.sha256, sha256, "{}", row.sidecar);
        }
        // A second run resumes: it reads the input once more, for its hash.
        batch.run(std::slice::from_ref(&trial), &|_| {}).unwrap();
        assert_eq!(crate::input::times_opened(&trial) - before, 2);
    }

    #[test]
    fn trials_are_found_in_folders_files_and_patterns_and_outputs_never_collide() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::create_dir_all(d.join("a/sub")).unwrap();
        for f in [
            "a/t1.csv",
            "a/t2.csv.gz",
            "a/sub/t3.sto",
            "a/t1.truth.csv.gz",
            "a/notes.md",
        ] {
            std::fs::write(d.join(f), "time,x\n").unwrap();
        }
        let s = |p: &str| d.join(p).display().to_string();
        let found = discover(&[s("a")]).unwrap();
        assert_eq!(found, [d.join("a/t1.csv"), d.join("a/t2.csv.gz")]);
        let found = discover(&[s("a/*/*.sto"), s("a/t1.csv"), s("a")]).unwrap();
        assert_eq!(found.len(), 3, "{found:?}");
        let e = discover(&[s("nothing/*.csv")]).unwrap_err().to_string();
        assert!(e.contains("no trial matches"), "{e}");
        let e = discover(&[s("a/[")]).unwrap_err().to_string();
        assert!(e.contains("bad pattern"), "{e}");
        // Two trials of one stem in different folders would share an output.
        std::fs::write(d.join("a/sub/t1.csv"), "time,x\n").unwrap();
        let (model, limits, settings) = (
            Model::infant13(),
            LimitTable::default_table(),
            Settings::default(),
        );
        let prep = Preparation::default();
        let batch = Batch {
            model: Some(&model),
            limits: &limits,
            limits_source: "<built-in>",
            settings: &settings,
            preparation: &prep,
            variants: &[Variant::Drift],
            format: None,
            out_dir: &d.join("out"),
            jobs: 1,
            shard: None,
        };
        let trials = discover(&[s("a"), s("a/sub")]).unwrap();
        let e = batch.check_outputs(&trials).unwrap_err().to_string();
        assert!(e.contains("would both be written to"), "{e}");
    }
}
