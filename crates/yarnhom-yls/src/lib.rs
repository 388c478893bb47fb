#![doc = include_str!("../README.md")]

pub mod dynamics;
pub mod interior;
pub mod record;
pub mod run;
pub mod scene;
pub mod swatch;
pub mod variations;
