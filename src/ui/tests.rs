//! Snapshot tests of every screen and state, flows driven through `update`,
//! and a no-panic test at tiny sizes. Background work runs through
//! [`SyncRunner`]; nothing sleeps.

mod flows;
mod layers;
mod live;
mod views;

use super::app::{update, App, Msg, Overlay};
use super::headless::{buffer_ansi, draw, load_app, show, write_demo_folder, Show, SCREENS};
use super::jobs::SyncRunner;
use super::msg::Screen;
use super::render::render;
use super::theme::Theme;
use crate::acm::Variant;
use ratatui::backend::TestBackend;
use ratatui::crossterm::event::{KeyCode, KeyEvent};
use ratatui::Terminal;
use std::path::Path;

/// Sizes every screen is checked at.
pub const SIZES: [(u16, u16); 3] = [(60, 20), (80, 24), (120, 40)];

pub(super) struct Fixture {
    tmp: tempfile::TempDir,
}

impl Fixture {
    pub(super) fn new() -> Fixture {
        let tmp = tempfile::tempdir().unwrap();
        write_demo_folder(&tmp.path().join("trials")).unwrap();
        Fixture { tmp }
    }

    pub(super) fn root(&self) -> &Path {
        self.tmp.path()
    }

    pub(super) fn app(&self) -> App {
        load_app(
            "trials",
            &self.root().join("trials"),
            &self.root().join("joint_limits"),
        )
        .unwrap()
    }
}

pub(super) fn key(app: &mut App, c: KeyCode) {
    SyncRunner::send(app, Msg::Key(KeyEvent::from(c)));
}

pub(super) fn keys(app: &mut App, s: &str) {
    for c in s.chars() {
        key(app, KeyCode::Char(c));
    }
}

pub(super) fn terminal(app: &App, w: u16, h: u16) -> Terminal<TestBackend> {
    let mut t = Terminal::new(TestBackend::new(w, h)).unwrap();
    t.draw(|f| render(app, &Theme::default(), f)).unwrap();
    t
}

pub(super) fn snap(name: &str, app: &App) {
    for (w, h) in SIZES {
        let t = terminal(app, w, h);
        insta::assert_snapshot!(format!("{name}_{w}x{h}"), t.backend());
    }
}

/// A snapshot at one size `w` x `h`, named `{name}_{w}x{h}` as [`snap`]'s.
pub(super) fn snap_at(name: &str, app: &App, w: u16, h: u16) {
    let t = terminal(app, w, h);
    insta::assert_snapshot!(format!("{name}_{w}x{h}"), t.backend());
}

/// Style snapshots (ANSI SGR per cell): under `NO_COLOR` at every size,
/// where only glyphs and modifiers tell things apart, and in colour at
/// 80x24.
pub(super) fn snap_styled(name: &str, app: &App) {
    let plain = Theme::builtin("dark", true).unwrap();
    for (w, h) in SIZES {
        let text = buffer_ansi(&draw(app, &plain, w, h));
        insta::assert_snapshot!(format!("{name}_nocolor_{w}x{h}"), text);
    }
    let text = buffer_ansi(&draw(app, &Theme::default(), 80, 24));
    insta::assert_snapshot!(format!("{name}_colour_80x24"), text);
}

fn shown(app: &mut App, screen: &str, trial: &str) {
    show(
        app,
        &Show {
            screen: screen.into(),
            trial: Some(trial.into()),
            ..Show::default()
        },
    )
    .unwrap();
}

#[test]
fn screens() {
    // The states `acmw render SCREEN --dir trials --trial knee.csv` prints.
    let fx = Fixture::new();
    for screen in SCREENS {
        let mut app = fx.app();
        shown(&mut app, screen, "knee.csv");
        snap(screen, &app);
        snap_styled(screen, &app);
    }
}

#[test]
fn trials_states() {
    let fx = Fixture::new();
    let mut app = fx.app();
    // A load error row is part of the list.
    assert!(app.trials.iter().any(|t| matches!(
        &t.load,
        super::workbench::LoadState::Failed(m) if m.starts_with("broken.csv:")
    )));
    // A run in progress at a fixed percentage.
    app.select_file("knee.csv");
    let fx_run = update(&mut app, Msg::Key(KeyEvent::from(KeyCode::Char('r'))));
    assert_eq!(fx_run.len(), 1);
    let gen = app.entry("knee.csv").unwrap().gen;
    update(
        &mut app,
        Msg::Progress {
            file: "knee.csv".into(),
            gen,
            pct: 42,
        },
    );
    // A stale job's progress is ignored.
    update(
        &mut app,
        Msg::Progress {
            file: "knee.csv".into(),
            gen: gen - 1,
            pct: 7,
        },
    );
    assert_eq!(app.entry("knee.csv").unwrap().running, Some(42));
    snap("trials_running", &app);
    // Filter and sort.
    keys(&mut app, "/kn");
    key(&mut app, KeyCode::Enter);
    assert_eq!(app.visible().len(), 1);
    snap("trials_filtered", &app);
    key(&mut app, KeyCode::Esc);
    assert_eq!(app.visible().len(), 3);
    keys(&mut app, "s");
    assert_eq!(app.sort, super::app::SortKey::Duration);
    assert_eq!(app.trials[0].file, "fb.csv.gz");
}

#[test]
fn trial_flow_run_compare_save() {
    let fx = Fixture::new();
    let mut app = fx.app();
    app.select_file("fb.csv.gz");
    key(&mut app, KeyCode::Enter);
    assert_eq!(app.screen, Screen::Trial);
    assert!(app.open_entry().unwrap().results.is_empty());
    keys(&mut app, "r");
    let e = app.open_entry().unwrap();
    assert_eq!(e.results.len(), Variant::ALL.len());
    assert_eq!(e.running, None);
    // Zoom, pan, cursor, variant, joint.
    keys(&mut app, "++");
    assert_eq!(app.view.zoom, 2);
    key(&mut app, KeyCode::Right);
    assert!(app.view.start_s > 0.0);
    key(&mut app, KeyCode::End);
    assert!(app.view.cursor_s > 29.9);
    keys(&mut app, "v");
    assert_eq!(app.variant, Variant::DriftCentroid);
    key(&mut app, KeyCode::Down);
    assert_eq!(app.joint, 1);
    snap("trial_zoomed", &app);
    keys(&mut app, "m");
    assert!(!app.view.braille);
    // Compare: choose drift, quitting asks, save, the trials screen shows it.
    keys(&mut app, "c");
    assert_eq!(app.screen, Screen::Compare);
    key(&mut app, KeyCode::Left);
    key(&mut app, KeyCode::Char(' '));
    assert_eq!(app.open_entry().unwrap().chosen, Some(Variant::Drift));
    keys(&mut app, "q");
    assert_eq!(app.overlay, Some(Overlay::QuitConfirm));
    snap("quit_confirm", &app);
    keys(&mut app, "n");
    assert!(!app.quit && app.overlay.is_none());
    keys(&mut app, "w");
    let out = fx.root().join("trials/corrected/fb.drift.csv.gz");
    assert!(out.exists(), "{:?}", app.message);
    assert!(fx
        .root()
        .join("trials/corrected/fb.drift.csv.gz.acmw.json")
        .exists());
    assert_eq!(
        app.open_entry().unwrap().results[&Variant::Drift]
            .saved
            .as_deref(),
        Some("corrected/fb.drift.csv.gz")
    );
    snap("compare_saved", &app);
    key(&mut app, KeyCode::Esc);
    key(&mut app, KeyCode::Esc);
    assert_eq!(app.screen, Screen::Trials);
    assert!(!app.unsaved());
    keys(&mut app, "q");
    assert!(app.quit);
}

#[test]
fn pose_calibration_toggles_and_ik_shows() {
    let fx = Fixture::new();
    let mut app = fx.app();
    shown(&mut app, "trial", "fb.csv.gz");
    for _ in 0..10 {
        keys(&mut app, ".");
    }
    let cursor = app.view.cursor_s;
    assert!(cursor > 0.0);
    keys(&mut app, "P");
    let e = app.open_entry().unwrap();
    let l = e.loaded().unwrap();
    let p = l.pose.as_ref().expect("calibrated");
    // At the sample under the cursor (50 Hz).
    let crate::pose::PoseTime::At(at) = p.calibration.at else {
        panic!("a single instant")
    };
    assert!((at - cursor).abs() <= 0.01 && (at * 50.0 - (at * 50.0).round()).abs() < 1e-9);
    assert!(l.uncalibrated.is_some());
    // Every variant ran again on the calibrated trial.
    assert_eq!(e.results.len(), Variant::ALL.len());
    assert!(e
        .results
        .values()
        .all(|r| r.correction.corrected.imus.len() == 13));
    while app.variant != Variant::Ik {
        keys(&mut app, "v");
    }
    let e = app.open_entry().unwrap();
    assert!(e.results[&Variant::Ik].correction.ik.is_some());
    snap("trial_pose_ik", &app);
    // P again: back to the trial as read, corrected again.
    keys(&mut app, "P");
    let e = app.open_entry().unwrap();
    assert!(e.loaded().unwrap().pose.is_none());
    assert_eq!(e.results.len(), Variant::ALL.len());
    // The knee trial has no base IMU: the calibration says why.
    shown(&mut app, "trial", "knee.csv");
    keys(&mut app, "P");
    let (m, is_error) = app.message.clone().unwrap();
    assert!(is_error && m.contains("base IMU"), "{m}");
    assert!(app.open_entry().unwrap().loaded().unwrap().pose.is_none());
}

#[test]
fn compare_scrolls_to_the_baselines_and_saves_one() {
    let fx = Fixture::new();
    let mut app = fx.app();
    app.select_file("fb.csv.gz");
    key(&mut app, KeyCode::Enter);
    keys(&mut app, "r");
    keys(&mut app, "c");
    for _ in 0..Variant::ALL.len() {
        if Variant::ALL[app.compare_col] != Variant::Mueller {
            key(&mut app, KeyCode::Right);
        }
    }
    assert_eq!(Variant::ALL[app.compare_col], Variant::Mueller);
    key(&mut app, KeyCode::Char(' '));
    assert_eq!(app.open_entry().unwrap().chosen, Some(Variant::Mueller));
    // At 80 columns the variants scroll: rivest and mueller are in view.
    snap("compare_baselines", &app);
    // Short of rows even in two columns, the status list scrolls to the
    // selected variant and says where it is.
    let small = super::headless::buffer_text(&draw(&app, &Theme::default(), 60, 16));
    assert!(small.contains("status, variant 7/12"), "{small}");
    assert!(small.contains("> mueller"), "{small}");
    keys(&mut app, "w");
    let out = fx.root().join("trials/corrected/fb.mueller.csv.gz");
    assert!(out.exists(), "{:?}", app.message);
    let sc = crate::sidecar::Sidecar::load(&crate::sidecar::sidecar_path(&out)).unwrap();
    assert_eq!(sc.variant, Variant::Mueller);
    for j in &sc.joints {
        let is_elbow = j.joint.ends_with("elbow");
        assert_eq!(j.baseline.is_some(), is_elbow, "{}", j.joint);
    }
}

fn limits_app(fx: &Fixture) -> App {
    let mut app = fx.app();
    shown(&mut app, "trial", "knee.csv");
    keys(&mut app, "L");
    assert_eq!(app.screen, Screen::Limits);
    // knee, Y, upper.
    app.limits.row = app
        .limits
        .table
        .rows
        .iter()
        .position(|r| r.joint == "knee" && r.axis == 1)
        .unwrap();
    app.limits.col = 4;
    app
}

#[test]
fn limits_editor_states_and_save() {
    let fx = Fixture::new();
    let mut app = limits_app(&fx);
    snap("limits_clean", &app);
    // Invalid as typed: cannot be committed.
    key(&mut app, KeyCode::Enter);
    for _ in 0..3 {
        key(&mut app, KeyCode::Backspace);
    }
    keys(&mut app, "-1");
    let err = app.limits.edit.as_ref().unwrap().error.clone().unwrap();
    assert!(err.contains("upper_deg > lower_deg"), "{err}");
    snap("limits_invalid", &app);
    key(&mut app, KeyCode::Enter);
    assert!(
        app.limits.edit.is_some(),
        "an invalid value cannot be committed"
    );
    key(&mut app, KeyCode::Esc);
    assert!(app.limits.edit.is_none() && !app.limits.dirty());
    // A valid edit re-runs the open trial's knee joint.
    let before = app.entry("knee.csv").unwrap().results[&Variant::Drift]
        .correction
        .clone();
    let gen = app.entry("knee.csv").unwrap().gen;
    key(&mut app, KeyCode::Enter);
    for _ in 0..3 {
        key(&mut app, KeyCode::Backspace);
    }
    keys(&mut app, "60");
    key(&mut app, KeyCode::Enter);
    assert!(app.limits.dirty());
    let e = app.entry("knee.csv").unwrap();
    assert_eq!(e.gen, gen + 1, "re-corrected after the edit");
    assert_ne!(e.results[&Variant::Drift].correction, before);
    snap("limits_unsaved", &app);
    // Save: CSV and settings written in joint_limits/ (created).
    keys(&mut app, "w");
    assert!(!app.limits.dirty());
    let csv = std::fs::read_to_string(fx.root().join("joint_limits/table_3_2.csv")).unwrap();
    assert!(csv.contains("knee,Y,flexion/extension,0,60,,0"), "{csv}");
    assert!(fx.root().join("joint_limits/settings.toml").exists());
    // Our own write coming back from the watcher changes nothing.
    let (t, s) = (app.limits.table.clone(), app.limits.settings.clone());
    update(&mut app, Msg::LimitsOnDisk(t, s));
    assert!(app.overlay.is_none());
}

#[test]
fn reload_conflict_keep_or_take() {
    let fx = Fixture::new();
    let mut app = limits_app(&fx);
    let mut disk = app.limits.table.clone();
    disk.rows[0].upper_deg = 29.0;
    let settings = app.limits.settings.clone();
    // Without edits: taken at once.
    update(&mut app, Msg::LimitsOnDisk(disk.clone(), settings.clone()));
    assert_eq!(app.limits.table.rows[0].upper_deg, 29.0);
    assert!(!app.limits.dirty());
    // With edits: asks.
    key(&mut app, KeyCode::Enter);
    key(&mut app, KeyCode::Backspace);
    key(&mut app, KeyCode::Backspace);
    key(&mut app, KeyCode::Backspace);
    keys(&mut app, "99");
    key(&mut app, KeyCode::Enter);
    assert!(app.limits.dirty());
    disk.rows[0].upper_deg = 28.0;
    update(&mut app, Msg::LimitsOnDisk(disk.clone(), settings.clone()));
    assert_eq!(app.overlay, Some(Overlay::ReloadConflict));
    snap("reload_conflict", &app);
    keys(&mut app, "K");
    assert!(app.overlay.is_none() && app.limits.dirty());
    assert_eq!(app.limits.saved_table.rows[0].upper_deg, 28.0);
    disk.rows[0].upper_deg = 27.0;
    update(&mut app, Msg::LimitsOnDisk(disk, settings));
    keys(&mut app, "T");
    assert!(!app.limits.dirty());
    assert_eq!(app.limits.table.rows[0].upper_deg, 27.0);
}

#[test]
fn folder_changes_update_the_list() {
    let fx = Fixture::new();
    let mut app = fx.app();
    let dir = fx.root().join("trials");
    std::fs::copy(dir.join("knee.csv"), dir.join("again.csv")).unwrap();
    SyncRunner::send(
        &mut app,
        Msg::FileChanged("again.csv".into(), dir.join("again.csv")),
    );
    assert_eq!(app.trials.len(), 4);
    assert!(app.entry("again.csv").unwrap().loaded().is_some());
    SyncRunner::send(&mut app, Msg::FileRemoved("knee.csv".into()));
    assert_eq!(app.trials.len(), 3);
    assert!(app.entry("knee.csv").is_none());
}

#[test]
fn tiny_sizes_never_panic() {
    let fx = Fixture::new();
    for screen in SCREENS {
        let mut app = fx.app();
        shown(&mut app, screen, "fb.csv.gz");
        for (w, h) in [(0, 0), (1, 1), (2, 2), (40, 12), (20, 5), (79, 6)] {
            let _ = draw(&app, &Theme::default(), w, h);
        }
    }
}

/// Under `NO_COLOR` the trial screen still tells raw, corrected and the
/// limits apart (by glyph, named in the legend), its three charts share one
/// plot column, and the y ticks are round values in degrees.
#[test]
fn trial_charts_read_without_colour() {
    let fx = Fixture::new();
    let mut app = fx.app();
    shown(&mut app, "trial", "knee.csv");
    let plain = Theme::builtin("dark", true).unwrap();
    let is_braille = |c: char| ('\u{2801}'..='\u{28ff}').contains(&c);
    for (w, h) in SIZES {
        let buf = draw(&app, &plain, w, h);
        assert!(buf
            .content
            .iter()
            .all(|c| c.fg == ratatui::style::Color::Reset && c.bg == ratatui::style::Color::Reset));
        let text = super::headless::buffer_text(&buf);
        // The legend, shortened where the full one does not fit.
        let items = if w >= 80 {
            ["⠒⠒ raw", "▄▀ drift", "══ limits", "┊ cursor"]
        } else {
            ["⠒raw", "▄drift", "═lim", "┊cur"]
        };
        let legend = text.lines().find(|l| l.contains(items[0])).expect("legend");
        for item in items {
            assert!(legend.contains(item), "{w}x{h}: {legend}");
        }
        let plot: String = text.lines().filter(|l| l.contains("°│")).collect();
        assert!(plot.chars().any(is_braille), "raw in braille");
        assert!(
            plot.contains('▄') || plot.contains('▀'),
            "corrected in half blocks"
        );
        assert!(plot.contains('═'), "limit lines");
        // Every tick ends its label at the same column, a multiple of 10 deg
        // here (the knee's angles span tens of degrees).
        let mut columns = std::collections::BTreeSet::new();
        let mut ticks = 0;
        for line in text.lines() {
            let chars: Vec<char> = line.chars().collect();
            if let Some(k) = chars.windows(2).position(|p| p == ['°', '│']) {
                columns.insert(k);
                let start = chars[..k]
                    .iter()
                    .rposition(|c| *c == ' ' || *c == '│')
                    .unwrap()
                    + 1;
                let v: f64 = chars[start..k].iter().collect::<String>().parse().unwrap();
                assert_eq!(v % 10.0, 0.0, "{line}");
                ticks += 1;
            }
        }
        assert_eq!(columns.len(), 1, "{w}x{h}: plot areas aligned\n{text}");
        assert!(ticks >= 3, "{w}x{h}: {ticks} ticks");
        assert!(text.contains("at cursor raw"), "cursor values labelled");
    }
    // ASCII: nothing but ASCII in the plots and the legend.
    let ascii = Theme::default().with_ascii(true);
    let text = super::headless::buffer_text(&draw(&app, &ascii, 80, 24));
    assert!(
        !text
            .chars()
            .any(|c| is_braille(c) || "▄▀█•═┄┊×".contains(c)),
        "{text}"
    );
    assert!(text.contains(".. raw  ** drift  == limits"), "{text}");
}

#[test]
fn ticks_are_round_and_few() {
    use super::axis::ticks;
    assert_eq!(ticks(-7.2, 136.4, 5), (50.0, vec![0.0, 50.0, 100.0]));
    assert_eq!(
        ticks(-7.2, 136.4, 8).1,
        vec![0.0, 20.0, 40.0, 60.0, 80.0, 100.0, 120.0]
    );
    let (step, v) = ticks(-0.8, 0.9, 4);
    assert_eq!(step, 0.5);
    assert_eq!(v, vec![-0.5, 0.0, 0.5]);
    assert!(ticks(f64::NAN, 1.0, 3).1.is_empty());
    assert_eq!(ticks(3.0, 3.5, 1).1, vec![3.0]);
}

/// Clears the cell being edited and types `text`.
fn retype(app: &mut App, text: &str) {
    use ratatui::crossterm::event::KeyModifiers;
    let ctrl_u = KeyEvent::new(KeyCode::Char('u'), KeyModifiers::CONTROL);
    SyncRunner::send(app, Msg::Key(ctrl_u));
    keys(app, text);
}

fn edit_error(app: &App) -> Option<String> {
    app.limits.edit.as_ref().and_then(|e| e.error.clone())
}

#[test]
fn limits_editor_keeps_centroids_inside_and_lambda2_in_range() {
    let fx = Fixture::new();
    let mut app = fx.app();
    keys(&mut app, "L");
    assert_eq!(app.screen, Screen::Limits);
    let row = |app: &App, joint: &str, axis: usize| {
        app.limits
            .table
            .rows
            .iter()
            .position(|r| r.joint == joint && r.axis == axis)
            .unwrap()
    };
    // Hip Y: -30..100, centroid 12 (Table 3-2, Table 3-3).
    app.limits.row = row(&app, "hip", 1);
    app.limits.col = 5;
    key(&mut app, KeyCode::Enter);
    retype(&mut app, "110");
    let e = edit_error(&app).expect("rejected");
    assert!(
        e.contains("centroid 110 must lie within the limits [-30, 100]"),
        "{e}"
    );
    key(&mut app, KeyCode::Enter);
    assert!(app.limits.edit.is_some(), "not committed");
    key(&mut app, KeyCode::Esc);
    // Limits moved past the centroid: the same rule.
    app.limits.col = 4;
    key(&mut app, KeyCode::Enter);
    retype(&mut app, "10");
    let e = edit_error(&app).expect("rejected");
    assert!(
        e.contains("centroid 12 must lie within the limits [-30, 10]"),
        "{e}"
    );
    key(&mut app, KeyCode::Esc);
    // lambda2: a stated range, and the joint's three rows, said before and after.
    app.limits.col = 6;
    let text = super::headless::buffer_text(&draw(&app, &Theme::default(), 120, 40));
    assert!(text.contains("applies to hip's three rows"), "{text}");
    key(&mut app, KeyCode::Enter);
    retype(&mut app, "1e9");
    let e = edit_error(&app).expect("rejected");
    assert!(e.contains("within 0..1000"), "{e}");
    retype(&mut app, "40");
    assert_eq!(edit_error(&app), None);
    key(&mut app, KeyCode::Enter);
    let hips: Vec<f64> = app
        .limits
        .table
        .rows
        .iter()
        .filter(|r| r.joint == "hip")
        .map(|r| r.lambda2)
        .collect();
    assert_eq!(hips, [40.0; 3]);
    let (m, _) = app.message.clone().unwrap();
    assert!(
        m.contains("lambda2 of hip set to 40 on its three rows"),
        "{m}"
    );
    // Only where a centroid is set: the knee has none.
    app.limits.row = row(&app, "knee", 1);
    key(&mut app, KeyCode::Enter);
    retype(&mut app, "30");
    let e = edit_error(&app).expect("rejected");
    assert!(e.contains("knee has none"), "{e}");
    retype(&mut app, "0");
    assert_eq!(edit_error(&app), None);
    key(&mut app, KeyCode::Esc);
}

/// Keys that move through lists and the help: Home/End and a counter on
/// the trials list, h/l as Left/Right, Esc pressed together with the next
/// key (an Alt-key) carried out as both, and the help scrolling at 60x20.
#[test]
fn lists_help_and_keys_after_esc() {
    use ratatui::crossterm::event::KeyModifiers;
    let fx = Fixture::new();
    let mut app = fx.app();
    let text = |app: &App, w, h| super::headless::buffer_text(&draw(app, &Theme::default(), w, h));
    assert!(text(&app, 80, 24).contains("trial 1/3 (sort: name)"));
    key(&mut app, KeyCode::End);
    assert_eq!(app.selected, 2);
    assert!(text(&app, 80, 24).contains("trial 3/3 (sort: name)"));
    key(&mut app, KeyCode::Home);
    assert_eq!(app.selected, 0);
    // Esc and `s` at once: the filter ends, then the list is sorted.
    keys(&mut app, "/kn");
    assert!(app.filter_editing);
    SyncRunner::send(
        &mut app,
        Msg::Key(KeyEvent::new(KeyCode::Char('s'), KeyModifiers::ALT)),
    );
    assert!(!app.filter_editing);
    assert_eq!(app.sort, super::app::SortKey::Duration);
    // h and l pan as Left and Right do; L opens the limits.
    shown(&mut app, "trial", "fb.csv.gz");
    keys(&mut app, "++l");
    let panned = app.view.start_s;
    assert!(panned > 0.0);
    keys(&mut app, "h");
    assert!(app.view.start_s < panned);
    // The trial screen's help is longer than 60x20 shows: it scrolls.
    keys(&mut app, "?");
    let first = text(&app, 60, 20);
    assert!(first.contains("Keys 1-"), "{first}");
    assert!(!first.contains("mean correction angle"), "{first}");
    key(&mut app, KeyCode::End);
    let last = text(&app, 60, 20);
    assert!(last.contains("mean correction angle"), "{last}");
    key(&mut app, KeyCode::Up);
    assert_eq!(app.help_scroll + 1, app.help_max.get());
    keys(&mut app, "x");
    assert!(app.overlay.is_none(), "other keys close the help");
    assert_eq!(app.screen, Screen::Trial);
    keys(&mut app, "L");
    assert_eq!(app.screen, Screen::Limits);
}

/// A click selects a trial and a second click opens it; `M` turns mouse
/// capture off and on (an effect for the runtime).
#[test]
fn mouse_clicks_select_and_m_toggles_capture() {
    use ratatui::crossterm::event::{KeyModifiers, MouseButton, MouseEvent, MouseEventKind};
    let fx = Fixture::new();
    let mut app = fx.app();
    let _ = draw(&app, &Theme::default(), 80, 24);
    let click = |row| {
        Msg::Mouse(MouseEvent {
            kind: MouseEventKind::Down(MouseButton::Left),
            column: 10,
            row,
            modifiers: KeyModifiers::NONE,
        })
    };
    // Title row, header row, then the trials (broken.csv, fb.csv.gz, knee.csv).
    SyncRunner::send(&mut app, click(3));
    assert_eq!(app.selected_entry().unwrap().file, "fb.csv.gz");
    SyncRunner::send(&mut app, click(20));
    assert_eq!(
        app.selected_entry().unwrap().file,
        "fb.csv.gz",
        "below the list"
    );
    SyncRunner::send(&mut app, click(3));
    assert_eq!(app.screen, Screen::Trial);
    assert_eq!(app.open.as_deref(), Some("fb.csv.gz"));
    let at = |column, row| {
        Msg::Mouse(MouseEvent {
            kind: MouseEventKind::Down(MouseButton::Left),
            column,
            row,
            modifiers: KeyModifiers::NONE,
        })
    };
    // The trial screen's joint list: title row, header, then the joints.
    let _ = draw(&app, &Theme::default(), 80, 24);
    SyncRunner::send(&mut app, at(5, 4));
    assert_eq!(app.joint, 2);
    // The compare screen at 80 columns: joint names (12) and the raw column
    // (14) after a 2-column margin, then 15-column variant columns.
    keys(&mut app, "rc");
    assert_eq!(app.screen, Screen::Compare);
    let _ = draw(&app, &Theme::default(), 80, 24);
    SyncRunner::send(&mut app, at(28 + 2 * 15 + 3, 2));
    assert_eq!(app.compare_col, 2, "a click on a column header picks it");
    SyncRunner::send(&mut app, at(28 + 2 * 15 + 3, 2));
    let chosen = app.open_entry().unwrap().chosen;
    assert_eq!(chosen, Some(Variant::ALL[2]), "a second click chooses it");
    SyncRunner::send(&mut app, at(5, 1 + 2 + 5));
    assert_eq!(app.joint, 5, "a click on a joint row selects it");
    SyncRunner::send(&mut app, at(28 + 15 + 3, 1 + 2 + 5));
    assert_eq!(app.compare_col, 1, "a click on a cell picks its column");
    // The limits editor: a click selects a cell, a second one edits it.
    keys(&mut app, "L");
    assert_eq!(app.screen, Screen::Limits);
    let _ = draw(&app, &Theme::default(), 80, 24);
    let before = app.limits.row;
    SyncRunner::send(&mut app, at(40, 2 + 3));
    assert_ne!(app.limits.row, before);
    let (row, col) = (app.limits.row, app.limits.col);
    SyncRunner::send(&mut app, at(40, 2 + 3));
    assert!(app.limits.edit.is_some(), "row {row} col {col}");
    key(&mut app, KeyCode::Esc);
    assert!(!app.mouse);
    let fx_m = update(&mut app, Msg::Key(KeyEvent::from(KeyCode::Char('M'))));
    assert!(app.mouse);
    assert!(matches!(fx_m[..], [super::msg::Effect::Mouse(true)]));
    let fx_m = update(&mut app, Msg::Key(KeyEvent::from(KeyCode::Char('M'))));
    assert!(matches!(fx_m[..], [super::msg::Effect::Mouse(false)]));
    app.mouse_possible = false;
    keys(&mut app, "M");
    assert!(!app.mouse && app.message.as_ref().unwrap().1);
}

/// What a key can change, for telling whether it did anything.
fn fingerprint(app: &App) -> String {
    format!(
        "{:?}",
        (
            (
                app.screen,
                &app.overlay,
                app.selected,
                app.variant,
                app.joint
            ),
            (app.view.zoom, app.view.start_s, app.view.cursor_s),
            (&app.message, app.filter_editing, app.sort, app.compare_col),
            (
                app.limits.edit.is_some(),
                app.limits.col,
                app.limits.row,
                app.quit
            ),
            (
                app.views.kind,
                app.views.time_colour,
                app.views.playing,
                app.calib.selected,
                app.view.braille,
            ),
            app.histogram.as_ref().map(|h| {
                (
                    h.span,
                    h.suggestion.is_some(),
                    h.overwrite.is_some(),
                    h.joint,
                )
            }),
            app.open_entry().map(|e| e.chosen),
        )
    )
}

/// Every hint in every screen's status bar names a key that has the hint's
/// action, and pressing it there does something: it changes the state or
/// asks the runtime for work (from a state where it can: Home after End,
/// Left after Right, ...). Driven through `update`; nothing sleeps.
#[test]
fn every_hint_does_what_it_says() {
    use super::keymap::{self, hints, Action, BINDINGS};
    let fx = Fixture::new();
    let base = fx.app();
    let key_of = |a: Action| {
        let b = BINDINGS.iter().find(|b| b.action == a).unwrap();
        KeyEvent::from(b.code[0])
    };
    for (screen, setup) in [
        ("trials", ""),
        ("trial", "+"),
        ("compare", ""),
        ("limits", ""),
        ("scatter", ""),
        ("calibration", ""),
        ("histogram", ""),
    ] {
        let mut app = base.clone();
        shown(&mut app, screen, "knee.csv");
        keys(&mut app, setup);
        app.message = None;
        let scope = super::render::scope_of(app.screen);
        let line = super::render::hints(&app);
        for h in hints(scope) {
            let what = format!("{screen}: `{}` {}", h.keys, h.text);
            assert!(line.contains(&format!("{} {}", h.keys, h.text)), "{what}");
            assert_eq!(
                keymap::action(&KeyEvent::from(h.key)),
                Some(h.action),
                "{what}"
            );
            let prep = match h.action {
                Action::Home => Some(Action::End),
                Action::End => Some(Action::Home),
                Action::Left => Some(Action::Right),
                Action::Right => Some(Action::Left),
                Action::Down => Some(Action::Up),
                Action::Up => Some(Action::Down),
                Action::Scatter => Some(Action::Globe),
                _ => None,
            };
            let acts = |from: &App| {
                let mut a = from.clone();
                let before = fingerprint(&a);
                let effects = update(&mut a, Msg::Key(KeyEvent::from(h.key)));
                !effects.is_empty() || fingerprint(&a) != before
            };
            let mut did = acts(&app);
            if !did {
                if let Some(p) = prep {
                    let mut from = app.clone();
                    SyncRunner::send(&mut from, Msg::Key(key_of(p)));
                    from.message = None;
                    did = acts(&from);
                }
            }
            assert!(did, "{what} did nothing");
        }
    }
}

/// Every key the help of a screen lists under that screen does something
/// there (from a state where it can), and every key the screen's status bar
/// hints at is in its help. The keys that answer a question (`K`/`T` of the
/// reload conflict) are pressed in `reload_conflict_keep_or_take`. Driven
/// through `update`; nothing sleeps.
#[test]
fn every_key_in_every_screens_help_does_something() {
    use super::keymap::{self, hints, Action, Scope, BINDINGS};
    let fx = Fixture::new();
    let base = fx.app();
    let key_of = |a: Action| {
        let b = BINDINGS.iter().find(|b| b.action == a).unwrap();
        KeyEvent::from(b.code[0])
    };
    for (screen, setup) in [
        ("trials", ""),
        ("trial", "+"),
        ("compare", ""),
        ("limits", ""),
        ("scatter", ""),
        ("calibration", ""),
        ("histogram", ""),
    ] {
        let mut app = base.clone();
        shown(&mut app, screen, "knee.csv");
        keys(&mut app, setup);
        app.message = None;
        let scope = super::render::scope_of(app.screen);
        let in_help = |a: Action| {
            BINDINGS
                .iter()
                .any(|b| b.action == a && (b.scope == scope || b.scope == Scope::Everywhere))
        };
        for h in hints(scope) {
            assert!(
                in_help(h.action),
                "{screen}: hint `{} {}` is not in the help",
                h.keys,
                h.text
            );
        }
        let own = BINDINGS.iter().filter(|b| b.scope == scope);
        for b in own.filter(|b| !matches!(b.action, Action::KeepMine | Action::TakeFile)) {
            for code in b.code {
                let what = format!("{screen}: {code:?} ({})", b.help);
                assert_eq!(
                    keymap::action(&KeyEvent::from(*code)),
                    Some(b.action),
                    "{what}"
                );
                let prep = match b.action {
                    Action::Home => Some(Action::End),
                    Action::End => Some(Action::Home),
                    Action::Left => Some(Action::Right),
                    Action::Right => Some(Action::Left),
                    Action::ZoomOut => Some(Action::ZoomIn),
                    Action::CursorLeft => Some(Action::CursorRight),
                    Action::Scatter => Some(Action::Globe),
                    Action::Play => Some(Action::Stick),
                    _ => None,
                };
                let acts = |from: &App| {
                    let mut a = from.clone();
                    let before = fingerprint(&a);
                    let effects = update(&mut a, Msg::Key(KeyEvent::from(*code)));
                    !effects.is_empty() || fingerprint(&a) != before
                };
                let mut did = acts(&app);
                if !did {
                    if let Some(p) = prep {
                        let mut from = app.clone();
                        SyncRunner::send(&mut from, Msg::Key(key_of(p)));
                        from.message = None;
                        did = acts(&from);
                    }
                }
                assert!(did, "{what} did nothing");
            }
        }
    }
}

#[test]
fn hints_are_dropped_whole_when_narrow() {
    use super::render::fit_hints;
    let line = "r run  v variant  ? help  q quit";
    assert_eq!(fit_hints(line, 80), "r run  v variant  q quit  ? help");
    assert_eq!(fit_hints(line, 24), "r run  v variant  ? help");
    assert_eq!(fit_hints(line, 23), "r run  ? help");
    assert_eq!(fit_hints(line, 6), "? help");
    assert_eq!(fit_hints("a b  c d", 5), "a b");
}

#[test]
fn compare_shows_and_overrides_autos_choice_per_joint() {
    let fx = Fixture::new();
    let mut app = fx.app();
    app.select_file("fb.csv.gz");
    key(&mut app, KeyCode::Enter);
    keys(&mut app, "r");
    keys(&mut app, "c");
    key(&mut app, KeyCode::Down);
    let joint = app.open_joints()[app.joint].clone();
    let record = |app: &App| {
        let e = app.open_entry().unwrap();
        let c = &e.results[&Variant::Auto].correction;
        c.joint(&joint).unwrap().auto.clone().unwrap()
    };
    let before = record(&app);
    assert_eq!(before.overridden, None);
    // `o`: the next candidate, recorded as the user's over auto's own.
    keys(&mut app, "o");
    let after = record(&app);
    let candidates = crate::acm::auto::CANDIDATES;
    let k = candidates.iter().position(|v| *v == before.chosen).unwrap();
    assert_eq!(after.chosen, candidates[(k + 1) % candidates.len()]);
    assert_eq!(after.overridden, Some(before.chosen));
    assert!(
        after.reason.starts_with("chosen by the user"),
        "{}",
        after.reason
    );
    // The other variants are untouched; auto's joint now is that variant's
    // candidate: its figures are the chosen candidate's.
    assert_eq!(app.open_entry().unwrap().results.len(), Variant::ALL.len());
    while Variant::ALL[app.compare_col] != Variant::Auto {
        key(&mut app, KeyCode::Right);
    }
    snap("compare_auto_override", &app);
    // Saved with the override in the sidecar.
    key(&mut app, KeyCode::Char(' '));
    keys(&mut app, "w");
    let out = fx.root().join("trials/corrected/fb.auto.csv.gz");
    assert!(out.exists(), "{:?}", app.message);
    let sc = crate::sidecar::Sidecar::load(&crate::sidecar::sidecar_path(&out)).unwrap();
    let j = sc.joints.iter().find(|j| j.joint == joint).unwrap();
    assert_eq!(j.auto.as_ref().unwrap().overridden, Some(before.chosen));
    // Cycling through every candidate comes back to auto's own choice.
    for _ in 1..candidates.len() {
        keys(&mut app, "o");
    }
    let back = record(&app);
    assert_eq!((back.chosen, back.overridden), (before.chosen, None));
}
