//! Validation while parsing: `deserialize_with` helpers that reject a bad value at its own
//! position in the file, and the `validated!` macro that runs a type's cross-field checks after
//! its fields are read (errors travel through serde as [`InvalidValue`] messages and are decoded
//! by [`crate::files`]).

use serde::de::Error as _;
use serde::{Deserialize, Deserializer};

use crate::error::{ErrorKind, InvalidValue};

/// A finite value ≥ 0.
pub fn non_negative_value(v: f64) -> Result<f64, InvalidValue> {
    if !v.is_finite() {
        Err(InvalidValue::new(
            ErrorKind::NotFinite,
            "",
            format!("{v} is not a finite number"),
        ))
    } else if v < 0.0 {
        Err(InvalidValue::new(
            ErrorKind::Negative,
            "",
            format!("{v} must not be negative"),
        ))
    } else {
        Ok(v)
    }
}

/// A finite value > 0.
pub fn positive_value(v: f64) -> Result<f64, InvalidValue> {
    let v = non_negative_value(v)?;
    if v == 0.0 {
        Err(InvalidValue::new(
            ErrorKind::OutOfRange,
            "",
            "0 must be positive",
        ))
    } else {
        Ok(v)
    }
}

/// `deserialize_with`: a finite value > 0.
pub fn positive<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    positive_value(f64::deserialize(d)?).map_err(D::Error::custom)
}

/// `deserialize_with`: a finite value ≥ 0.
pub fn non_negative<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    non_negative_value(f64::deserialize(d)?).map_err(D::Error::custom)
}

/// `deserialize_with`: an optional finite value > 0.
pub fn opt_positive<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    Option::<f64>::deserialize(d)?
        .map(positive_value)
        .transpose()
        .map_err(D::Error::custom)
}

/// `deserialize_with`: an optional finite value ≥ 0.
pub fn opt_non_negative<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    Option::<f64>::deserialize(d)?
        .map(non_negative_value)
        .transpose()
        .map_err(D::Error::custom)
}

/// `deserialize_with`: a string that is not blank.
pub fn non_empty<'de, D: Deserializer<'de>>(d: D) -> Result<String, D::Error> {
    let s = String::deserialize(d)?;
    if s.trim().is_empty() {
        return Err(D::Error::custom(InvalidValue::new(
            ErrorKind::OutOfRange,
            "",
            "must not be empty",
        )));
    }
    Ok(s)
}

/// Types whose fields must agree with each other; checked right after parsing.
pub trait Validate {
    /// Check the fields against each other; the error names the field path below `self`.
    fn validate(&self) -> Result<(), InvalidValue>;
}

/// Implement `Deserialize` (and `Serialize`) for a type declared with
/// `#[derive(Serialize, Deserialize)] #[serde(remote = "Self")]`: the derived code reads the
/// fields, then [`Validate::validate`] runs, so its error carries the position of the value.
#[macro_export]
macro_rules! validated {
    ($t:ty) => {
        impl<'de> serde::Deserialize<'de> for $t {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                let value = <$t>::deserialize(d)?;
                $crate::check::Validate::validate(&value).map_err(serde::de::Error::custom)?;
                Ok(value)
            }
        }
        impl serde::Serialize for $t {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                <$t>::serialize(self, s)
            }
        }
    };
}
pub use validated;
