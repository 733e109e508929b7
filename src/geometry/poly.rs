//! Polynomials in N = 2 or 3 variables in the monomial basis, of any degree up to [`MAX_DEGREE`].
//!
//! The monomial order is the one of seed 003: by total degree, then by descending power of the first variable, then
//! of the second. For two variables and degree 2 that is `[1, x, y, x^2, xy, y^2]`.
//! Evaluation (value, gradient, Hessian) allocates nothing: powers live in fixed-size arrays on the stack.

use nalgebra::{SMatrix, SVector};
use serde::{Deserialize, Serialize};

/// The highest degree supported. Degree 16 in normalised coordinates is already far past what a 3L fit keeps stable.
pub const MAX_DEGREE: usize = 16;

/// The monomial basis of degree `degree` in `N` variables: the exponent of every term, in the canonical order.
#[derive(Debug, Clone, PartialEq)]
pub struct Basis<const N: usize> {
    degree: usize,
    exponents: Vec<[u8; N]>,
}

impl<const N: usize> Basis<N> {
    /// The basis of all monomials of total degree `<= degree`. Panics above [`MAX_DEGREE`] (a programming error:
    /// user-facing code checks the degree first).
    pub fn new(degree: usize) -> Self {
        assert!(
            degree <= MAX_DEGREE,
            "degree {degree} exceeds the maximum {MAX_DEGREE}"
        );
        let mut exponents = Vec::with_capacity(Self::len_for(degree));
        for total in 0..=degree {
            push_exponents_of_total::<N>(total, 0, [0; N], &mut exponents);
        }
        Self { degree, exponents }
    }

    /// Number of monomials of total degree `<= degree` in `N` variables: C(degree + N, N).
    pub fn len_for(degree: usize) -> usize {
        (1..=N).fold(1, |acc, k| acc * (degree + k) / k)
    }

    pub fn degree(&self) -> usize {
        self.degree
    }

    pub fn len(&self) -> usize {
        self.exponents.len()
    }

    pub fn is_empty(&self) -> bool {
        self.exponents.is_empty()
    }

    pub fn exponents(&self) -> &[[u8; N]] {
        &self.exponents
    }

    /// Position of a monomial in the basis, if it belongs to it.
    pub fn index_of(&self, exponent: &[u8; N]) -> Option<usize> {
        self.exponents.iter().position(|e| e == exponent)
    }

    /// Writes every monomial evaluated at `p` into `out` (length [`Basis::len`]): one row of a fitting matrix.
    pub fn monomials_into(&self, p: &SVector<f64, N>, out: &mut [f64]) {
        let powers = Powers::<N>::new(p, self.degree);
        for (slot, e) in out.iter_mut().zip(&self.exponents) {
            *slot = (0..N).map(|k| powers.value[k][e[k] as usize]).product();
        }
    }
}

/// Appends, in canonical order, every exponent vector whose components from `var` on sum to `remaining`.
fn push_exponents_of_total<const N: usize>(
    remaining: usize,
    var: usize,
    mut current: [u8; N],
    out: &mut Vec<[u8; N]>,
) {
    if var == N - 1 {
        current[var] = remaining as u8;
        out.push(current);
        return;
    }
    for power in (0..=remaining).rev() {
        current[var] = power as u8;
        push_exponents_of_total::<N>(remaining - power, var + 1, current, out);
    }
}

/// Powers x^e of every variable, e = 0..=degree (derivatives of a monomial are formed from these on the fly:
/// d/dx x^e = e x^(e-1)), kept on the stack.
struct Powers<const N: usize> {
    value: [[f64; MAX_DEGREE + 1]; N],
}

impl<const N: usize> Powers<N> {
    #[inline]
    fn new(p: &SVector<f64, N>, degree: usize) -> Self {
        let mut value = [[1.0; MAX_DEGREE + 1]; N];
        for (k, row) in value.iter_mut().enumerate() {
            for e in 1..=degree {
                row[e] = row[e - 1] * p[k];
            }
        }
        Self { value }
    }

    /// x_k^e, and zero for negative powers (the derivative of a constant).
    #[inline]
    fn get(&self, k: usize, e: usize, lowered: usize) -> f64 {
        if e < lowered {
            0.0
        } else {
            self.value[k][e - lowered]
        }
    }
}

/// The powers with their first and second derivatives tabulated, e x^(e-1) and e (e-1) x^(e-2) (zero below the
/// zeroth power), for the Hessian: the exact distance's Newton steps evaluate it at every step, and a table read
/// per monomial is cheaper there than forming each derivative from the powers with a branch.
struct PowersWithDerivatives<const N: usize> {
    value: [[f64; MAX_DEGREE + 1]; N],
    first: [[f64; MAX_DEGREE + 1]; N],
    second: [[f64; MAX_DEGREE + 1]; N],
}

impl<const N: usize> PowersWithDerivatives<N> {
    #[inline]
    fn new(p: &SVector<f64, N>, degree: usize) -> Self {
        let value = Powers::new(p, degree).value;
        let mut first = [[0.0; MAX_DEGREE + 1]; N];
        let mut second = [[0.0; MAX_DEGREE + 1]; N];
        for k in 0..N {
            for e in 1..=degree {
                first[k][e] = e as f64 * value[k][e - 1];
            }
            for e in 2..=degree {
                second[k][e] = (e * (e - 1)) as f64 * value[k][e - 2];
            }
        }
        Self {
            value,
            first,
            second,
        }
    }
}

/// A polynomial: coefficients over a [`Basis`].
#[derive(Debug, Clone, PartialEq)]
pub struct Poly<const N: usize> {
    basis: Basis<N>,
    coeffs: Vec<f64>,
}

impl<const N: usize> Poly<N> {
    /// Panics when the coefficient count does not match the basis (a programming error).
    pub fn new(degree: usize, coeffs: Vec<f64>) -> Self {
        let basis = Basis::new(degree);
        assert_eq!(
            coeffs.len(),
            basis.len(),
            "a degree-{degree} polynomial in {N} variables has {} coefficients",
            basis.len()
        );
        Self { basis, coeffs }
    }

    pub fn zero(degree: usize) -> Self {
        let basis = Basis::new(degree);
        let coeffs = vec![0.0; basis.len()];
        Self { basis, coeffs }
    }

    pub fn degree(&self) -> usize {
        self.basis.degree
    }

    /// The same polynomial written over the basis of a higher degree (the new monomials' coefficients zero; the
    /// basis is graded, so the old coefficients keep their places). Panics below the current degree.
    pub fn elevated(&self, degree: usize) -> Self {
        assert!(
            degree >= self.degree(),
            "cannot lower a polynomial's degree"
        );
        let mut coeffs = self.coeffs.clone();
        coeffs.resize(Basis::<N>::len_for(degree), 0.0);
        Self::new(degree, coeffs)
    }

    pub fn basis(&self) -> &Basis<N> {
        &self.basis
    }

    pub fn coeffs(&self) -> &[f64] {
        &self.coeffs
    }

    pub fn coeffs_mut(&mut self) -> &mut [f64] {
        &mut self.coeffs
    }

    /// The coefficient of one monomial (zero when the monomial is above the degree).
    pub fn coeff(&self, exponent: &[u8; N]) -> f64 {
        self.basis
            .index_of(exponent)
            .map_or(0.0, |i| self.coeffs[i])
    }

    pub fn value(&self, p: &SVector<f64, N>) -> f64 {
        let powers = Powers::<N>::new(p, self.basis.degree);
        let mut value = 0.0;
        for (e, &c) in self.basis.exponents.iter().zip(&self.coeffs) {
            let mut term = c;
            for (row, &power) in powers.value.iter().zip(e) {
                term *= row[power as usize];
            }
            value += term;
        }
        value
    }

    pub fn value_gradient(&self, p: &SVector<f64, N>) -> (f64, SVector<f64, N>) {
        let powers = Powers::<N>::new(p, self.basis.degree);
        let mut value = 0.0;
        let mut gradient = SVector::<f64, N>::zeros();
        for (e, &c) in self.basis.exponents.iter().zip(&self.coeffs) {
            let v: [f64; N] = std::array::from_fn(|k| powers.value[k][e[k] as usize]);
            value += c * v.iter().product::<f64>();
            for k in 0..N {
                let ek = e[k] as usize;
                let mut term = c * ek as f64 * powers.get(k, ek, 1);
                for (j, vj) in v.iter().enumerate() {
                    if j != k {
                        term *= vj;
                    }
                }
                gradient[k] += term;
            }
        }
        (value, gradient)
    }

    pub fn value_gradient_hessian(
        &self,
        p: &SVector<f64, N>,
    ) -> (f64, SVector<f64, N>, SMatrix<f64, N, N>) {
        let powers = PowersWithDerivatives::<N>::new(p, self.basis.degree);
        let mut value = 0.0;
        let mut gradient = SVector::<f64, N>::zeros();
        let mut hessian = SMatrix::<f64, N, N>::zeros();
        for (e, &c) in self.basis.exponents.iter().zip(&self.coeffs) {
            let idx: [usize; N] = std::array::from_fn(|k| e[k] as usize);
            let v: [f64; N] = std::array::from_fn(|k| powers.value[k][idx[k]]);
            let d1: [f64; N] = std::array::from_fn(|k| powers.first[k][idx[k]]);
            let d2: [f64; N] = std::array::from_fn(|k| powers.second[k][idx[k]]);
            value += c * v.iter().product::<f64>();
            // Products of the other variables' powers: with N at most 3 these are at most two factors, written
            // out so that the hot path of the exact distance has no loops over filtered indices.
            let others = |skip: usize| -> f64 {
                let mut product = 1.0;
                for (j, vj) in v.iter().enumerate() {
                    if j != skip {
                        product *= vj;
                    }
                }
                product
            };
            for k in 0..N {
                let rest_k = others(k);
                gradient[k] += c * d1[k] * rest_k;
                hessian[(k, k)] += c * d2[k] * rest_k;
                for l in (k + 1)..N {
                    let rest = if N == 2 { 1.0 } else { v[3 - k - l] };
                    let mixed = c * d1[k] * d1[l] * rest;
                    hessian[(k, l)] += mixed;
                    hessian[(l, k)] += mixed;
                }
            }
        }
        (value, gradient, hessian)
    }

    /// The same function written in other coordinates: returns Q with Q(u') = P(alpha * u' + shift).
    /// Used to bring profile models fitted in different normalisations into one common frame.
    pub fn compose_affine(&self, alpha: f64, shift: &SVector<f64, N>) -> Self {
        let mut out = Self::zero(self.degree());
        for (e, &c) in self.basis.exponents.iter().zip(&self.coeffs) {
            if c == 0.0 {
                continue;
            }
            // Expand prod_k (alpha u'_k + shift_k)^e_k term by term with binomial coefficients.
            let mut terms: Vec<([u8; N], f64)> = vec![([0; N], c)];
            for k in 0..N {
                let ek = e[k] as usize;
                let mut next = Vec::with_capacity(terms.len() * (ek + 1));
                for (exp, coef) in &terms {
                    for j in 0..=ek {
                        let mut new_exp = *exp;
                        new_exp[k] = j as u8;
                        let factor = binomial(ek, j) as f64
                            * alpha.powi(j as i32)
                            * shift[k].powi((ek - j) as i32);
                        next.push((new_exp, coef * factor));
                    }
                }
                terms = next;
            }
            for (exp, coef) in terms {
                let i = out
                    .basis
                    .index_of(&exp)
                    .expect("composition keeps the degree");
                out.coeffs[i] += coef;
            }
        }
        out
    }
}

pub(crate) fn binomial(n: usize, k: usize) -> u64 {
    (0..k).fold(1u64, |acc, i| acc * (n - i) as u64 / (i as u64 + 1))
}

pub(crate) fn factorial(n: usize) -> f64 {
    (1..=n).map(|k| k as f64).product()
}

/// Serialised form: the coefficient vector in the canonical order, with its degree (the order is fixed by the
/// format version, so files stay readable when the code changes).
#[derive(Serialize, Deserialize)]
struct PolyRepr {
    degree: usize,
    coefficients: Vec<f64>,
}

impl<const N: usize> Serialize for Poly<N> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        PolyRepr {
            degree: self.degree(),
            coefficients: self.coeffs.clone(),
        }
        .serialize(s)
    }
}

impl<'de, const N: usize> Deserialize<'de> for Poly<N> {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let repr = PolyRepr::deserialize(d)?;
        if repr.degree > MAX_DEGREE {
            return Err(serde::de::Error::custom(format!(
                "degree {} exceeds the maximum {MAX_DEGREE}",
                repr.degree
            )));
        }
        let expected = Basis::<N>::len_for(repr.degree);
        if repr.coefficients.len() != expected {
            return Err(serde::de::Error::custom(format!(
                "a degree-{} polynomial in {N} variables has {expected} coefficients, the file has {}",
                repr.degree,
                repr.coefficients.len()
            )));
        }
        if let Some(bad) = repr.coefficients.iter().find(|c| !c.is_finite()) {
            return Err(serde::de::Error::custom(format!(
                "coefficient {bad} is not a finite number"
            )));
        }
        Ok(Self::new(repr.degree, repr.coefficients))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Vector2, Vector3};

    #[test]
    fn an_elevated_polynomial_has_the_same_values() {
        let coeffs: Vec<f64> = (0..Basis::<2>::len_for(4))
            .map(|i| 0.5 - i as f64 * 0.1)
            .collect();
        let p = Poly::<2>::new(4, coeffs);
        let q = p.elevated(6);
        assert_eq!(q.degree(), 6);
        for point in [Vector2::new(0.3, -0.7), Vector2::new(1.2, 0.4)] {
            assert_eq!(p.value(&point), q.value(&point));
        }
        assert_eq!(q.coeff(&[2, 2]), p.coeff(&[2, 2]));
        assert_eq!(q.coeff(&[6, 0]), 0.0);
    }

    #[test]
    fn order_matches_seed_003() {
        let b = Basis::<2>::new(4);
        let names: Vec<String> = b
            .exponents()
            .iter()
            .map(|e| format!("{}{}", e[0], e[1]))
            .collect();
        assert_eq!(
            names.join(" "),
            "00 10 01 20 11 02 30 21 12 03 40 31 22 13 04"
        );
        assert_eq!(Basis::<3>::new(6).len(), 84);
        assert_eq!(Basis::<3>::len_for(2), 10);
        assert_eq!(
            Basis::<3>::new(1).exponents(),
            &[[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]]
        );
    }

    fn sample_poly3() -> Poly<3> {
        let n = Basis::<3>::len_for(4);
        Poly::new(4, (0..n).map(|i| ((i * 7919) % 13) as f64 - 6.0).collect())
    }

    #[test]
    fn gradient_and_hessian_match_finite_differences() {
        let f = sample_poly3();
        let p = Vector3::new(0.3, -0.7, 1.1);
        let (v, g, h) = f.value_gradient_hessian(&p);
        assert!((v - f.value(&p)).abs() < 1e-12);
        let eps = 1e-6;
        for k in 0..3 {
            let mut dp = Vector3::zeros();
            dp[k] = eps;
            let fd = (f.value(&(p + dp)) - f.value(&(p - dp))) / (2.0 * eps);
            assert!(
                (g[k] - fd).abs() < 1e-6 * (1.0 + fd.abs()),
                "grad {k}: {} vs {fd}",
                g[k]
            );
            let gp = f.value_gradient(&(p + dp)).1;
            let gm = f.value_gradient(&(p - dp)).1;
            for l in 0..3 {
                let fd2 = (gp[l] - gm[l]) / (2.0 * eps);
                assert!((h[(k, l)] - fd2).abs() < 1e-5 * (1.0 + fd2.abs()));
            }
        }
    }

    #[test]
    fn explicit_quadratic() {
        // 1 + 2x + 3y + 4x^2 + 5xy + 6y^2
        let f = Poly::<2>::new(2, vec![1.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        let p = Vector2::new(2.0, -1.0);
        assert_eq!(f.value(&p), 1.0 + 4.0 - 3.0 + 16.0 - 10.0 + 6.0);
        let (_, g, h) = f.value_gradient_hessian(&p);
        assert_eq!(
            g,
            Vector2::new(2.0 + 8.0 * 2.0 - 5.0, 3.0 + 5.0 * 2.0 - 12.0)
        );
        assert_eq!(h, nalgebra::Matrix2::new(8.0, 5.0, 5.0, 12.0));
    }

    #[test]
    fn affine_composition_is_the_same_function() {
        let f = sample_poly3();
        let shift = Vector3::new(0.2, -0.4, 0.7);
        let q = f.compose_affine(1.7, &shift);
        for p in [Vector3::new(0.1, 0.2, 0.3), Vector3::new(-1.0, 0.5, 2.0)] {
            let expected = f.value(&(p * 1.7 + shift));
            assert!((q.value(&p) - expected).abs() < 1e-9 * (1.0 + expected.abs()));
        }
    }

    #[test]
    fn serde_rejects_wrong_length() {
        let json = r#"{"degree":2,"coefficients":[1,2,3]}"#;
        let err = serde_json::from_str::<Poly<2>>(json)
            .unwrap_err()
            .to_string();
        assert!(err.contains("has 6 coefficients, the file has 3"), "{err}");
    }
}
