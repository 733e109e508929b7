//! The global error of fit of seed 001 eq. 15, sum_i ( OR_j sqrt(a1 a2 a3)_j f2_j(P_i) )^2, as the similarity of
//! points to a model; and the pose fit the paper closes section 6.1 with: the rotation, translation and scale of
//! measured points that minimise it against a fixed reference.
//!
//! Eq. 15 weighs each truncated supershape by the square root of its volume term. Here every primitive of the
//! CSG tree is weighed by its own: a supershape by sqrt(a1 a2 a3), a box by sqrt(h1 h2 h3) of its half extents.
//! For the recovered models (a truncating box just outside its supershape, holes subtracted) the two agree where
//! the supershape decides the value, and R_p, homogeneous of degree one, keeps the zero set and signs of the
//! tree whatever the weights.

use std::f64::consts::FRAC_PI_2;

use nalgebra::{Point3, Quaternion, Rotation3, UnitQuaternion, Vector3};

use crate::geometry::supershape::csg::{Node, NodeKind, Solid};
use crate::geometry::supershape::deform::Deformations;
use crate::geometry::supershape::differences;
use crate::geometry::supershape::shape::Supershape;

/// Seed 001 eq. 15 of the points against the solid, mm^3 (the weights are in mm^(3/2), the radial values
/// dimensionless).
pub fn global_error(solid: &Solid, points: &[Point3<f64>]) -> f64 {
    points
        .iter()
        .map(|p| weighted(solid.root(), p).powi(2))
        .sum()
}

/// The tree's R-function value with every primitive's radial function weighed by its volume term.
fn weighted(node: &Node, p: &Point3<f64>) -> f64 {
    match &node.kind {
        NodeKind::Supershape { shape } => {
            shape.scale.iter().product::<f64>().sqrt() * node.value(p)
        }
        NodeKind::Cuboid { half_extents } => {
            half_extents.iter().product::<f64>().sqrt() * node.value(p)
        }
        NodeKind::Boolean {
            op,
            rfunction,
            left,
            right,
        } => {
            let q = node.place.inverse(p);
            rfunction.combine(*op, weighted(left, &q), weighted(right, &q))
        }
    }
}

/// The RMS of the distances (`surface_distance_bound`) from `samples` parametric points of each placed supershape
/// to the other, mm: how far apart two surfaces are, for judging a recovery against a truth. Infinite when a
/// distance is not a number.
pub fn surface_gap_rms(
    a: (&Supershape, &Deformations),
    b: (&Supershape, &Deformations),
    samples: usize,
) -> f64 {
    let one_way = |from: (&Supershape, &Deformations), to: (&Supershape, &Deformations)| {
        from.0
            .surface_points(samples)
            .iter()
            .map(|p| surface_distance_bound(to.0, to.1, &from.1.apply(p)).powi(2))
            .sum::<f64>()
    };
    let sum = one_way(a, b) + one_way(b, a);
    if sum.is_nan() {
        return f64::INFINITY;
    }
    (sum / (2 * samples) as f64).sqrt()
}

/// The distance from `p` to a surface point of the placed supershape reached by Gauss-Newton on |S(theta, phi) -
/// P|^2 from the radial foot (the surface point on the ray from the centre through P, whose angles are P's by
/// seed 000 eq. 8), mm. Never more than the radial distance and never less than the true distance: a bound that
/// is tight where the foot's basin is the nearest one, for judging fits (the station's exact distance to a solid is
/// `SolidDistance`).
pub fn surface_distance_bound(shape: &Supershape, place: &Deformations, p: &Point3<f64>) -> f64 {
    let q = place.inverse(p);
    let unscaled = Vector3::new(
        q.x / shape.scale[0],
        q.y / shape.scale[1],
        q.z / shape.scale[2],
    );
    let theta = unscaled.y.atan2(unscaled.x);
    let phi = (unscaled.z * shape.r1.radius(theta)).atan2(unscaled.x.hypot(unscaled.y));
    let gap = |t: f64, f: f64| (shape.point(t, f) - q).norm_squared();
    let (mut t, mut f, mut best) = (theta, phi, gap(theta, phi));
    let h = 1e-6;
    for _ in 0..20 {
        let at = shape.point(t, f).coords - q.coords;
        let dt = (shape.point(t + h, f) - shape.point(t - h, f)) / (2.0 * h);
        let df = (shape.point(t, f + h) - shape.point(t, f - h)) / (2.0 * h);
        let normal = nalgebra::Matrix2::new(dt.dot(&dt), dt.dot(&df), dt.dot(&df), df.dot(&df));
        let Some(step) = normal
            .try_inverse()
            .map(|inv| inv * nalgebra::Vector2::new(-dt.dot(&at), -df.dot(&at)))
        else {
            break;
        };
        let mut scale = 1.0;
        while scale > 1e-4 {
            let (nt, nf) = (
                t + scale * step.x,
                (f + scale * step.y).clamp(-FRAC_PI_2, FRAC_PI_2),
            );
            let trial = gap(nt, nf);
            if trial < best {
                (t, f, best) = (nt, nf, trial);
                break;
            }
            scale /= 2.0;
        }
        if scale <= 1e-4 {
            break;
        }
    }
    best.sqrt()
}

/// A similarity transform of measured points into a reference's frame: P -> scale R P + translation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    pub rotation: Rotation3<f64>,
    pub translation: Vector3<f64>,
    pub scale: f64,
}

impl Pose {
    pub fn identity() -> Self {
        Self {
            rotation: Rotation3::identity(),
            translation: Vector3::zeros(),
            scale: 1.0,
        }
    }

    pub fn apply(&self, p: &Point3<f64>) -> Point3<f64> {
        Point3::from(self.rotation * p.coords * self.scale + self.translation)
    }
}

/// The pose found and the global error before (at the start pose) and after, mm^3.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseFit {
    pub pose: Pose,
    pub error_before: f64,
    pub error_after: f64,
}

/// The pose that minimises eq. 15 of the moved points against `reference`, from `start` (the identity when the
/// part sits where the reference was taught). Levenberg-Marquardt over a Gibbs vector of the turn from `start`,
/// the translation and the logarithm of the scale, with central differences (the tree's value is not generic over
/// dual numbers, and seven parameters make that cheap).
pub fn fit_pose(reference: &Solid, points: &[Point3<f64>], start: Pose) -> PoseFit {
    let error_at = |pose: &Pose| {
        global_error(
            reference,
            &points.iter().map(|p| pose.apply(p)).collect::<Vec<_>>(),
        )
    };
    let t = start.translation;
    let (solved, _) =
        differences::minimise([0.0, 0.0, 0.0, t.x, t.y, t.z, start.scale.ln()], |p| {
            let pose = pose_of(&start, p);
            let values: Vec<f64> = points
                .iter()
                .map(|q| weighted(reference.root(), &pose.apply(q)))
                .collect();
            values.iter().all(|v| v.is_finite()).then_some(values)
        });
    let pose = pose_of(&start, &solved);
    PoseFit {
        error_before: error_at(&start),
        error_after: error_at(&pose),
        pose,
    }
}

/// The pose of the parameters [Gibbs vector of the turn from `start` (3), translation (3), ln scale].
fn pose_of(start: &Pose, p: &[f64; 7]) -> Pose {
    let turn = UnitQuaternion::from_quaternion(Quaternion::new(1.0, p[0], p[1], p[2]));
    Pose {
        rotation: turn.to_rotation_matrix() * start.rotation,
        translation: Vector3::new(p[3], p[4], p[5]),
        scale: p[6].exp(),
    }
}
