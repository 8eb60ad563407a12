//! What a follow reads: one growing CSV ([`Tail`]) or a folder of growing
//! Xsens exports ([`ExportsTail`]), behind one interface, so that `acmw
//! follow` and the workbench follow both the same way.

use super::{ExportsEvent, ExportsTail, Follower, Tail, TailEvent};
use crate::model::Model;
use crate::trial::{Trial, TrialError};
use std::ops::Range;
use std::path::{Path, PathBuf};

/// A growing trial as it is read: a canonical or Euler CSV, or a folder of
/// Xsens exports.
pub enum LiveSource {
    /// One CSV file, read line by line.
    Csv {
        /// The file followed.
        path: PathBuf,
        /// Its reader.
        tail: Box<Tail>,
    },
    /// A folder of exports, one per sensor, rows aligned on the packet counter.
    Exports(Box<ExportsTail>),
}

/// What one look at a [`LiveSource`] found.
pub enum Look {
    /// Nothing new.
    Nothing,
    /// The file (or an export) was truncated or replaced, or the folder holds
    /// other exports: everything read so far is void (the reason, to say).
    Restarted(String),
    /// Complete new lines of a CSV, the first one's number (from 1).
    Lines {
        /// The lines, each ending in a newline.
        text: String,
        /// Line number of the first.
        first_line: u64,
    },
    /// New samples of an export folder, aligned over every sensor.
    Samples(Trial),
}

impl LiveSource {
    /// A reader of `path`: a folder is read as Xsens exports, its IMUs named
    /// through `model`'s aliases; anything else as a CSV. Nothing read yet.
    pub fn new(path: &Path, model: &Model) -> LiveSource {
        if path.is_dir() {
            LiveSource::Exports(Box::new(ExportsTail::new(path, model)))
        } else {
            LiveSource::Csv {
                path: path.to_path_buf(),
                tail: Box::new(Tail::new(path)),
            }
        }
    }

    /// Looks once: what was appended since the last look (complete lines or
    /// rows only), or that the source restarted. Errors are located in the
    /// file at fault.
    pub fn poll(&mut self) -> Result<Look, TrialError> {
        Ok(match self {
            LiveSource::Csv { path, tail } => match tail
                .poll()
                .map_err(|e| TrialError::file(path.display().to_string(), e.to_string()))?
            {
                TailEvent::Nothing => Look::Nothing,
                TailEvent::Restarted { reason } => Look::Restarted(reason),
                TailEvent::Lines { text, first_line } => Look::Lines { text, first_line },
            },
            LiveSource::Exports(x) => match x.poll()? {
                ExportsEvent::Nothing => Look::Nothing,
                ExportsEvent::Restarted { reason } => Look::Restarted(reason),
                ExportsEvent::Samples(t) => Look::Samples(t),
            },
        })
    }

    /// Bytes read so far (over every export of a folder): it grew when this
    /// changed.
    pub fn offset(&self) -> u64 {
        match self {
            LiveSource::Csv { tail, .. } => tail.offset(),
            LiveSource::Exports(x) => x.offset(),
        }
    }

    /// Whether every byte on disk was read, with no unfinished line (for a
    /// folder: of every export it still holds).
    pub fn read_whole(&self) -> bool {
        match self {
            LiveSource::Csv { path, tail } => {
                let len = std::fs::metadata(path).map(|m| m.len()).ok();
                !tail.has_partial_line() && len == Some(tail.offset())
            }
            LiveSource::Exports(x) => x.read_whole(),
        }
    }

    /// SHA-256 (hex) of the bytes read so far, where it is the input's own
    /// hash once every byte was read: a CSV's running hash. An export
    /// folder's hash covers its mapping and every export in turn, which only
    /// reading it whole gives: `None` while it is followed.
    pub fn sha256_hex(&self) -> Option<String> {
        match self {
            LiveSource::Csv { tail, .. } => Some(tail.sha256_hex()),
            LiveSource::Exports(_) => None,
        }
    }
}

/// Adds what a look found to `follower`: the indices of the new samples
/// (empty for nothing, or a restart, which the caller handles).
pub fn push(follower: &mut Follower, look: Look) -> Result<Range<usize>, TrialError> {
    let n = follower.trial().map_or(0, Trial::len);
    match look {
        Look::Lines { text, first_line } => follower.push(&text, first_line),
        Look::Samples(batch) => follower.push_samples(batch),
        Look::Nothing | Look::Restarted(_) => Ok(n..n),
    }
}
