#![doc = include_str!("../README.md")]

pub mod auto_model;
pub mod cause;
pub mod data;
pub mod diagnosis;
pub mod experiments;
pub mod figures;
pub mod optimize;
pub mod report;
pub mod shell;
#[cfg(test)]
mod test_support;
pub mod yarn;
