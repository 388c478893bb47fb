//! Small shared geometry for yarnhom: closest points between segments (yarn-yarn contact and
//! minimum-distance queries), 2D segment crossings, the macroscale strain parametrization (4.1)
//! and the RVE midsurface of a macro deformation (Sec. 3.2.2, App. A.1.1), least-squares solved on a
//! grid for doubly curved strains, and the summary statistics ([`stats`]) every stage reports with.

mod least_squares;
pub mod midsurface;
pub mod segment;
pub mod stats;
pub mod strain;

pub use midsurface::{DEFAULT_GRID_CELLS, Midsurface};
pub use segment::{SegmentDistance, segment_crossing_2d, segment_distance};
pub use strain::{InPlaneStrain, MacroStrain, StrainError};
