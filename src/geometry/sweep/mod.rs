//! The probe ball's sweep along a scan: its envelope is the measured surface (seed 002).
pub mod compensation;
