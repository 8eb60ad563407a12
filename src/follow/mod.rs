//! Following a trial while another program is still writing it: the core of
//! `acmw follow`, with nothing of the terminal or the command line.
//!
//! * [`tail`] reads what was appended to a canonical or Euler CSV since the
//!   last look, complete lines only, and notices when the file was
//!   truncated or replaced;
//! * [`exports`] does the same for a folder of Xsens exports, one [`Tail`]
//!   per export, and hands out the rows every sensor has written, aligned
//!   on the packet counter;
//! * [`schedule`] says when the growing trial is solved again: while the
//!   first drift window fills, every few seconds of trial time; then each
//!   time a window `[k * hop, k * hop + window)` is complete;
//! * [`extrapolate`] turns the correction of the samples so far into one for
//!   samples past its end (the last correction held, or for the heading
//!   variants the heading drift continued at its last rate);
//! * [`source`] puts the two behind one interface, [`LiveSource`];
//! * [`live`] keeps the rows read, solves the prefixes in a background
//!   thread through the one pipeline ([`crate::correct::pipeline`]) and
//!   corrects each new row with the newest solution.
//!
//! The final, offline-quality correction is the pipeline's own, run on the
//! whole trial once it stops growing.

pub mod exports;
pub mod extrapolate;
pub mod live;
pub mod schedule;
pub mod source;
pub mod tail;

pub use exports::{exports_ready, ExportsEvent, ExportsTail};
pub use extrapolate::{Extrapolation, ImuExtrapolation, Solution};
pub use live::{Follower, FollowerConfig, Solved};
pub use schedule::Schedule;
pub use source::{push, LiveSource, Look};
pub use tail::{Tail, TailEvent};
