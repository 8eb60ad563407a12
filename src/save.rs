//! Atomic saves: write a temporary file beside the target, then rename it into
//! place, keeping the previous file as `<name>.bak` so that nothing is lost.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The backup path kept for `path` (`<name>.bak` beside it).
pub fn backup_path(path: &Path) -> PathBuf {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(".bak");
    path.with_file_name(name)
}

/// Writes `bytes` to `path` atomically. An existing file is first copied to
/// [`backup_path`]; a reader sees either the old or the new content, never a mix.
pub fn atomic_write(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let mut tmp = tempfile::Builder::new()
        .prefix(".acmw-")
        .suffix(".tmp")
        .tempfile_in(&dir)?;
    tmp.write_all(bytes)?;
    // A temporary file is private (0600); give the new file the old one's
    // permissions, or the usual ones for a new file.
    let perms = match fs::metadata(path) {
        Ok(m) => m.permissions(),
        Err(_) => default_permissions(),
    };
    tmp.as_file().set_permissions(perms)?;
    tmp.as_file().sync_all()?;
    if path.exists() {
        fs::copy(path, backup_path(path))?;
    }
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

#[cfg(unix)]
fn default_permissions() -> fs::Permissions {
    use std::os::unix::fs::PermissionsExt;
    fs::Permissions::from_mode(0o644)
}

#[cfg(not(unix))]
fn default_permissions() -> fs::Permissions {
    let f = tempfile::tempfile().expect("temporary file");
    f.metadata().expect("metadata").permissions()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_backup_of_previous_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.csv");
        atomic_write(&p, b"one").unwrap();
        assert!(!backup_path(&p).exists());
        atomic_write(&p, b"two").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"two");
        assert_eq!(fs::read(backup_path(&p)).unwrap(), b"one");
        let leftovers: Vec<_> = fs::read_dir(dir.path())
            .unwrap()
            .filter_map(|e| e.ok())
            .filter(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
            .collect();
        assert!(leftovers.is_empty());
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = fs::metadata(&p).unwrap().permissions().mode() & 0o777;
            assert_eq!(mode, 0o644);
        }
    }
}
