//! Calibration of yarnhom's models against real fabric measurements (thesis Ch. 6), in rooms,
//! each using only the ones before it: [`optimize`], [`data`], [`experiments`], [`shell`],
//! [`cause`], [`yarn`], [`diagnosis`]; [`report`] reads any of their reports.

pub mod cause;
pub mod data;
pub mod diagnosis;
pub mod experiments;
pub mod optimize;
pub mod report;
pub mod shell;
#[cfg(test)]
mod test_support;
pub mod yarn;
