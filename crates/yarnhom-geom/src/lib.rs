//! Small shared geometry for yarnhom: closest points between segments (yarn-yarn contact and
//! minimum-distance queries), 2D segment crossings, the macroscale strain parametrization (4.1)
//! and the RVE midsurface of a macro deformation (App. A.1.1).

pub mod midsurface;
pub mod segment;
pub mod strain;

pub use midsurface::Midsurface;
pub use segment::{SegmentDistance, segment_crossing_2d, segment_distance};
pub use strain::{InPlaneStrain, MacroStrain, StrainError};
