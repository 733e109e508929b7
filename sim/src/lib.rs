//! zeroset-sim: the simulated CMM. Its parts are analytic ground truth written independently of the station's
//! geometry code, so that a fitting bug in the station cannot hide itself in the simulator.
//!
//! [`simulator::run`] serves every machine of a [`config::SimConfig`]; each machine is a
//! [`protocol::Controller`] (the I++ DME server, free of I/O) driven by a [`machine::Machine`] task on its
//! [`link::Link`], measuring a [`part::Part`] with a [`probe`] under [`kinematics`] limits, with
//! [`faults`] on demand and a [`transcript`].

pub mod cli;
pub mod config;
pub mod faults;
pub mod kinematics;
pub mod link;
pub mod machine;
pub mod naca;
pub mod part;
pub mod probe;
pub mod protocol;
pub mod simulator;
pub mod transcript;
