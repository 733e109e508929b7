//! The `Machine` trait: what the station needs of a CMM, whatever the driver behind it. The I++ DME
//! client in [`crate::client`] implements it; with the `mock` feature, mockall's `MockMachine`,
//! `MockScanning` and `MockMoveReporting` do too.
//!
//! Every method takes `&self` so that one task can abort or query the error state while another waits
//! for a move or reads a scan.

mod error;
mod event;
mod stream;
mod types;

use std::sync::Arc;

use async_trait::async_trait;
use tokio::sync::broadcast;

use crate::wire::EventTag;

pub use error::{Error, ErrorKind, TransportError};
pub use event::Event;
pub use stream::{MoveReports, ScanStream};
pub use types::{
    CurveScan, Density, InPlaneScan, InPlaneSpacing, MeasuredPoint, MoveReportRate, Nominal,
    ScanPoint, Speeds, Xyz,
};

/// A coordinate measuring machine.
#[cfg_attr(feature = "mock", mockall::automock)]
#[async_trait]
pub trait Machine: Send + Sync {
    /// A receiver of the machine's events (emergency stops, warnings, link loss) from now on.
    fn events(&self) -> broadcast::Receiver<Event>;

    /// Starts a session; this also clears the machine's errors.
    async fn start_session(&self) -> Result<(), Error>;

    /// Ends the session; the machine stops every daemon.
    async fn end_session(&self) -> Result<(), Error>;

    /// Moves to the home position; the machine must be homed before any other motion.
    async fn home(&self) -> Result<(), Error>;

    async fn is_homed(&self) -> Result<bool, Error>;

    /// Activates the tool of this name (a move: the head may go to a tool changer).
    async fn change_tool(&self, name: &str) -> Result<(), Error>;

    /// The active tool's calibrated ball radius, mm (I++ `Tool.AvrRadius`; read only: it comes from
    /// the tool's qualification).
    async fn tool_radius(&self) -> Result<f64, Error>;

    async fn set_speeds(&self, speeds: Speeds) -> Result<(), Error>;

    /// Where the probe ball's centre is now (I++ `Get(X(), Y(), Z())`): a station that starts or resumes
    /// with the probe in an unknown place retracts from here before any move across the part.
    async fn position(&self) -> Result<Xyz, Error>;

    /// Moves the probe ball's centre to `target`.
    async fn go_to(&self, target: Xyz) -> Result<(), Error>;

    /// Measures one point: approaches `nominal` along `normal` (the outward surface normal) and probes.
    async fn pt_meas(&self, nominal: Xyz, normal: Xyz) -> Result<MeasuredPoint, Error>;

    /// Stops all motion and aborts every command in progress or queued. Motion stays locked out until
    /// `clear_all_errors` succeeds.
    async fn abort(&self) -> Result<(), Error>;

    /// Clears the machine's error state, lifting the lockout of motion.
    async fn clear_all_errors(&self) -> Result<(), Error>;

    /// Whether the machine is in an error state; answered ahead of queued commands.
    async fn in_error(&self) -> Result<bool, Error>;

    /// Scanning, if the machine's probe can scan (a touch-trigger probe cannot).
    fn scanning(&self) -> Option<Arc<dyn Scanning>>;

    /// Position reports while moving, if the machine sends them.
    fn move_reporting(&self) -> Option<Arc<dyn MoveReporting>>;
}

/// Scanning a profile, the points streaming while the probe moves.
#[cfg_attr(feature = "mock", mockall::automock)]
#[async_trait]
pub trait Scanning: Send + Sync {
    /// Starts a scan of a closed profile of unknown shape; returns once the machine has accepted it.
    async fn scan_in_plane(&self, plan: InPlaneScan) -> Result<ScanStream, Error>;

    /// Starts a scan along a known nominal curve; returns once the machine has accepted it.
    async fn scan_on_curve(&self, plan: CurveScan) -> Result<ScanStream, Error>;
}

/// Reports of the position while the machine moves.
#[cfg_attr(feature = "mock", mockall::automock)]
#[async_trait]
pub trait MoveReporting: Send + Sync {
    /// Starts reporting; stop it before starting another.
    async fn start_move_reports(&self, rate: MoveReportRate) -> Result<MoveReports, Error>;

    /// Stops the reports of the daemon tagged `daemon`; its stream then ends.
    async fn stop_move_reports(&self, daemon: EventTag) -> Result<(), Error>;
}
