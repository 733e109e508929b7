//! Rows of the fitting matrices: every monomial of the basis at a point, by recurrence. The basis is graded, so
//! each monomial but the constant is an earlier one times one variable: one multiplication per monomial, instead
//! of a product of powers per monomial.

use nalgebra::SVector;

use crate::geometry::poly::Basis;

/// For each monomial after the constant, the earlier monomial and the variable it is multiplied by.
pub(super) struct Monomials<const N: usize> {
    steps: Vec<(usize, usize)>,
}

impl<const N: usize> Monomials<N> {
    pub(super) fn new(basis: &Basis<N>) -> Self {
        let steps = basis
            .exponents()
            .iter()
            .skip(1)
            .map(|e| {
                let var = e
                    .iter()
                    .position(|&x| x > 0)
                    .expect("only the first is constant");
                let mut lower = *e;
                lower[var] -= 1;
                let parent = basis
                    .index_of(&lower)
                    .expect("the basis is closed under lowering");
                (parent, var)
            })
            .collect();
        Self { steps }
    }

    /// The number of monomials (the row length).
    pub(super) fn len(&self) -> usize {
        self.steps.len() + 1
    }

    /// Writes every monomial at `p` into `out` (length [`Monomials::len`]), in the basis order.
    pub(super) fn fill(&self, p: &SVector<f64, N>, out: &mut [f64]) {
        out[0] = 1.0;
        for (j, &(parent, var)) in self.steps.iter().enumerate() {
            out[j + 1] = out[parent] * p[var];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector3;

    #[test]
    fn rows_by_recurrence_are_the_basis_monomials() {
        let basis = Basis::<3>::new(6);
        let monomials = Monomials::new(&basis);
        let p = Vector3::new(0.7, -1.3, 0.4);
        let mut fast = vec![0.0; monomials.len()];
        let mut slow = vec![0.0; basis.len()];
        monomials.fill(&p, &mut fast);
        basis.monomials_into(&p, &mut slow);
        for (f, s) in fast.iter().zip(&slow) {
            assert!((f - s).abs() <= 1e-15 * s.abs().max(1.0), "{f} vs {s}");
        }
    }
}
