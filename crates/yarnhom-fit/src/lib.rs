#![doc = include_str!("../README.md")]

pub mod compare;
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
pub mod report;
pub mod residual;
pub mod shape;
pub mod synthetic;

pub use compare::{TermComparison, compare_1d_terms, comparison_report};
pub use difference::diff_spline_materials;
pub use fit::{FitError, RegularizedFit, TermError, fit_errors, fit_grid, fit_grid_with_regularized_terms};
pub use material::{EnergyJet, SplineMaterial};
pub use ranges::{RangeError, SampledRanges, sampled_ranges};
pub use shape::{TermShape, regularized_term_shapes, term_shapes};
