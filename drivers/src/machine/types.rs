//! What the station asks of a machine and what it gets back, free of wire syntax. Millimetres, seconds
//! and radians, in the machine's current coordinate system.

use std::time::Duration;

/// A position or a direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Xyz {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

impl Xyz {
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Xyz { x, y, z }
    }
}

/// The result of a single-point measurement (`PtMeas`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeasuredPoint {
    /// The probe ball's centre when it touched, as CMMs report it (not the surface point).
    pub centre: Xyz,
    /// The surface normal at the touch, pointing out of the material.
    pub normal: Xyz,
}

/// One point of a scan, as reported while the scan runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScanPoint {
    /// The probe ball's centre.
    pub centre: Xyz,
    /// The surface normal, pointing out of the material.
    pub normal: Xyz,
    /// I++'s quality figure: 0 a good point, up to 100 a bad one.
    pub quality: f64,
}

/// The speeds of the active tool, mm/s: I++'s `Tool.GoToPar.Speed`, `Tool.PtMeasPar.Speed` and
/// `Tool.ScanPar.Speed`. A new tool starts at its own defaults, so set them after `change_tool`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Speeds {
    /// Free moves (`GoTo`, and the approach of a measurement).
    pub travel: f64,
    /// The probing move of `PtMeas`.
    pub probing: f64,
    /// Scanning.
    pub scanning: f64,
}

/// A closed profile of unknown shape in a plane (I++ `ScanInPlaneEndIsSphere`): the master's scan.
/// The machine probes `start` along `-start_normal`, follows the surface in the plane through the
/// probed point with normal `plane_normal`, heading first towards `direction`, and stops when it
/// enters the sphere of `stop_diameter` around `end` for the `passes`-th time.
#[derive(Debug, Clone, PartialEq)]
pub struct InPlaneScan {
    pub start: Xyz,
    pub start_normal: Xyz,
    pub plane_normal: Xyz,
    /// A point that gives the direction of travel from `start`; must differ from `start`.
    pub direction: Xyz,
    /// Which points the machine reports.
    pub spacing: InPlaneSpacing,
    pub end: Xyz,
    pub stop_diameter: f64,
    /// On which entry into the stop sphere the scan ends: 1 for a closed profile ending where it
    /// started (a machine that starts inside the sphere leaves it before it checks).
    pub passes: u32,
    /// The surface normal at `end`: the direction of the retract.
    pub end_normal: Xyz,
}

/// How densely an in-plane scan reports points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InPlaneSpacing {
    /// A point every `step` mm on average (I++'s `StepW`).
    Step(f64),
    /// A point at least every `max_distance` mm, and wherever the path turns by more than `max_angle`
    /// radians (I++'s `ScanUnknownDensity(Dis(..), Angle(..))`, sent before the scan, with `StepW` 0): a
    /// small radius (a blade's nose, a ball rolling round a sharp edge) gets points as densely as its turn
    /// asks, not one per step.
    Spacing { max_distance: f64, max_angle: f64 },
}

impl InPlaneSpacing {
    /// The longest distance between reported points, mm (the average one for `Step`).
    pub fn max_distance(&self) -> f64 {
        match *self {
            InPlaneSpacing::Step(step) => step,
            InPlaneSpacing::Spacing { max_distance, .. } => max_distance,
        }
    }
}

/// A profile scanned along its known nominal (I++ `ScanOnCurve`, with `ScanOnCurveHint` and
/// `ScanOnCurveDensity` sent before it): the other instances' scans.
#[derive(Debug, Clone, PartialEq)]
pub struct CurveScan {
    /// Whether the last nominal joins the first.
    pub closed: bool,
    /// Points on the nominal surface, in order of travel.
    pub nominals: Vec<Nominal>,
    /// The largest expected distance of the real surface from the nominal, along the normals.
    pub max_deviation: f64,
    /// The smallest radius of curvature along the curve (> 0); the machine slows down for it.
    pub min_radius: f64,
    /// Which points the machine reports.
    pub density: Density,
}

/// A nominal surface point and its outward normal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Nominal {
    pub point: Xyz,
    pub normal: Xyz,
}

/// How densely a curve scan reports points.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Density {
    /// One point at each nominal.
    AtNominals,
    /// A point at least every `max_distance` mm, and wherever the path turns by more than
    /// `max_angle` radians.
    Spacing { max_distance: f64, max_angle: f64 },
}

/// How often a move-report daemon reports the position (I++ `OnMoveReportE(Time(..), Dis(..))`):
/// after `interval`, or after a move of `distance` mm, whichever comes first (at most 10 per second).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoveReportRate {
    /// At least 0.1 s, the spec's floor.
    pub interval: Duration,
    pub distance: f64,
}
