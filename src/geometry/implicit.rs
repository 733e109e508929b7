//! Implicit functions F: R^N -> R whose zero set is a curve (N = 2) or a surface (N = 3), and the implicit
//! polynomial model: a polynomial in normalised coordinates together with its normalisation.
//!
//! Convention everywhere: F > 0 outside the material, F < 0 inside, in millimetres (world coordinates).

use nalgebra::{SMatrix, SVector};
use serde::{Deserialize, Serialize};

use super::poly::Poly;
use super::taylor::Taylor;

/// What the distance and sampling code needs of a model: the value and its first and second derivatives.
pub trait Implicit<const N: usize>: Sync {
    fn value(&self, p: &SVector<f64, N>) -> f64 {
        self.value_gradient(p).0
    }
    fn value_gradient(&self, p: &SVector<f64, N>) -> (f64, SVector<f64, N>);
    fn value_gradient_hessian(
        &self,
        p: &SVector<f64, N>,
    ) -> (f64, SVector<f64, N>, SMatrix<f64, N, N>);
    /// The model re-expanded about `at`, for bounds over a box: only polynomials have one, and only they get the
    /// exact distance's certificate.
    fn taylor(&self, _at: &SVector<f64, N>) -> Option<Taylor<N>> {
        None
    }
}

impl<const N: usize> Implicit<N> for Poly<N> {
    fn value(&self, p: &SVector<f64, N>) -> f64 {
        Poly::value(self, p)
    }
    fn value_gradient(&self, p: &SVector<f64, N>) -> (f64, SVector<f64, N>) {
        Poly::value_gradient(self, p)
    }
    fn value_gradient_hessian(
        &self,
        p: &SVector<f64, N>,
    ) -> (f64, SVector<f64, N>, SMatrix<f64, N, N>) {
        Poly::value_gradient_hessian(self, p)
    }
    fn taylor(&self, at: &SVector<f64, N>) -> Option<Taylor<N>> {
        Some(Taylor::of_poly(self, at, 1.0))
    }
}

/// The normalisation of a data set: centred on its centroid and scaled to unit RMS radius, so that monomials of
/// any degree stay of order one and the fitting matrix stays well conditioned. `u = (p - center) / scale`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Frame<const N: usize> {
    #[serde(with = "vector_as_array")]
    pub center: SVector<f64, N>,
    /// Millimetres per normalised unit.
    pub scale: f64,
}

impl<const N: usize> Frame<N> {
    pub fn identity() -> Self {
        Self {
            center: SVector::zeros(),
            scale: 1.0,
        }
    }

    /// Centroid and RMS radius of the points. `None` for an empty set or one where every point coincides.
    pub fn of_points(points: &[SVector<f64, N>]) -> Option<Self> {
        if points.is_empty() {
            return None;
        }
        let center = points.iter().sum::<SVector<f64, N>>() / points.len() as f64;
        let mean_square = points
            .iter()
            .map(|p| (p - center).norm_squared())
            .sum::<f64>()
            / points.len() as f64;
        let scale = mean_square.sqrt();
        (scale > 0.0 && scale.is_finite()).then_some(Self { center, scale })
    }

    pub fn to_unit(&self, p: &SVector<f64, N>) -> SVector<f64, N> {
        (p - self.center) / self.scale
    }
}

/// An implicit polynomial model: F(p) = scale * P((p - center) / scale).
/// The factor `scale` makes F read in millimetres: a fitted P has unit gradient near its data in normalised
/// coordinates, so F near the data is close to the signed distance in mm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct IpModel<const N: usize> {
    pub frame: Frame<N>,
    pub poly: Poly<N>,
}

impl<const N: usize> IpModel<N> {
    pub fn degree(&self) -> usize {
        self.poly.degree()
    }

    /// The same function expressed in another frame (for blending profiles fitted in different frames).
    pub fn reframed(&self, target: Frame<N>) -> Self {
        // u = (p - c) / s = (s' u' + c' - c) / s = alpha u' + shift;  F = s P(u) = s' Q(u')  =>  Q = (s / s') P(...)
        let alpha = target.scale / self.frame.scale;
        let shift = (target.center - self.frame.center) / self.frame.scale;
        let mut poly = self.poly.compose_affine(alpha, &shift);
        let factor = self.frame.scale / target.scale;
        poly.coeffs_mut().iter_mut().for_each(|c| *c *= factor);
        Self {
            frame: target,
            poly,
        }
    }
}

impl<const N: usize> Implicit<N> for IpModel<N> {
    fn value(&self, p: &SVector<f64, N>) -> f64 {
        self.frame.scale * self.poly.value(&self.frame.to_unit(p))
    }
    fn value_gradient(&self, p: &SVector<f64, N>) -> (f64, SVector<f64, N>) {
        let (v, g) = self.poly.value_gradient(&self.frame.to_unit(p));
        (self.frame.scale * v, g)
    }
    fn value_gradient_hessian(
        &self,
        p: &SVector<f64, N>,
    ) -> (f64, SVector<f64, N>, SMatrix<f64, N, N>) {
        let (v, g, h) = self.poly.value_gradient_hessian(&self.frame.to_unit(p));
        (self.frame.scale * v, g, h / self.frame.scale)
    }
    fn taylor(&self, at: &SVector<f64, N>) -> Option<Taylor<N>> {
        Some(Taylor::of_poly(
            &self.poly,
            &self.frame.to_unit(at),
            self.frame.scale,
        ))
    }
}

/// Serialises a fixed-size vector as a plain JSON array, so model files read naturally.
pub(crate) mod vector_as_array {
    use nalgebra::SVector;
    use serde::{Deserialize, Deserializer, Serialize, Serializer};

    pub fn serialize<S: Serializer, const N: usize>(
        v: &SVector<f64, N>,
        s: S,
    ) -> Result<S::Ok, S::Error> {
        v.as_slice().serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>, const N: usize>(
        d: D,
    ) -> Result<SVector<f64, N>, D::Error> {
        let values = Vec::<f64>::deserialize(d)?;
        if values.len() != N || values.iter().any(|v| !v.is_finite()) {
            return Err(serde::de::Error::custom(format!(
                "expected {N} finite numbers, found {values:?}"
            )));
        }
        Ok(SVector::from_column_slice(&values))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    #[test]
    fn reframing_keeps_world_values_and_derivatives() {
        let poly = Poly::<2>::new(3, (0..10).map(|i| (i as f64 * 0.37).sin()).collect());
        let model = IpModel {
            frame: Frame {
                center: Vector2::new(10.0, -4.0),
                scale: 25.0,
            },
            poly,
        };
        let other = model.reframed(Frame {
            center: Vector2::new(3.0, 2.0),
            scale: 40.0,
        });
        for p in [Vector2::new(12.0, -1.0), Vector2::new(-20.0, 30.0)] {
            let (v1, g1, h1) = model.value_gradient_hessian(&p);
            let (v2, g2, h2) = other.value_gradient_hessian(&p);
            assert!((v1 - v2).abs() < 1e-9 * (1.0 + v1.abs()));
            assert!((g1 - g2).norm() < 1e-9 * (1.0 + g1.norm()));
            assert!((h1 - h2).norm() < 1e-9 * (1.0 + h1.norm()));
        }
    }
}
