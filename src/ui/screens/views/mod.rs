//! The analysis views of the open trial: 3-D scatter projections
//! ([`scatter`], key `x`), the globographic plot ([`globe`], `o`),
//! the applied correction over time ([`applied`], `a`) and the stick
//! figure ([`stick`], `f`), and the heading drift per IMU
//! ([`heading`], `D`). This module holds their state, their keys
//! and what they share; the numbers come from [`crate::analysis`].

pub mod applied;
pub mod globe;
pub mod heading;
pub mod scatter;
pub mod stick;

use crate::analysis::scatter::Raster;
use crate::model::Joint;
use crate::ui::glyphs::{dots_per_cell, TIME_DIGITS};
use crate::ui::keymap::Action;
pub use crate::ui::msg::ViewKind;
use crate::ui::msg::{Nav, Reply, Screen};
use crate::ui::theme::Theme;
use crate::ui::workbench::{JointAngles, TrialEntry, Workbench};
use ratatui::layout::Rect;
use ratatui::style::Color;
use ratatui::symbols::Marker;
use ratatui::widgets::canvas::{Context, Painter, Shape};
use ratatui::widgets::Paragraph;
use ratatui::Frame;

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
pub fn open(st: &mut ViewsState, app: &Workbench, kind: ViewKind, from_views: bool) {
    if !from_views {
        st.time_s = app.view.cursor_s;
    }
    st.kind = kind;
    st.playing = false;
}

/// What a view draws from: the shared data and the views' own state.
pub struct Ctx<'a> {
    pub wb: &'a Workbench,
    pub views: &'a ViewsState,
}

impl std::ops::Deref for Ctx<'_> {
    type Target = Workbench;
    fn deref(&self) -> &Workbench {
        self.wb
    }
}

fn duration(app: &Workbench) -> f64 {
    app.open_entry()
        .and_then(|e| e.loaded())
        .map_or(0.0, |l| l.trial.duration_s())
}

/// What a key does on a view.
pub fn action(v: &mut ViewsState, app: &mut Workbench, a: Action) -> Reply {
    let d = duration(app);
    let joints = app.open_joints().len();
    let scrub = |v: &mut ViewsState, by: f64| {
        v.time_s = (v.time_s + by).clamp(0.0, d);
        v.playing = false;
    };
    match a {
        Action::Back => {
            v.playing = false;
            app.view.cursor_s = v.time_s.clamp(0.0, d);
            return Reply::nav(Nav::To(Screen::Trial));
        }
        Action::Scatter => return Reply::nav(Nav::View(ViewKind::Scatter)),
        Action::Globe => return Reply::nav(Nav::View(ViewKind::Globe)),
        Action::Applied => return Reply::nav(Nav::View(ViewKind::Applied)),
        Action::Stick => return Reply::nav(Nav::View(ViewKind::Stick)),
        Action::HeadingDrift => return Reply::nav(Nav::View(ViewKind::Heading)),
        Action::TimeColour => v.time_colour = !v.time_colour,
        Action::Up => app.joint = app.joint.saturating_sub(1),
        Action::Down => app.joint = (app.joint + 1).min(joints.saturating_sub(1)),
        Action::Variant => app.next_variant(),
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
    Reply::default()
}

/// Advances a playing stick figure; stops at the end of the trial.
pub fn tick(v: &mut ViewsState, app: &Workbench, in_front: bool) {
    if !in_front || !v.playing {
        v.playing = false;
        return;
    }
    let d = duration(app);
    v.time_s = (v.time_s + PLAY_STEP_S).min(d);
    if v.time_s >= d {
        v.playing = false;
    }
}

/// Whether the runtime should send ticks.
pub fn wants_ticks(v: &ViewsState) -> bool {
    v.playing
}

/// Draws the view in front.
pub fn render(views: &ViewsState, wb: &Workbench, theme: &Theme, f: &mut Frame, area: Rect) {
    let app = &Ctx { wb, views };
    let Some(e) = app.open_entry() else {
        f.render_widget(Paragraph::new("no trial open (Esc)"), area);
        return;
    };
    if e.loaded().is_none() {
        f.render_widget(Paragraph::new("trial not loaded"), area);
        return;
    }
    match app.views.kind {
        ViewKind::Scatter => scatter::render(app, e, theme, f, area),
        ViewKind::Globe => globe::render(app, e, theme, f, area),
        ViewKind::Applied => applied::render(app, e, theme, f, area),
        ViewKind::Stick => stick::render(app, e, theme, f, area),
        ViewKind::Heading => heading::render(app, e, theme, f, area),
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
pub fn joint_data<'a>(app: &Workbench, e: &'a TrialEntry) -> Option<JointData<'a>> {
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
/// The edge of a swing-twist table's region on the globe.
pub const SWING_COLOUR: Color = Color::Cyan;

/// `c`, or no colour when the theme has none (`NO_COLOR`).
pub fn colour(theme: &Theme, c: Color) -> Color {
    if theme.limit.fg.is_none() && theme.raw.fg.is_none() {
        Color::Reset
    } else {
        c
    }
}

/// The canvas marker of the views (`m` switches braille / dots; `--ascii`
/// plain characters).
pub fn marker(app: &Workbench, theme: &Theme) -> Marker {
    theme.glyphs(app.view.braille).fine()
}

/// The marker of each key of a point raster (limit class or time band), so
/// that keys differ by glyph, not by colour alone: the limit classes by
/// [`Glyphs::classes`](crate::ui::glyphs::Glyphs), the time bands by digit
/// when there is no colour.
pub fn key_markers(app: &Workbench, theme: &Theme, time: bool) -> Vec<Marker> {
    let g = theme.glyphs(app.view.braille);
    if !time {
        g.classes.to_vec()
    } else if theme.has_colour() {
        vec![g.fine(); TIME_COLOURS.len()]
    } else {
        TIME_DIGITS.iter().map(|&c| Marker::Custom(c)).collect()
    }
}

/// One key of a raster made for a finer marker, drawn with a coarser one:
/// dot `(c, r)` lands on dot `(c / div.0, r / div.1)`.
struct KeyShape<'a> {
    raster: &'a Raster,
    key: u8,
    colour: Color,
    div: (usize, usize),
}

impl Shape for KeyShape<'_> {
    fn draw(&self, painter: &mut Painter) {
        for (c, r, k) in self.raster.dots() {
            if k == self.key {
                painter.paint(c / self.div.0, r / self.div.1, self.colour);
            }
        }
    }
}

/// Draws the keys of `raster` (made at the resolution of `main`) each on a
/// layer of its own marker, later keys on top; the context is left with
/// `main`.
pub fn draw_keys(
    ctx: &mut Context,
    raster: &Raster,
    colours: &[Color],
    markers: &[Marker],
    main: Marker,
) {
    let (mx, my) = dots_per_cell(main);
    for (k, (m, c)) in markers.iter().zip(colours).enumerate() {
        ctx.marker(*m);
        let (gx, gy) = dots_per_cell(*m);
        ctx.draw(&KeyShape {
            raster,
            key: k as u8,
            colour: *c,
            div: ((mx / gx).max(1), (my / gy).max(1)),
        });
    }
    ctx.marker(main);
}

/// What a marker's point looks like in a legend.
pub fn point_glyph(m: Marker) -> String {
    match m {
        Marker::Braille => "⠿".into(),
        Marker::Dot => "•".into(),
        Marker::Custom(c) => c.to_string(),
        other => crate::ui::glyphs::sample(other).chars().take(1).collect(),
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
