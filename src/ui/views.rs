//! The analysis views of the open trial: 3-D scatter projections
//! ([`super::scatter`], key `x`), the globographic plot ([`super::globe`], `o`),
//! the applied correction over time ([`super::applied`], `a`) and the stick
//! figure ([`super::stick`], `f`), and the heading drift per IMU
//! ([`super::heading`], `D`). This module holds their state, their keys
//! and what they share; the numbers come from [`crate::analysis`].

use super::app::{App, JointAngles, Screen, TrialEntry};
use super::keymap::Action;
use super::theme::Theme;
use crate::analysis::scatter::Raster;
use crate::model::Joint;
use ratatui::layout::Rect;
use ratatui::style::Color;
use ratatui::symbols::Marker;
use ratatui::widgets::canvas::{Painter, Shape};
use ratatui::widgets::Paragraph;
use ratatui::Frame;

/// Which view is in front.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ViewKind {
    #[default]
    Scatter,
    Globe,
    Applied,
    Stick,
    /// The heading drift per IMU of a heading variant ([`super::heading`]).
    Heading,
}

impl ViewKind {
    /// The view's name in titles and `acmw render`.
    pub fn name(self) -> &'static str {
        match self {
            ViewKind::Scatter => "scatter",
            ViewKind::Globe => "globe",
            ViewKind::Applied => "applied",
            ViewKind::Stick => "stick",
            ViewKind::Heading => "heading",
        }
    }

    /// The view of a name.
    pub fn from_name(name: &str) -> Option<ViewKind> {
        [
            ViewKind::Scatter,
            ViewKind::Globe,
            ViewKind::Applied,
            ViewKind::Stick,
            ViewKind::Heading,
        ]
        .into_iter()
        .find(|k| k.name() == name)
    }
}

/// State of the analysis views.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ViewsState {
    pub kind: ViewKind,
    /// Colour points by time instead of by limit class.
    pub time_colour: bool,
    /// The stick figure's time, seconds from the first sample.
    pub time_s: f64,
    /// The stick figure plays (advanced by [`tick`]).
    pub playing: bool,
}

/// Trial seconds the stick figure advances per tick while playing.
pub const PLAY_STEP_S: f64 = 0.1;
/// Interval between ticks while playing (real time: plays at 1x).
pub const TICK: std::time::Duration = std::time::Duration::from_millis(100);

/// Opens a view from the trial screen.
pub fn open(app: &mut App, kind: ViewKind) {
    if app.screen != Screen::Views {
        app.views.time_s = app.view.cursor_s;
    }
    app.views.kind = kind;
    app.views.playing = false;
    app.screen = Screen::Views;
}

fn duration(app: &App) -> f64 {
    app.open_entry()
        .and_then(|e| e.loaded())
        .map_or(0.0, |l| l.trial.duration_s())
}

/// What a key does on a view.
pub fn action(app: &mut App, a: Action) {
    let d = duration(app);
    let joints = app.open_joints().len();
    let v = &mut app.views;
    let scrub = |v: &mut ViewsState, by: f64| {
        v.time_s = (v.time_s + by).clamp(0.0, d);
        v.playing = false;
    };
    match a {
        Action::Back => {
            v.playing = false;
            app.view.cursor_s = v.time_s.clamp(0.0, d);
            app.screen = Screen::Trial;
        }
        Action::Scatter => open(app, ViewKind::Scatter),
        Action::Globe => open(app, ViewKind::Globe),
        Action::Applied => open(app, ViewKind::Applied),
        Action::Stick => open(app, ViewKind::Stick),
        Action::HeadingDrift => open(app, ViewKind::Heading),
        Action::TimeColour => v.time_colour = !v.time_colour,
        Action::Up => app.joint = app.joint.saturating_sub(1),
        Action::Down => app.joint = (app.joint + 1).min(joints.saturating_sub(1)),
        Action::Variant => super::app::next_variant(app),
        Action::Marker => app.view.braille = !app.view.braille,
        Action::Left | Action::CursorLeft => scrub(v, -1.0),
        Action::Right | Action::CursorRight => scrub(v, 1.0),
        Action::PageUp => scrub(v, -10.0),
        Action::PageDown => scrub(v, 10.0),
        Action::Home => scrub(v, -d),
        Action::End => scrub(v, d),
        Action::Play | Action::Choose if v.kind == ViewKind::Stick => {
            if v.time_s >= d {
                v.time_s = 0.0;
            }
            v.playing = !v.playing;
        }
        _ => {}
    }
}

/// Advances a playing stick figure; stops at the end of the trial.
pub fn tick(app: &mut App) {
    if app.screen != Screen::Views || !app.views.playing {
        app.views.playing = false;
        return;
    }
    let d = duration(app);
    let v = &mut app.views;
    v.time_s = (v.time_s + PLAY_STEP_S).min(d);
    if v.time_s >= d {
        v.playing = false;
    }
}

/// Whether the runtime should send ticks.
pub fn wants_ticks(app: &App) -> bool {
    app.screen == Screen::Views && app.views.playing
}

/// Draws the view in front.
pub fn render(app: &App, theme: &Theme, f: &mut Frame, area: Rect) {
    let Some(e) = app.open_entry() else {
        f.render_widget(Paragraph::new("no trial open (Esc)"), area);
        return;
    };
    if e.loaded().is_none() {
        f.render_widget(Paragraph::new("trial not loaded"), area);
        return;
    }
    match app.views.kind {
        ViewKind::Scatter => super::scatter::render(app, e, theme, f, area),
        ViewKind::Globe => super::globe::render(app, e, theme, f, area),
        ViewKind::Applied => super::applied::render(app, e, theme, f, area),
        ViewKind::Stick => super::stick::render(app, e, theme, f, area),
        ViewKind::Heading => super::heading::render(app, e, theme, f, area),
    }
}

/// The selected joint of the open trial with its uncorrected and (when the
/// variant has run) corrected angles.
pub struct JointData<'a> {
    pub joint: &'a Joint,
    pub raw: JointAngles,
    pub cor: Option<JointAngles>,
}

/// The joint the views show (the trial screen's selection).
pub fn joint_data<'a>(app: &App, e: &'a TrialEntry) -> Option<JointData<'a>> {
    let l = e.loaded()?;
    let name = l.before.get(app.joint)?.joint.clone();
    let joint = l.model.joint(&name)?;
    let raw = l.angles.get(&l.trial, joint)?;
    let cor = e
        .results
        .get(&app.variant)
        .and_then(|r| r.angles.get(&r.correction.corrected, joint));
    Some(JointData { joint, raw, cor })
}

/// Colours of the limit classes (thesis: blue within, purple within 10 deg,
/// red beyond) and of the time bands (earliest first).
pub const CLASS_COLOURS: [Color; 3] = [Color::Blue, Color::Magenta, Color::Red];
pub const TIME_COLOURS: [Color; 6] = [
    Color::Blue,
    Color::Cyan,
    Color::Green,
    Color::Yellow,
    Color::LightRed,
    Color::Magenta,
];
/// The limit band of the globe (thesis: yellow).
pub const BAND_COLOUR: Color = Color::Yellow;

/// `c`, or no colour when the theme has none (`NO_COLOR`).
pub fn colour(theme: &Theme, c: Color) -> Color {
    if theme.limit.fg.is_none() && theme.raw.fg.is_none() {
        Color::Reset
    } else {
        c
    }
}

/// The canvas marker of the views (`m` switches braille / dots).
pub fn marker(app: &App) -> Marker {
    if app.view.braille {
        Marker::Braille
    } else {
        Marker::Dot
    }
}

/// Dots across and down a canvas of `area` (inside its border) with `marker`.
pub fn resolution(area: Rect, marker: Marker, bordered: bool) -> (usize, usize) {
    let b = if bordered { 2 } else { 0 };
    let (w, h) = (
        area.width.saturating_sub(b) as usize,
        area.height.saturating_sub(b) as usize,
    );
    match marker {
        Marker::Braille => (2 * w, 4 * h),
        _ => (w, h),
    }
}

/// Bounds `bx` x `by` widened about their centre on one axis so that one unit
/// spans as many dots across as down (a circle stays round): braille dots are
/// square on a 1:2 cell, dot markers are twice as tall as wide.
pub fn square_around(
    area: Rect,
    marker: Marker,
    bordered: bool,
    bx: [f64; 2],
    by: [f64; 2],
) -> ([f64; 2], [f64; 2]) {
    let (cx, cy) = ((bx[0] + bx[1]) / 2.0, (by[0] + by[1]) / 2.0);
    let (x, y) = square_bounds(
        area,
        marker,
        bordered,
        (bx[1] - bx[0]) / 2.0,
        (by[1] - by[0]) / 2.0,
    );
    ([cx + x[0], cx + x[1]], [cy + y[0], cy + y[1]])
}

/// Bounds around `[-rx, rx] x [-ry, ry]` widened on one axis as
/// [`square_around`] does.
pub fn square_bounds(
    area: Rect,
    marker: Marker,
    bordered: bool,
    rx: f64,
    ry: f64,
) -> ([f64; 2], [f64; 2]) {
    let (w, h) = resolution(area, marker, bordered);
    let (w, h) = (w.max(1) as f64, h.max(1) as f64);
    // Physical size of the dot grid, in cell widths.
    let (pw, ph) = match marker {
        Marker::Braille => (w / 2.0, h / 2.0),
        _ => (w, 2.0 * h),
    };
    let (mut x, mut y) = (rx, ry);
    if x / pw < y / ph {
        x = y * pw / ph;
    } else {
        y = x * ph / pw;
    }
    ([-x, x], [-y, y])
}

/// A raster drawn on a canvas whose resolution it was made for, dot by dot;
/// a cell takes the colour of its highest key.
pub struct RasterShape<'a> {
    pub raster: &'a Raster,
    pub colours: &'a [Color],
}

impl Shape for RasterShape<'_> {
    fn draw(&self, painter: &mut Painter) {
        for key in 0..self.colours.len() as u8 {
            for (c, r, k) in self.raster.dots() {
                if k == key {
                    painter.paint(c, r, self.colours[k as usize]);
                }
            }
        }
    }
}
