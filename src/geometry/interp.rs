//! Profile interpolation (seed 003 section 4): two parallel profile IPs F_a(y, z) at x_a and F_b(y, z) at x_b are
//! blended linearly along x into the 3-D IP
//!     F(x, y, z) = sum (alpha_ij + x beta_ij) y^i z^j,
//!     alpha_ij = (a_ij x_b - b_ij x_a) / (x_b - x_a),  beta_ij = (b_ij - a_ij) / (x_b - x_a),
//! so that F(x_a, .) = F_a and F(x_b, .) = F_b. A stack of profiles gives one such segment between each adjacent
//! pair: a piecewise 3-D model.
//!
//! The blend needs the profiles' coefficients in one coordinate system, so every profile is first re-expressed in
//! a frame common to the stack (exact polynomial substitution), and the segments are built in normalised
//! coordinates of that frame, where their coefficients stay of order one.

use nalgebra::{SMatrix, SVector, Vector2, Vector3};
use serde::{Deserialize, Serialize};

use super::implicit::{Frame, Implicit, IpModel};
use super::poly::{Poly, MAX_DEGREE};
use super::sampling::Aabb;

/// One measured profile: its model in the (y, z) plane at position `x` along the profile axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Profile {
    pub x: f64,
    pub model: IpModel<2>,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum StackError {
    #[error("a stack needs at least two profiles, got {0}")]
    TooFewProfiles(usize),
    #[error(
        "profiles at x = {0} mm and x = {1} mm coincide; profiles must be at distinct positions"
    )]
    SamePosition(f64, f64),
    #[error("profiles have different degrees ({0} and {1}); fit every profile of a stack at the same degree")]
    MixedDegrees(usize, usize),
    #[error("profiles of degree {0} blend into a 3-D polynomial of degree {1}, above the maximum {MAX_DEGREE}; fit the profiles at degree {max} or less", max = MAX_DEGREE - 1)]
    DegreeTooHigh(usize, usize),
}

/// A piecewise 3-D model interpolated between parallel profiles along x.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileStack {
    profiles: Vec<Profile>,
    frame: Frame<3>,
    /// Segment k lies between profiles k and k + 1, as a 3-D polynomial in the normalised coordinates of `frame`.
    segments: Vec<Poly<3>>,
}

impl ProfileStack {
    pub fn new(mut profiles: Vec<Profile>) -> Result<Self, StackError> {
        if profiles.len() < 2 {
            return Err(StackError::TooFewProfiles(profiles.len()));
        }
        profiles.sort_by(|a, b| a.x.total_cmp(&b.x));
        let degree = profiles[0].model.degree();
        if degree + 1 > MAX_DEGREE {
            return Err(StackError::DegreeTooHigh(degree, degree + 1));
        }
        for pair in profiles.windows(2) {
            if pair[0].x == pair[1].x {
                return Err(StackError::SamePosition(pair[0].x, pair[1].x));
            }
            if pair[0].model.degree() != pair[1].model.degree() {
                return Err(StackError::MixedDegrees(
                    pair[0].model.degree(),
                    pair[1].model.degree(),
                ));
            }
        }
        let n = profiles.len() as f64;
        let center_yz = profiles
            .iter()
            .map(|p| p.model.frame.center)
            .sum::<Vector2<f64>>()
            / n;
        let center_x = profiles.iter().map(|p| p.x).sum::<f64>() / n;
        let scale = profiles
            .iter()
            .map(|p| p.model.frame.scale)
            .fold(0.0, f64::max);
        let frame_yz = Frame {
            center: center_yz,
            scale,
        };
        let frame = Frame {
            center: Vector3::new(center_x, center_yz.x, center_yz.y),
            scale,
        };
        let common: Vec<Poly<2>> = profiles
            .iter()
            .map(|p| p.model.reframed(frame_yz).poly)
            .collect();
        let segments = (0..profiles.len() - 1)
            .map(|k| {
                let ua = (profiles[k].x - center_x) / scale;
                let ub = (profiles[k + 1].x - center_x) / scale;
                blend(&common[k], ua, &common[k + 1], ub)
            })
            .collect();
        Ok(Self {
            profiles,
            frame,
            segments,
        })
    }

    pub fn profiles(&self) -> &[Profile] {
        &self.profiles
    }

    /// The 3-D IP of segment k (between profiles k and k + 1), in world coordinates.
    pub fn segment_model(&self, k: usize) -> IpModel<3> {
        IpModel {
            frame: self.frame,
            poly: self.segments[k].clone(),
        }
    }

    /// Which segment serves position x: the one whose profiles enclose it, or the end segment beyond the stack.
    pub fn segment_at(&self, x: f64) -> usize {
        let last = self.segments.len() - 1;
        self.profiles[1..]
            .iter()
            .position(|p| x <= p.x)
            .unwrap_or(last)
            .min(last)
    }

    /// The box the stack spans: x from the first to the last profile, (y, z) twice the profiles' data boxes.
    pub fn bounds(&self, profile_domains: &[Aabb<2>]) -> Aabb<3> {
        let yz = profile_domains
            .iter()
            .skip(1)
            .fold(profile_domains[0], |a, b| Aabb {
                min: a.min.inf(&b.min),
                max: a.max.sup(&b.max),
            })
            .scaled(2.0);
        Aabb {
            min: Vector3::new(self.profiles[0].x, yz.min.x, yz.min.y),
            max: Vector3::new(self.profiles[self.profiles.len() - 1].x, yz.max.x, yz.max.y),
        }
    }

    fn unit(&self, p: &Vector3<f64>) -> (usize, Vector3<f64>) {
        (self.segment_at(p.x), self.frame.to_unit(p))
    }
}

/// The paper's alpha + x beta blend of two profile polynomials (in the same normalised coordinates) at ua and ub.
fn blend(a: &Poly<2>, ua: f64, b: &Poly<2>, ub: f64) -> Poly<3> {
    let degree = a.degree() + 1;
    let mut out = Poly::<3>::zero(degree);
    let span = ub - ua;
    for (e, (ca, cb)) in a
        .basis()
        .exponents()
        .iter()
        .zip(a.coeffs().iter().zip(b.coeffs()))
    {
        let alpha = (ca * ub - cb * ua) / span;
        let beta = (cb - ca) / span;
        let constant_in_x = out
            .basis()
            .index_of(&[0, e[0], e[1]])
            .expect("within degree");
        let linear_in_x = out
            .basis()
            .index_of(&[1, e[0], e[1]])
            .expect("within degree");
        out.coeffs_mut()[constant_in_x] += alpha;
        out.coeffs_mut()[linear_in_x] += beta;
    }
    out
}

impl Implicit<3> for ProfileStack {
    fn value(&self, p: &Vector3<f64>) -> f64 {
        let (k, u) = self.unit(p);
        self.frame.scale * self.segments[k].value(&u)
    }
    fn value_gradient(&self, p: &Vector3<f64>) -> (f64, Vector3<f64>) {
        let (k, u) = self.unit(p);
        let (v, g) = self.segments[k].value_gradient(&u);
        (self.frame.scale * v, g)
    }
    fn value_gradient_hessian(
        &self,
        p: &SVector<f64, 3>,
    ) -> (f64, SVector<f64, 3>, SMatrix<f64, 3, 3>) {
        let (k, u) = self.unit(p);
        let (v, g, h) = self.segments[k].value_gradient_hessian(&u);
        (self.frame.scale * v, g, h / self.frame.scale)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn circle_model(center: Vector2<f64>, radius: f64, frame: Frame<2>) -> IpModel<2> {
        // (|p - c|^2 - r^2) / (2 r) in world coordinates, then re-expressed in `frame`.
        let world = Poly::<2>::new(
            2,
            vec![
                (center.norm_squared() - radius * radius) / (2.0 * radius),
                -center.x / radius,
                -center.y / radius,
                0.5 / radius,
                0.0,
                0.5 / radius,
            ],
        );
        IpModel {
            frame: Frame::identity(),
            poly: world,
        }
        .reframed(frame)
    }

    #[test]
    fn segments_reproduce_their_profiles_and_blend_linearly() {
        let a = circle_model(
            Vector2::new(0.0, 0.0),
            10.0,
            Frame {
                center: Vector2::new(1.0, 2.0),
                scale: 7.0,
            },
        );
        let b = circle_model(
            Vector2::new(3.0, 1.0),
            14.0,
            Frame {
                center: Vector2::new(-2.0, 0.5),
                scale: 9.0,
            },
        );
        let stack = ProfileStack::new(vec![
            Profile {
                x: 200.0,
                model: b.clone(),
            },
            Profile {
                x: 100.0,
                model: a.clone(),
            },
        ])
        .unwrap();
        assert_eq!(stack.profiles()[0].x, 100.0, "profiles are sorted along x");
        for (y, z) in [(3.0, 4.0), (-12.0, 5.0), (0.0, 0.0)] {
            let at_a = stack.value(&Vector3::new(100.0, y, z));
            let at_b = stack.value(&Vector3::new(200.0, y, z));
            let fa = a.value(&Vector2::new(y, z));
            let fb = b.value(&Vector2::new(y, z));
            assert!((at_a - fa).abs() < 1e-9 * (1.0 + fa.abs()));
            assert!((at_b - fb).abs() < 1e-9 * (1.0 + fb.abs()));
            let mid = stack.value(&Vector3::new(125.0, y, z));
            assert!((mid - (0.75 * fa + 0.25 * fb)).abs() < 1e-9 * (1.0 + fa.abs() + fb.abs()));
        }
        assert_eq!(
            stack.segment_model(0).degree(),
            3,
            "a quadratic profile blends into a cubic"
        );
    }
}
