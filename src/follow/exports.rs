//! Following a folder of Xsens MT Manager exports (one `.txt` per sensor)
//! while MT Manager appends to them: each export is read by its own
//! [`Tail`] (complete lines only), the rows are aligned on the packet
//! counter as the whole-folder reader aligns them
//! ([`GrowingExports`]), and a row is handed out once every sensor has
//! written past its packet.

use super::tail::{Tail, TailEvent};
use crate::model::Model;
use crate::trial::xsens_trial::{resolve, GrowingExports, XsensSource};
use crate::trial::{Trial, TrialError};
use std::path::{Path, PathBuf};

/// What one look at the folder found.
#[derive(Debug, Clone, PartialEq)]
pub enum ExportsEvent {
    /// No new row every sensor has.
    Nothing,
    /// New aligned rows (samples every sensor recorded, in counter order).
    Samples(Trial),
    /// An export was truncated, replaced, rewritten or removed, or the set
    /// of exports changed: everything read is void and the next look reads
    /// every export from its start.
    Restarted { reason: String },
}

/// The exports being followed.
struct Followed {
    source: XsensSource,
    tails: Vec<Tail>,
    rows: GrowingExports,
}

/// An incremental reader of a folder of exports being written.
pub struct ExportsTail {
    folder: PathBuf,
    model: Model,
    followed: Option<Followed>,
}

/// Whether `folder` holds the exports of a trial (as the whole-folder
/// reader resolves them) and every one has a complete header line: what
/// following it waits for (the IMU names, hence the model, are known then).
pub fn exports_ready(folder: &Path) -> bool {
    let Ok(source) = resolve(folder) else {
        return false;
    };
    source.files.iter().all(|(f, _)| {
        let Ok(bytes) = crate::input::read_bytes(f) else {
            return false;
        };
        String::from_utf8_lossy(&bytes)
            .split_inclusive('\n')
            .any(|l| {
                let t = l.trim_start_matches('\u{feff}').trim();
                l.ends_with('\n') && !t.is_empty() && !t.starts_with("//")
            })
    })
}

impl ExportsTail {
    /// A reader of the exports in `folder`, their IMUs named through
    /// `model`'s aliases; nothing read yet.
    pub fn new(folder: &Path, model: &Model) -> ExportsTail {
        ExportsTail {
            folder: folder.to_path_buf(),
            model: model.clone(),
            followed: None,
        }
    }

    /// Bytes read so far, over every export.
    pub fn offset(&self) -> u64 {
        self.followed
            .as_ref()
            .map_or(0, |f| f.tails.iter().map(Tail::offset).sum())
    }

    /// Whether every export was read to its end as it is on disk now, with
    /// no partial line waiting, and the folder still holds those exports:
    /// the rows read are the whole trial.
    pub fn read_whole(&self) -> bool {
        let Some(f) = &self.followed else {
            return false;
        };
        let same = resolve(&self.folder).is_ok_and(|s| same_exports(&s, &f.source));
        same && f.tails.iter().zip(&f.source.files).all(|(t, (p, _))| {
            !t.has_partial_line() && std::fs::metadata(p).is_ok_and(|m| m.len() == t.offset())
        })
    }

    fn restart(&mut self, reason: String) -> ExportsEvent {
        self.followed = None;
        ExportsEvent::Restarted { reason }
    }

    /// Looks at every export once: the rows every sensor has written since
    /// the last look, or that it restarted. Before the folder holds exports
    /// (or, with a mapping, every export it names) this is
    /// [`ExportsEvent::Nothing`]. Errors are located in the export at fault.
    pub fn poll(&mut self) -> Result<ExportsEvent, TrialError> {
        let source = match resolve(&self.folder) {
            Ok(s) => s,
            Err(e) if self.followed.is_some() => {
                return Ok(self.restart(format!("no longer holds the exports read ({e})")));
            }
            Err(_) => return Ok(ExportsEvent::Nothing),
        };
        if let Some(f) = &self.followed {
            if !same_exports(&source, &f.source) {
                let names: Vec<String> = source.files.iter().map(|(p, _)| file_name(p)).collect();
                return Ok(self.restart(format!("has other exports now ({})", names.join(", "))));
            }
        }
        if self.followed.is_none() {
            let rows = GrowingExports::new(&self.folder, &source, &self.model)?;
            let tails = source.files.iter().map(|(p, _)| Tail::new(p)).collect();
            self.followed = Some(Followed {
                source,
                tails,
                rows,
            });
        }
        let Some(f) = self.followed.as_mut() else {
            return Ok(ExportsEvent::Nothing);
        };
        for k in 0..f.tails.len() {
            let event = f.tails[k].poll().map_err(|e| {
                TrialError::file(f.source.files[k].0.display().to_string(), e.to_string())
            })?;
            match event {
                TailEvent::Nothing => {}
                TailEvent::Lines { text, first_line } => {
                    f.rows.push_lines(k, &text, first_line)?;
                }
                TailEvent::Restarted { reason } => {
                    let name = file_name(&f.source.files[k].0);
                    return Ok(self.restart(format!("export {name} {reason}")));
                }
            }
        }
        Ok(match f.rows.aligned()? {
            Some(t) => ExportsEvent::Samples(t),
            None => ExportsEvent::Nothing,
        })
    }
}

/// The same export files, IMU names and mapping.
fn same_exports(a: &XsensSource, b: &XsensSource) -> bool {
    a.files == b.files && a.mapping_text == b.mapping_text
}

fn file_name(p: &Path) -> String {
    p.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| p.display().to_string())
}
