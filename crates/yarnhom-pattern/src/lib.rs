//! Built-in yarn pattern generators.
