//! Supershapes (Gielis surfaces) as reference models for mechanical parts, after Fougerolle et al.,
//! "Radial Supershapes for Solid Modeling" (seed 000) and "Rational Supershapes for Surface
//! Reconstruction" (seed 001). Pure geometry: the superformula, the 3-D supershape with its parametric
//! form and two implicit functions, R-functions to combine implicit functions into Boolean solids, and
//! the global deformations that bring a point into a primitive's canonical frame.
//!
//! Sign convention (the papers'): every implicit function here is positive inside the solid, zero on
//! its surface and negative outside. The station's deviations use the opposite sign (positive outside
//! the material); the conversion belongs to the caller that turns these values into distances.

pub mod csg;
pub mod deform;
pub mod differences;
pub mod distance;
pub mod formula;
pub mod lobes;
pub mod mesh;
pub mod prism;
pub mod recover;
pub mod rfunc;
pub mod shape;
