//! Small invariant checks shared by the artifact kinds' `validate` methods.

use crate::error::ValidationError;

type Check = Result<(), ValidationError>;

/// Every value is finite (no NaN, no infinity).
pub fn finite<'a>(field: &str, values: impl IntoIterator<Item = &'a f64>) -> Check {
    match values.into_iter().position(|v| !v.is_finite()) {
        Some(i) => Err(ValidationError::new(format!("{field}[{i}]"), "not a finite number")),
        None => Ok(()),
    }
}

/// One value is finite and strictly positive.
pub fn positive(field: &str, value: f64) -> Check {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ValidationError::new(field, format!("must be a finite number > 0, got {value}")))
    }
}

/// One value is finite and not negative.
pub fn non_negative(field: &str, value: f64) -> Check {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(ValidationError::new(field, format!("must be a finite number >= 0, got {value}")))
    }
}

/// A per-item array has the expected number of entries.
pub fn len(field: &str, actual: usize, expected: usize, per: &str) -> Check {
    if actual == expected {
        Ok(())
    } else {
        Err(ValidationError::new(field, format!("has {actual} entries but there are {expected} {per}")))
    }
}

/// Every entry of every row is finite; the error names row and column.
pub fn finite_rows<const N: usize>(field: &str, rows: &[[f64; N]]) -> Check {
    for (i, row) in rows.iter().enumerate() {
        if let Some(j) = row.iter().position(|v| !v.is_finite()) {
            return Err(ValidationError::new(format!("{field}[{i}][{j}]"), "not a finite number"));
        }
    }
    Ok(())
}
