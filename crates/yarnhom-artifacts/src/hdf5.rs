//! HDF5 export (in progress).
