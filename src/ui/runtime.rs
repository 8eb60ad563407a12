//! The terminal side: raw mode, the event loop, worker threads, file watching.
//!
//! One loop, many producers: the input thread, workers, the watchers and the
//! signal thread all send [`Event`]s over one channel; the loop takes one, drains
//! the rest, updates the state and draws once, only when something happened.

use super::app::{update, App, Effect, Msg};
use super::jobs::{self, list_trials, load_limits, read_limits_on_disk};
use super::render::render;
use super::term::{BasicColours, Caps};
use super::theme::Theme;
use crate::trial::format::could_name_trial;
use crate::trial::is_trial_path;
use crossbeam_channel::{unbounded, Receiver, Sender};
use notify::RecursiveMode;
use notify_debouncer_full::{new_debouncer, new_debouncer_opt, DebounceEventResult};
use ratatui::crossterm::event::{self, DisableMouseCapture, EnableMouseCapture, Event as CtEvent};
use ratatui::crossterm::terminal::{
    self, BeginSynchronizedUpdate, EndSynchronizedUpdate, EnterAlternateScreen,
    LeaveAlternateScreen,
};
use ratatui::crossterm::{cursor, execute};
use ratatui::Terminal;
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::io::{stdout, Write as _};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU8, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How often a trial being followed is looked at.
pub const LIVE_POLL: Duration = Duration::from_millis(100);
/// A trial being followed that has not grown for this long is complete: it
/// is read whole and corrected (a writer that resumes later is followed anew).
pub const LIVE_IDLE: Duration = Duration::from_secs(5);

/// Delay between a limit edit and the re-correction it causes.
pub const RECORRECT_DEBOUNCE: Duration = Duration::from_millis(300);

/// What reaches the event loop.
#[allow(clippy::large_enum_variant)]
enum Event {
    Msg(Msg),
    /// SIGTERM / SIGHUP / SIGINT: restore and leave.
    Signal(i32),
}

/// Whether mouse capture is on (so that leaving turns it off).
static MOUSE_ON: AtomicBool = AtomicBool::new(false);
/// Whether the terminal takes synchronized output.
static SYNC: AtomicBool = AtomicBool::new(false);

/// Leaves raw mode, the alternate screen and mouse capture (the codes of
/// what was turned on only).
pub fn restore_terminal() {
    let mut out = stdout();
    if SYNC.load(Ordering::Relaxed) {
        let _ = execute!(out, EndSynchronizedUpdate);
    }
    if MOUSE_ON.swap(false, Ordering::Relaxed) {
        let _ = execute!(out, DisableMouseCapture);
    }
    let _ = execute!(out, LeaveAlternateScreen, cursor::Show);
    let _ = terminal::disable_raw_mode();
    let _ = out.flush();
}

/// Turns mouse capture on or off.
pub fn set_mouse(on: bool) -> std::io::Result<()> {
    if MOUSE_ON.swap(on, Ordering::Relaxed) != on {
        if on {
            execute!(stdout(), EnableMouseCapture)?;
        } else {
            execute!(stdout(), DisableMouseCapture)?;
        }
    }
    Ok(())
}

/// Where the workbench looks.
pub struct Options {
    /// The trials folder as named by the user.
    pub dir: PathBuf,
    /// The limits folder (normally `./joint_limits`).
    pub limits_dir: PathBuf,
    /// The body model of every trial (None: detected per trial).
    pub model: Option<crate::model::Model>,
    /// Watch the folders by reading them at this interval instead of through
    /// the system's change notifications (network file systems).
    pub poll: Option<Duration>,
    pub theme: Theme,
    /// What the terminal can do (mouse reports, synchronized output).
    pub caps: Caps,
    /// Capture the mouse (where the terminal reports it); off leaves the
    /// terminal's own text selection alone.
    pub mouse: bool,
}

/// Runs the workbench until the user quits or a signal ends it; returns the
/// signal's number in that case.
pub fn run(opts: Options) -> anyhow::Result<Option<i32>> {
    // Listing names is fast; the trials are read in the background.
    let files = list_trials(&opts.dir).map_err(anyhow::Error::msg)?;
    let limits = load_limits(&opts.limits_dir).map_err(anyhow::Error::msg)?;
    let label = opts.dir.display().to_string();
    let mut app = App::new(label, opts.dir.clone(), files, limits);
    app.model = opts.model.clone().map(Arc::new);
    super::signals::offer_back(&mut app);
    app.mouse_possible = opts.caps.mouse;
    app.mouse = opts.caps.mouse && opts.mouse;
    super::signals::install(restore_terminal);
    terminal::enable_raw_mode()?;
    execute!(stdout(), EnterAlternateScreen)?;
    SYNC.store(opts.caps.sync, Ordering::Relaxed);
    set_mouse(app.mouse)?;
    let result = event_loop(&mut app, &opts);
    restore_terminal();
    result
}

fn spawn_input(tx: Sender<Event>) {
    std::thread::spawn(move || loop {
        let msg = match event::read() {
            Ok(CtEvent::Key(k)) => Msg::Key(k),
            Ok(CtEvent::Mouse(m)) => Msg::Mouse(m),
            Ok(CtEvent::Resize(..)) => Msg::Resize,
            Ok(_) => continue,
            Err(_) => return,
        };
        if tx.send(Event::Msg(msg)).is_err() {
            return;
        }
    });
}

fn spawn_signals(tx: Sender<Event>) {
    use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};
    let Ok(mut signals) = signal_hook::iterator::Signals::new([SIGTERM, SIGHUP, SIGINT]) else {
        return;
    };
    std::thread::spawn(move || {
        if let Some(s) = signals.forever().next() {
            let _ = tx.send(Event::Signal(s));
        }
    });
}

/// A folder watcher, kept alive while held: the system's notifications, or
/// polling for file systems that do not deliver them (network mounts).
#[allow(dead_code)] // held for its Drop, never read
pub enum Watcher {
    Native(
        notify_debouncer_full::Debouncer<
            notify::RecommendedWatcher,
            notify_debouncer_full::RecommendedCache,
        >,
    ),
    Poll(notify_debouncer_full::Debouncer<notify::PollWatcher, notify_debouncer_full::NoCache>),
}

/// Paths whose content, name or existence changed. Reading a file (ours
/// included) raises access events and metadata changes touch no content:
/// neither counts, or every read would trigger a reload. When polling, a newer
/// modification time is how a changed content shows (reads do not change it).
fn changed_paths(
    events: &[notify_debouncer_full::DebouncedEvent],
    polling: bool,
) -> impl Iterator<Item = &PathBuf> {
    use notify::event::{EventKind, MetadataKind, ModifyKind};
    events
        .iter()
        .filter(move |e| match e.kind {
            EventKind::Create(_)
            | EventKind::Remove(_)
            | EventKind::Modify(ModifyKind::Data(_) | ModifyKind::Name(_) | ModifyKind::Any) => {
                true
            }
            EventKind::Modify(ModifyKind::Metadata(MetadataKind::WriteTime)) => polling,
            _ => false,
        })
        .flat_map(|e| e.paths.iter())
}

/// Watches `dir` (with `recursive`, its sub-folders too; debounced 250 ms)
/// and hands each batch of content changes ([`changed_paths`]) to
/// `on_change`; with `poll`, by reading the folder at that interval instead
/// of through the system's notifications.
pub fn watch_folder(
    dir: &Path,
    recursive: bool,
    poll: Option<Duration>,
    on_change: impl Fn(Vec<PathBuf>) + Send + 'static,
) -> Option<Watcher> {
    let debounce = Duration::from_millis(250);
    let mode = if recursive {
        RecursiveMode::Recursive
    } else {
        RecursiveMode::NonRecursive
    };
    let handler = move |r: DebounceEventResult| {
        if let Ok(events) = r {
            let paths: Vec<PathBuf> = changed_paths(&events, poll.is_some()).cloned().collect();
            if !paths.is_empty() {
                on_change(paths);
            }
        }
    };
    match poll {
        None => {
            let mut w = new_debouncer(debounce, None, handler).ok()?;
            w.watch(dir, mode).ok()?;
            Some(Watcher::Native(w))
        }
        Some(every) => {
            let config = notify::Config::default().with_poll_interval(every);
            let mut w = new_debouncer_opt::<_, notify::PollWatcher, _>(
                debounce,
                None,
                handler,
                notify_debouncer_full::NoCache,
                config,
            )
            .ok()?;
            w.watch(dir, mode).ok()?;
            Some(Watcher::Poll(w))
        }
    }
}

/// Watches the trials folder: changed and removed trial files, and folders
/// of Xsens exports whose exports change (MT Manager appending to them).
fn watch_trials(dir: &Path, poll: Option<Duration>, tx: Sender<Event>) -> Option<Watcher> {
    let d = dir.to_path_buf();
    watch_folder(dir, true, poll, move |paths| {
        for (name, path) in changed_trials(&d, &paths) {
            // A deleted trial leaves the list, whatever its name says.
            let msg = if !path.exists() {
                Msg::FileRemoved(name)
            } else if is_trial_path(&path) {
                Msg::FileChanged(name, path)
            } else {
                continue;
            };
            let _ = tx.send(Event::Msg(msg));
        }
    })
}

/// The entries of the trials folder `dir` that changed paths touch, by name:
/// a file in it, or a folder in it that holds a changed path deeper down
/// when that folder is itself a trial (a folder of exports that no mapping
/// in `dir` reads; `corrected/` and a mapping's folder are not).
fn changed_trials(dir: &Path, paths: &[PathBuf]) -> BTreeMap<String, PathBuf> {
    let mut listed: Option<BTreeSet<PathBuf>> = None;
    let mut out = BTreeMap::new();
    // The watcher may report paths under the folder's canonical path.
    let canonical = dir.canonicalize().ok();
    for p in paths {
        let rel = p
            .strip_prefix(dir)
            .ok()
            .or_else(|| canonical.as_ref().and_then(|c| p.strip_prefix(c).ok()));
        let Some(rel) = rel else { continue };
        let mut parts = rel.components();
        let Some(first) = parts.next() else { continue };
        let name = first.as_os_str().to_string_lossy().into_owned();
        let entry = dir.join(&name);
        let wanted = if parts.next().is_some() {
            listed
                .get_or_insert_with(|| {
                    crate::trial::folder_trials(dir)
                        .map(|v| v.into_iter().collect())
                        .unwrap_or_default()
                })
                .contains(&entry)
        } else {
            could_name_trial(p) || p.is_dir() || !p.exists()
        };
        if wanted {
            out.insert(name, entry);
        }
    }
    out
}

/// Watches the limits folder: a changed table or settings file is re-read.
fn watch_limits(
    dir: &Path,
    table: String,
    poll: Option<Duration>,
    tx: Sender<Event>,
) -> Option<Watcher> {
    if !dir.is_dir() {
        return None;
    }
    let d = dir.to_path_buf();
    watch_folder(dir, false, poll, move |paths| {
        let relevant = paths.iter().any(|p| {
            p.file_name()
                .is_some_and(|n| n == "settings.toml" || *n == *table.as_str())
        });
        if relevant {
            if let Some(msg) = read_limits_on_disk(&d, &table) {
                let _ = tx.send(Event::Msg(msg));
            }
        }
    })
}

struct Workers {
    tx: Sender<Event>,
    dir: PathBuf,
    /// One job slot per trial: the cancel flag of its newest job.
    jobs: HashMap<String, Arc<AtomicBool>>,
    /// One follow per trial: the cancel flag of its newest.
    follows: HashMap<String, Arc<AtomicBool>>,
    debounce: Option<Instant>,
}

impl Workers {
    fn execute(&mut self, effect: Effect) {
        let tx = self.tx.clone();
        match effect {
            Effect::Load {
                files,
                limits,
                glitch_deg,
                model,
            } => {
                std::thread::spawn(move || {
                    use rayon::prelude::*;
                    files.par_iter().for_each(|(f, p)| {
                        let m = model.as_deref();
                        let msg = match super::signals::caught(|| {
                            Ok(jobs::load_trial(f, p, &limits, glitch_deg, m))
                        }) {
                            Ok(msg) => msg,
                            Err(e) => Msg::Loaded(f.clone(), Err(e)),
                        };
                        let _ = tx.send(Event::Msg(msg));
                    });
                });
            }
            Effect::Run(job) => {
                let cancel = Arc::new(AtomicBool::new(false));
                if let Some(old) = self.jobs.insert(job.file.clone(), cancel.clone()) {
                    old.store(true, Ordering::Relaxed);
                }
                std::thread::spawn(move || {
                    let last = AtomicU8::new(0);
                    let ptx = tx.clone();
                    let progress = |pct: u8| {
                        if last.swap(pct, Ordering::Relaxed) != pct {
                            let _ = ptx.send(Event::Msg(Msg::Progress {
                                file: job.file.clone(),
                                gen: job.gen,
                                pct,
                            }));
                        }
                    };
                    let msg =
                        super::signals::caught(|| Ok(jobs::run_job(&job, &cancel, &progress)))
                            .unwrap_or_else(|e| Msg::RunDone {
                                file: job.file.clone(),
                                gen: job.gen,
                                result: Err(e),
                            });
                    let _ = tx.send(Event::Msg(msg));
                });
            }
            Effect::Follow(job) => {
                let cancel = Arc::new(AtomicBool::new(false));
                if let Some(old) = self.follows.insert(job.file.clone(), cancel.clone()) {
                    old.store(true, Ordering::Relaxed);
                }
                std::thread::spawn(move || {
                    let file = job.file.clone();
                    let gen = job.gen;
                    let send = |m: Msg| tx.send(Event::Msg(m)).is_ok();
                    let caught = super::signals::caught(|| {
                        jobs::live::run(*job, &cancel, LIVE_POLL, LIVE_IDLE, send);
                        Ok(())
                    });
                    if let Err(e) = caught {
                        let _ = tx.send(Event::Msg(Msg::Live {
                            file,
                            gen,
                            event: super::msg::LiveEvent::Ended {
                                result: Err(e),
                                grew: false,
                            },
                        }));
                    }
                });
            }
            Effect::Debounce => self.debounce = Some(Instant::now() + RECORRECT_DEBOUNCE),
            Effect::Mouse(on) => {
                let _ = set_mouse(on);
            }
            other => {
                let dir = self.dir.clone();
                std::thread::spawn(move || {
                    for m in jobs::execute(&dir, other) {
                        let _ = tx.send(Event::Msg(m));
                    }
                });
            }
        }
    }
}

fn draw(
    terminal: &mut Terminal<BasicColours<std::io::Stdout>>,
    app: &App,
    theme: &Theme,
) -> std::io::Result<()> {
    let sync = SYNC.load(Ordering::Relaxed);
    if sync {
        execute!(stdout(), BeginSynchronizedUpdate)?;
    }
    terminal.draw(|f| render(app, theme, f))?;
    if sync {
        execute!(stdout(), EndSynchronizedUpdate)?;
    }
    Ok(())
}

fn event_loop(app: &mut App, opts: &Options) -> anyhow::Result<Option<i32>> {
    let (tx, rx): (Sender<Event>, Receiver<Event>) = unbounded();
    let mut terminal = Terminal::new(BasicColours::new(stdout()))?;
    terminal.clear()?;
    draw(&mut terminal, app, &opts.theme)?;
    spawn_input(tx.clone());
    spawn_signals(tx.clone());
    let _trials_watch = watch_trials(&opts.dir, opts.poll, tx.clone());
    let mut limits_watch = watch_limits(
        &opts.limits_dir,
        app.limits.table_name.clone(),
        opts.poll,
        tx.clone(),
    );
    let mut workers = Workers {
        tx: tx.clone(),
        dir: opts.dir.clone(),
        jobs: HashMap::new(),
        follows: HashMap::new(),
        debounce: None,
    };
    for e in app.start() {
        workers.execute(e);
    }
    let mut next_tick: Option<Instant> = None;
    loop {
        // Ticks only while something plays; the debounce and the tick share the wait.
        next_tick = crate::ui::app::wants_ticks(app)
            .then(|| next_tick.unwrap_or_else(|| Instant::now() + crate::ui::views::TICK));
        let wake = match (workers.debounce, next_tick) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        let first = match wake {
            Some(at) => match rx.recv_timeout(at.saturating_duration_since(Instant::now())) {
                Ok(e) => e,
                Err(crossbeam_channel::RecvTimeoutError::Timeout) => {
                    if workers.debounce.is_some_and(|d| d <= Instant::now()) {
                        workers.debounce = None;
                        Event::Msg(Msg::RecorrectDue)
                    } else {
                        next_tick = None;
                        Event::Msg(Msg::Tick)
                    }
                }
                Err(_) => break,
            },
            None => match rx.recv() {
                Ok(e) => e,
                Err(_) => break,
            },
        };
        let mut batch = vec![first];
        batch.extend(rx.try_iter());
        for ev in batch {
            match ev {
                Event::Signal(s) => {
                    // Edits are kept whatever the signal; a failure to keep
                    // them cannot be shown any more, only printed.
                    if let Err(e) = super::signals::keep_unsaved(&app.limits) {
                        restore_terminal();
                        eprintln!("acmw: cannot keep the unsaved limit edits: {e}");
                    }
                    return Ok(Some(s));
                }
                Event::Msg(m) => {
                    let saved_limits = matches!(m, Msg::LimitsSaved(Ok(_)));
                    for e in update(app, m) {
                        workers.execute(e);
                    }
                    if saved_limits && limits_watch.is_none() {
                        limits_watch = watch_limits(
                            &opts.limits_dir,
                            app.limits.table_name.clone(),
                            opts.poll,
                            tx.clone(),
                        );
                    }
                }
            }
        }
        if app.quit {
            return Ok(None);
        }
        draw(&mut terminal, app, &opts.theme)?;
    }
    Ok(None)
}

#[cfg(test)]
mod tests {
    use super::*;
    use notify::event::{AccessKind, DataChange, EventKind, MetadataKind, ModifyKind};
    use notify_debouncer_full::DebouncedEvent;

    fn event(kind: EventKind, path: &str) -> DebouncedEvent {
        DebouncedEvent::new(
            notify::Event::new(kind).add_path(path.into()),
            Instant::now(),
        )
    }

    #[test]
    fn a_newer_write_time_counts_only_when_polling() {
        let events = [
            event(EventKind::Access(AccessKind::Any), "read.csv"),
            event(
                EventKind::Modify(ModifyKind::Metadata(MetadataKind::WriteTime)),
                "written.csv",
            ),
            event(
                EventKind::Modify(ModifyKind::Metadata(MetadataKind::Permissions)),
                "chmod.csv",
            ),
            event(
                EventKind::Modify(ModifyKind::Data(DataChange::Any)),
                "data.csv",
            ),
        ];
        let names = |polling| -> Vec<String> {
            changed_paths(&events, polling)
                .map(|p| p.display().to_string())
                .collect()
        };
        assert_eq!(names(false), ["data.csv"]);
        assert_eq!(names(true), ["written.csv", "data.csv"]);
    }

    #[test]
    fn polling_sees_a_new_file_and_an_atomic_save() {
        let dir = tempfile::tempdir().unwrap();
        let (tx, rx) = unbounded();
        let poll = Some(Duration::from_millis(50));
        let _w = watch_folder(dir.path(), false, poll, move |paths| {
            let _ = tx.send(paths);
        })
        .expect("a poll watcher starts on any folder");
        let file = dir.path().join("t.csv");
        // Each change must arrive; the deadline only keeps a broken watcher
        // from hanging the suite.
        let arrives = |what: &str| loop {
            let paths = rx
                .recv_timeout(Duration::from_secs(20))
                .unwrap_or_else(|_| panic!("no change seen after {what}"));
            if paths.contains(&file) {
                break;
            }
        };
        std::fs::write(&file, "time\n").unwrap();
        arrives("creating the file");
        // A save one second later (modification times may be coarse).
        std::thread::sleep(Duration::from_millis(1100));
        crate::save::atomic_write(&file, b"time,x\n").unwrap();
        arrives("an atomic save over it");
    }

    #[test]
    fn a_change_inside_an_export_folder_names_that_folder() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("a.csv"), "time\n").unwrap();
        let walk = d.join("walk");
        std::fs::create_dir_all(&walk).unwrap();
        let export = walk.join("walk_00B4227C.txt");
        std::fs::write(
            &export,
            "PacketCounter\tQuat_q0\tQuat_q1\tQuat_q2\tQuat_q3\n",
        )
        .unwrap();
        let corrected = d.join("corrected");
        std::fs::create_dir_all(&corrected).unwrap();
        std::fs::write(d.join("notes.txt~"), "").unwrap();
        let paths = [
            d.join("a.csv"),
            export.clone(),
            corrected.join("a.drift.sto"),
            d.join("gone.csv"),
            d.join("notes.txt~"),
        ];
        let got = changed_trials(d, &paths);
        let names: Vec<&str> = got.keys().map(String::as_str).collect();
        // The file, the folder the export is in (a trial), a removed file
        // (whatever its name); not `corrected/` (not a trial) nor an
        // editor's backup.
        assert_eq!(names, ["a.csv", "gone.csv", "walk"]);
        assert_eq!(got["walk"], walk);
        assert!(crate::trial::is_trial_path(&got["walk"]));
        // The folder as the user named it, the paths as the system reports
        // them (canonical): the same names.
        let named = d.join("walk").join("..");
        let again = changed_trials(&named, &paths);
        assert_eq!(
            again.keys().collect::<Vec<_>>(),
            got.keys().collect::<Vec<_>>()
        );
        assert_eq!(again["walk"], named.join("walk"));
    }

    #[test]
    fn a_deleted_trial_is_reported_removed() {
        let dir = tempfile::tempdir().unwrap();
        let file = dir.path().join("t.csv");
        std::fs::write(&file, "time\n").unwrap();
        let (tx, rx) = unbounded();
        let _w = watch_trials(dir.path(), Some(Duration::from_millis(50)), tx)
            .expect("a poll watcher starts on any folder");
        std::fs::remove_file(&file).unwrap();
        // The deadline only keeps a broken watcher from hanging the suite.
        loop {
            match rx.recv_timeout(Duration::from_secs(20)) {
                Ok(Event::Msg(Msg::FileRemoved(name))) => {
                    assert_eq!(name, "t.csv");
                    break;
                }
                Ok(Event::Msg(Msg::FileChanged(name, _))) => {
                    panic!("{name} was deleted, not changed")
                }
                Ok(_) => {}
                Err(_) => panic!("no removal seen"),
            }
        }
    }
}
