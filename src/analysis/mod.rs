//! The source's analysis views as numbers (thesis 4.1-4.5, appendices A-C):
//! what the workbench draws and `acmw plot` writes, computed without a terminal.
//!
//! * [`scatter`]: limit classes of joint angles and their 3-D scatter as three
//!   projections, reduced to a raster of the display's resolution;
//! * [`globe`]: the globographic mapping (the distal segment's direction on a
//!   sphere around the joint) and its limit band;
//! * [`applied`]: the applied correction over time;
//! * [`stick`]: the stick figure from segment orientations and lengths.

pub mod applied;
pub mod globe;
pub mod scatter;
pub mod stick;
