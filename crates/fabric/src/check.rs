//! The fabric file's own checks while parsing (a locking angle, measured tensile and shear
//! branches, each point at its own position); the generic ones ([`Validate`], [`validated!`],
//! the value checks) are `atelier_files::check`'s, re-exported here.

use serde::de::Error as _;
use serde::{Deserialize, Deserializer};

pub use atelier_files::check::{
    Validate, non_empty, non_negative, non_negative_value, opt_non_negative, opt_positive,
    positive, positive_value,
};
pub use atelier_files::validated;

use crate::error::{ErrorKind, InvalidValue};

pub(crate) fn opt_locking_angle<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    let v = opt_positive(d)?;
    if let Some(deg) = v
        && deg >= 90.0
    {
        return Err(D::Error::custom(InvalidValue::new(
            ErrorKind::OutOfRange,
            "",
            format!("{deg}° must lie below 90°"),
        )));
    }
    Ok(v)
}

/// A measured tensile branch (force, strain): see [`crate::tensile::validate_branch`].
pub(crate) fn branch<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<(f64, f64)>, D::Error> {
    let points = Vec::<(f64, f64)>::deserialize(d)?;
    crate::tensile::validate_branch(&points).map_err(D::Error::custom)?;
    Ok(points)
}

/// A measured shear branch `(angle °, force gf/cm)`, each point checked as soon as it is read
/// (so an error carries the position of the point itself), then the branch as a whole: see
/// [`crate::shear::check_shear_point`] and [`crate::shear::check_shear_branch`].
pub(crate) fn shear_branch<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<(f64, f64)>, D::Error> {
    struct Points;
    impl<'de> serde::de::Visitor<'de> for Points {
        type Value = Vec<(f64, f64)>;
        fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.write_str("a list of (angle °, force gf/cm) points")
        }
        fn visit_seq<A: serde::de::SeqAccess<'de>>(
            self,
            mut seq: A,
        ) -> Result<Self::Value, A::Error> {
            let mut points: Vec<(f64, f64)> = Vec::new();
            while let Some(p) = seq.next_element::<(f64, f64)>()? {
                crate::shear::check_shear_point(&points, p).map_err(A::Error::custom)?;
                points.push(p);
            }
            crate::shear::check_shear_extent(&points).map_err(A::Error::custom)?;
            Ok(points)
        }
    }
    d.deserialize_seq(Points)
}
