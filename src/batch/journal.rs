//! The batch's journal: every finished trial's manifest rows appended as one
//! JSON line (`manifest.journal.jsonl` beside `manifest.json`), synced to
//! disk before the trial counts as done.
//!
//! Appending costs the same for the first trial and the two-thousandth, so
//! recording progress stays linear in the archive's size; the whole manifest
//! is rewritten only now and then ([`SavePace`]) and at the end, when the
//! journal goes. A run killed at any instant leaves the manifest it last
//! wrote plus the journal: together they hold every trial recorded done. A
//! line cut by the kill (the last one, with no newline) is ignored; any
//! other line that does not parse is an error naming the file, line and
//! column.

use super::manifest::{ManifestError, Row};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// An open journal, appended to by the batch's workers in turn.
pub struct Journal {
    path: PathBuf,
    file: std::fs::File,
}

impl Journal {
    /// The journal beside the manifest `manifest_json` (same stem,
    /// `.journal.jsonl`).
    pub fn path_for(manifest_json: &Path) -> PathBuf {
        manifest_json.with_extension("journal.jsonl")
    }

    /// Opens (creating if needed) the journal at `path` for appending.
    pub fn open(path: &Path) -> std::io::Result<Journal> {
        let file = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(path)?;
        Ok(Journal {
            path: path.to_path_buf(),
            file,
        })
    }

    /// Appends one trial's rows as one line and syncs it to disk.
    pub fn append(&mut self, rows: &[Row]) -> std::io::Result<()> {
        let mut line = serde_json::to_vec(rows).expect("manifest rows serialise");
        line.push(b'\n');
        self.file.write_all(&line)?;
        self.file.sync_data()
    }

    /// Removes the journal (its rows are in the manifest just written).
    pub fn remove(self) -> std::io::Result<()> {
        drop(self.file);
        match std::fs::remove_file(&self.path) {
            Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(e),
            _ => Ok(()),
        }
    }
}

/// The rows recorded in the journal at `path`, in the order they were
/// appended (none when there is no journal). A last line without its
/// newline (a write cut short) is left out.
pub fn read(path: &Path) -> Result<Vec<Row>, ManifestError> {
    let bytes = match std::fs::read(path) {
        Ok(b) => b,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => {
            return Err(ManifestError::Read {
                path: path.display().to_string(),
                message: e.to_string(),
            })
        }
    };
    let mut rows = Vec::new();
    let complete = bytes.split_inclusive(|&b| b == b'\n').enumerate();
    for (i, line) in complete {
        let Some(line) = line.strip_suffix(b"\n") else {
            break;
        };
        if line.iter().all(u8::is_ascii_whitespace) {
            continue;
        }
        let parsed: Vec<Row> = serde_json::from_slice(line).map_err(|e| ManifestError::Parse {
            path: path.display().to_string(),
            line: i + 1,
            column: e.column(),
            message: e.to_string(),
        })?;
        rows.extend(parsed);
    }
    Ok(rows)
}

/// Every row a run in progress (or killed) has recorded in the manifest
/// `manifest_json` and its journal: the manifest's rows with the journal's
/// newer ones in their place, in manifest order.
pub fn recorded(manifest_json: &Path) -> Result<Vec<Row>, ManifestError> {
    let mut rows = std::collections::BTreeMap::new();
    if manifest_json.is_file() {
        for r in super::manifest::Manifest::load(manifest_json)?.rows {
            rows.insert((r.trial.clone(), r.variant), r);
        }
    }
    for r in read(&Journal::path_for(manifest_json))? {
        rows.insert((r.trial.clone(), r.variant), r);
    }
    Ok(rows.into_values().collect())
}

/// When to rewrite the whole manifest during a run: after at least
/// [`SavePace::MIN_INTERVAL`] and at least twenty times as long as the last
/// rewrite took, so rewriting costs at most about 5% of the run however
/// large the manifest grows (the journal holds what is between).
pub struct SavePace {
    last: Instant,
    took: Duration,
}

impl SavePace {
    /// The least time between two rewrites.
    pub const MIN_INTERVAL: Duration = Duration::from_secs(5);

    /// A pace whose first rewrite is due after the least interval.
    pub fn new() -> SavePace {
        SavePace {
            last: Instant::now(),
            took: Duration::ZERO,
        }
    }

    /// Whether a rewrite is due now.
    pub fn due(&self) -> bool {
        self.last.elapsed() >= Self::MIN_INTERVAL.max(self.took * 20)
    }

    /// Records a rewrite that started at `started`.
    pub fn saved(&mut self, started: Instant) {
        self.took = started.elapsed();
        self.last = Instant::now();
    }
}

impl Default for SavePace {
    fn default() -> Self {
        SavePace::new()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::variant::Variant;

    fn row(trial: &str) -> Row {
        Row::failed(Path::new(trial), Variant::Basic, "x".into())
    }

    #[test]
    fn appended_rows_read_back_and_a_cut_last_line_is_left_out() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("manifest.journal.jsonl");
        let mut j = Journal::open(&path).unwrap();
        j.append(&[row("a.csv")]).unwrap();
        j.append(&[row("b.csv"), row("c.csv")]).unwrap();
        drop(j);
        let names = |rows: Vec<Row>| rows.into_iter().map(|r| r.trial).collect::<Vec<_>>();
        assert_eq!(names(read(&path).unwrap()), ["a.csv", "b.csv", "c.csv"]);
        // A kill in the middle of an append leaves part of a line.
        let mut bytes = std::fs::read(&path).unwrap();
        let whole = bytes.len();
        bytes.extend_from_slice(&serde_json::to_vec(&[row("d.csv")]).unwrap()[..20]);
        std::fs::write(&path, &bytes).unwrap();
        assert_eq!(names(read(&path).unwrap()), ["a.csv", "b.csv", "c.csv"]);
        // (A resumed run folds the journal into the manifest and starts a
        // fresh one, so nothing is ever appended after a cut line.)
        std::fs::write(&path, &bytes[..whole]).unwrap();
        assert_eq!(read(&path).unwrap().len(), 3);
    }

    #[test]
    fn a_damaged_line_in_the_middle_is_located() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("manifest.journal.jsonl");
        let good = String::from_utf8(serde_json::to_vec(&[row("a.csv")]).unwrap()).unwrap();
        std::fs::write(&path, format!("{good}\n[{{\"trial\": 3}}]\n{good}\n")).unwrap();
        let e = read(&path).unwrap_err().to_string();
        assert!(e.contains("manifest.journal.jsonl:2:"), "{e}");
    }

    #[test]
    fn no_journal_is_no_rows() {
        let dir = tempfile::tempdir().unwrap();
        assert!(read(&dir.path().join("none.jsonl")).unwrap().is_empty());
    }
}
