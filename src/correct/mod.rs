//! Correcting trials: the one pipeline every front end calls ([`pipeline`]),
//! and the dispatch from a variant's kind to its solver ([`solve`]), above
//! the solvers (`acm`, `baselines`, `ik`).

pub mod pipeline;
pub mod solve;

pub use solve::{correct_trial, recorrect};
