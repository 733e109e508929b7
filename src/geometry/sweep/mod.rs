//! The stylus's swept volume along planned moves (issue 6), after Seong, Kim, Kim and Elber, "Perspective
//! silhouette of a general swept volume" (seed 002): the stylus as a moving rigid body, the envelope of its ball
//! (closed forms, and the characteristic curves traced numerically), the clearance of a planned move against the
//! part's model by conservative advancement, the perspective silhouette of the swept ball, and the inverse: the
//! contact points a ball-centre path came from (probe-radius compensation).

pub mod ball_system;
pub mod charts;
pub mod clearance;
pub mod closest;
pub mod compensation;
pub mod envelope;
pub mod mesh;
pub mod motion;
pub mod part;
pub mod silhouette;
pub mod stylus;
pub mod tracer;

#[cfg(test)]
mod tests;
