//! A pole-free atlas of the unit sphere for the ball's surface S(u, v) = r n(u, v). A single latitude-longitude
//! chart degenerates at its poles (n_u = 0 there, so N = S_u x S_v vanishes and F = G = 0 holds trivially: the
//! fake solutions seed 002's approach must avoid). Two charts whose poles lie on different axes (z and x) cover
//! the sphere; a point is always expressed in the chart where it lies within 45 degrees of the equator, and a
//! traced curve switches charts before it comes within 30 degrees of a pole.

use nalgebra::Vector3;

/// Latitude beyond which a point is moved to the other chart (60 degrees).
const RECHART_LATITUDE: f64 = std::f64::consts::FRAC_PI_3;

/// A point of the unit sphere in one of the two charts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpherePoint {
    /// 0: poles on the z axis, n = (cos u cos v, sin u cos v, sin v); 1: poles on the x axis,
    /// n = (sin v, cos u cos v, sin u cos v) (the same chart with coordinates permuted cyclically, so both have
    /// n_u x n_v = cos v n: the same orientation).
    pub chart: u8,
    pub u: f64,
    pub v: f64,
}

/// The unit normal and its two partial derivatives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChartFrame {
    pub n: Vector3<f64>,
    pub n_u: Vector3<f64>,
    pub n_v: Vector3<f64>,
}

/// From the z-pole chart's components (x, y, z) to the chart's own.
fn place(chart: u8, a: Vector3<f64>) -> Vector3<f64> {
    match chart {
        0 => a,
        _ => Vector3::new(a.z, a.x, a.y),
    }
}

impl SpherePoint {
    pub fn frame(&self) -> ChartFrame {
        let (su, cu) = self.u.sin_cos();
        let (sv, cv) = self.v.sin_cos();
        ChartFrame {
            n: place(self.chart, Vector3::new(cu * cv, su * cv, sv)),
            n_u: place(self.chart, Vector3::new(-su * cv, cu * cv, 0.0)),
            n_v: place(self.chart, Vector3::new(-cu * sv, -su * sv, cv)),
        }
    }

    pub fn normal(&self) -> Vector3<f64> {
        self.frame().n
    }

    /// The chart point of a unit vector, in the chart where it is nearer the equator.
    pub fn from_normal(n: &Vector3<f64>) -> Self {
        let n = n.normalize();
        if n.z.abs() <= n.x.abs() {
            Self {
                chart: 0,
                u: n.y.atan2(n.x),
                v: n.z.atan2(n.x.hypot(n.y)),
            }
        } else {
            Self {
                chart: 1,
                u: n.z.atan2(n.y),
                v: n.x.atan2(n.y.hypot(n.z)),
            }
        }
    }

    /// The same point, moved to the other chart if it has come too near this chart's pole.
    pub fn rechart(self) -> Self {
        if self.v.abs() > RECHART_LATITUDE {
            Self::from_normal(&self.normal())
        } else {
            self
        }
    }
}
