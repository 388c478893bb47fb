//! Small shared geometry for yarnhom: closest points between segments (yarn-yarn contact and
//! minimum-distance queries) and 2D segment crossings.

pub mod segment;

pub use segment::{SegmentDistance, segment_crossing_2d, segment_distance};
