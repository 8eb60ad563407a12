//! The terminal workbench (`acmw` without a subcommand). The only part of the
//! library that knows ratatui.
//!
//! * [`app`]: state, messages and `update(&mut App, Msg) -> Vec<Effect>` (no I/O);
//! * [`render`] and one module per screen ([`trials`], [`trial`], [`compare`],
//!   [`limits`]): pure drawing functions of the state;
//! * [`jobs`]: the work behind effects, and a synchronous runner for tests;
//! * [`runtime`]: terminal, event loop, workers, file watching;
//! * [`headless`]: any screen as text (`acmw render`, snapshot tests);
//! * [`views`]: the analysis views ([`scatter`], [`globe`], [`applied`], [`stick`]).

pub mod app;
pub mod applied;
pub mod calibration;
pub mod compare;
pub mod glitches;
pub mod globe;
pub mod heading;
pub mod headless;
pub mod histogram;
pub mod jobs;
pub mod keymap;
pub mod limits;
pub mod pose;
pub mod render;
pub mod runtime;
pub mod scatter;
pub mod signals;
pub mod stick;
pub mod theme;
pub mod trial;
pub mod trials;
pub mod views;

#[cfg(test)]
mod tests;
#[cfg(test)]
mod views_tests;
