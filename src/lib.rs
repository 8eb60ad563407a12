//! acm-workbench: the Anatomical Constraint Method for IMU joint angles.
//!
//! The numerical core (`rotation`, `model`, `limits`, `trial`, `acm`, `calibration`, `metrics`,
//! `sidecar`, `simulate`, `truth`) knows nothing of the terminal; `ui` and the
//! `acmw` binary are thin layers over it.

pub mod acm;
pub mod analysis;
pub mod baselines;
pub mod batch;
pub mod calibration;
pub mod correct;
pub mod ik;
pub mod input;
pub mod limits;
pub mod metrics;
pub mod model;
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
pub mod ui;
pub mod variant;
pub mod vertical;
pub mod window;
