//! Sparse symmetric positive definite solves with faer, reusing the symbolic Cholesky analysis
//! while the sparsity pattern stays the same (it changes only when contacts appear or vanish).

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{Argsort, Pair, SparseColMat, SymbolicSparseColMat};
use faer::{MatMut, Side};

/// The matrix was not positive definite (or the factorization failed otherwise).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NotPositiveDefinite;

/// A Cholesky factorization of `A + shift I`, and the cached symbolic analysis behind it.
#[derive(Default)]
pub struct SpdSolver {
    pattern: Vec<(usize, usize)>,
    symbolic: Option<(SymbolicSparseColMat<usize>, Argsort<usize>, SymbolicLlt<usize>)>,
    factor: Option<Llt<usize, f64>>,
    /// How many symbolic analyses were computed (for statistics).
    pub symbolic_analyses: usize,
}

impl SpdSolver {
    /// Factor `A + shift I` for the symmetric matrix `A` given as triplets (duplicates summed;
    /// only the lower triangle is read).
    pub fn factor(
        &mut self,
        n: usize,
        triplets: &[(usize, usize, f64)],
        shift: f64,
    ) -> Result<(), NotPositiveDefinite> {
        let mut entries: Vec<(usize, usize, f64)> =
            triplets.iter().copied().filter(|&(i, j, _)| i >= j).collect();
        entries.extend((0..n).map(|i| (i, i, shift)));
        let pattern: Vec<(usize, usize)> = entries.iter().map(|&(i, j, _)| (i, j)).collect();
        if self.symbolic.is_none() || pattern != self.pattern {
            let pairs: Vec<Pair<usize, usize>> =
                pattern.iter().map(|&(row, col)| Pair { row, col }).collect();
            let (symbolic, argsort) =
                SymbolicSparseColMat::try_new_from_indices(n, n, &pairs).map_err(|_| NotPositiveDefinite)?;
            let llt =
                SymbolicLlt::try_new(symbolic.as_ref(), Side::Lower).map_err(|_| NotPositiveDefinite)?;
            self.symbolic = Some((symbolic, argsort, llt));
            self.pattern = pattern;
            self.symbolic_analyses += 1;
        }
        let (symbolic, argsort, llt) = self.symbolic.as_ref().ok_or(NotPositiveDefinite)?;
        let values: Vec<f64> = entries.iter().map(|e| e.2).collect();
        let matrix = SparseColMat::new_from_argsort(symbolic.clone(), argsort, &values)
            .map_err(|_| NotPositiveDefinite)?;
        let factor = Llt::try_new_with_symbolic(llt.clone(), matrix.as_ref(), Side::Lower)
            .map_err(|_| NotPositiveDefinite)?;
        self.factor = Some(factor);
        Ok(())
    }

    /// Solve in place for the `columns` right-hand sides stored column-major in `rhs`.
    pub fn solve_in_place(&self, rhs: &mut [f64], columns: usize) {
        if let Some(factor) = &self.factor {
            let rows = rhs.len() / columns;
            factor.solve_in_place(MatMut::from_column_major_slice_mut(rhs, rows, columns));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_small_spd_system_and_reuses_the_analysis() {
        // [[4, 1], [1, 3]] x = [1, 2] -> x = [1/11, 7/11].
        let a = [(0, 0, 4.0), (1, 0, 1.0), (0, 1, 1.0), (1, 1, 3.0)];
        let mut s = SpdSolver::default();
        s.factor(2, &a, 0.0).expect("SPD");
        let mut x = vec![1.0, 2.0];
        s.solve_in_place(&mut x, 1);
        assert!((x[0] - 1.0 / 11.0).abs() < 1e-15 && (x[1] - 7.0 / 11.0).abs() < 1e-15);
        s.factor(2, &a, 1.0).expect("SPD");
        assert_eq!(s.symbolic_analyses, 1);
        let indefinite = [(0, 0, 1.0), (1, 0, 2.0), (1, 1, 1.0)];
        assert_eq!(s.factor(2, &indefinite, 0.0), Err(NotPositiveDefinite));
    }
}
