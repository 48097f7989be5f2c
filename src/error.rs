//! Errors that name what went wrong and what to change.

use std::fmt;

/// Everything grainlab can refuse or stop with.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A scene field outside its allowed range.
    #[error("invalid scene: {field} = {value} is outside the allowed range {allowed}")]
    Invalid { field: String, value: String, allowed: String },
    /// A scene that cannot be read or is inconsistent as a whole.
    #[error("invalid scene: {0}")]
    Scene(String),
    /// A run that went unstable, with a diagnosis.
    #[error("run stopped at step {step} (t = {time:.6e} s): {what}\n  what to change: {advice}")]
    Unstable { step: u64, time: f64, what: String, advice: String },
    #[error("{context}: {source}")]
    Io { context: String, source: std::io::Error },
    #[error("{0}")]
    Other(String),
}

impl Error {
    pub fn io(context: impl fmt::Display, source: std::io::Error) -> Self {
        Error::Io { context: context.to_string(), source }
    }
}

/// `Ok(())` when `ok`, else an [`Error::Invalid`] naming `at.field`, the value and the range.
pub fn check(ok: bool, at: &str, field: &str, value: impl fmt::Display, allowed: &str) -> Result<(), Error> {
    if ok {
        Ok(())
    } else {
        let field = if at.is_empty() { field.to_string() } else { format!("{at}.{field}") };
        Err(Error::Invalid { field, value: value.to_string(), allowed: allowed.to_string() })
    }
}
