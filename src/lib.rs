//! acm-workbench: the Anatomical Constraint Method for IMU joint angles.
//!
//! The numerical core (`rotation`, `model`, `limits`, `trial`, `acm`, `calibration`, `metrics`,
//! `sidecar`, `simulate`, `truth`, ...) knows nothing of the terminal or the command line:
//! built with `--no-default-features` the library pulls none of clap, ratatui, crossterm or
//! notify. The `terminal` feature (on by default, needed by the `acmw` binary) adds `ui`, the
//! workbench; the command line lives in the binary. Choice types carry their names for
//! parsers in [`names`].

pub mod acm;
pub mod analysis;
pub mod baselines;
pub mod batch;
pub mod builtin_box;
pub mod calibration;
pub mod correct;
pub mod file_names;
pub mod follow;
pub mod ik;
pub mod input;
pub mod limits;
pub mod located;
pub mod metrics;
pub mod model;
pub mod names;
pub mod plot;
pub mod pose;
pub mod reference;
pub mod report;
pub mod rotation;
pub mod run;
pub mod save;
pub mod sidecar;
pub mod simulate;
pub mod trial;
#[cfg(feature = "terminal")]
pub mod ui;
pub mod variant;
pub mod vertical;
pub mod window;
