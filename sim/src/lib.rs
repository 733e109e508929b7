//! zeroset-sim: the simulated CMM. Its parts are analytic ground truth written independently of the station's
//! geometry code, so that a fitting bug in the station cannot hide itself in the simulator.

pub mod naca;
