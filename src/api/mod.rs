//! The control API between the daemon and the operator CLI: newline-delimited JSON over a Unix domain socket.
//!
//! A client writes one [`RequestLine`] per line and reads one [`ReplyLine`] per request. After a
//! [`Request::Subscribe`] the daemon answers [`Reply::Subscribed`] and from then on writes one [`EventLine`] per
//! line on that connection until the client hangs up. Every line carries the API version, so that a CLI and a
//! daemon of different builds refuse each other clearly instead of misreading each other.

use std::path::PathBuf;

use crate::analysis::section::{SectionBestFit, SectionParametersReport};
use serde::{Deserialize, Serialize};

#[doc(hidden)]
pub mod fuzz;
mod results;
mod states;

pub(crate) use results::counted;
pub use results::{DeviationStats, Verdict};
pub use states::{FaultKind, JobPhase, MachineFault, MachineState};

/// The version of these types; bumped on any change a reader of the old version would misread.
pub const API_VERSION: u32 = 2;

/// One request line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RequestLine {
    pub version: u32,
    #[serde(flatten)]
    pub request: Request,
}

/// What a client asks of the daemon.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "request", rename_all = "snake_case")]
pub enum Request {
    /// The station: machines, the current job and its progress.
    Status,
    /// Scan the master instance of a part and fit its reference model.
    Teach { part: String },
    /// Scan every instance of the part with this serial number and report its deviations.
    Inspect { part: String, serial: String },
    /// Stop all motion and end the current job (its scans so far stay on disk).
    Abort,
    /// Clear the machines' errors and continue the stopped job from its last complete profile.
    Clear,
    /// The latest report of a part serial number.
    Report { serial: String },
    /// Turn this connection into a stream of [`Event`]s.
    Subscribe,
}

/// One reply line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReplyLine {
    pub version: u32,
    #[serde(flatten)]
    pub reply: Reply,
}

/// The daemon's answer to one request.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "reply", rename_all = "snake_case")]
pub enum Reply {
    /// A job was started; its progress comes as events.
    Started {
        job: JobInfo,
    },
    /// A request that needs no job was done.
    Done {
        message: String,
    },
    Status(Box<StationStatus>),
    Report {
        dir: PathBuf,
        summary: String,
    },
    /// Events follow on this connection.
    Subscribed,
    /// The request was refused or failed: what happened and what to do next.
    Error {
        message: String,
    },
}

/// One event line.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EventLine {
    pub version: u32,
    #[serde(flatten)]
    pub event: Event,
}

/// Teach or inspect.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum JobKind {
    Teach,
    Inspect,
}

impl std::fmt::Display for JobKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Teach => "teach",
            Self::Inspect => "inspect",
        })
    }
}

/// What a job is about: enough for a watcher that joins late to lay out its display.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JobInfo {
    pub id: String,
    pub kind: JobKind,
    pub part: String,
    /// The part's serial number (inspect only).
    pub serial: Option<String>,
    /// The instances scanned by this job, in plan order (only the master for a teach).
    pub instances: Vec<String>,
    /// Every profile of the plan, in order.
    pub profiles: Vec<String>,
    pub machines: Vec<String>,
    pub tolerance_mm: [f64; 2],
}

/// Something that happened, as it happened.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum Event {
    JobStarted {
        job: JobInfo,
        /// Profiles already complete (on disk) when the job started or resumed.
        done: Vec<ScanRef>,
    },
    /// A machine started scanning a profile.
    ScanStarted {
        job: String,
        machine: String,
        scan: ScanRef,
        at_unix_ms: u64,
    },
    /// One measured point, probe-compensated; its deviation when inspecting.
    Point {
        job: String,
        machine: String,
        scan: ScanRef,
        /// The point's index in its profile's scan, from 0.
        index: usize,
        /// The surface point, machine coordinates, mm.
        surface_mm: [f64; 3],
        /// Signed deviation from the reference (mm, positive outside the material); `None` when teaching.
        deviation_mm: Option<f64>,
        /// Compensation flagged the point's contact as not unique (a cusp: the surface more concave than the
        /// ball): kept, but left out of the statistics. Absent (false) from older daemons.
        #[serde(default)]
        flagged: bool,
        /// When the point's line arrived from the machine, microseconds since the Unix epoch.
        received_unix_us: u64,
    },
    /// A point's deviation the moment it arrives, while its `Point` waits for the four points after it (the
    /// look-ahead of the probe compensation): compensated from the path up to it, within about a micron of its
    /// `Point` except where the surface bends sharply within the look-ahead. Live display only: the `Point` that
    /// follows is the measurement, the one statistics, files and reports hold.
    PointPreview {
        job: String,
        machine: String,
        scan: ScanRef,
        index: usize,
        /// The surface point, machine coordinates, mm.
        surface_mm: [f64; 3],
        /// Signed deviation from the reference (mm, positive outside the material); `None` when teaching.
        deviation_mm: Option<f64>,
        /// As `Point`'s: the contact is not to be trusted.
        flagged: bool,
        /// When the point's line arrived from the machine, microseconds since the Unix epoch.
        received_unix_us: u64,
    },
    /// A profile's points are on disk and it counts as done.
    ProfileDone {
        job: String,
        machine: String,
        scan: ScanRef,
        points: usize,
        /// Deviation statistics (inspect only).
        stats: Option<DeviationStats>,
        verdict: Option<Verdict>,
        at_unix_ms: u64,
    },
    /// A section evaluated at its profile's end (inspect only, off the points' path: it may come after the next
    /// profile's first points): where it lies after its best fits (least squares, then minimum zone) and its
    /// parameters beside the nominal's; either may be missing, the daemon's log saying why.
    SectionEvaluated {
        job: String,
        machine: String,
        scan: ScanRef,
        best_fits: Vec<SectionBestFit>,
        parameters: Option<Box<SectionParametersReport>>,
        at_unix_ms: u64,
    },
    /// The job stopped on a fault and waits for `zeroset clear`.
    JobStopped {
        job: String,
        machine: Option<String>,
        scan: Option<ScanRef>,
        reason: String,
        next_step: String,
    },
    /// A profile's scan came back with a hole in it (a line of points lost on the way) and is scanned again.
    ProfileRescanned {
        job: String,
        machine: String,
        scan: ScanRef,
        reason: String,
    },
    /// `zeroset clear` lifted the stop; the job continues.
    JobResumed { job: String },
    /// A teach saved its reference model.
    ReferenceSaved {
        job: String,
        part: String,
        path: PathBuf,
        profiles: Vec<ProfileFit>,
    },
    /// An inspection ended and its report is written.
    JobFinished {
        job: String,
        report: Option<PathBuf>,
        instances: Vec<InstanceSummary>,
        verdict: Option<Verdict>,
    },
    /// The operator aborted the job.
    JobAborted { job: String },
    /// The job could not go on (e.g. the reference could not be fitted).
    JobFailed { job: String, error: String },
    /// This subscriber fell behind and missed events (the daemon never waits for a slow watcher).
    Lagged { missed: u64 },
}

/// A profile of an instance, by name.
#[derive(Debug, Clone, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct ScanRef {
    pub instance: String,
    pub profile: String,
}

/// How well a taught profile was fitted: the distances of its points to the reference, mm (`None` where the
/// reference kind keeps no such statistic).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ProfileFit {
    pub profile: String,
    pub points: usize,
    pub rms_mm: Option<f64>,
    pub max_mm: Option<f64>,
    /// What the fit's statistics say against the data and the part's tolerance: each doubt with its reason and
    /// what to try (none for a fit that models its data).
    #[serde(default)]
    pub doubts: Vec<String>,
}

/// One instance's result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InstanceSummary {
    pub instance: String,
    pub stats: Option<DeviationStats>,
    pub verdict: Option<Verdict>,
}

/// The station as `zeroset status` shows it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StationStatus {
    pub station: String,
    pub machines: Vec<MachineStatus>,
    /// A job being set up (its part and reference loaded, its moves checked) before it starts.
    pub preparing: Option<PreparingJob>,
    pub job: Option<JobStatus>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MachineStatus {
    pub name: String,
    pub state: MachineState,
}

/// A job requested and being set up.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PreparingJob {
    pub kind: JobKind,
    pub part: String,
    pub serial: Option<String>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JobStatus {
    pub job: JobInfo,
    pub state: JobPhase,
    pub profiles_done: usize,
    pub profiles_total: usize,
}

impl RequestLine {
    pub fn new(request: Request) -> Self {
        RequestLine {
            version: API_VERSION,
            request,
        }
    }
}

impl ReplyLine {
    pub fn new(reply: Reply) -> Self {
        ReplyLine {
            version: API_VERSION,
            reply,
        }
    }
}

impl EventLine {
    pub fn new(event: Event) -> Self {
        EventLine {
            version: API_VERSION,
            event,
        }
    }
}

/// Why a line could not be read as this API.
#[derive(Debug, thiserror::Error)]
pub enum LineError {
    #[error("not a line of the zeroset control API: {0}")]
    Json(#[from] serde_json::Error),
    #[error("the other side speaks control API version {got}, this build speaks {API_VERSION}; use a zeroset CLI and daemon of the same build")]
    Version { got: u32 },
}

/// Reads one line of a versioned type, refusing another version before looking at the rest.
pub fn parse_line<T: serde::de::DeserializeOwned>(line: &str) -> Result<T, LineError> {
    #[derive(Deserialize)]
    struct Versioned {
        version: u32,
    }
    let Versioned { version } = serde_json::from_str(line)?;
    if version != API_VERSION {
        return Err(LineError::Version { got: version });
    }
    Ok(serde_json::from_str(line)?)
}

/// One line of JSON, newline included.
pub fn to_line<T: Serialize>(value: &T) -> String {
    let mut line = serde_json::to_string(value).expect("API types serialise");
    line.push('\n');
    line
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn requests_are_tagged_json_lines_with_the_version() {
        let line = to_line(&RequestLine::new(Request::Inspect {
            part: "propeller".into(),
            serial: "SN-1".into(),
        }));
        assert_eq!(
            line,
            "{\"version\":2,\"request\":\"inspect\",\"part\":\"propeller\",\"serial\":\"SN-1\"}\n"
        );
        let back: RequestLine = parse_line(line.trim()).unwrap();
        assert_eq!(
            back.request,
            Request::Inspect {
                part: "propeller".into(),
                serial: "SN-1".into()
            }
        );
    }

    #[test]
    fn another_version_is_refused_by_name() {
        let err = parse_line::<RequestLine>("{\"version\":1,\"request\":\"status\"}").unwrap_err();
        assert!(err.to_string().contains("version 1"), "{err}");
        let err = parse_line::<RequestLine>("{\"version\":2,\"request\":\"fly\"}").unwrap_err();
        assert!(err.to_string().contains("fly"), "{err}");
    }

    #[test]
    fn events_round_trip() {
        let event = EventLine::new(Event::Point {
            job: "j".into(),
            machine: "cmm1".into(),
            scan: ScanRef {
                instance: "B".into(),
                profile: "r300".into(),
            },
            index: 7,
            surface_mm: [300.0, 1.5, -2.25],
            deviation_mm: Some(-0.4125),
            flagged: true,
            received_unix_us: 1_700_000_000_000_000,
        });
        let line = to_line(&event);
        let back: EventLine = parse_line(line.trim()).unwrap();
        assert_eq!(back, event);
    }
}
