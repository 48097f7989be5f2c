//! Errors that name what went wrong and what to change, and the exit code of each class.

use std::fmt;

/// The exit codes of `grainlab` (README, "The output folder, interruption and exit
/// codes"); [`Error::exit_code`] maps an error to its class.
pub mod exit {
    /// Everything done as asked.
    pub const SUCCESS: u8 = 0;
    /// A failure of no class below (e.g. `compare` with comparisons outside their bound).
    pub const OTHER: u8 = 1;
    /// Bad input: a scene refused, a field an export cannot express, a command-line value
    /// refused, an output folder grainlab may not use. clap exits with 2 on usage errors
    /// too.
    pub const BAD_INPUT: u8 = 2;
    /// A file could not be read or written (also when only `summary.json` could not be
    /// written: the summary is then on stdout).
    pub const IO_FAILURE: u8 = 3;
    /// The run went unstable and stopped with a diagnosis (`status: "stopped"`).
    pub const UNSTABLE: u8 = 4;
    /// SIGINT or SIGTERM ended the run, everything written (`status: "interrupted"`):
    /// 128 + SIGINT, as a shell reports a process that SIGINT ended.
    pub const INTERRUPTED: u8 = 130;
}

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
    /// A command-line option's value outside what this build allows.
    #[error("invalid option: {option} = {value}; allowed: {allowed}")]
    BadOption { option: String, value: String, allowed: String },
    /// An output folder grainlab may not write into (it holds files grainlab did not
    /// write, or an earlier run's files and no `--overwrite`).
    #[error("output folder {dir}: {why}")]
    Folder { dir: String, why: String },
    /// A scene field a reference code cannot express, refused by the exporter by name.
    #[error("{0}")]
    Export(String),
    /// A run that went unstable, with a diagnosis.
    #[error("run stopped at step {step} (t = {time:.6e} s): {what}\n  what to change: {advice}")]
    Unstable { step: u64, time: f64, what: String, advice: String },
    /// A run ended early on request (SIGINT or SIGTERM), with everything written.
    #[error("run interrupted at step {step} (t = {time:.6e} s) on a stop request (SIGINT or SIGTERM); everything it computed is written")]
    Interrupted { step: u64, time: f64 },
    /// A checkpoint that cannot be resumed: corrupt, truncated, of another format or
    /// build, or of another run than its folder's.
    #[error("checkpoint {file}: {why}")]
    Checkpoint { file: String, why: String },
    #[error("{context}: {source}")]
    Io { context: String, source: std::io::Error },
    #[error("{0}")]
    Other(String),
}

impl Error {
    pub fn io(context: impl fmt::Display, source: std::io::Error) -> Self {
        Error::Io { context: context.to_string(), source }
    }

    /// The process exit code for this error ([`exit`]).
    pub fn exit_code(&self) -> u8 {
        match self {
            Error::Invalid { .. } | Error::Scene(_) | Error::Parse { .. } | Error::BadOption { .. } | Error::Folder { .. } | Error::Export(_) | Error::Checkpoint { .. } => exit::BAD_INPUT,
            Error::Io { .. } => exit::IO_FAILURE,
            Error::Unstable { .. } => exit::UNSTABLE,
            Error::Interrupted { .. } => exit::INTERRUPTED,
            Error::Other(_) => exit::OTHER,
        }
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

/// Numbers as `a, b` (or `a, b, c`), each [`Shown`]: a point's coordinates in a message.
pub fn shown_joined(c: &[f64]) -> String {
    c.iter().map(|c| c.shown()).collect::<Vec<_>>().join(", ")
}

impl<T: Shown> Shown for &T {
    fn shown(&self) -> String {
        (**self).shown()
    }
}

/// `Ok(())` when `ok`, else an [`Error::BadOption`] naming the command-line `option`, the
/// value and the range.
pub fn check_option(ok: bool, option: &str, value: impl fmt::Display, allowed: &str) -> Result<(), Error> {
    if ok { Ok(()) } else { Err(Error::BadOption { option: option.to_string(), value: value.to_string(), allowed: allowed.to_string() }) }
}
