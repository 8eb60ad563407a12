//! The terminal workbench (`acmw` without a subcommand). The only part of the
//! library that knows ratatui.
//!
//! * [`workbench`]: the data every screen shares (trials, limits, selection),
//!   and [`loaded`], a trial as read;
//! * [`msg`]: messages, effects and navigation (a leaf);
//! * [`screens`]: one module per screen, each with its state, keys and drawing;
//! * [`app`]: the router, `update(&mut App, Msg) -> Vec<Effect>` (no I/O);
//! * [`axis`]: round y-axis ticks the charts share;
//! * [`render`]: the frame around the screens (title, status bar, overlays);
//! * [`jobs`]: the work behind effects, and a synchronous runner for tests;
//! * [`runtime`]: terminal, event loop, workers, file watching;
//! * [`headless`]: any screen as text (`acmw render`, snapshot tests).

pub mod app;
pub mod axis;
pub mod cells;
pub mod glitches;
pub mod glyphs;
pub mod headless;
pub mod jobs;
pub mod keymap;
pub mod loaded;
pub mod msg;
pub mod pose;
pub mod render;
pub mod runtime;
pub mod screens;
pub mod signals;
pub mod term;
pub mod theme;
pub mod workbench;

pub use screens::views;

#[cfg(test)]
mod tests;
