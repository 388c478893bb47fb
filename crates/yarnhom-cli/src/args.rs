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

/// A number of the range `ok` accepts, else `message`.
pub fn number(text: &str, ok: impl Fn(f64) -> bool, message: &str) -> Result<f64, String> {
    text.parse::<f64>().ok().filter(|x| ok(*x)).ok_or_else(|| message.to_string())
}

/// A finite number > 0 (a `value_parser`).
pub fn positive(text: &str) -> Result<f64, String> {
    number(text, |x| x.is_finite() && x > 0.0, "must be a positive finite number")
}

pub fn non_negative(text: &str) -> Result<f64, String> {
    number(text, |x| x.is_finite() && x >= 0.0, "must be a number >= 0")
}

pub fn finite(text: &str) -> Result<f64, String> {
    number(text, f64::is_finite, "must be a finite number")
}

pub fn max_stretch(text: &str) -> Result<f64, String> {
    number(text, |x| x.is_finite() && x > 0.0 && x <= 2.0, "must be in (0, 2]")
}

/// `K/N`: shard `K` of `N`, `0 <= K < N` (a `value_parser`).
pub fn parse_shard(text: &str) -> Result<(u32, u32), String> {
    let (k, n) = text.split_once('/').ok_or("expected K/N, e.g. 0/4")?;
    let (k, n): (u32, u32) =
        (k.parse().map_err(|_| "K is not a number")?, n.parse().map_err(|_| "N is not a number")?);
    if n == 0 || k >= n {
        return Err(format!("shard {k}/{n}: need 0 <= K < N"));
    }
    Ok((k, n))
}
