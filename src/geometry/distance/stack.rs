//! Exact distances to a profile stack. The stack is piecewise: each segment is a smooth 3-D polynomial between
//! two profile planes, and the surface has a crease at every inner profile. Newton cannot converge on a crease,
//! so the nearest point is found as the best of (a) each nearby segment's own foot, kept only when it lies within
//! the segment's slab, and (b) the nearest point of each bounding profile curve, in its plane.

use nalgebra::{Vector2, Vector3};

use super::{DistanceError, ExactDistance, Foot};
use crate::geometry::implicit::{Implicit, IpModel};
use crate::geometry::interp::ProfileStack;
use crate::geometry::sampling::{Aabb, ZeroSetSamples};

/// Sampling of each segment's zero set: cells along x per segment, and across (y, z).
const SEGMENT_CELLS_ALONG: usize = 4;
const SEGMENT_CELLS_ACROSS: usize = 256;
const PROFILE_CELLS: usize = 512;
/// Points this far beyond the first or last profile plane still count as on it (a probe's x scatters too).
const PLANE_TOLERANCE_MM: f64 = 0.05;

pub struct StackDistance<'a> {
    stack: &'a ProfileStack,
    segments: Vec<(IpModel<3>, ZeroSetSamples<3>)>,
    profiles: Vec<ZeroSetSamples<2>>,
}

impl<'a> StackDistance<'a> {
    /// `profile_domains`: the data box of each profile, in stack order.
    pub fn new(stack: &'a ProfileStack, profile_domains: &[Aabb<2>]) -> Self {
        let bounds = stack.bounds(profile_domains);
        let xs: Vec<f64> = stack.profiles().iter().map(|p| p.x).collect();
        let segments = (0..xs.len() - 1)
            .map(|k| {
                let model = stack.segment_model(k);
                let slab = Aabb {
                    min: Vector3::new(xs[k], bounds.min.y, bounds.min.z),
                    max: Vector3::new(xs[k + 1], bounds.max.y, bounds.max.z),
                };
                let counts = [
                    SEGMENT_CELLS_ALONG,
                    SEGMENT_CELLS_ACROSS,
                    SEGMENT_CELLS_ACROSS,
                ];
                let samples = ZeroSetSamples::with_counts(&model, &slab, counts);
                (model, samples)
            })
            .collect();
        let profiles = stack
            .profiles()
            .iter()
            .zip(profile_domains)
            .map(|(p, domain)| ZeroSetSamples::new(&p.model, &domain.scaled(2.0), PROFILE_CELLS))
            .collect();
        Self {
            stack,
            segments,
            profiles,
        }
    }

    pub fn foot(&self, p: &Vector3<f64>) -> Result<Foot<3>, DistanceError> {
        let profiles = self.stack.profiles();
        // Beyond the end profiles the blend is an extrapolation, not a model of the part.
        let (first, last) = (profiles[0].x, profiles[profiles.len() - 1].x);
        if p.x < first - PLANE_TOLERANCE_MM || p.x > last + PLANE_TOLERANCE_MM {
            return Err(DistanceError::OutsideModelRange);
        }
        let k = self.stack.segment_at(p.x);
        let side = self.stack.value(p);
        let mut best: Option<Foot<3>> = None;
        let mut consider = |candidate: Foot<3>| {
            if best.is_none_or(|b| candidate.distance.abs() < b.distance.abs()) {
                best = Some(candidate);
            }
        };
        let first = k.saturating_sub(1);
        let last = (k + 1).min(self.segments.len() - 1);
        for j in first..=last {
            let (model, samples) = &self.segments[j];
            let (xa, xb) = (profiles[j].x, profiles[j + 1].x);
            // The segment's polynomial stands for the part only between its planes: a nearer zero beyond them
            // must not displace the foot within them, so the certificate (over the whole zero set) is not asked.
            if let Ok(foot) = ExactDistance::new(model, samples).uncertified_foot(p, None) {
                if foot.point.x >= xa && foot.point.x <= xb {
                    consider(foot);
                }
            }
        }
        let planes = profiles
            .iter()
            .zip(&self.profiles)
            .skip(first)
            .take(last + 2 - first);
        for (plane, plane_samples) in planes {
            let exact = ExactDistance::new(&plane.model, plane_samples);
            if let Ok(in_plane) = exact.foot(&Vector2::new(p.y, p.z), None) {
                let point = Vector3::new(plane.x, in_plane.point.x, in_plane.point.y);
                let unsigned = (p - point).norm();
                consider(Foot {
                    point,
                    distance: if side < 0.0 { -unsigned } else { unsigned },
                });
            }
        }
        best.ok_or(DistanceError::NoFootPoint)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::implicit::Frame;
    use crate::geometry::interp::Profile;
    use crate::geometry::poly::Poly;

    fn circle(radius: f64) -> IpModel<2> {
        IpModel {
            frame: Frame::identity(),
            poly: Poly::new(
                2,
                vec![-radius / 2.0, 0.0, 0.0, 0.5 / radius, 0.0, 0.5 / radius],
            ),
        }
    }

    #[test]
    fn distances_to_a_stack_of_circles_match_the_cone_and_its_creases() {
        // Circles of radius 10 and 20 mm at x = 0 and 100, radius 10 again at 200: the blend is not exactly a
        // cone (F blends, not radii), so the reference is a dense numerical minimum over the surface.
        let stack = ProfileStack::new(vec![
            Profile {
                x: 0.0,
                model: circle(10.0),
            },
            Profile {
                x: 100.0,
                model: circle(20.0),
            },
            Profile {
                x: 200.0,
                model: circle(10.0),
            },
        ])
        .unwrap();
        let domains = vec![
            Aabb {
                min: Vector2::new(-10.0, -10.0),
                max: Vector2::new(10.0, 10.0),
            },
            Aabb {
                min: Vector2::new(-20.0, -20.0),
                max: Vector2::new(20.0, 20.0),
            },
            Aabb {
                min: Vector2::new(-10.0, -10.0),
                max: Vector2::new(10.0, 10.0),
            },
        ];
        let distance = StackDistance::new(&stack, &domains);
        // The surface's radius at x, from F(x, r) = 0 of the blend along the y axis.
        let radius_at = |x: f64| {
            let (mut lo, mut hi) = (0.0, 40.0);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if stack.value(&Vector3::new(x, mid, 0.0)) < 0.0 {
                    lo = mid
                } else {
                    hi = mid
                }
            }
            0.5 * (lo + hi)
        };
        let profile: Vec<(f64, f64)> = (0..=4_000)
            .map(|i| {
                let x = i as f64 * 0.05;
                (x, radius_at(x))
            })
            .collect();
        let points: [Vector3<f64>; 5] = [
            Vector3::new(50.0, 25.0, 0.0),
            Vector3::new(100.0, 0.0, 24.0),
            Vector3::new(100.0, 15.0, 0.0),
            Vector3::new(150.0, 3.0, 4.0),
            Vector3::new(99.0, 0.0, 21.0),
        ];
        for p in points {
            let r = (p.y * p.y + p.z * p.z).sqrt();
            let reference = profile
                .iter()
                .map(|(x, radius)| ((p.x - x).powi(2) + (r - radius).powi(2)).sqrt())
                .fold(f64::INFINITY, f64::min);
            let foot = distance.foot(&p).unwrap();
            assert!(
                (foot.distance.abs() - reference).abs() < 2e-3,
                "at {p}: {} vs {reference}",
                foot.distance
            );
            assert_eq!(foot.distance.signum(), stack.value(&p).signum());
        }
        assert_eq!(
            distance.foot(&Vector3::new(200.2, 10.0, 0.0)),
            Err(DistanceError::OutsideModelRange)
        );
        assert_eq!(
            distance.foot(&Vector3::new(-1.0, 10.0, 0.0)),
            Err(DistanceError::OutsideModelRange)
        );
    }
}
