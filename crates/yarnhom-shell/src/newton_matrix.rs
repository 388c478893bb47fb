//! The Newton matrices of a cloth's time steps on one sparsity pattern, analysed once: the lower
//! triangle of the union of the elements' vertex couplings and of every vertex's 3 x 3 diagonal
//! block (inertia, contact), in compressed columns. Each element's Hessian entries are added
//! straight into the pattern's values through slots computed once, and the Cholesky
//! factorization (faer) reuses the pattern's symbolic analysis.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{
    LltRef, SymbolicCholesky, SymbolicCholeskyRaw, factorize_symbolic_cholesky,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat};
use faer::{Conj, MatMut, Side, get_global_parallelism};

use crate::elastic::{ElementSink, SplitHessian};

/// The slot of an entry of an absent vertex.
const ABSENT: u32 = u32::MAX;

/// The matrix is not positive definite.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct NotPositiveDefinite;

/// A lower-triangle pattern over `3 n` DOFs with its symbolic Cholesky analysis and the value
/// slots of its elements' entries.
pub(crate) struct HessianPattern {
    structure: SymbolicSparseColMat<usize>,
    symbolic: SymbolicCholesky<usize>,
    /// Flops of a numeric factorization and one solve with it.
    factorization_flops: f64,
    /// Per element, the slot of each entry `(i, j)`, `j <= i`, of its local lower triangle in
    /// row-major order ([`ABSENT`] where a vertex is absent); element `e`'s slots start at
    /// `element_starts[e]`.
    element_slots: Vec<u32>,
    element_starts: Vec<usize>,
}

impl HessianPattern {
    /// The pattern of `vertices` vertices and the elements over `elements` (absent vertices
    /// `None`), in the order of the element indices an assembly hands on.
    pub(crate) fn new(vertices: usize, elements: &[Vec<Option<u32>>]) -> Self {
        // Per vertex column, the vertices coupled to it at or below it.
        let mut coupled: Vec<Vec<u32>> = (0..vertices as u32).map(|v| vec![v]).collect();
        for element in elements {
            for a in element.iter().flatten() {
                for b in element.iter().flatten().filter(|b| b <= &a) {
                    coupled[*b as usize].push(*a);
                }
            }
        }
        let mut col_ptr = vec![0];
        let mut row_idx = Vec::new();
        for (v, below) in coupled.iter_mut().enumerate() {
            below.sort_unstable();
            below.dedup();
            for l in 0..3 {
                for &a in below.iter() {
                    let first = if a as usize == v { l } else { 0 };
                    row_idx.extend((first..3).map(|k| 3 * a as usize + k));
                }
                col_ptr.push(row_idx.len());
            }
        }
        let n = 3 * vertices;
        let structure = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        let symbolic = factorize_symbolic_cholesky(
            structure.as_ref(),
            Side::Lower,
            Default::default(),
            Default::default(),
        )
        .unwrap_or_else(|e| unreachable!("a valid pattern has a symbolic Cholesky factor: {e:?}"));
        let factorization_flops = factorization_flops(&symbolic);
        let mut pattern = Self {
            structure,
            symbolic,
            factorization_flops,
            element_slots: Vec::new(),
            element_starts: Vec::new(),
        };
        for element in elements {
            pattern.element_starts.push(pattern.element_slots.len());
            let slots = pattern.local_slots(element);
            pattern.element_slots.extend(slots);
        }
        pattern
    }

    /// How many values the pattern holds.
    pub(crate) fn len(&self) -> usize {
        self.structure.row_idx().len()
    }

    /// How many DOFs (rows and columns) the pattern has.
    pub(crate) fn dofs(&self) -> usize {
        self.structure.ncols()
    }

    /// Flops of a numeric Cholesky factorization on the pattern and one solve with it.
    pub(crate) fn factorization_flops(&self) -> f64 {
        self.factorization_flops
    }

    /// The slot of entry `(row, col)`, `row >= col`, of the pattern.
    fn slot(&self, row: usize, col: usize) -> usize {
        let range = self.structure.col_range(col);
        let rows = &self.structure.row_idx()[range.clone()];
        range.start
            + rows.binary_search(&row).unwrap_or_else(|_| unreachable!("({row}, {col}) is in the pattern"))
    }

    /// The slots of an element's local lower triangle in row-major order.
    fn local_slots(&self, vertices: &[Option<u32>]) -> Vec<u32> {
        let dof = |i: usize| vertices[i / 3].map(|v| 3 * v as usize + i % 3);
        let mut slots = Vec::with_capacity(3 * vertices.len() * (3 * vertices.len() + 1) / 2);
        for i in 0..3 * vertices.len() {
            for j in 0..=i {
                slots.push(match (dof(i), dof(j)) {
                    (Some(r), Some(c)) => self.slot(r.max(c), r.min(c)) as u32,
                    _ => ABSENT,
                });
            }
        }
        slots
    }

    /// The slot of diagonal entry `dof`: the first of its column.
    pub(crate) fn diagonal_slot(&self, dof: usize) -> usize {
        self.structure.col_range(dof).start
    }

    /// The slot of entry `(k, l)`, `k >= l`, of vertex `v`'s diagonal block: its column holds the
    /// block's rows below the diagonal right after it.
    pub(crate) fn vertex_block_slot(&self, v: usize, k: usize, l: usize) -> usize {
        self.diagonal_slot(3 * v + l) + (k - l)
    }

    /// The slots in the rows or columns of the `fixed` DOFs.
    pub(crate) fn slots_touching(&self, fixed: &[bool]) -> Vec<usize> {
        (0..self.structure.ncols())
            .flat_map(|col| {
                let range = self.structure.col_range(col);
                let rows = &self.structure.row_idx()[range.clone()];
                range.zip(rows).filter(move |&(_, &row)| fixed[row] || fixed[col]).map(|(slot, _)| slot)
            })
            .collect()
    }

    /// `f(row, col, value)` for every stored entry (`row >= col`) of `values` on the pattern.
    pub(crate) fn for_each_entry(&self, values: &[f64], mut f: impl FnMut(usize, usize, f64)) {
        for col in 0..self.structure.ncols() {
            let range = self.structure.col_range(col);
            for (&row, &a) in self.structure.row_idx()[range.clone()].iter().zip(&values[range]) {
                f(row, col, a);
            }
        }
    }

    /// `A v` for the symmetric `A` with lower-triangle `values` on the pattern.
    pub(crate) fn symmetric_product(&self, values: &[f64], v: &[f64]) -> Vec<f64> {
        let mut out = vec![0.0; v.len()];
        self.symmetric_product_into(values, v, &mut out);
        out
    }

    /// `out = A v` for the symmetric `A` with lower-triangle `values` on the pattern.
    pub(crate) fn symmetric_product_into(&self, values: &[f64], v: &[f64], out: &mut [f64]) {
        out.fill(0.0);
        for (col, &v_col) in v.iter().enumerate() {
            let range = self.structure.col_range(col);
            let rows = &self.structure.row_idx()[range.clone()];
            let mut sum = 0.0;
            for (&row, &a) in rows.iter().zip(&values[range]) {
                out[row] += a * v_col;
                if row != col {
                    sum += a * v[row];
                }
            }
            out[col] += sum;
        }
    }

    /// Memory for the numeric factors of this pattern and their solves, allocated once.
    pub(crate) fn workspace(&self) -> CholeskyWorkspace {
        let par = get_global_parallelism();
        let scratch = self
            .symbolic
            .factorize_numeric_llt_scratch::<f64>(par, Default::default())
            .or(self.symbolic.solve_in_place_scratch::<f64>(1, par));
        CholeskyWorkspace { values: vec![0.0; self.symbolic.len_val()], scratch: MemBuffer::new(scratch) }
    }

    /// The Cholesky factor of the symmetric matrix with lower-triangle `values`, in `workspace`
    /// (no allocation: the factor of a 50 x 50 cloth takes tens of MB, whose fresh pages cost
    /// about as much as the factorization).
    pub(crate) fn factor<'w>(
        &'w self,
        values: &[f64],
        workspace: &'w mut CholeskyWorkspace,
    ) -> Result<Cholesky<'w>, NotPositiveDefinite> {
        let matrix = SparseColMatRef::new(self.structure.as_ref(), values);
        let par = get_global_parallelism();
        self.symbolic
            .factorize_numeric_llt(
                &mut workspace.values,
                matrix,
                Side::Lower,
                Default::default(),
                par,
                MemStack::new(&mut workspace.scratch),
                Default::default(),
            )
            .map_err(|_| NotPositiveDefinite)?;
        Ok(Cholesky {
            factor: LltRef::new(&self.symbolic, &workspace.values),
            scratch: &mut workspace.scratch,
        })
    }
}

/// Flops of a numeric factorization with `symbolic` (`Σ_j c_j²` over the factor's column
/// counts `c_j`) and of one solve with it (`4 nnz(L)`).
fn factorization_flops(symbolic: &SymbolicCholesky<usize>) -> f64 {
    let columns: Vec<f64> = match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => s.col_ptr().windows(2).map(|w| (w[1] - w[0]) as f64).collect(),
        SymbolicCholeskyRaw::Supernodal(s) => (0..s.n_supernodes())
            .flat_map(|k| {
                let width = s.supernode_end()[k] - s.supernode_begin()[k];
                let below = s.col_ptr_for_row_idx()[k + 1] - s.col_ptr_for_row_idx()[k];
                (0..width).map(move |j| (width - j + below) as f64)
            })
            .collect(),
    };
    columns.iter().map(|c| c * c).sum::<f64>() + 4.0 * columns.iter().sum::<f64>()
}

/// The numeric factor's values and the scratch memory of factorizations and solves on one
/// [`HessianPattern`].
pub(crate) struct CholeskyWorkspace {
    values: Vec<f64>,
    scratch: MemBuffer,
}

/// A Cholesky factorization on a [`HessianPattern`].
pub(crate) struct Cholesky<'w> {
    factor: LltRef<'w, usize, f64>,
    scratch: &'w mut MemBuffer,
}

impl Cholesky<'_> {
    /// Solve `A x = b` in place (`b` in, `x` out).
    pub(crate) fn solve_in_place(&mut self, b: &mut [f64]) {
        let rows = b.len();
        self.factor.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(b, rows, 1),
            get_global_parallelism(),
            MemStack::new(self.scratch),
        );
    }
}

/// Energy, gradient and Newton matrix of a time step assembled on a [`HessianPattern`]: element
/// Hessians enter with their eigenvalues replaced by their absolute values (a direction of
/// negative curvature keeps its magnitude, where the clamp to zero leaves it flat; Newton takes
/// fewer iterations).
pub(crate) struct NewtonAssembly<'p> {
    pattern: &'p HessianPattern,
    /// Energy (J).
    pub energy: f64,
    /// Gradient over the DOFs (N).
    pub gradient: Vec<f64>,
    /// Lower-triangle values of the Newton matrix on the pattern (N/m).
    pub matrix: Vec<f64>,
}

impl<'p> NewtonAssembly<'p> {
    /// An empty assembly over the DOFs of `pattern`.
    pub(crate) fn new(pattern: &'p HessianPattern) -> Self {
        Self {
            pattern,
            energy: 0.0,
            gradient: vec![0.0; pattern.structure.ncols()],
            matrix: vec![0.0; pattern.len()],
        }
    }

    /// Empty it, keeping its memory.
    pub(crate) fn clear(&mut self) {
        self.energy = 0.0;
        self.gradient.fill(0.0);
        self.matrix.fill(0.0);
    }
}

impl ElementSink for NewtonAssembly<'_> {
    fn add<const N: usize>(
        &mut self,
        index: usize,
        vertices: &[Option<u32>],
        energy: f64,
        gradient: &nalgebra::SVector<f64, N>,
        hessian: Option<&SplitHessian<N>>,
    ) {
        self.energy += energy;
        for (a, va) in vertices.iter().enumerate() {
            let Some(va) = va else { continue };
            for k in 0..3 {
                self.gradient[3 * *va as usize + k] += gradient[3 * a + k];
            }
        }
        let Some(h) = hessian else { return };
        let absolute = h.absolute();
        let mut slots = self.pattern.element_slots[self.pattern.element_starts[index]..].iter();
        for i in 0..N {
            for (j, &slot) in (0..=i).zip(&mut slots) {
                if slot != ABSENT {
                    self.matrix[slot as usize] += absolute[(i, j)];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elements_land_in_their_slots_and_products_use_both_triangles() {
        // Two 2-vertex elements sharing vertex 1; vertex 2 of the second is absent in a third.
        let elements = vec![vec![Some(0), Some(1)], vec![Some(1), Some(2)], vec![Some(2), None]];
        let pattern = HessianPattern::new(3, &elements);
        let mut a = NewtonAssembly::new(&pattern);
        a.clear();
        let h = SplitHessian::<6> {
            matrix: nalgebra::SMatrix::from_fn(|i, j| (1 + i + j) as f64),
            negative: None,
        };
        a.add(0, &elements[0], 1.0, &nalgebra::SVector::<f64, 6>::repeat(1.0), Some(&h));
        a.add(1, &elements[1], 2.0, &nalgebra::SVector::<f64, 6>::repeat(1.0), Some(&h));
        // The dense sum of both elements.
        let mut dense = nalgebra::DMatrix::<f64>::zeros(9, 9);
        for offset in [0, 3] {
            let mut block = dense.view_mut((offset, offset), (6, 6));
            block += h.matrix;
        }
        let v: Vec<f64> = (0..9).map(|i| (i as f64).sin()).collect();
        let expected = &dense * nalgebra::DVector::from_column_slice(&v);
        let product = pattern.symmetric_product(&a.matrix, &v);
        assert!(product.iter().zip(expected.iter()).all(|(p, e)| (p - e).abs() < 1e-12));
        assert_eq!(a.energy, 3.0);
        assert_eq!(a.gradient, vec![1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 1.0, 1.0, 1.0]);
        assert_eq!(pattern.vertex_block_slot(1, 2, 0), pattern.slot(5, 3));
        assert_eq!(
            pattern.slots_touching(&[false, false, false, true, false, false, false, false, false]).len(),
            9
        );
    }

    /// The dense lower triangle summed from triplets.
    fn dense_from_triplets(n: usize, triplets: &[(usize, usize, f64)]) -> nalgebra::DMatrix<f64> {
        let mut dense = nalgebra::DMatrix::zeros(n, n);
        for &(i, j, v) in triplets {
            dense[(i, j)] += v;
        }
        dense
    }

    #[test]
    fn the_pattern_assembly_is_the_triplet_assembly() {
        use crate::elastic::{Assembly, ElasticModel, NewtonMatrix};
        use crate::material::{HingeBending, ShellMaterial};
        use crate::mesh::ShellMesh;
        let path = format!("{}/../../../shared/data/hylc-materials/stock1.json", env!("CARGO_MANIFEST_DIR"));
        let spline = yarnhom_artifacts::open::open_artifact::<yarnhom_artifacts::Spline>(&path)
            .expect("published")
            .value;
        let stvk = crate::test_support::test_membrane();
        let materials = [
            ShellMaterial::spline(yarnhom_fit::SplineMaterial::from(&spline)),
            ShellMaterial::stvk(0.3, stvk, HingeBending::anisotropic(1e-4, 2e-4, 3e-4)),
        ];
        let mesh = ShellMesh::rectangle(0.02, 0.02, 5, 4).expect("mesh");
        let x: Vec<_> = mesh
            .material
            .iter()
            .map(|m| {
                nalgebra::Vector3::new(
                    0.9 * m.x + 0.05 * m.y,
                    0.95 * m.y,
                    20.0 * m.x * m.x - 15.0 * m.y * m.y,
                )
            })
            .collect();
        for material in materials {
            let model = ElasticModel::new(mesh.clone(), material);
            let pattern = HessianPattern::new(x.len(), &model.element_vertices());
            // Gauss-Newton element matrices have no negative part, so the triplets' clamped
            // matrices and the pattern's absolute-valued ones are the same.
            let (mut triplets, mut a) = (Assembly::new(3 * x.len()), NewtonAssembly::new(&pattern));
            model.assemble(&x, Some(NewtonMatrix::GaussNewton), &mut triplets);
            a.clear();
            model.assemble(&x, Some(NewtonMatrix::GaussNewton), &mut a);
            assert!(triplets.triplets.iter().any(|t| t.2 != 0.0));
            let expected = dense_from_triplets(3 * x.len(), &triplets.triplets);
            let mut entries = Vec::new();
            for col in 0..3 * x.len() {
                let range = pattern.structure.col_range(col);
                let rows = &pattern.structure.row_idx()[range.clone()];
                entries.extend(rows.iter().zip(&a.matrix[range]).map(|(&r, &v)| (r, col, v)));
            }
            let actual = dense_from_triplets(3 * x.len(), &entries);
            assert!((actual - &expected).amax() < 1e-12 * expected.amax());
            assert_eq!(a.gradient, triplets.gradient);
            assert_eq!(a.energy, triplets.energy);
        }
    }
}
