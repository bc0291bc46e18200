//! Errors of the reference model.
//!
//! Every entry point returns `Result<_, RefError>`; no input, however wild, makes the reference
//! panic. The `Display` text names the model, the key and the rule that was broken, so that the
//! command-line tool can print it unchanged.

use std::fmt;

/// Why a reference evaluation was refused.
#[derive(Debug, Clone, PartialEq)]
pub enum RefError {
    /// The model name is not one of [`super::MODELS`].
    UnknownModel(String),
    /// A required input key is absent.
    MissingInput {
        /// Model being evaluated.
        model: &'static str,
        /// Name of the missing key.
        key: &'static str,
    },
    /// An input key that the model does not read (probably a typo).
    UnknownInput {
        /// Model being evaluated.
        model: &'static str,
        /// The unexpected key.
        key: String,
    },
    /// A variant key that the model does not know.
    UnknownVariantKey {
        /// Model being evaluated.
        model: &'static str,
        /// The unexpected variant key.
        key: String,
    },
    /// A known variant key with a value outside its allowed set.
    UnknownVariantValue {
        /// Variant key.
        key: &'static str,
        /// Value that was given.
        value: String,
        /// Allowed values, as text.
        allowed: &'static str,
    },
    /// An input is NaN or infinite.
    NonFiniteInput {
        /// Input key.
        key: &'static str,
        /// The value.
        value: f64,
    },
    /// An input is finite but outside the model's domain (negative load, |nu| >= 1, ...).
    OutOfDomain {
        /// Input key.
        key: &'static str,
        /// The value.
        value: f64,
        /// The rule it breaks, e.g. "must be > 0".
        rule: &'static str,
    },
    /// The inputs are individually valid but the model does not apply (e.g. the separation
    /// d would be <= 0, the real contact area would exceed the nominal area, no relative motion).
    ModelValidity(String),
    /// A result came out NaN or infinite (overflow at extreme inputs).
    NonFiniteResult {
        /// Model being evaluated.
        model: &'static str,
        /// Output key that overflowed.
        output: &'static str,
    },
    /// An adaptive integral or root search did not reach its tolerance within its budget.
    NotConverged(&'static str),
}

impl fmt::Display for RefError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::UnknownModel(name) => write!(
                f,
                "unknown model `{name}` (known: {})",
                super::MODELS.join(", ")
            ),
            Self::MissingInput { model, key } => {
                write!(f, "model `{model}`: missing input `{key}`")
            }
            Self::UnknownInput { model, key } => {
                write!(f, "model `{model}`: unknown input key `{key}`")
            }
            Self::UnknownVariantKey { model, key } => {
                write!(f, "model `{model}`: unknown variant key `{key}`")
            }
            Self::UnknownVariantValue {
                key,
                value,
                allowed,
            } => write!(
                f,
                "variant `{key}`: unknown value `{value}` (allowed: {allowed})"
            ),
            Self::NonFiniteInput { key, value } => {
                write!(f, "input `{key}` = {value} is not a finite number")
            }
            Self::OutOfDomain { key, value, rule } => {
                write!(f, "input `{key}` = {value:e} is out of domain: {rule}")
            }
            Self::ModelValidity(why) => write!(f, "outside the model's validity: {why}"),
            Self::NonFiniteResult { model, output } => write!(
                f,
                "model `{model}`: output `{output}` is not finite (overflow at these inputs)"
            ),
            Self::NotConverged(what) => write!(f, "numerical method did not converge: {what}"),
        }
    }
}

impl std::error::Error for RefError {}

/// Checks that `value` is finite; `key` names it in the error.
pub(crate) fn finite(key: &'static str, value: f64) -> Result<f64, RefError> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(RefError::NonFiniteInput { key, value })
    }
}

/// Checks that `value` is finite and strictly positive.
pub(crate) fn positive(key: &'static str, value: f64) -> Result<f64, RefError> {
    finite(key, value)?;
    if value > 0.0 {
        Ok(value)
    } else {
        Err(RefError::OutOfDomain {
            key,
            value,
            rule: "must be > 0",
        })
    }
}

/// Checks that `value` is finite and not negative.
pub(crate) fn non_negative(key: &'static str, value: f64) -> Result<f64, RefError> {
    finite(key, value)?;
    if value >= 0.0 {
        Ok(value)
    } else {
        Err(RefError::OutOfDomain {
            key,
            value,
            rule: "must be >= 0",
        })
    }
}

/// Checks that `value` lies in the closed interval `[lo, hi]`.
pub(crate) fn within(
    key: &'static str,
    value: f64,
    lo: f64,
    hi: f64,
    rule: &'static str,
) -> Result<f64, RefError> {
    finite(key, value)?;
    if (lo..=hi).contains(&value) {
        Ok(value)
    } else {
        Err(RefError::OutOfDomain { key, value, rule })
    }
}
