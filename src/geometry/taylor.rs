//! A polynomial model re-expanded about a point: F(x0 + w) = sum_m q_m w^m, with w in millimetres.
//!
//! The expansion turns a polynomial into bounds that hold over a whole box: on |w_k| <= r every monomial is at most
//! r^|m| in size, so |F(x0 + w) - F(x0)| <= sum_{m != 0} |q_m| r^|m| (the centred form), and likewise for the
//! second derivatives. The exact distance's certificate is built on these bounds. They are tight where it matters:
//! the terms that are left grow with r, so small boxes get sharp bounds.

use nalgebra::{SMatrix, SVector};

use super::poly::Poly;

/// The Taylor coefficients q_m of a polynomial about a point, each with its exponent m.
#[derive(Debug, Clone)]
pub struct Taylor<const N: usize> {
    terms: Vec<([usize; N], f64)>,
    /// A bound on the rounding error of the value at the point (see [`Taylor::rounding`]).
    rounding: f64,
}

impl<const N: usize> Taylor<N> {
    /// The expansion of `scale * poly(at_unit + w / scale)` in w: a polynomial in normalised coordinates seen in
    /// millimetres, as an implicit polynomial model reads (`scale` mm per normalised unit).
    pub(crate) fn of_poly(poly: &Poly<N>, at_unit: &SVector<f64, N>, scale: f64) -> Self {
        let degree = poly.degree();
        let side = degree + 1;
        let mut coeffs = vec![0.0; side.pow(N as u32)];
        for (e, &c) in poly.basis().exponents().iter().zip(poly.coeffs()) {
            coeffs[dense_index::<N>(e.map(usize::from), side)] = c;
        }
        // The shift adds terms c_e C(e, m) a^(e - m): each coefficient's rounding error is a few epsilons of the sum
        // of their sizes, at most sum_e |c_e| prod_k (1 + |a_k|)^e_k, times the number of additions.
        let growth: [Vec<f64>; N] = std::array::from_fn(|k| {
            (0..side)
                .scan(1.0, |power, _| {
                    let this = *power;
                    *power *= 1.0 + at_unit[k].abs();
                    Some(this)
                })
                .collect()
        });
        let size: f64 = poly
            .basis()
            .exponents()
            .iter()
            .zip(poly.coeffs())
            .map(|(e, c)| {
                c.abs()
                    * (0..N)
                        .map(|k| growth[k][usize::from(e[k])])
                        .product::<f64>()
            })
            .sum();
        let rounding = 4.0 * (N * side) as f64 * f64::EPSILON * size * scale;
        // One axis at a time: every line of coefficients along axis k is shifted by at_unit[k], in place by
        // repeated synthetic division (Horner's Taylor shift); a line whose other exponents sum to o holds terms up
        // to degree - o only, and shifting keeps it so.
        for k in 0..N {
            let stride = side.pow(k as u32);
            let a = at_unit[k];
            for start in 0..coeffs.len() {
                let exponent = exponent_of::<N>(start, side);
                let others: usize = exponent.iter().sum();
                if exponent[k] != 0 || others > degree {
                    continue;
                }
                let top = degree - others;
                for i in 0..top {
                    for j in (i..top).rev() {
                        coeffs[start + j * stride] += a * coeffs[start + (j + 1) * stride];
                    }
                }
            }
        }
        // w = scale * (u - at_unit): the coefficient of w^m is q_m = scale * p_m / scale^|m|.
        let factors: Vec<f64> = (0..=degree)
            .scan(scale, |factor, _| {
                let this = *factor;
                *factor /= scale;
                Some(this)
            })
            .collect();
        let terms = coeffs
            .iter()
            .enumerate()
            .filter(|(_, q)| **q != 0.0)
            .filter_map(|(index, &q)| {
                let m = exponent_of::<N>(index, side);
                let order: usize = m.iter().sum();
                (order <= degree).then(|| (m, q * factors[order]))
            })
            .collect();
        Self { terms, rounding }
    }

    fn terms(&self) -> impl Iterator<Item = ([usize; N], f64)> + '_ {
        self.terms.iter().copied()
    }

    fn coeff(&self, m: [usize; N]) -> f64 {
        self.terms
            .iter()
            .find(|(e, _)| *e == m)
            .map_or(0.0, |(_, q)| *q)
    }

    /// F at the expansion point.
    pub(crate) fn value(&self) -> f64 {
        self.coeff([0; N])
    }

    /// The Hessian at the expansion point (mm^-1).
    pub(crate) fn hessian(&self) -> SMatrix<f64, N, N> {
        SMatrix::from_fn(|a, b| {
            let mut m = [0; N];
            m[a] += 1;
            m[b] += 1;
            let factor = if a == b { 2.0 } else { 1.0 };
            factor * self.coeff(m)
        })
    }

    /// Entrywise bounds on how far the Hessian moves from its value at the expansion point over |w_k| <= r:
    /// d^2 w^m / dw_a dw_b = m_a (m_b - [a = b]) w^(m - e_a - e_b), at most that factor times r^(|m| - 2).
    pub(crate) fn hessian_variation(&self, r: f64) -> SMatrix<f64, N, N> {
        let mut bound = SMatrix::<f64, N, N>::zeros();
        for (m, q) in self.terms() {
            let order: usize = m.iter().sum();
            if order < 3 {
                continue;
            }
            let size = q.abs() * r.powi(order as i32 - 2);
            for a in 0..N {
                for b in 0..N {
                    let factor = m[a] * m[b].saturating_sub(usize::from(a == b));
                    bound[(a, b)] += size * factor as f64;
                }
            }
        }
        bound
    }

    /// A bound on the rounding error of [`Taylor::value`] (mm), for tests that must not exclude a zero by it.
    pub(crate) fn rounding(&self) -> f64 {
        self.rounding
    }

    /// A bound on |F(x0 + w) - F(x0)| over |w_k| <= r.
    pub(crate) fn variation(&self, r: f64) -> f64 {
        self.variation_from(1, r)
    }

    /// The gradient at the expansion point.
    pub(crate) fn gradient(&self) -> SVector<f64, N> {
        SVector::from_fn(|a, _| {
            let mut m = [0; N];
            m[a] = 1;
            self.coeff(m)
        })
    }

    /// A bound on |F(x0 + w) - F(x0) - grad F(x0).w| over |w_k| <= r: how far F departs from its tangent plane.
    pub(crate) fn curved_variation(&self, r: f64) -> f64 {
        self.variation_from(2, r)
    }

    /// The centred form's bound on the terms of order `lowest` and up.
    fn variation_from(&self, lowest: usize, r: f64) -> f64 {
        self.terms()
            .map(|(m, q)| (m.iter().sum::<usize>(), q))
            .filter(|(order, _)| *order >= lowest)
            .map(|(order, q)| q.abs() * r.powi(order as i32))
            .sum()
    }
}

fn dense_index<const N: usize>(m: [usize; N], side: usize) -> usize {
    m.iter().rev().fold(0, |index, &e| index * side + e)
}

fn exponent_of<const N: usize>(mut index: usize, side: usize) -> [usize; N] {
    std::array::from_fn(|_| {
        let e = index % side;
        index /= side;
        e
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::implicit::{Frame, Implicit, IpModel};
    use nalgebra::{Vector2, Vector3};

    fn model_2d() -> IpModel<2> {
        let poly = Poly::new(
            4,
            vec![
                -1.0, 0.3, -0.2, 1.1, 0.25, 0.9, 0.05, -0.02, 0.07, 0.01, 0.2, -0.04, 0.03, 0.06,
                0.15,
            ],
        );
        IpModel {
            frame: Frame {
                center: Vector2::new(12.0, -3.0),
                scale: 7.5,
            },
            poly,
        }
    }

    #[test]
    fn the_expansion_reproduces_the_model_its_gradient_and_hessian_away_from_its_point() {
        let model = model_2d();
        let at = Vector2::new(15.0, 1.0);
        let taylor = Taylor::of_poly(&model.poly, &model.frame.to_unit(&at), model.frame.scale);
        let (v, _, h) = model.value_gradient_hessian(&at);
        assert!((taylor.value() - v).abs() < 1e-12);
        assert!((taylor.hessian() - h).norm() < 1e-12);
        for w in [Vector2::<f64>::new(0.3, -0.7), Vector2::new(-2.0, 1.5)] {
            let sum: f64 = taylor
                .terms()
                .map(|(m, q)| q * w[0].powi(m[0] as i32) * w[1].powi(m[1] as i32))
                .sum();
            assert!((sum - model.value(&(at + w))).abs() < 1e-10, "at w = {w}");
        }
    }

    #[test]
    fn the_bounds_hold_over_the_box_and_are_nearly_reached() {
        let model = model_2d();
        let at = Vector2::new(10.0, -6.0);
        let taylor = Taylor::of_poly(&model.poly, &model.frame.to_unit(&at), model.frame.scale);
        let r = 1.5;
        let (f0, h0) = (taylor.value(), taylor.hessian());
        let (variation, hessian_variation) = (taylor.variation(r), taylor.hessian_variation(r));
        let (mut seen, mut seen_h) = (0.0f64, 0.0f64);
        for i in 0..=20 {
            for j in 0..=20 {
                let w = Vector2::new(-r + 0.15 * i as f64, -r + 0.15 * j as f64);
                let (v, _, h) = model.value_gradient_hessian(&(at + w));
                assert!((v - f0).abs() <= variation + 1e-12);
                let moved = (h - h0).abs();
                assert!(moved
                    .iter()
                    .zip(hessian_variation.iter())
                    .all(|(m, b)| *m <= b + 1e-12));
                seen = seen.max((v - f0).abs());
                seen_h = seen_h.max((h - h0).abs().max());
            }
        }
        // Not a loose bound: within a small factor of what the box's own points reach.
        assert!(variation < 4.0 * seen, "{variation} against {seen}");
        assert!(
            hessian_variation.max() < 6.0 * seen_h,
            "{hessian_variation} against {seen_h}"
        );
    }

    #[test]
    fn three_variables_expand_the_same_way() {
        let poly = Poly::<3>::new(
            3,
            (0..20)
                .map(|i| ((i * 7 % 11) as f64 - 5.0) / 10.0)
                .collect(),
        );
        let at = Vector3::new(0.4, -0.3, 0.8);
        let taylor = Taylor::of_poly(&poly, &at, 1.0);
        let (v, _, h) = poly.value_gradient_hessian(&at);
        assert!((taylor.value() - v).abs() < 1e-12);
        assert!((taylor.hessian() - h).norm() < 1e-12);
    }
}
