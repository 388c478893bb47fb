//! Calibration inputs of yarnhom: measurement sets of real fabric swatches.
//!
//! A measurement set is a directory holding `fabric.toml` (what was measured), `stretch.csv`
//! (uniaxial stretch tests) and optionally `bending.csv` (pear-loop bending tests) and
//! `cantilever.csv` (cantilever bending tests, both faces); see
//! [`measure`] and `schemas/measurement-set.md`. [`stitch_by_stitch`] (feature `hdf5`) turns the
//! published stitch-by-stitch HDF5 files into measurement sets.

pub mod bending_fit;
pub mod cantilever;
pub mod diagnose;
pub mod figures;
pub mod lm;
pub mod measure;
pub mod pear_loop;
pub mod shell_fit;
#[cfg(feature = "hdf5")]
pub mod stitch_by_stitch;
pub mod strip;
pub mod swarm;
pub mod swatch;
pub mod synth;
pub mod targets;
#[cfg(test)]
mod test_support;
pub mod uniform;
pub mod yarn_confirm;
pub mod yarn_fit;
pub mod yarn_objective;
pub mod yarn_params;
pub mod yarn_tile;

pub use measure::{
    BendingPoint, CantileverPoint, Direction, Fabric, Face, MeasureError, MeasurementSet, Phase, Specimen,
    StretchPoint, Swatch, SwatchOverride, Yarn,
};
