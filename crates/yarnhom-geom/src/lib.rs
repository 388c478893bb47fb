#![doc = include_str!("../README.md")]

mod least_squares;
pub mod midsurface;
pub mod segment;
pub mod stats;
pub mod strain;
pub mod symlog;

pub use midsurface::{DEFAULT_GRID_CELLS, Midsurface};
pub use segment::{SegmentDistance, segment_crossing_2d, segment_distance};
pub use strain::{InPlaneStrain, MacroStrain, StrainError};
