//! Errors that name what went wrong and what to change.

use std::fmt;

/// Everything grainlab can refuse or stop with.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A scene field outside its allowed range, or inconsistent with the rest of the
    /// scene: its JSON path, its value, and what would be allowed.
    #[error("invalid scene: {field} = {value}; allowed: {allowed}")]
    Invalid { field: String, value: String, allowed: String },
    /// A scene that cannot be read or is inconsistent as a whole.
    #[error("invalid scene: {0}")]
    Scene(String),
    /// A scene file that does not parse: the JSON path of the field, and what is wrong.
    #[error("invalid scene: at `{path}`: {what}")]
    Parse { path: String, what: String },
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
pub fn check(ok: bool, at: &str, field: &str, value: impl Shown, allowed: &str) -> Result<(), Error> {
    if ok {
        Ok(())
    } else {
        let field = if at.is_empty() { field.to_string() } else { format!("{at}.{field}") };
        Err(Error::Invalid { field, value: value.shown(), allowed: allowed.to_string() })
    }
}

/// A value as a message shows it: numbers far from 1 in exponent form (`1e300`, not three
/// hundred digits), each as the shortest text that reads back to the same number.
pub trait Shown {
    fn shown(&self) -> String;
}

impl Shown for f64 {
    fn shown(&self) -> String {
        let a = self.abs();
        if a == 0.0 || !a.is_finite() || (1e-4..1e7).contains(&a) { format!("{self}") } else { format!("{self:e}") }
    }
}

macro_rules! shown_as_display {
    ($($t:ty),*) => {$(impl Shown for $t { fn shown(&self) -> String { self.to_string() } })*};
}
shown_as_display!(usize, u64, u32, i64, &str, String);

impl<T: Shown> Shown for &T {
    fn shown(&self) -> String {
        (**self).shown()
    }
}
