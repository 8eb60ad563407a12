//! How the workbench ends when it does not end by `q`: signals, panics and
//! aborts.
//!
//! * SIGTERM, SIGINT and SIGHUP: unsaved limit-table and settings edits are
//!   kept beside the files they edit (`<table>.unsaved`,
//!   `settings.toml.unsaved`, written together), the terminal is restored and
//!   the process exits with status 128 + the signal's number. The next start
//!   offers the kept edits back as unsaved edits (`w` saves them, `q` asks).
//! * A panic in a worker thread is caught: that trial is marked failed with the
//!   panic's message and the workbench goes on. A panic in the main thread
//!   restores the terminal before its message is printed.
//! * An abort (SIGABRT) restores the terminal from a signal handler before the
//!   process dies: raw mode off, alternate screen and mouse reporting left.

use super::app::App;
use super::workbench::LimitsState;
use crate::limits::{LimitTable, SettingsFile};
use std::path::{Path, PathBuf};

/// Suffix of the files that keep unsaved edits across a signal.
pub const UNSAVED_SUFFIX: &str = ".unsaved";

/// The exit status of a process ended by signal `signal` (the shell's convention).
pub fn exit_status(signal: i32) -> i32 {
    128 + signal
}

/// Where unsaved edits of the table `table_name` in `dir` are kept:
/// `(table, settings)`.
pub fn unsaved_paths(dir: &Path, table_name: &str) -> (PathBuf, PathBuf) {
    (
        dir.join(format!("{table_name}{UNSAVED_SUFFIX}")),
        dir.join(format!("settings.toml{UNSAVED_SUFFIX}")),
    )
}

/// Keeps the unsaved table and settings edits beside the files they edit,
/// both in one commit. Nothing is written when nothing is unsaved.
pub fn keep_unsaved(limits: &LimitsState) -> std::io::Result<Option<PathBuf>> {
    if !limits.dirty() {
        return Ok(None);
    }
    std::fs::create_dir_all(&limits.dir)?;
    let (table, settings) = unsaved_paths(&limits.dir, &limits.table_name);
    let table_csv = limits.table.to_csv();
    let settings_toml = limits.settings.to_toml();
    crate::save::atomic_write_all(&[
        (&table, table_csv.as_bytes()),
        (&settings, settings_toml.as_bytes()),
    ])?;
    Ok(Some(table))
}

/// Offers back edits kept by [`keep_unsaved`] when a signal ended the last
/// session: they become the current, unsaved edits and a message says so.
/// The kept files are removed once read (the edits live on in the workbench,
/// and the next signal keeps them again). Files that do not parse are left
/// where they are and the message names them.
pub fn offer_back(app: &mut App) {
    let l = &app.limits;
    let (table_path, settings_path) = unsaved_paths(&l.dir, &l.table_name);
    if !table_path.exists() && !settings_path.exists() {
        return;
    }
    let _ = crate::save::recover(&l.dir);
    let table = read_kept(&table_path, LimitTable::parse);
    let settings = read_kept(&settings_path, SettingsFile::parse);
    match (table, settings) {
        (Ok(table), Ok(settings)) => {
            if let Some(t) = table {
                app.limits.table = t;
            }
            if let Some(s) = settings {
                // The kept settings may name the table under another name; the
                // workbench edits the one it opened.
                app.limits.settings = SettingsFile {
                    table: app.limits.settings.table.clone(),
                    ..s
                };
            }
            app.settings = app.limits.settings.settings();
            let _ = std::fs::remove_file(&table_path);
            let _ = std::fs::remove_file(&settings_path);
            app.info(
                "offered back the unsaved limit and settings edits of the session a signal ended: w saves them, q discards",
            );
        }
        (Err(e), _) | (_, Err(e)) => {
            app.error(format!(
                "unsaved edits of the last session not restored: {e}"
            ));
        }
    }
}

fn read_kept<T, E: std::fmt::Display>(
    path: &Path,
    parse: impl Fn(&str, &str) -> Result<T, E>,
) -> Result<Option<T>, String> {
    if !path.exists() {
        return Ok(None);
    }
    let origin = path.display().to_string();
    let text = crate::input::read_text(path).map_err(|e| format!("{origin}: {e}"))?;
    parse(&text, &origin).map(Some).map_err(|e| e.to_string())
}

/// Runs `f`, turning a panic into an error message (for worker threads: the
/// trial is marked failed, the workbench goes on).
pub fn caught<T>(f: impl FnOnce() -> Result<T, String>) -> Result<T, String> {
    match std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown panic".into());
            Err(format!("internal error (please report): {what}"))
        }
    }
}

/// Installs the panic hook and the abort handler (see the module docs).
/// `restore` puts the terminal back; it runs for panics of the main thread.
pub fn install(restore: fn()) {
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if std::thread::current().name() == Some("main") {
            restore();
            hook(info);
        }
        // Other threads' panics are caught by [`caught`] and shown in the
        // workbench; printing them would scribble over its screen.
    }));
    #[cfg(unix)]
    abort::install();
}

#[cfg(unix)]
mod abort {
    use std::sync::OnceLock;

    /// The terminal settings before raw mode, for the abort handler.
    static SAVED: OnceLock<libc::termios> = OnceLock::new();

    /// Leaves mouse reporting and the alternate screen, shows the cursor.
    const RESET: &[u8] =
        b"\x1b[?1000l\x1b[?1002l\x1b[?1003l\x1b[?1006l\x1b[?1015l\x1b[?1049l\x1b[?25h";

    pub fn install() {
        // SAFETY: tcgetattr fills a plain C struct.
        let mut t: libc::termios = unsafe { std::mem::zeroed() };
        if unsafe { libc::tcgetattr(libc::STDIN_FILENO, &mut t) } == 0 {
            let _ = SAVED.set(t);
        }
        // SAFETY: the handler only calls async-signal-safe functions (write,
        // tcsetattr) and reads a value set before it was installed.
        let _ = unsafe {
            signal_hook::low_level::register(signal_hook::consts::SIGABRT, || {
                libc::write(libc::STDOUT_FILENO, RESET.as_ptr().cast(), RESET.len());
                if let Some(t) = SAVED.get() {
                    libc::tcsetattr(libc::STDIN_FILENO, libc::TCSANOW, t);
                }
            })
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panics_become_messages() {
        let r: Result<(), String> = caught(|| panic!("window list empty"));
        assert_eq!(
            r.unwrap_err(),
            "internal error (please report): window list empty"
        );
        assert_eq!(caught(|| Ok::<_, String>(3)), Ok(3));
        assert_eq!(exit_status(15), 143);
    }

    #[test]
    fn kept_edits_are_offered_back_at_the_next_start() {
        let dir = tempfile::tempdir().unwrap();
        let limits_dir = dir.path().join("joint_limits");
        let open = || {
            let limits = crate::ui::jobs::load_limits(&limits_dir).unwrap();
            App::new("t".into(), dir.path().to_path_buf(), vec![], limits)
        };
        let mut app = open();
        assert_eq!(keep_unsaved(&app.limits).unwrap(), None);
        app.limits.table.rows[0].upper_deg -= 7.0;
        app.limits.settings.lambda1 = 0.5;
        let kept = keep_unsaved(&app.limits).unwrap().unwrap();
        assert!(kept.exists());
        let (table, settings) = (app.limits.table.clone(), app.limits.settings.clone());
        let mut next = open();
        assert!(!next.limits.dirty());
        offer_back(&mut next);
        assert_eq!(next.limits.table, table);
        assert_eq!(next.limits.settings, settings);
        assert_eq!(next.settings.lambda1, 0.5);
        assert!(next.limits.dirty(), "offered back as unsaved edits");
        let (t, s) = unsaved_paths(&limits_dir, &next.limits.table_name);
        assert!(!t.exists() && !s.exists());
        assert!(next.message.as_ref().unwrap().0.contains("offered back"));
    }
}
