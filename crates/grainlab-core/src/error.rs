//! Errors the engine reports: bad input before any work, and unstable runs.
use std::fmt;

/// What went wrong, with enough context for a user to act on it.
#[derive(Debug, Clone, PartialEq)]
pub enum EngineError {
    /// An input is outside its allowed range. `field` names it (e.g. `radius[3]`).
    InvalidInput {
        /// The offending field, with an index where it applies.
        field: String,
        /// What was wrong and what is allowed.
        message: String,
    },
    /// The simulation blew up (NaN, runaway overlap); the state is no longer trustworthy.
    Unstable {
        /// Step count at which it was detected.
        step: u64,
        /// Description naming the particles involved.
        message: String,
        /// Indices of the particles involved.
        particles: Vec<usize>,
    },
}

impl EngineError {
    /// Shorthand for an [`EngineError::InvalidInput`].
    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        EngineError::InvalidInput {
            field: field.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for EngineError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EngineError::InvalidInput { field, message } => write!(f, "{field}: {message}"),
            EngineError::Unstable { step, message, .. } => {
                write!(f, "simulation unstable at step {step}: {message}")
            }
        }
    }
}

impl std::error::Error for EngineError {}

/// Result type of fallible engine calls.
pub type Result<T> = std::result::Result<T, EngineError>;

/// Checks that `value` is finite and strictly positive.
pub fn require_positive(field: &str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(EngineError::invalid(
            field,
            format!("must be finite and > 0, got {value}"),
        ))
    }
}

/// Checks that `value` is finite and >= 0.
pub fn require_non_negative(field: &str, value: f64) -> Result<()> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(EngineError::invalid(
            field,
            format!("must be finite and >= 0, got {value}"),
        ))
    }
}

/// Checks that `value` is finite.
pub fn require_finite(field: &str, value: f64) -> Result<()> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(EngineError::invalid(
            field,
            format!("must be finite, got {value}"),
        ))
    }
}

/// Checks that every value is finite; the error names the first that is not
/// (`field[k]`).
pub fn require_finite_values(field: &str, values: &[f64]) -> Result<()> {
    match values.iter().position(|x| !x.is_finite()) {
        Some(k) => Err(EngineError::invalid(
            format!("{field}[{k}]"),
            format!("must be finite, got {}", values[k]),
        )),
        None => Ok(()),
    }
}

/// Checks that every point is finite; the error names the first that is not
/// (`field[k]`).
pub fn require_finite_points(field: &str, points: &[[f64; 2]]) -> Result<()> {
    match points
        .iter()
        .position(|p| !(p[0].is_finite() && p[1].is_finite()))
    {
        Some(k) => Err(EngineError::invalid(
            format!("{field}[{k}]"),
            format!("must be finite, got {:?}", points[k]),
        )),
        None => Ok(()),
    }
}
