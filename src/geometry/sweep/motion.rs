//! The stylus's planned motions relative to the part, A(t) = (R(t), c(t)) for t in [0, 1]: the pose maps body
//! coordinates (ball centre at the origin) into the part's frame. Each motion also gives its twist (angular
//! velocity and the ball centre's velocity, per unit t) and a bound on the speed of any body point, which is
//! what conservative advancement divides a gap by.

use nalgebra::{Isometry3, Point3, Translation3, Unit, UnitQuaternion, Vector3};

/// A polyline of ball-centre points, traversed at constant speed (t proportional to arc length).
#[derive(Debug, Clone, PartialEq)]
pub struct ScanPath {
    points: Vec<Point3<f64>>,
    /// Arc length at each point, from 0 to the total length.
    cumulative: Vec<f64>,
    /// The ball follows the part's surface (a contact scan): the clearance check then measures shank and
    /// extension only, since the ball touches by design.
    pub contact: bool,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MotionError {
    #[error("a scan path needs at least two points, got {0}")]
    TooFewPoints(usize),
    #[error("the scan path has zero length")]
    ZeroLength,
    #[error("the arc's start lies on its axis (zero radius)")]
    ZeroRadius,
    #[error("the arc's axis must be a non-zero vector")]
    ZeroAxis,
}

impl ScanPath {
    pub fn new(points: Vec<Point3<f64>>, contact: bool) -> Result<Self, MotionError> {
        if points.len() < 2 {
            return Err(MotionError::TooFewPoints(points.len()));
        }
        let mut cumulative = Vec::with_capacity(points.len());
        let mut s = 0.0;
        cumulative.push(0.0);
        for w in points.windows(2) {
            s += (w[1] - w[0]).norm();
            cumulative.push(s);
        }
        if s == 0.0 {
            return Err(MotionError::ZeroLength);
        }
        Ok(Self {
            points,
            cumulative,
            contact,
        })
    }

    pub fn points(&self) -> &[Point3<f64>] {
        &self.points
    }

    pub fn length_mm(&self) -> f64 {
        *self.cumulative.last().expect("at least two points")
    }

    /// The segment holding arc length s and the fraction along it.
    fn locate(&self, t: f64) -> (usize, f64) {
        let s = t.clamp(0.0, 1.0) * self.length_mm();
        let i = self
            .cumulative
            .partition_point(|&c| c <= s)
            .clamp(1, self.points.len() - 1)
            - 1;
        let len = self.cumulative[i + 1] - self.cumulative[i];
        let f = if len > 0.0 {
            (s - self.cumulative[i]) / len
        } else {
            0.0
        };
        (i, f)
    }
}

/// One planned motion of the stylus relative to the part.
#[derive(Debug, Clone, PartialEq)]
pub enum Motion {
    /// Straight move of the ball centre, orientation fixed.
    Line { from: Point3<f64>, to: Point3<f64> },
    /// The ball centre moves along a circular arc (rotation of `start` about the line through `centre` along
    /// `axis`, by `angle_rad`, right-handed), the stylus's orientation fixed: a CMM's circular interpolation.
    Arc {
        centre: Point3<f64>,
        axis: Unit<Vector3<f64>>,
        start: Point3<f64>,
        angle_rad: f64,
    },
    /// A rotary-table index: the table turns from `from_rad` to `to_rad` about the line through `axis_point`
    /// along `axis` (right-handed) while the stylus stands still at `ball_centre` (machine coordinates).
    /// The part model is in the table's frame at angle 0, so relative to the part the stylus turns by the
    /// opposite angle: pose(t) = rotation by -theta(t) about the table axis applied to the stylus at rest.
    RotaryIndex {
        axis_point: Point3<f64>,
        axis: Unit<Vector3<f64>>,
        ball_centre: Point3<f64>,
        from_rad: f64,
        to_rad: f64,
    },
    /// A scan along a polyline of ball-centre points.
    Scan(ScanPath),
}

/// Rigid velocity at time t in the part's frame: a body point x moves at `omega x (x - c(t)) + centre_velocity`
/// (mm and radians per unit t).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Twist {
    pub omega: Vector3<f64>,
    pub centre_velocity: Vector3<f64>,
}

impl Twist {
    pub fn point_velocity(&self, centre: &Point3<f64>, x: &Point3<f64>) -> Vector3<f64> {
        self.omega.cross(&(x - centre)) + self.centre_velocity
    }
}

fn rotation(axis: &Unit<Vector3<f64>>, angle: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(axis, angle)
}

/// Distance of p from the line through o along the unit axis.
fn distance_from_axis(p: &Point3<f64>, o: &Point3<f64>, axis: &Unit<Vector3<f64>>) -> f64 {
    let r = p - o;
    (r - axis.into_inner() * r.dot(axis)).norm()
}

impl Motion {
    pub fn line(from: Point3<f64>, to: Point3<f64>) -> Self {
        Self::Line { from, to }
    }

    pub fn arc(
        centre: Point3<f64>,
        axis: Vector3<f64>,
        start: Point3<f64>,
        angle_rad: f64,
    ) -> Result<Self, MotionError> {
        let axis = Unit::try_new(axis, 1e-12).ok_or(MotionError::ZeroAxis)?;
        if distance_from_axis(&start, &centre, &axis) == 0.0 {
            return Err(MotionError::ZeroRadius);
        }
        Ok(Self::Arc {
            centre,
            axis,
            start,
            angle_rad,
        })
    }

    /// Index of a table turning about the vertical (machine z) axis through `axis_point`.
    pub fn rotary_index(
        axis_point: Point3<f64>,
        ball_centre: Point3<f64>,
        from_rad: f64,
        to_rad: f64,
    ) -> Self {
        Self::RotaryIndex {
            axis_point,
            axis: Vector3::z_axis(),
            ball_centre,
            from_rad,
            to_rad,
        }
    }

    /// The rigid map from body coordinates to the part's frame at time t.
    pub fn pose(&self, t: f64) -> Isometry3<f64> {
        match self {
            Self::Line { from, to } => Isometry3::from_parts(
                Translation3::from(from.lerp(to, t).coords),
                UnitQuaternion::identity(),
            ),
            Self::Arc {
                centre,
                axis,
                start,
                angle_rad,
            } => {
                let c = centre + rotation(axis, angle_rad * t) * (start - centre);
                Isometry3::from_parts(Translation3::from(c.coords), UnitQuaternion::identity())
            }
            Self::RotaryIndex {
                axis_point,
                axis,
                ball_centre,
                from_rad,
                to_rad,
            } => {
                let r = rotation(axis, -(from_rad + (to_rad - from_rad) * t));
                let c = axis_point + r * (ball_centre - axis_point);
                Isometry3::from_parts(Translation3::from(c.coords), r)
            }
            Self::Scan(path) => {
                let (i, f) = path.locate(t);
                let c = path.points[i].lerp(&path.points[i + 1], f);
                Isometry3::from_parts(Translation3::from(c.coords), UnitQuaternion::identity())
            }
        }
    }

    /// The ball centre at time t.
    pub fn centre(&self, t: f64) -> Point3<f64> {
        Point3::from(self.pose(t).translation.vector)
    }

    /// Angular velocity and ball-centre velocity at time t (for a scan, the velocity of the segment holding t).
    pub fn twist(&self, t: f64) -> Twist {
        match self {
            Self::Line { from, to } => Twist {
                omega: Vector3::zeros(),
                centre_velocity: to - from,
            },
            Self::Arc {
                centre,
                axis,
                angle_rad,
                ..
            } => Twist {
                omega: Vector3::zeros(),
                centre_velocity: axis.into_inner().cross(&(self.centre(t) - centre)) * *angle_rad,
            },
            Self::RotaryIndex {
                axis_point,
                axis,
                from_rad,
                to_rad,
                ..
            } => {
                let omega = -axis.into_inner() * (to_rad - from_rad);
                Twist {
                    omega,
                    centre_velocity: omega.cross(&(self.centre(t) - axis_point)),
                }
            }
            Self::Scan(path) => {
                let (i, _) = path.locate(t);
                let d = path.points[i + 1] - path.points[i];
                Twist {
                    omega: Vector3::zeros(),
                    centre_velocity: d * (path.length_mm() / d.norm()),
                }
            }
        }
    }

    /// An upper bound, over t in [0, 1], of the speed (mm per unit t) of any body point within `reach_mm` of the
    /// ball centre. Translations move every point with the centre; a rotation about a fixed axis moves a point
    /// at |omega| times its distance from the axis, at most the centre's distance plus the reach.
    pub fn max_point_speed(&self, reach_mm: f64) -> f64 {
        match self {
            Self::Line { from, to } => (to - from).norm(),
            Self::Arc {
                centre,
                axis,
                start,
                angle_rad,
            } => angle_rad.abs() * distance_from_axis(start, centre, axis),
            Self::RotaryIndex {
                axis_point,
                axis,
                ball_centre,
                from_rad,
                to_rad,
            } => {
                (to_rad - from_rad).abs()
                    * (distance_from_axis(ball_centre, axis_point, axis) + reach_mm)
            }
            Self::Scan(path) => path.length_mm(),
        }
    }

    /// Whether the pose is twice differentiable in t over [0, 1] (a scan's corners are not).
    pub fn is_smooth(&self) -> bool {
        !matches!(self, Self::Scan(_))
    }

    /// Whether the ball is meant to touch the part during this motion (a contact scan).
    pub fn ball_in_contact(&self) -> bool {
        matches!(self, Self::Scan(path) if path.contact)
    }
}
