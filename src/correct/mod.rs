//! Correcting trials: the one pipeline every front end calls ([`pipeline`]),
//! above the solvers (`acm`, `baselines`, `ik`).

pub mod pipeline;
