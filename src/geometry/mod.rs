//! The geometry kernel: pure mathematics, no I/O. Implicit polynomials, their fitting, distances to their zero
//! sets and profile interpolation. Nothing here imports from the station.

pub(crate) mod circle;
pub mod distance;
pub mod faces;
pub mod fit3l;
pub(crate) mod held_out;
pub mod implicit;
pub mod interp;
pub mod nearest;
pub mod normals;
pub mod poly;
pub mod published;
pub mod sampling;
pub(crate) mod section_fit;
pub(crate) mod section_parameters;
pub mod small;
pub mod supershape;
pub mod sweep;
pub(crate) mod taylor;
pub mod trace;
