//! Measured data: what was measured on a real fabric, and what the fits take from it.
//!
//! - [`set`]: the measurement-set directory (`fabric.toml`, `stretch.csv`, `bending.csv`,
//!   `cantilever.csv`; `schemas/measurement-set.md`), read with every value validated.
//! - [`stitch_by_stitch`] (feature `hdf5`): the importer of the published stitch-by-stitch
//!   HDF5 files.
//! - [`targets`]: the stretch targets drawn from a set's readings (thesis Sec. 6.3.1).
//!
//! Synthetic sets, made by simulating the tests on a known truth, are simulated experiments:
//! `experiments::synth`.

pub mod set;
#[cfg(feature = "hdf5")]
pub mod stitch_by_stitch;
pub mod targets;
