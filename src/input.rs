//! Reading input files within bounds: only regular files (never a FIFO that
//! blocks, a device that never ends, or a folder), and never more bytes than
//! a cap, raw or after decompression.
//!
//! The cap is [`DEFAULT_MAX_INPUT_MB`] megabytes (2^20 bytes) unless the
//! environment variable [`MAX_INPUT_ENV`] sets another number of megabytes.

pub mod locate;

use std::fs::File;
use std::io::{self, Read};
use std::path::Path;

/// Cap on the bytes of one input file, raw or decompressed, in megabytes
/// (2^20 bytes): an hour of 17 IMUs at 100 Hz is about 500 MB of CSV.
pub const DEFAULT_MAX_INPUT_MB: u64 = 4096;

/// Environment variable that overrides [`DEFAULT_MAX_INPUT_MB`] (megabytes).
pub const MAX_INPUT_ENV: &str = "ACMW_MAX_INPUT_MB";

/// The cap on one input's bytes, raw or decompressed.
pub fn max_input_bytes() -> u64 {
    std::env::var(MAX_INPUT_ENV)
        .ok()
        .and_then(|v| v.trim().parse::<u64>().ok())
        .filter(|&mb| mb > 0)
        .unwrap_or(DEFAULT_MAX_INPUT_MB)
        .saturating_mul(1 << 20)
}

/// Every path [`open_regular`] opened, in unit tests: how often an input is read.
#[cfg(test)]
pub(crate) static OPENED: std::sync::Mutex<Vec<std::path::PathBuf>> =
    std::sync::Mutex::new(Vec::new());

/// How many times the unit tests so far opened `path` through [`open_regular`].
#[cfg(test)]
pub(crate) fn times_opened(path: &Path) -> usize {
    let opened = OPENED.lock().unwrap_or_else(|e| e.into_inner());
    opened.iter().filter(|p| p.as_path() == path).count()
}

/// Opens `path` for reading when it is a regular file (symbolic links
/// followed). FIFOs, sockets, devices and folders are refused without
/// blocking: the file is opened non-blocking and checked before any read.
pub fn open_regular(path: &Path) -> io::Result<File> {
    #[cfg(test)]
    OPENED
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .push(path.to_path_buf());
    let meta = std::fs::metadata(path)?;
    check_kind(&meta)?;
    let mut options = std::fs::OpenOptions::new();
    options.read(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path)?;
    // The path may have been swapped between the look and the open.
    check_kind(&file.metadata()?)?;
    Ok(file)
}

fn check_kind(meta: &std::fs::Metadata) -> io::Result<()> {
    if meta.is_file() {
        return Ok(());
    }
    let what = if meta.is_dir() {
        "a folder"
    } else {
        kind_of_special(meta)
    };
    Err(io::Error::new(
        io::ErrorKind::InvalidInput,
        format!("expected a regular file, found {what}"),
    ))
}

#[cfg(unix)]
fn kind_of_special(meta: &std::fs::Metadata) -> &'static str {
    use std::os::unix::fs::FileTypeExt;
    let t = meta.file_type();
    if t.is_fifo() {
        "a FIFO (named pipe)"
    } else if t.is_socket() {
        "a socket"
    } else if t.is_char_device() || t.is_block_device() {
        "a device"
    } else {
        "a special file"
    }
}

#[cfg(not(unix))]
fn kind_of_special(_: &std::fs::Metadata) -> &'static str {
    "a special file"
}

fn too_large(limit: u64, what: &str) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!(
            "{what} more than {} MB: expected at most the cap ({MAX_INPUT_ENV} raises it)",
            limit >> 20
        ),
    )
}

/// Reads all of `reader`, failing once it yields more than `limit` bytes;
/// `what` names the bytes in the error ("file is", "decompressed data is").
pub fn read_to_end_capped(reader: impl Read, limit: u64, what: &str) -> io::Result<Vec<u8>> {
    let mut out = Vec::new();
    reader.take(limit.saturating_add(1)).read_to_end(&mut out)?;
    if out.len() as u64 > limit {
        return Err(too_large(limit, what));
    }
    Ok(out)
}

/// The bytes of the regular file at `path`, at most [`max_input_bytes`].
pub fn read_bytes(path: &Path) -> io::Result<Vec<u8>> {
    let limit = max_input_bytes();
    let file = open_regular(path)?;
    let len = file.metadata()?.len();
    if len > limit {
        return Err(too_large(limit, "file is"));
    }
    // Sized for the file as it is (one read, no regrowing); a file that grows
    // meanwhile is still read to its end, up to the limit.
    let mut out = Vec::with_capacity(usize::try_from(len).map_or(0, |n| n.saturating_add(1)));
    file.take(limit.saturating_add(1)).read_to_end(&mut out)?;
    if out.len() as u64 > limit {
        return Err(too_large(limit, "file is"));
    }
    Ok(out)
}

/// The text of the regular file at `path` (UTF-8), at most [`max_input_bytes`].
/// An invalid byte's error says its line and column (as
/// [`read_text_located`] finds them) in its message.
pub fn read_text(path: &Path) -> io::Result<String> {
    read_text_located(path).map_err(|e| match e.line {
        0 => e.error,
        line => io::Error::new(
            e.error.kind(),
            format!("line {line}, column {}: {}", e.column, e.error),
        ),
    })
}

/// Why a file could not be read as text, and where: line and column (1-based,
/// characters) of an invalid UTF-8 byte, 0 and 0 when the file as a whole is meant.
#[derive(Debug)]
pub struct ReadFailure {
    pub line: u64,
    pub column: usize,
    pub error: io::Error,
}

/// [`read_text`], locating invalid UTF-8 by line and column.
pub fn read_text_located(path: &Path) -> Result<String, ReadFailure> {
    let whole = |error| ReadFailure {
        line: 0,
        column: 0,
        error,
    };
    let bytes = read_bytes(path).map_err(whole)?;
    String::from_utf8(bytes).map_err(|e| invalid_utf8(e.as_bytes(), e.utf8_error().valid_up_to()))
}

/// The bytes as UTF-8 text; where they are not, the line and column of the
/// first invalid byte (as [`read_text_located`] reports it).
pub fn str_of(bytes: &[u8]) -> Result<&str, ReadFailure> {
    std::str::from_utf8(bytes).map_err(|e| invalid_utf8(bytes, e.valid_up_to()))
}

/// The failure of text whose first invalid UTF-8 byte is at `at`.
fn invalid_utf8(bytes: &[u8], at: usize) -> ReadFailure {
    let before = String::from_utf8_lossy(&bytes[..at]);
    let line = before.matches('\n').count() as u64 + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    ReadFailure {
        line,
        column,
        error: io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "expected UTF-8 text, found invalid byte 0x{:02x}",
                bytes[at]
            ),
        ),
    }
}

/// Decompresses gzip data (all members), at most [`max_input_bytes`] out.
pub fn gunzip_capped(raw: &[u8]) -> io::Result<Vec<u8>> {
    read_to_end_capped(
        flate2::read::MultiGzDecoder::new(raw),
        max_input_bytes(),
        "decompressed data is",
    )
}

/// The 1-based line of `text` that holds the first name quoted in `message`
/// (`'l_knee'`), as a TOML string (`"l_knee"`): where a validation message
/// about that name points. `None` when the message quotes nothing found.
pub fn line_naming(text: &str, message: &str) -> Option<u64> {
    let start = message.find('\'')? + 1;
    let len = message[start..].find('\'')?;
    let needle = format!("\"{}\"", &message[start..start + len]);
    text.lines()
        .position(|l| l.contains(&needle))
        .map(|i| i as u64 + 1)
}

/// 1-based line and column (in characters) of a byte offset in `text`.
pub fn line_col(text: &str, offset: usize) -> (u64, usize) {
    let mut at = offset.min(text.len());
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    let before = &text[..at];
    let line = before.matches('\n').count() as u64 + 1;
    let col = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, col)
}

/// Hex SHA-256 of bytes (how sidecars and settings name what they read).
pub fn sha256_hex(bytes: &[u8]) -> String {
    <sha2::Sha256 as sha2::Digest>::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_folders_and_caps_readers() {
        let dir = tempfile::tempdir().unwrap();
        let e = read_bytes(dir.path()).unwrap_err();
        assert!(e.to_string().contains("found a folder"), "{e}");
        let e = read_to_end_capped(&[0u8; 11][..], 10, "data is").unwrap_err();
        assert!(e.to_string().starts_with("data is more than"), "{e}");
        assert_eq!(
            read_to_end_capped(&[0u8; 10][..], 10, "x").unwrap().len(),
            10
        );
    }

    #[cfg(unix)]
    #[test]
    fn refuses_fifos_and_devices_without_blocking() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("t.csv");
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        // SAFETY: a valid NUL-terminated path.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let e = read_bytes(&fifo).unwrap_err();
        assert!(e.to_string().contains("FIFO"), "{e}");
        let link = dir.path().join("z.csv");
        std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
        let e = read_bytes(&link).unwrap_err();
        assert!(e.to_string().contains("a device"), "{e}");
    }

    #[test]
    fn read_text_says_where_the_text_stops_being_utf8() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.json");
        std::fs::write(&path, b"{\n  \"a\": \"x\xff\"\n}\n").unwrap();
        let e = read_text(&path).unwrap_err().to_string();
        assert_eq!(
            e,
            "line 2, column 10: expected UTF-8 text, found invalid byte 0xff"
        );
    }
}
