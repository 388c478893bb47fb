//! Small shared geometry for yarnhom.
