//! Validating field readers for `#[serde(deserialize_with = ...)]` and serde
//! defaults, shared by every scene kind. A reader's error carries the value's span, so the TOML
//! loader reports the line and the field of a bad value. An optional field
//! (`Option`) needs `default` for reading but no `skip_serializing_if` for
//! writing: the `toml` serializer leaves a `None` field out of its table.

use serde::de::Error as _;
use serde::{Deserialize, Deserializer};

/// A finite `f64`.
pub(crate) fn finite<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let v = f64::deserialize(d)?;
    accept(v, v.is_finite(), "a finite number")
}

/// `v` where `ok`, else the readers' error `must be {what}, got {v}`.
fn accept<E: serde::de::Error>(v: f64, ok: bool, what: &str) -> Result<f64, E> {
    if ok {
        Ok(v)
    } else {
        Err(E::custom(format!("must be {what}, got {v}")))
    }
}

/// A finite `f64 > 0`.
pub(crate) fn positive<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let v = finite(d)?;
    accept(v, v > 0.0, "> 0")
}

/// A finite `f64 >= 0`.
pub(crate) fn nonnegative<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let v = finite(d)?;
    accept(v, v >= 0.0, ">= 0")
}

/// An optional field that, when present, is a finite `f64 > 0`.
pub(crate) fn opt_positive<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    positive(d).map(Some)
}

/// `N` finite numbers.
pub(crate) fn finite_array<'de, D: Deserializer<'de>, const N: usize>(
    d: D,
) -> Result<[f64; N], D::Error> {
    let v = Vec::<f64>::deserialize(d)?;
    match <[f64; N]>::try_from(v.as_slice()) {
        Ok(a) if a.iter().all(|x| x.is_finite()) => Ok(a),
        Ok(a) => Err(D::Error::custom(format!(
            "must be {N} finite numbers, got {a:?}"
        ))),
        Err(_) => Err(D::Error::custom(format!(
            "must be {N} numbers, got {} ({v:?})",
            v.len()
        ))),
    }
}

/// An integer in `lo..=hi`.
pub(crate) fn bounded_u32<'de, D: Deserializer<'de>>(
    d: D,
    lo: u32,
    hi: u32,
) -> Result<u32, D::Error> {
    let v = i64::deserialize(d)?;
    if (lo as i64..=hi as i64).contains(&v) {
        Ok(v as u32)
    } else {
        Err(D::Error::custom(format!(
            "must be an integer from {lo} to {hi}, got {v}"
        )))
    }
}

/// A finite number in the closed interval `[0, 1]`.
pub(crate) fn unit_interval_closed<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let v = finite(d)?;
    accept(v, (0.0..=1.0).contains(&v), "between 0 and 1")
}

/// A finite number in the half-open interval `(0, 1]`: a fraction that may
/// not be zero.
pub(crate) fn unit_interval_open_low<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
    let v = finite(d)?;
    accept(v, v > 0.0 && v <= 1.0, "in (0, 1]")
}

/// An optional field that, when present, is a finite `f64`.
pub(crate) fn opt_finite<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    finite(d).map(Some)
}

/// Two finite numbers (a 2D vector).
pub(crate) fn finite2<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 2], D::Error> {
    finite_array::<D, 2>(d)
}

/// Three finite numbers (a 3D vector).
pub(crate) fn finite3<'de, D: Deserializer<'de>>(d: D) -> Result<[f64; 3], D::Error> {
    finite_array::<D, 3>(d)
}

// ---- serde defaults shared by the scene kinds ------------------------------

/// Default `1.0`.
pub(crate) fn one() -> f64 {
    1.0
}

/// Default `0.5`.
pub(crate) fn half() -> f64 {
    0.5
}

/// Default `true`.
pub(crate) fn yes() -> bool {
    true
}
