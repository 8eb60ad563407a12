//! Flows and snapshots of the analysis views (scatter, globe, applied
//! correction, stick figure), driven through `update` with fixed data.

use super::{key, keys, snap, snap_at, terminal, Fixture};
use crate::simulate::{simulate, SimConfig};
use crate::trial::{write_trial, TrialFormat};
use crate::ui::app::{update, App, Msg};
use crate::ui::jobs::SyncRunner;
use crate::ui::msg::Screen;
use crate::ui::views::{ViewKind, CLASS_COLOURS, PLAY_STEP_S};
use ratatui::crossterm::event::KeyCode;
use ratatui::style::Color;

fn open_trial(app: &mut App, file: &str) {
    app.select_file(file);
    key(app, KeyCode::Enter);
    assert_eq!(app.screen, Screen::Trial);
    keys(app, "r");
    assert!(app.open_entry().unwrap().running.is_none());
}

/// Puts the cursor on `joint` of the open trial.
fn select_joint(app: &mut App, joint: &str) {
    app.joint = app.open_joints().iter().position(|j| j == joint).unwrap();
}

/// Cells of a colour in columns `[x0, x1)` below the title row.
fn cells_of(app: &App, colour: Color, x0: u16, x1: u16) -> usize {
    let t = terminal(app, 120, 40);
    let buf = t.backend().buffer();
    (2..38)
        .flat_map(|y| (x0..x1).map(move |x| (x, y)))
        .filter(|&(x, y)| buf[(x, y)].fg == colour)
        .count()
}

#[test]
fn scatter_and_globe_colour_the_classes_raw_beside_corrected() {
    let fx = Fixture::new();
    let mut app = fx.app();
    open_trial(&mut app, "knee.csv");
    keys(&mut app, "x");
    assert_eq!(
        (app.screen, app.views.kind),
        (Screen::Views, ViewKind::Scatter)
    );
    // knee_calf_z15: every raw sample is more than 10 deg out (red, left
    // half); after `drift` nearly all are within (blue, right half).
    let [blue, _, red] = CLASS_COLOURS;
    for kind in ["x", "o"] {
        keys(&mut app, kind);
        assert!(cells_of(&app, red, 0, 60) > 10);
        assert_eq!(cells_of(&app, blue, 0, 60), 0);
        assert!(cells_of(&app, blue, 60, 120) > 10);
        assert_eq!(cells_of(&app, red, 60, 120), 0);
    }
    keys(&mut app, "t");
    assert!(app.views.time_colour);
    snap("globe_time", &app);
    keys(&mut app, "xt");
    assert!(!app.views.time_colour);
    // The shoulder: rotation about Y, flexion X, abduction Z.
    let mut app = fx.app();
    open_trial(&mut app, "fb.csv.gz");
    select_joint(&mut app, "l_shoulder");
    keys(&mut app, "o");
    snap("globe_shoulder", &app);
    keys(&mut app, "x");
    snap("scatter_shoulder", &app);
    key(&mut app, KeyCode::Esc);
    assert_eq!(app.screen, Screen::Trial);
}

/// With a swing-twist table (`table = "swing_twist.csv"` in the limits
/// folder) the globe draws the region's edge over the band in both panels,
/// and names it; with the Euler table there is no edge. One size: the
/// globe's snapshot at 120x40.
#[test]
fn globe_draws_a_swing_twist_region() {
    use crate::ui::views::SWING_COLOUR;
    // Cells of the edge's colour inside the panels (below their titles).
    let edge_cells = |app: &App, x0: u16, x1: u16| -> usize {
        let t = terminal(app, 120, 40);
        let buf = t.backend().buffer();
        (3..38)
            .flat_map(|y| (x0..x1).map(move |x| (x, y)))
            .filter(|&(x, y)| buf[(x, y)].fg == SWING_COLOUR)
            .count()
    };
    let fx = Fixture::new();
    let mut euler = fx.app();
    open_trial(&mut euler, "knee.csv");
    keys(&mut euler, "o");
    assert_eq!(edge_cells(&euler, 0, 120), 0);
    let dir = fx.root().join("joint_limits");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("settings.toml"),
        "table = \"swing_twist.csv\"\nlambda1 = 0.05\nwindow_s = 60.0\nhop_s = 30.0\n",
    )
    .unwrap();
    let mut app = fx.app();
    assert_eq!(app.limits.table.model_name(), "swing-twist");
    open_trial(&mut app, "knee.csv");
    keys(&mut app, "o");
    assert_eq!(app.views.kind, ViewKind::Globe);
    assert!(edge_cells(&app, 0, 60) > 10);
    assert!(edge_cells(&app, 60, 120) > 10);
    let text = format!("{}", terminal(&app, 120, 40).backend());
    assert_eq!(text.matches("swing-twist edge").count(), 2, "{text}");
    snap_at("globe_swing_twist", &app, 120, 40);
    // The shoulder (twist about Y): the region's edge away from the band's.
    let mut app = fx.app();
    open_trial(&mut app, "fb.csv.gz");
    select_joint(&mut app, "l_shoulder");
    keys(&mut app, "o");
    assert!(edge_cells(&app, 0, 60) > 10);
    snap_at("globe_swing_twist_shoulder", &app, 120, 40);
}

#[test]
fn applied_correction_marks_window_centres() {
    // 150 s: five windows (60 s, hop 30 s) whose centres the view marks.
    let fx = Fixture::new();
    let mut cfg = SimConfig::full_body(5);
    cfg.duration_s = 150.0;
    let sim = simulate(&cfg).unwrap();
    let dir = fx.root().join("trials");
    write_trial(&sim.trial, &dir.join("long.csv"), TrialFormat::QuatCsv).unwrap();
    let mut app = fx.app();
    open_trial(&mut app, "long.csv");
    select_joint(&mut app, "l_knee");
    keys(&mut app, "a");
    assert_eq!(app.views.kind, ViewKind::Applied);
    let text = format!("{}", terminal(&app, 120, 40).backend());
    assert!(text.contains("4 window centres"), "{text}");
    assert!(text.contains("centres at 30, 60, 90, ... s"), "{text}");
    snap("applied_windows", &app);
    // basic: one window for the whole trial.
    while app.variant != crate::acm::Variant::Basic {
        keys(&mut app, "v");
    }
    let text = format!("{}", terminal(&app, 120, 40).backend());
    assert!(text.contains("1 windows"), "{text}");
}

#[test]
fn stick_figure_scrubs_and_plays() {
    let fx = Fixture::new();
    let mut app = fx.app();
    open_trial(&mut app, "fb.csv.gz");
    keys(&mut app, "f");
    assert_eq!(app.views.kind, ViewKind::Stick);
    assert_eq!(app.views.time_s, 0.0);
    snap("stick_fb", &app);
    for _ in 0..5 {
        key(&mut app, KeyCode::Right);
    }
    key(&mut app, KeyCode::Left);
    assert_eq!(app.views.time_s, 4.0);
    keys(&mut app, "p");
    assert!(app.views.playing && crate::ui::app::wants_ticks(&app));
    for _ in 0..10 {
        update(&mut app, Msg::Tick);
    }
    assert!((app.views.time_s - (4.0 + 10.0 * PLAY_STEP_S)).abs() < 1e-9);
    snap("stick_playing", &app);
    // Space pauses too; playing stops at the end of the trial.
    key(&mut app, KeyCode::Char(' '));
    assert!(!app.views.playing);
    key(&mut app, KeyCode::End);
    keys(&mut app, "p");
    assert_eq!(app.views.time_s, 0.0, "play from the end starts over");
    app.views.time_s = 29.95;
    for _ in 0..5 {
        update(&mut app, Msg::Tick);
    }
    assert!(!app.views.playing);
    // Back on the trial screen the cursor is where the figure stood.
    key(&mut app, KeyCode::Esc);
    assert_eq!(app.screen, Screen::Trial);
    assert!(
        (app.view.cursor_s
            - app
                .open_entry()
                .unwrap()
                .loaded()
                .unwrap()
                .trial
                .duration_s())
        .abs()
            < 1e-9
    );
    SyncRunner::send(&mut app, Msg::Tick);
    assert!(!app.views.playing);
}
