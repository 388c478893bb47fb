#![doc = include_str!("../README.md")]

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{MatMut, Side};

/// The matrix was not positive definite (or the factorization failed otherwise).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NotPositiveDefinite;

/// A lower-triangle sparsity pattern (always with the full diagonal) and its symbolic Cholesky
/// factorization.
struct Analysis {
    structure: SymbolicSparseColMat<usize>,
    llt: SymbolicLlt<usize>,
    /// Value slot of each diagonal entry.
    diagonal: Vec<usize>,
}

impl Analysis {
    /// Analyse the `n x n` pattern of the lower-triangle positions `entries` (any order, repeats
    /// allowed) and the diagonal.
    fn new(n: usize, entries: impl Iterator<Item = (usize, usize)>) -> Result<Self, NotPositiveDefinite> {
        let structure = column_structure(n, entries.chain((0..n).map(|i| (i, i))))?;
        let llt = SymbolicLlt::try_new(structure.as_ref(), Side::Lower).map_err(|_| NotPositiveDefinite)?;
        let mut analysis = Analysis { structure, llt, diagonal: Vec::new() };
        analysis.diagonal =
            (0..n).map(|i| analysis.slot(i, i).ok_or(NotPositiveDefinite)).collect::<Result<_, _>>()?;
        Ok(analysis)
    }

    fn size(&self) -> usize {
        self.structure.ncols()
    }

    /// The positions `(row, column)` of the pattern.
    fn entries(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        (0..self.size())
            .flat_map(move |col| self.structure.row_idx_of_col_raw(col).iter().map(move |&row| (row, col)))
    }

    /// Where the value of entry `(row, col)` is stored, if it is in the pattern (rows are sorted
    /// within each column).
    fn slot(&self, row: usize, col: usize) -> Option<usize> {
        let range = self.structure.col_range(col);
        let rows = &self.structure.row_idx()[range.clone()];
        rows.binary_search(&row).ok().map(|k| range.start + k)
    }

    /// The value slot of every triplet (`None` above the diagonal, which is not read) into
    /// `slots`; whether all lower-triangle triplets are in the pattern. The triplets are
    /// bucketed by column, and each column's rows are looked up in a row-indexed table of its
    /// slots (a pass over the triplets and the pattern, where a search per triplet costs far more).
    fn map_slots(&self, triplets: &[(usize, usize, f64)], slots: &mut Vec<Option<usize>>) -> bool {
        let n = self.size();
        slots.clear();
        slots.resize(triplets.len(), None);
        let lower = |&(i, j, _): &(usize, usize, f64)| i >= j && i < n;
        let mut starts = vec![0; n + 1];
        for t in triplets.iter().filter(|t| lower(t)) {
            starts[t.1 + 1] += 1;
        }
        for col in 0..n {
            starts[col + 1] += starts[col];
        }
        let mut next = starts.clone();
        let mut bucketed = vec![0; starts[n]];
        for (k, t) in triplets.iter().enumerate().filter(|(_, t)| lower(t)) {
            bucketed[next[t.1]] = k;
            next[t.1] += 1;
        }
        let mut slot_of_row = vec![usize::MAX; n];
        let mut covered = triplets.iter().all(|t| t.0 < n && t.1 < n);
        for col in 0..n {
            let range = self.structure.col_range(col);
            for (slot, &row) in range.clone().zip(&self.structure.row_idx()[range.clone()]) {
                slot_of_row[row] = slot;
            }
            for &k in &bucketed[starts[col]..starts[col + 1]] {
                let slot = slot_of_row[triplets[k].0];
                covered &= slot != usize::MAX;
                slots[k] = (slot != usize::MAX).then_some(slot);
            }
            for &row in &self.structure.row_idx()[range] {
                slot_of_row[row] = usize::MAX;
            }
        }
        covered
    }
}

/// The compressed-column pattern of the `n x n` positions `(row, column)` (any order, repeats
/// allowed): bucketed by column, repeats dropped with a marker per row, rows sorted within
/// each column (a pass over the positions, where a global sort of them would cost far more).
fn column_structure(
    n: usize,
    positions: impl Iterator<Item = (usize, usize)>,
) -> Result<SymbolicSparseColMat<usize>, NotPositiveDefinite> {
    let positions: Vec<(usize, usize)> = positions.collect();
    if positions.iter().any(|&(row, col)| row >= n || col >= n) {
        return Err(NotPositiveDefinite);
    }
    let mut starts = vec![0; n + 1];
    for &(_, col) in &positions {
        starts[col + 1] += 1;
    }
    for col in 0..n {
        starts[col + 1] += starts[col];
    }
    let mut next = starts.clone();
    let mut bucketed = vec![0; positions.len()];
    for &(row, col) in &positions {
        bucketed[next[col]] = row;
        next[col] += 1;
    }
    let mut seen_in = vec![usize::MAX; n];
    let mut col_ptr = Vec::with_capacity(n + 1);
    let mut row_idx = Vec::new();
    col_ptr.push(0);
    for col in 0..n {
        let first = row_idx.len();
        for &row in &bucketed[starts[col]..starts[col + 1]] {
            if seen_in[row] != col {
                seen_in[row] = col;
                row_idx.push(row);
            }
        }
        row_idx[first..].sort_unstable();
        col_ptr.push(row_idx.len());
    }
    Ok(SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx))
}

/// A Cholesky factorization of `A + shift I`, and the growing symbolic analysis behind it.
#[derive(Default)]
pub struct SpdSolver {
    analysis: Option<Analysis>,
    /// Positions of the triplets of the last call, and the value slot of each.
    positions: Vec<(usize, usize)>,
    slots: Vec<Option<usize>>,
    /// Values of the loaded matrix on the analysed pattern, and of the shifted one factored.
    matrix: Vec<f64>,
    values: Vec<f64>,
    factor: Option<Llt<usize, f64>>,
    /// How many symbolic analyses were computed (for statistics).
    pub symbolic_analyses: usize,
}

impl SpdSolver {
    /// Factor `A + shift I` for the symmetric `n x n` matrix `A` given as triplets (duplicates
    /// summed; only the lower triangle is read).
    pub fn factor(
        &mut self,
        n: usize,
        triplets: &[(usize, usize, f64)],
        shift: f64,
    ) -> Result<(), NotPositiveDefinite> {
        self.load(n, triplets)?;
        self.factor_shifted(shift)
    }

    /// Take the symmetric `n x n` matrix `A` given as triplets (duplicates summed; only the
    /// lower triangle is read) for [`SpdSolver::factor_shifted`].
    pub fn load(&mut self, n: usize, triplets: &[(usize, usize, f64)]) -> Result<(), NotPositiveDefinite> {
        if !self.same_positions(n, triplets) {
            self.map_positions(n, triplets)?;
        }
        let analysis = self.analysis.as_ref().ok_or(NotPositiveDefinite)?;
        self.matrix.clear();
        self.matrix.resize(analysis.structure.row_idx().len(), 0.0);
        for (&(_, _, v), slot) in triplets.iter().zip(&self.slots) {
            if let Some(k) = *slot {
                self.matrix[k] += v;
            }
        }
        Ok(())
    }

    /// Factor `A + shift I` for the `A` of the last [`SpdSolver::load`] (the shifts of a
    /// regularization search need one pass over the triplets, not one each).
    pub fn factor_shifted(&mut self, shift: f64) -> Result<(), NotPositiveDefinite> {
        let analysis = self.analysis.as_ref().ok_or(NotPositiveDefinite)?;
        self.values.clone_from(&self.matrix);
        for &k in &analysis.diagonal {
            self.values[k] += shift;
        }
        let matrix = SparseColMatRef::new(analysis.structure.as_ref(), &self.values);
        let factor = Llt::try_new_with_symbolic(analysis.llt.clone(), matrix, Side::Lower)
            .map_err(|_| NotPositiveDefinite)?;
        self.factor = Some(factor);
        Ok(())
    }

    /// Whether `triplets` has the positions of the last call (then its value slots are known).
    fn same_positions(&self, n: usize, triplets: &[(usize, usize, f64)]) -> bool {
        self.analysis.as_ref().is_some_and(|a| a.size() == n)
            && self.positions.len() == triplets.len()
            && self.positions.iter().zip(triplets).all(|(&p, &(i, j, _))| p == (i, j))
    }

    /// Map the triplets' positions to value slots, first analysing the union of the analysed
    /// pattern and theirs if some lie outside it.
    fn map_positions(
        &mut self,
        n: usize,
        triplets: &[(usize, usize, f64)],
    ) -> Result<(), NotPositiveDefinite> {
        let covered =
            self.analysis.as_ref().is_some_and(|a| a.size() == n && a.map_slots(triplets, &mut self.slots));
        if !covered {
            let old = self.analysis.take().filter(|a| a.size() == n);
            let new = triplets.iter().filter(|t| t.0 >= t.1).map(|&(i, j, _)| (i, j));
            let analysis = Analysis::new(n, old.iter().flat_map(Analysis::entries).chain(new))?;
            self.symbolic_analyses += 1;
            analysis.map_slots(triplets, &mut self.slots);
            self.analysis = Some(analysis);
        }
        self.positions.clear();
        self.positions.extend(triplets.iter().map(|&(i, j, _)| (i, j)));
        Ok(())
    }

    /// The size and lower-triangle positions of the analysed pattern, if any: with
    /// [`SpdSolver::with_pattern`] they restore a solver whose factorizations are those of this
    /// one, to the bit (the fill-reducing ordering depends on the pattern analysed).
    pub fn analysed_pattern(&self) -> Option<(usize, Vec<(usize, usize)>)> {
        self.analysis.as_ref().map(|a| (a.size(), a.entries().collect()))
    }

    /// A solver with the `n x n` pattern `entries` analysed (see [`SpdSolver::analysed_pattern`]).
    pub fn with_pattern(n: usize, entries: &[(usize, usize)]) -> Result<Self, NotPositiveDefinite> {
        if entries.iter().any(|&(i, j)| i >= n || j > i) {
            return Err(NotPositiveDefinite);
        }
        let analysis = Analysis::new(n, entries.iter().copied())?;
        Ok(SpdSolver { analysis: Some(analysis), symbolic_analyses: 1, ..SpdSolver::default() })
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

    fn solve(s: &SpdSolver, b: &[f64]) -> Vec<f64> {
        let mut x = b.to_vec();
        s.solve_in_place(&mut x, 1);
        x
    }

    fn close(x: &[f64], y: &[f64]) -> bool {
        x.iter().zip(y).all(|(a, b)| (a - b).abs() < 1e-14)
    }

    #[test]
    fn solves_a_small_spd_system_and_reuses_the_analysis() {
        // [[4, 1], [1, 3]] x = [1, 2] -> x = [1/11, 7/11].
        let a = [(0, 0, 4.0), (1, 0, 1.0), (0, 1, 1.0), (1, 1, 3.0)];
        let mut s = SpdSolver::default();
        s.factor(2, &a, 0.0).expect("SPD");
        assert!(close(&solve(&s, &[1.0, 2.0]), &[1.0 / 11.0, 7.0 / 11.0]));
        s.factor(2, &a, 1.0).expect("SPD");
        assert_eq!(s.symbolic_analyses, 1);
        let indefinite = [(0, 0, 1.0), (1, 0, 2.0), (1, 1, 1.0)];
        assert_eq!(s.factor(2, &indefinite, 0.0), Err(NotPositiveDefinite));
    }

    #[test]
    fn the_pattern_grows_and_subsets_reuse_the_analysis() {
        // Tridiagonal [2, -1] with one extra coupling (2, 0) = 0.5, duplicates split in two.
        let full = [
            (0, 0, 1.0),
            (0, 0, 1.0),
            (1, 1, 2.0),
            (2, 2, 2.0),
            (1, 0, -1.0),
            (0, 1, -1.0),
            (2, 1, -1.0),
            (2, 0, 0.5),
        ];
        let b = [1.0, 0.0, 1.0];
        // [[2, -1, .5], [-1, 2, -1], [.5, -1, 2]] x = b -> x = (2/3, 2/3, 2/3).
        let x_full = [2.0 / 3.0; 3];
        // Without the coupling: [[2, -1, 0], [-1, 2, -1], [0, -1, 2]] x = b -> x = (1, 1, 1).
        let tridiagonal: Vec<_> = full.iter().copied().filter(|t| (t.0, t.1) != (2, 0)).collect();
        let mut s = SpdSolver::default();
        s.factor(3, &full, 0.0).expect("SPD");
        assert_eq!(s.symbolic_analyses, 1);
        assert!(close(&solve(&s, &b), &x_full));
        // A subset of the pattern: reused, the missing entry is an explicit zero.
        s.factor(3, &tridiagonal, 0.0).expect("SPD");
        assert_eq!(s.symbolic_analyses, 1);
        assert!(close(&solve(&s, &b), &[1.0, 1.0, 1.0]));

        // Starting from the subset, the new entry (2, 0) grows the pattern once...
        let mut s = SpdSolver::default();
        s.factor(3, &tridiagonal, 0.0).expect("SPD");
        s.factor(3, &full, 0.0).expect("SPD");
        assert_eq!(s.symbolic_analyses, 2);
        assert!(close(&solve(&s, &b), &x_full));
        // ...and both patterns, in any order of triplets, reuse it from then on.
        let mut reversed = full;
        reversed.reverse();
        for triplets in [&tridiagonal[..], &full[..], &reversed[..], &tridiagonal[..]] {
            s.factor(3, triplets, 0.0).expect("SPD");
        }
        assert_eq!(s.symbolic_analyses, 2);
        assert!(close(&solve(&s, &b), &[1.0, 1.0, 1.0]));
        // A shift applies to the whole diagonal: (A + I) x = b.
        s.factor(3, &full, 1.0).expect("SPD");
        let x = solve(&s, &b);
        let r = [3.0 * x[0] - x[1] + 0.5 * x[2], -x[0] + 3.0 * x[1] - x[2], 0.5 * x[0] - x[1] + 3.0 * x[2]];
        assert!(close(&r, &b));
    }
}
