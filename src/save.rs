//! Saves that survive a kill at any instant and a full disk.
//!
//! A file is written to a temporary file beside the target, flushed to disk,
//! then renamed into place: a reader sees the old content or the new, never a
//! mix. The previous version is kept as `<name>.bak`, made by a hard link to
//! the old file renamed over the old backup (never a copy that a kill or a
//! full disk could cut short): at every instant `<name>.bak` is a complete
//! earlier version. Temporary files carry the writer's process id, and a
//! save removes those of writers no longer running.
//!
//! Several files that belong together (a limit table and the settings naming
//! it) are committed by [`atomic_write_all`]: every new version is written
//! first, then a journal lists the renames, then they happen. A save killed
//! after the journal is finished by the next [`recover`] of that folder (every
//! reader of such a folder calls it); one killed before it changed nothing.
//!
//! [`OutputLock`] keeps two processes from writing one output at once.

use std::fs;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// A file that could not be written: its path and why.
#[derive(Debug, thiserror::Error)]
#[error("{path}: {message}")]
pub struct WriteError {
    /// The file as the user named it.
    pub path: String,
    /// What went wrong (starts "cannot write" for I/O failures).
    pub message: String,
}

impl WriteError {
    /// An I/O failure writing `path`.
    pub fn io(path: &Path, e: &io::Error) -> WriteError {
        WriteError {
            path: path.display().to_string(),
            message: format!("cannot write: {e}"),
        }
    }
}

/// Prefix of every temporary file a save makes
/// (`.acmw-<pid>.<host>-<random>.tmp`).
const TMP_PREFIX: &str = ".acmw-";

/// The writer part of this process's temporary files: `<pid>.<host>`. The
/// host keeps a save from removing, as a dead writer's, the temporary of a
/// process on another machine writing to the same shared folder.
fn temp_owner_tag() -> &'static str {
    static TAG: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    TAG.get_or_init(|| format!("{}.{}", std::process::id(), host_tag()))
}

/// This machine's name, letters and digits only, at most 32 of them.
fn host_tag() -> String {
    #[cfg(unix)]
    {
        let mut buf = [0u8; 256];
        // SAFETY: the buffer is writable for its length; the name is cut at its NUL.
        let r = unsafe { libc::gethostname(buf.as_mut_ptr().cast(), buf.len()) };
        if r == 0 {
            let end = buf.iter().position(|&b| b == 0).unwrap_or(buf.len());
            let tag: String = String::from_utf8_lossy(&buf[..end])
                .chars()
                .filter(char::is_ascii_alphanumeric)
                .take(32)
                .collect();
            if !tag.is_empty() {
                return tag;
            }
        }
    }
    "localhost".into()
}

/// Name of the journal of a multi-file save in its folder.
const JOURNAL: &str = ".acmw-commit.json";

/// The backup path kept for `path` (`<name>.bak` beside it).
pub fn backup_path(path: &Path) -> PathBuf {
    let mut name = path.file_name().unwrap_or_default().to_os_string();
    name.push(".bak");
    path.with_file_name(name)
}

fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// Writes `bytes` to `path` atomically, keeping the previous file as
/// [`backup_path`]. A reader sees either the old or the new content.
pub fn atomic_write(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let dir = folder_of(path);
    remove_stale_temps(&dir);
    let tmp = write_temp(&dir, bytes, path)?;
    step();
    keep_backup(path, &dir)?;
    step();
    tmp.persist(path).map_err(|e| e.error)?;
    step();
    sync_dir(&dir);
    Ok(())
}

/// Environment variable naming a save step (1, 2, ...) at which the process
/// kills itself with SIGKILL: how the tests kill a save at each of its steps.
pub const KILL_AT_STEP_ENV: &str = "ACMW_KILL_AT_SAVE_STEP";

/// Counts a step of a save (a temporary written, a backup made, a rename)
/// and dies at the one [`KILL_AT_STEP_ENV`] names, if any.
fn step() {
    use std::sync::atomic::{AtomicU32, Ordering};
    static STEPS: AtomicU32 = AtomicU32::new(0);
    static AT: std::sync::OnceLock<Option<u32>> = std::sync::OnceLock::new();
    let at = *AT.get_or_init(|| std::env::var(KILL_AT_STEP_ENV).ok()?.parse().ok());
    let n = STEPS.fetch_add(1, Ordering::SeqCst) + 1;
    if at == Some(n) {
        #[cfg(unix)]
        // SAFETY: sends SIGKILL to this process; nothing after it runs.
        unsafe {
            libc::kill(libc::getpid(), libc::SIGKILL);
        }
        std::process::abort();
    }
}

/// Writes several files so that either all are replaced or none (see the
/// module docs). All paths must be in one folder.
pub fn atomic_write_all(files: &[(&Path, &[u8])]) -> io::Result<()> {
    let Some((first, _)) = files.first() else {
        return Ok(());
    };
    let dir = folder_of(first);
    if files.iter().any(|(p, _)| folder_of(p) != dir) {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            "a multi-file save must stay in one folder",
        ));
    }
    recover(&dir)?;
    remove_stale_temps(&dir);
    let mut temps = Vec::with_capacity(files.len());
    for (path, bytes) in files {
        temps.push((write_temp(&dir, bytes, path)?, path.to_path_buf()));
    }
    let entries: Vec<[String; 2]> = temps
        .iter()
        .map(|(t, p)| {
            [
                t.path()
                    .file_name()
                    .unwrap_or_default()
                    .to_string_lossy()
                    .into_owned(),
                p.file_name()
                    .unwrap_or_default()
                    .to_string_lossy()
                    .into_owned(),
            ]
        })
        .collect();
    let journal = dir.join(JOURNAL);
    let text = serde_json::to_vec(&entries).map_err(io::Error::other)?;
    // The temporaries must outlive this process once the journal names them.
    let kept: Vec<(PathBuf, PathBuf)> = temps
        .into_iter()
        .map(|(t, p)| t.keep().map(|(_, tp)| (tp, p)).map_err(|e| e.error))
        .collect::<io::Result<_>>()?;
    step();
    let journal_tmp = write_temp(&dir, &text, &journal)?;
    journal_tmp.persist(&journal).map_err(|e| e.error)?;
    step();
    sync_dir(&dir);
    for (tmp, path) in &kept {
        backup_then_rename(tmp, path)?;
        step();
    }
    sync_dir(&dir);
    fs::remove_file(&journal)?;
    Ok(())
}

/// Finishes a multi-file save in `dir` that was interrupted after its journal
/// was written (renames the new versions into place); a no-op otherwise.
pub fn recover(dir: &Path) -> io::Result<()> {
    let journal = dir.join(JOURNAL);
    let text = match fs::read(&journal) {
        Ok(t) => t,
        Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(e),
    };
    // A journal that does not parse was never renamed into place whole; it
    // cannot exist (it is written by rename), but is dropped if it does.
    let entries: Vec<[String; 2]> = serde_json::from_slice(&text).unwrap_or_default();
    for [tmp, target] in &entries {
        let plain = |n: &str| !n.is_empty() && !n.contains(['/', '\\']) && n != "..";
        if !(plain(tmp) && plain(target) && tmp.starts_with(TMP_PREFIX)) {
            continue;
        }
        let tmp = dir.join(tmp);
        if tmp.exists() {
            backup_then_rename(&tmp, &dir.join(target))?;
        }
    }
    sync_dir(dir);
    fs::remove_file(&journal)
}

/// A complete temporary copy of `bytes` in `dir`, flushed, with the
/// permissions of `target` (or the usual ones for a new file).
fn write_temp(dir: &Path, bytes: &[u8], target: &Path) -> io::Result<tempfile::NamedTempFile> {
    let mut tmp = tempfile::Builder::new()
        .prefix(&format!("{TMP_PREFIX}{}-", temp_owner_tag()))
        .suffix(".tmp")
        .tempfile_in(dir)?;
    tmp.write_all(bytes)?;
    // A temporary file is private (0600); give the new file the old one's
    // permissions, or the usual ones for a new file.
    let perms = match fs::metadata(target) {
        Ok(m) => m.permissions(),
        Err(_) => default_permissions(),
    };
    tmp.as_file().set_permissions(perms)?;
    tmp.as_file().sync_all()?;
    Ok(tmp)
}

fn backup_then_rename(tmp: &Path, path: &Path) -> io::Result<()> {
    keep_backup(path, &folder_of(path))?;
    fs::rename(tmp, path)
}

/// Makes the current `path` (if any) its backup without ever leaving a
/// partial one: a hard link under a temporary name renamed over the old
/// backup. Where hard links are not supported, a flushed copy under a
/// temporary name is renamed instead.
fn keep_backup(path: &Path, dir: &Path) -> io::Result<()> {
    if !path.exists() {
        return Ok(());
    }
    let name = tempfile::Builder::new()
        .prefix(&format!("{TMP_PREFIX}{}-", temp_owner_tag()))
        .suffix(".tmp")
        .make_in(dir, |p| fs::hard_link(path, p));
    match name {
        Ok(link) => link
            .persist(backup_path(path))
            .map(|_| ())
            .map_err(|e| e.error),
        Err(_) => {
            let bytes = fs::read(path)?;
            let copy = write_temp(dir, &bytes, path)?;
            copy.persist(backup_path(path))
                .map(|_| ())
                .map_err(|e| e.error)
        }
    }
}

/// Flushes the folder's entries (the renames) to disk where that is possible.
fn sync_dir(dir: &Path) {
    #[cfg(unix)]
    if let Ok(d) = fs::File::open(dir) {
        let _ = d.sync_all();
    }
    #[cfg(not(unix))]
    let _ = dir;
}

/// Removes temporary files of saves whose process is gone (killed mid-save).
/// Those of running processes, this one included, are left alone.
pub fn remove_stale_temps(dir: &Path) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    let me = std::process::id();
    let journal_names = journal_temps(dir);
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let Some(pid) = temp_owner(&name) else {
            continue;
        };
        if pid != me && !process_alive(pid) && !journal_names.contains(&name) {
            let _ = fs::remove_file(e.path());
        }
    }
}

/// Temporaries a pending journal still needs.
fn journal_temps(dir: &Path) -> Vec<String> {
    fs::read(dir.join(JOURNAL))
        .ok()
        .and_then(|t| serde_json::from_slice::<Vec<[String; 2]>>(&t).ok())
        .map(|v| v.into_iter().map(|[t, _]| t).collect())
        .unwrap_or_default()
}

/// The process id in a temporary file's name `.acmw-<pid>[.<host>]-<random>.tmp`,
/// when that process ran on this machine (or the name records no machine).
fn temp_owner(name: &str) -> Option<u32> {
    let rest = name.strip_prefix(TMP_PREFIX)?.strip_suffix(".tmp")?;
    let owner = rest.split_once('-')?.0;
    match owner.split_once('.') {
        Some((pid, host)) if host == host_tag() => pid.parse().ok(),
        Some(_) => None,
        None => owner.parse().ok(),
    }
}

#[cfg(unix)]
fn process_alive(pid: u32) -> bool {
    let Ok(pid) = libc::pid_t::try_from(pid) else {
        return false;
    };
    // SAFETY: signal 0 only checks that the process exists.
    let r = unsafe { libc::kill(pid, 0) };
    r == 0 || io::Error::last_os_error().raw_os_error() == Some(libc::EPERM)
}

#[cfg(not(unix))]
fn process_alive(_: u32) -> bool {
    true
}

/// An exclusive lock on an output path, held while it and the files that go
/// with it (its sidecar) are written, so that two runs never pair one's
/// trial with the other's sidecar. The lock is a hidden file beside the
/// output (`.<name>.lock`), released when this is dropped or the process ends.
pub struct OutputLock {
    _file: fs::File,
}

/// How long [`OutputLock::acquire`] waits for another writer before refusing.
pub const LOCK_WAIT: Duration = Duration::from_secs(30);

impl OutputLock {
    /// Takes the lock of `output`, waiting up to [`LOCK_WAIT`] for another
    /// process holding it; then refuses with an error that says so.
    pub fn acquire(output: &Path) -> io::Result<OutputLock> {
        let name = output.file_name().unwrap_or_default().to_string_lossy();
        let path = output.with_file_name(format!(".{name}.lock"));
        let file = fs::OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(&path)?;
        let start = Instant::now();
        loop {
            match file.try_lock() {
                Ok(()) => return Ok(OutputLock { _file: file }),
                Err(fs::TryLockError::WouldBlock) if start.elapsed() < LOCK_WAIT => {
                    std::thread::sleep(Duration::from_millis(50));
                }
                Err(fs::TryLockError::WouldBlock) => {
                    return Err(io::Error::new(
                        io::ErrorKind::WouldBlock,
                        format!(
                            "another acmw process is writing {} (lock {} held for {} s)",
                            output.display(),
                            path.display(),
                            LOCK_WAIT.as_secs()
                        ),
                    ))
                }
                Err(fs::TryLockError::Error(e)) => return Err(e),
            }
        }
    }
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

    fn leftovers(dir: &Path) -> Vec<String> {
        fs::read_dir(dir)
            .unwrap()
            .filter_map(|e| e.ok())
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".tmp") || n == JOURNAL)
            .collect()
    }

    #[test]
    fn keeps_backup_of_previous_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.csv");
        atomic_write(&p, b"one").unwrap();
        assert!(!backup_path(&p).exists());
        atomic_write(&p, b"two").unwrap();
        assert_eq!(fs::read(&p).unwrap(), b"two");
        assert_eq!(fs::read(backup_path(&p)).unwrap(), b"one");
        atomic_write(&p, b"three").unwrap();
        assert_eq!(fs::read(backup_path(&p)).unwrap(), b"two");
        assert!(leftovers(dir.path()).is_empty());
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let mode = fs::metadata(&p).unwrap().permissions().mode() & 0o777;
            assert_eq!(mode, 0o644);
        }
    }

    #[test]
    fn temporaries_of_dead_writers_are_removed() {
        let dir = tempfile::tempdir().unwrap();
        // A pid far above any the kernel hands out, and this process's own.
        let dead = dir.path().join(".acmw-4000000000-abc.tmp");
        let mine = dir
            .path()
            .join(format!(".acmw-{}-abc.tmp", std::process::id()));
        let other = dir.path().join("notes.tmp");
        // A dead writer of this machine, and one of another machine sharing
        // the folder (whose process this machine cannot see).
        let dead_here = dir
            .path()
            .join(format!(".acmw-4000000000.{}-abc.tmp", host_tag()));
        let elsewhere = dir.path().join(".acmw-4000000000.othermachine1-abc.tmp");
        for p in [&dead, &mine, &other, &dead_here, &elsewhere] {
            fs::write(p, b"x").unwrap();
        }
        atomic_write(&dir.path().join("t.csv"), b"one").unwrap();
        assert!(!dead.exists() && mine.exists() && other.exists());
        assert!(!dead_here.exists() && elsewhere.exists());
    }

    #[test]
    fn multi_file_save_commits_all_or_is_finished_by_recover() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a.csv"), dir.path().join("s.toml"));
        atomic_write_all(&[(&a, b"a1"), (&b, b"b1")]).unwrap();
        atomic_write_all(&[(&a, b"a2"), (&b, b"b2")]).unwrap();
        assert_eq!(fs::read(&a).unwrap(), b"a2");
        assert_eq!(fs::read(backup_path(&b)).unwrap(), b"b1");
        assert!(leftovers(dir.path()).is_empty());
        // A save killed after its journal and one rename: recover finishes it.
        let t = dir.path().join(".acmw-4000000000-x.tmp");
        fs::write(&t, b"b3").unwrap();
        fs::write(&a, b"a3").unwrap();
        fs::write(
            dir.path().join(JOURNAL),
            serde_json::to_vec(&[[".acmw-4000000000-x.tmp", "s.toml"]]).unwrap(),
        )
        .unwrap();
        // The journal's temporaries survive the clean-up of dead writers'.
        remove_stale_temps(dir.path());
        assert!(t.exists());
        recover(dir.path()).unwrap();
        assert_eq!(fs::read(&b).unwrap(), b"b3");
        assert!(leftovers(dir.path()).is_empty());
    }

    #[test]
    fn a_second_writer_waits_for_the_lock() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("t.csv");
        let lock = OutputLock::acquire(&out).unwrap();
        let (tx, rx) = std::sync::mpsc::channel();
        let o = out.clone();
        let h = std::thread::spawn(move || {
            let l = OutputLock::acquire(&o);
            tx.send(()).unwrap();
            l.map(|_| ())
        });
        assert!(rx.recv_timeout(Duration::from_millis(300)).is_err());
        drop(lock);
        rx.recv_timeout(Duration::from_secs(5)).unwrap();
        h.join().unwrap().unwrap();
    }
}
