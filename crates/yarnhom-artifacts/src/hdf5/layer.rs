//! The HDF5 helpers every yarnhom export writes with: datasets described by their units and a
//! sentence, groups and attributes created without time stamps (so the same content gives the
//! same bytes), strings as variable-length UTF-8. Used by the artifact exports here and by the
//! trace exports of `yarnhom-trace`.

use ::hdf5::types::VarLenUnicode;
use ::hdf5::{Group, Location};

use crate::error::{Error, Result};

/// The `units` and `description` attributes a dataset carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Spec {
    /// SI units of the values (`1` for dimensionless, counts and indices).
    pub units: &'static str,
    /// One sentence saying what the values are.
    pub description: &'static str,
}

/// An HDF5 library error, with what was being done.
pub fn h5(context: impl std::fmt::Display, e: ::hdf5::Error) -> Error {
    Error::Hdf5(format!("{context}: {e}"))
}

/// Creates the group `name` in `parent`.
pub fn create_group(parent: &Group, name: &str) -> Result<Group> {
    let path = format!("{}/{name}", parent.name().trim_end_matches('/'));
    parent
        .create_group_builder()
        .obj_track_times(false)
        .create(name)
        .map_err(|e| h5(format_args!("cannot create the group {path}"), e))
}

/// Opens the group `name` of `parent`, creating it if it does not exist.
pub fn open_or_create_group(parent: &Group, name: &str) -> Result<Group> {
    if parent.link_exists(name) {
        parent.group(name).map_err(|e| h5(format_args!("cannot open the group {name}"), e))
    } else {
        create_group(parent, name)
    }
}

/// A string as HDF5 variable-length UTF-8 (which cannot hold NUL characters); `what` names it.
pub fn varlen(what: &str, value: &str) -> Result<VarLenUnicode> {
    value
        .parse()
        .map_err(|e| Error::Unrepresentable { format: "hdf5", message: format!("{what} {value:?}: {e}") })
}

/// Writes the string attribute `name`.
pub fn write_str_attr(location: &Location, name: &str, value: &str) -> Result<()> {
    let value = varlen(&format!("the attribute {name:?}"), value)?;
    location
        .new_attr::<VarLenUnicode>()
        .create(name)
        .and_then(|attr| attr.write_scalar(&value))
        .map_err(|e| h5(format_args!("cannot write the attribute {name:?}"), e))
}

/// Writes the unsigned integer attribute `name`.
pub fn write_u32_attr(location: &Location, name: &str, value: u32) -> Result<()> {
    location
        .new_attr::<u32>()
        .create(name)
        .and_then(|attr| attr.write_scalar(&value))
        .map_err(|e| h5(format_args!("cannot write the attribute {name:?}"), e))
}

/// Writes a dataset's `units` and `description` attributes.
pub fn describe(dataset: &Location, spec: &Spec) -> Result<()> {
    write_str_attr(dataset, "units", spec.units)?;
    write_str_attr(dataset, "description", spec.description)
}
