//! The screens, one module each: its own state, what its keys do and how it
//! is drawn. A screen reads and changes the shared [`Workbench`] data, answers
//! a key with a [`Reply`] (effects for the runtime, perhaps another screen to
//! open) and never names the router or another screen.
//!
//! [`Workbench`]: super::workbench::Workbench
//! [`Reply`]: super::msg::Reply

pub mod calibration;
pub mod compare;
pub mod histogram;
pub mod limits;
pub mod trial;
pub mod trials;
pub mod views;
