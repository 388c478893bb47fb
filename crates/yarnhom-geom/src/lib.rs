//! Small shared geometry for yarnhom: closest points between segments (yarn-yarn contact and
//! minimum-distance queries), 2D segment crossings, and the macroscale strain parametrization
//! (4.1) of the thesis.

pub mod segment;
pub mod strain;

pub use segment::{SegmentDistance, segment_crossing_2d, segment_distance};
pub use strain::{InPlaneStrain, MacroStrain, StrainError};
