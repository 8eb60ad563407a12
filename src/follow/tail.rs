//! Reading a file another program is appending to: complete lines only.

use sha2::{Digest, Sha256};
use std::io::{Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

/// Bytes at the start of the file kept to notice a rewrite in place.
const HEAD_BYTES: usize = 4096;
/// Most bytes read in one look (the rest is read at the next).
const CHUNK_BYTES: u64 = 16 << 20;

/// What one look at the file found.
#[derive(Debug, Clone, PartialEq)]
pub enum TailEvent {
    /// Nothing new, or only part of a line (kept until its newline lands).
    Nothing,
    /// Complete lines (each ending in `\n`, `\r\n` included), starting at
    /// 1-based line `first_line` of the file.
    Lines { text: String, first_line: u64 },
    /// The file was truncated, replaced, rewritten or removed: everything
    /// read so far is void and the next look reads it from its start.
    Restarted { reason: String },
}

/// An incremental reader of one growing text file. Only regular files are
/// read ([`crate::input::open_regular`]); at most
/// [`crate::input::max_input_bytes`] of one file.
#[derive(Debug)]
pub struct Tail {
    path: PathBuf,
    /// Bytes read so far (complete lines and `pending`).
    offset: u64,
    /// Bytes after the last newline read.
    pending: Vec<u8>,
    /// Complete lines handed out.
    lines: u64,
    /// The first bytes of the file as read, to notice a rewrite.
    head: Vec<u8>,
    /// Device and inode of the file read (unix), to notice a replacement.
    identity: Option<(u64, u64)>,
    /// SHA-256 of the `offset` bytes read so far, in order, updated as they
    /// are read (the file is never read twice for it).
    hash: Sha256,
}

impl Tail {
    /// A reader of `path` that has read nothing yet.
    pub fn new(path: &Path) -> Tail {
        Tail {
            path: path.to_path_buf(),
            offset: 0,
            pending: Vec::new(),
            lines: 0,
            head: Vec::new(),
            identity: None,
            hash: Sha256::new(),
        }
    }

    /// SHA-256 (hex) of the bytes read so far (complete lines and a partial
    /// one): once the writer has stopped and everything was read, the hash
    /// of the whole file, as [`crate::input::sha256_hex`] of its bytes and a
    /// sidecar's input hash record it.
    pub fn sha256_hex(&self) -> String {
        self.hash
            .clone()
            .finalize()
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect()
    }

    /// Bytes read so far, complete lines and a partial one.
    pub fn offset(&self) -> u64 {
        self.offset
    }

    /// Whether a partial line (no newline yet) is waiting.
    pub fn has_partial_line(&self) -> bool {
        !self.pending.is_empty()
    }

    fn restart(&mut self, reason: String) -> TailEvent {
        *self = Tail::new(&self.path);
        TailEvent::Restarted { reason }
    }

    /// Looks at the file once: returns the complete lines appended since the
    /// last look, or that it restarted. A missing file before anything was
    /// read is [`TailEvent::Nothing`] (the writer has not begun).
    pub fn poll(&mut self) -> std::io::Result<TailEvent> {
        let mut file = match crate::input::open_regular(&self.path) {
            Ok(f) => f,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Ok(if self.offset == 0 {
                    TailEvent::Nothing
                } else {
                    self.restart(format!("was removed after {} bytes were read", self.offset))
                });
            }
            Err(e) => return Err(e),
        };
        let meta = file.metadata()?;
        let identity = identity_of(&meta);
        if self.offset > 0 && identity.is_some() && identity != self.identity {
            return Ok(self.restart("was replaced by another file".into()));
        }
        self.identity = identity;
        let len = meta.len();
        if len < self.offset {
            return Ok(self.restart(format!(
                "was truncated to {len} bytes after {} were read",
                self.offset
            )));
        }
        if !self.head.is_empty() {
            let mut now = vec![0u8; self.head.len()];
            file.seek(SeekFrom::Start(0))?;
            match file.read_exact(&mut now) {
                Ok(()) => {}
                // Cut shorter than what was read since the length was taken.
                Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
                    return Ok(self.restart(format!(
                        "was truncated while being read, after {} bytes were read",
                        self.offset
                    )));
                }
                Err(e) => return Err(e),
            }
            if now != self.head {
                return Ok(self.restart(format!(
                    "was rewritten: its first {} bytes changed",
                    self.head.len()
                )));
            }
        }
        if len == self.offset {
            return Ok(TailEvent::Nothing);
        }
        let cap = crate::input::max_input_bytes();
        if len > cap {
            return Err(std::io::Error::other(format!(
                "{}: larger than {} MB; expected at most that much of one trial (ACMW_MAX_INPUT_MB sets another cap)",
                self.path.display(),
                cap >> 20
            )));
        }
        file.seek(SeekFrom::Start(self.offset))?;
        let mut data = Vec::new();
        (&mut file)
            .take((len - self.offset).min(CHUNK_BYTES))
            .read_to_end(&mut data)?;
        if self.head.len() < HEAD_BYTES {
            let want = HEAD_BYTES - self.head.len();
            self.head.extend_from_slice(&data[..want.min(data.len())]);
        }
        self.offset += data.len() as u64;
        self.hash.update(&data);
        self.pending.extend_from_slice(&data);
        let Some(last) = self.pending.iter().rposition(|&b| b == b'\n') else {
            return Ok(TailEvent::Nothing);
        };
        let rest = self.pending.split_off(last + 1);
        let complete = std::mem::replace(&mut self.pending, rest);
        let first_line = self.lines + 1;
        let count = complete.iter().filter(|&&b| b == b'\n').count() as u64;
        let text = String::from_utf8(complete).map_err(|e| {
            let at = e.utf8_error().valid_up_to();
            let bytes = e.as_bytes();
            let line = first_line + bytes[..at].iter().filter(|&&b| b == b'\n').count() as u64;
            std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!(
                    "{}:{line}: expected UTF-8 text, found invalid byte 0x{:02x}",
                    self.path.display(),
                    bytes[at]
                ),
            )
        })?;
        self.lines += count;
        Ok(TailEvent::Lines { text, first_line })
    }
}

#[cfg(unix)]
fn identity_of(meta: &std::fs::Metadata) -> Option<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    Some((meta.dev(), meta.ino()))
}

#[cfg(not(unix))]
fn identity_of(_meta: &std::fs::Metadata) -> Option<(u64, u64)> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Write;

    fn lines(e: TailEvent) -> (String, u64) {
        match e {
            TailEvent::Lines { text, first_line } => (text, first_line),
            other => panic!("expected lines, got {other:?}"),
        }
    }

    #[test]
    fn hands_out_complete_lines_and_notices_truncation_and_replacement() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.csv");
        let mut tail = Tail::new(&path);
        assert_eq!(tail.poll().unwrap(), TailEvent::Nothing);
        let mut f = std::fs::File::create(&path).unwrap();
        f.write_all(b"time,a_q").unwrap();
        assert_eq!(tail.poll().unwrap(), TailEvent::Nothing);
        assert!(tail.has_partial_line());
        f.write_all(b"w\n0,1\n0.0").unwrap();
        assert_eq!(lines(tail.poll().unwrap()), ("time,a_qw\n0,1\n".into(), 1));
        f.write_all(b"2,1\r\n").unwrap();
        assert_eq!(lines(tail.poll().unwrap()), ("0.02,1\r\n".into(), 3));
        assert_eq!(tail.poll().unwrap(), TailEvent::Nothing);
        // The running hash is the whole file's, read in four looks.
        let whole = std::fs::read(&path).unwrap();
        assert_eq!(tail.offset(), whole.len() as u64);
        assert_eq!(tail.sha256_hex(), crate::input::sha256_hex(&whole));
        // Truncated below what was read.
        f.set_len(5).unwrap();
        let TailEvent::Restarted { reason } = tail.poll().unwrap() else {
            panic!("truncation not noticed");
        };
        assert!(reason.contains("truncated to 5 bytes"), "{reason}");
        drop(f);
        std::fs::write(&path, "time,b_qw\n0,1\n").unwrap();
        assert_eq!(lines(tail.poll().unwrap()).1, 1);
        // Started over: the hash covers the new bytes only.
        assert_eq!(
            tail.sha256_hex(),
            crate::input::sha256_hex(b"time,b_qw\n0,1\n")
        );
        // Rewritten in place, same length or longer.
        std::fs::write(&path, "time,c_qw\n0,1\n1,1\n").unwrap();
        let TailEvent::Restarted { reason } = tail.poll().unwrap() else {
            panic!("rewrite not noticed");
        };
        assert!(
            reason.contains("rewritten") || reason.contains("replaced"),
            "{reason}"
        );
        assert_eq!(lines(tail.poll().unwrap()).0, "time,c_qw\n0,1\n1,1\n");
        // Replaced by a rename over it (another inode).
        let other = dir.path().join("u.csv");
        std::fs::write(&other, "time,c_qw\n0,1\n1,1\n2,1\n").unwrap();
        std::fs::rename(&other, &path).unwrap();
        let e = tail.poll().unwrap();
        if cfg!(unix) {
            assert!(matches!(e, TailEvent::Restarted { .. }), "{e:?}");
        }
    }
}
