//! JSON text of fitted models: the one reading path of the models whose sizes are checked
//! when read, so that a damaged or edited file is an error, not an index out of bounds
//! when the model scores.

use serde::de::DeserializeOwned;
use wscg_math::{Error, Result};

/// Parses a `what` model from `s` and runs `check` on it (its size checks).
///
/// Errors: not the JSON of such a model ([`Error::InvalidArgument`] naming `model`), or
/// what `check` refuses.
pub(crate) fn checked_from_json<T: DeserializeOwned>(
    s: &str,
    what: &str,
    check: impl FnOnce(&T) -> Result<()>,
) -> Result<T> {
    let m: T = serde_json::from_str(s)
        .map_err(|e| Error::invalid("model", format!("not a {what}: {e}")))?;
    check(&m)?;
    Ok(m)
}
