//! Homogenized yarn-level cloth materials (thesis Ch. 4, App. A.3-A.5, B).
//!
//! - [`fit`]: a sampled grid into a spline material (Algorithms 3-5).
//! - [`mls`]: moving least squares in symlog space (A.35).
//! - [`monotone_cubic`], [`monotone_bicubic`]: monotone Hermite interpolation (Fritsch-Carlson
//!   1980; App. B).
//! - [`march`]: quasiconvex marching (A.36) and increasing extrapolation (A.3.5).
//! - [`residual`]: residualization (A.37, A.38).
//! - [`shape`]: single-minimum checks of the fitted terms (A.36).
//! - [`ranges`]: the strain ranges a fitted material was sampled over, from its control points.
//! - [`hermite`]: cubic and bicubic Hermite splines with derivatives and linear extrapolation.
//! - [`curvature`]: the curvature split (A.39)-(A.41), smooth at umbilics.
//! - [`synthetic`]: a synthetic thesis-shaped grid of a known energy, for tests.
//! - [`material`]: the spline material `Ψ(I, II)` (4.3), (A.34) with exact derivatives.
//! - [`figures`]: the figures of a fit against its grid (Fig. 4.4, 4.5) as `yarnhom_figures` data.
//! - [`difference`]: two spline materials compared by their energies and stresses on a dense
//!   strain plan (`yarnhom diff`).

pub mod curvature;
pub mod difference;
pub mod figures;
pub mod fit;
pub mod hermite;
pub mod march;
pub mod material;
pub mod mls;
pub mod monotone_bicubic;
pub mod monotone_cubic;
pub mod ranges;
pub mod residual;
pub mod shape;
pub mod synthetic;

pub use difference::diff_spline_materials;
pub use fit::{FitError, RegularizedFit, TermError, fit_errors, fit_grid, fit_grid_with_regularized_terms};
pub use material::{EnergyJet, SplineMaterial};
pub use ranges::{RangeError, SampledRanges, sampled_ranges};
pub use shape::{TermShape, regularized_term_shapes, term_shapes};
