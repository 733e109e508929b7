//! The stylus as a rigid body: a ball, the shank that carries it and an optional extension, each a solid of
//! revolution about the probe axis. Body coordinates: the ball centre at the origin, axes parallel to the
//! machine's at rest (a motion's pose maps body coordinates to the part's frame).

use nalgebra::{Point3, Unit, Vector3};

/// A cylindrical section of the stylus along the probe axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Section {
    pub radius_mm: f64,
    pub length_mm: f64,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StylusError {
    #[error("the {0} must be finite and positive, got {1} mm")]
    NotPositive(&'static str, f64),
    #[error("the probe axis must be a non-zero vector")]
    ZeroAxis,
}

/// Ball, shank (from the ball centre along `axis`) and optional extension (beyond the shank's end).
#[derive(Debug, Clone, PartialEq)]
pub struct Stylus {
    pub ball_radius_mm: f64,
    pub shank: Section,
    pub extension: Option<Section>,
    /// Unit direction from the ball centre towards the probe head, in machine coordinates at rest.
    pub axis: Unit<Vector3<f64>>,
}

/// A capsule in body coordinates: all points within `radius_mm` of the segment [a, b]. The clearance check
/// measures each stylus part as a capsule; a capsule holds the cylinder of the same radius and axis, so its
/// distance to the part never exceeds the cylinder's (conservative by at most the radius at the flat ends).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyCapsule {
    pub name: &'static str,
    pub a: Point3<f64>,
    pub b: Point3<f64>,
    pub radius_mm: f64,
}

fn positive(what: &'static str, value: f64) -> Result<f64, StylusError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(StylusError::NotPositive(what, value))
    }
}

impl Stylus {
    /// A stylus pointing down the machine's z axis (shank along +z from the ball centre).
    pub fn new(
        ball_radius_mm: f64,
        shank_radius_mm: f64,
        shank_length_mm: f64,
    ) -> Result<Self, StylusError> {
        Ok(Self {
            ball_radius_mm: positive("ball radius", ball_radius_mm)?,
            shank: Section {
                radius_mm: positive("shank radius", shank_radius_mm)?,
                length_mm: positive("shank length", shank_length_mm)?,
            },
            extension: None,
            axis: Vector3::z_axis(),
        })
    }

    pub fn with_extension(mut self, radius_mm: f64, length_mm: f64) -> Result<Self, StylusError> {
        self.extension = Some(Section {
            radius_mm: positive("extension radius", radius_mm)?,
            length_mm: positive("extension length", length_mm)?,
        });
        Ok(self)
    }

    /// The stylus with its shank along `axis` (machine coordinates, towards the probe head).
    pub fn with_axis(mut self, axis: Vector3<f64>) -> Result<Self, StylusError> {
        self.axis = Unit::try_new(axis, 1e-12).ok_or(StylusError::ZeroAxis)?;
        Ok(self)
    }

    /// The parts of the body as capsules in body coordinates, ball first.
    pub fn capsules(&self) -> Vec<BodyCapsule> {
        let top_of_shank = Point3::from(self.axis.into_inner() * self.shank.length_mm);
        let mut parts = vec![
            BodyCapsule {
                name: "ball",
                a: Point3::origin(),
                b: Point3::origin(),
                radius_mm: self.ball_radius_mm,
            },
            BodyCapsule {
                name: "shank",
                a: Point3::origin(),
                b: top_of_shank,
                radius_mm: self.shank.radius_mm,
            },
        ];
        if let Some(ext) = self.extension {
            parts.push(BodyCapsule {
                name: "extension",
                a: top_of_shank,
                b: top_of_shank + self.axis.into_inner() * ext.length_mm,
                radius_mm: ext.radius_mm,
            });
        }
        parts
    }

    /// The largest distance of any body point (of the capsules) from the ball centre: the lever arm that turns an
    /// angular speed into a point speed.
    pub fn reach_mm(&self) -> f64 {
        self.capsules()
            .iter()
            .map(|c| c.a.coords.norm().max(c.b.coords.norm()) + c.radius_mm)
            .fold(0.0, f64::max)
    }
}
