//! Parsers of argument values that several commands share.

use yarnhom_artifacts::grid::AXIS_NAMES;

/// The index of a strain parameter by its name (`sx`, `sa`, `sy`, `kx`, `ky`).
pub fn parse_axis(name: &str) -> Result<usize, String> {
    AXIS_NAMES
        .iter()
        .position(|&a| a == name.trim())
        .ok_or_else(|| format!("unknown axis '{name}' (axes: {})", AXIS_NAMES.join(", ")))
}

/// `MIN:MAX` as two numbers.
pub fn parse_interval(text: &str) -> Result<[f64; 2], String> {
    let (min, max) = text.split_once(':').ok_or_else(|| format!("expected MIN:MAX, got '{text}'"))?;
    let number = |v: &str| v.trim().parse::<f64>().map_err(|e| format!("'{v}': {e}"));
    Ok([number(min)?, number(max)?])
}
