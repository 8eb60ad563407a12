//! Screens without a terminal: build the state synchronously, draw it into a
//! ratatui `TestBackend`, and turn the buffer into text (optionally with ANSI
//! SGR colours). `acmw render` and the snapshot tests share this path.

use super::app::{act, navigate, open, App, Overlay};
use super::jobs::{list_trials, load_limits, SyncRunner};
use super::keymap::Action;
use super::msg::{Nav, Screen};
use super::render::render;
use super::theme::Theme;
use super::workbench::LimitsState;
use crate::acm::Variant;
use crate::model::Model;
use ratatui::backend::TestBackend;
use ratatui::buffer::{Buffer, CellWidth};
use ratatui::Terminal;
use std::fmt::Write as _;
use std::path::Path;

/// The screens `acmw render` knows.
pub const SCREENS: [&str; 12] = [
    "trials",
    "trial",
    "compare",
    "limits",
    "help",
    "calibration",
    "histogram",
    "scatter",
    "globe",
    "applied",
    "stick",
    "heading",
];

/// A workbench over `dir` (shown as `dir_label`) with every trial read.
pub fn load_app(dir_label: &str, dir: &Path, limits_dir: &Path) -> Result<App, String> {
    load_app_with(dir_label, dir, load_limits(limits_dir)?, None)
}

/// As [`load_app`], with the limits already read and every trial read with
/// `model` (None: detected per trial).
pub fn load_app_with(
    dir_label: &str,
    dir: &Path,
    limits: LimitsState,
    model: Option<Model>,
) -> Result<App, String> {
    let files = list_trials(dir)?;
    let mut app = App::new(dir_label.to_string(), dir.to_path_buf(), files, limits);
    app.model = model.map(std::sync::Arc::new);
    let start = app.start();
    SyncRunner::run(&mut app, start);
    Ok(app)
}

/// What to show.
#[derive(Debug, Clone, Default)]
pub struct Show {
    pub screen: String,
    pub trial: Option<String>,
    pub joint: Option<String>,
    pub variant: Option<Variant>,
}

/// Puts `app` on a screen, running the corrections a trial screen needs.
pub fn show(app: &mut App, s: &Show) -> Result<(), String> {
    if !SCREENS.contains(&s.screen.as_str()) {
        return Err(format!(
            "unknown screen '{}' (screens: {})",
            s.screen,
            SCREENS.join(", ")
        ));
    }
    if let Some(v) = s.variant {
        app.variant = v;
    }
    let trial = match &s.trial {
        Some(t) => {
            let e = app
                .entry(t)
                .ok_or_else(|| format!("no trial '{t}' in {}", app.dir_label))?;
            if let Some(m) = match &e.load {
                super::workbench::LoadState::Failed(m) => Some(m.clone()),
                _ => None,
            } {
                if !matches!(s.screen.as_str(), "trials" | "limits" | "help") {
                    return Err(m);
                }
            }
            Some(t.clone())
        }
        None => app
            .trials
            .iter()
            .find(|e| e.loaded().is_some())
            .map(|e| e.file.clone()),
    };
    if let Some(t) = &trial {
        app.select_file(t);
    }
    match s.screen.as_str() {
        "trial" | "compare" | "scatter" | "globe" | "applied" | "stick" | "heading" => {
            let t = trial.ok_or("no trial could be read")?;
            open(app, t.clone());
            if let Some(j) = &s.joint {
                app.joint = app
                    .open_joints()
                    .iter()
                    .position(|x| x == j)
                    .ok_or_else(|| format!("no joint '{j}' in {t}"))?;
            }
            if app.open_entry().is_some_and(|e| e.results.is_empty()) {
                let fx = act(app, Action::Run);
                SyncRunner::run(app, fx);
            }
            app.message = None;
            if s.screen == "compare" {
                app.screen = Screen::Compare;
            }
            if let Some(kind) = super::msg::ViewKind::from_name(&s.screen) {
                navigate(app, Nav::View(kind));
            }
        }
        "limits" => app.screen = Screen::Limits,
        "help" => app.overlay = Some(Overlay::Help),
        "calibration" => {
            let fx = navigate(app, Nav::Calibration);
            SyncRunner::run(app, fx);
        }
        "histogram" => {
            let t = trial.ok_or("no trial could be read")?;
            open(app, t.clone());
            let fx = navigate(app, Nav::Histogram);
            SyncRunner::run(app, fx);
            if let (Some(j), Some(st)) = (&s.joint, app.histogram.as_mut()) {
                st.joint = st
                    .hists
                    .iter()
                    .position(|h| h.name == *j)
                    .ok_or_else(|| format!("no joint '{j}' in {t}"))?;
            }
        }
        _ => {}
    }
    Ok(())
}

/// Draws the app into a buffer of `w` x `h` cells.
pub fn draw(app: &App, theme: &Theme, w: u16, h: u16) -> Buffer {
    let mut t = Terminal::new(TestBackend::new(w, h)).expect("test backend");
    t.draw(|f| render(app, theme, f)).expect("draw");
    t.backend().buffer().clone()
}

/// The buffer's characters, one line per row (as the snapshots hold them).
pub fn buffer_text(buf: &Buffer) -> String {
    let mut out = String::new();
    let w = buf.area.width as usize;
    if w == 0 {
        return out;
    }
    for row in buf.content.chunks(w) {
        let mut skip = 0u16;
        for c in row {
            if skip == 0 {
                out.push_str(c.symbol());
            }
            skip = skip.max(c.cell_width()).saturating_sub(1);
        }
        out.push('\n');
    }
    out
}

/// The buffer with ANSI SGR codes wherever the style changes.
pub fn buffer_ansi(buf: &Buffer) -> String {
    let mut out = String::new();
    let w = buf.area.width as usize;
    if w == 0 {
        return out;
    }
    for row in buf.content.chunks(w) {
        let mut last: Option<String> = None;
        let mut skip = 0u16;
        for c in row {
            let sgr = super::term::sgr(c.fg, c.bg, c.modifier);
            if last.as_deref() != Some(sgr.as_str()) {
                out.push_str(&sgr);
                last = Some(sgr);
            }
            if skip == 0 {
                out.push_str(c.symbol());
            }
            skip = skip.max(c.cell_width()).saturating_sub(1);
        }
        let _ = write!(out, "\x1b[0m");
        out.push('\n');
    }
    out
}

/// Writes a small fixed folder of trials into `dir` (created): `knee.csv`
/// (knee_calf_z15, 60 s), `fb.csv.gz` (full_body_clean, 30 s), both with their
/// truth beside, and `broken.csv` (not a trial). Snapshot tests, the `acmw
/// render` test and demos use it.
pub fn write_demo_folder(dir: &Path) -> Result<(), String> {
    use crate::simulate::{preset, simulate};
    use crate::trial::{write_trial, TrialFormat};
    std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    for (name, preset_name, seconds) in [
        ("knee.csv", "knee_calf_z15", 60.0),
        ("fb.csv.gz", "full_body_clean", 30.0),
    ] {
        let mut cfg = preset(preset_name).ok_or("unknown preset")?;
        cfg.duration_s = seconds;
        let sim = simulate(&cfg).map_err(|e| e.to_string())?;
        let out = dir.join(name);
        write_trial(&sim.trial, &out, TrialFormat::QuatCsv).map_err(|e| e.to_string())?;
        sim.truth.save_beside(&out).map_err(|e| e.to_string())?;
    }
    std::fs::write(dir.join("broken.csv"), "garbage,1,2\n").map_err(|e| e.to_string())?;
    super::jobs::calibration::write_demo_recordings(dir)?;
    Ok(())
}
