//! One error type for the whole crate.
//!
//! Every failure a user can cause (a broken mesh file, an unknown method, a bad parameter, an
//! unwritable output) becomes an [`Error`] that names *what* was wrong and *where*: the file and,
//! when known, the line or element. The binary prints it on stderr and exits with status 2; the
//! library never panics on bad input.

use std::fmt;
use std::path::Path;

/// What went wrong, with enough context to act on it.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A mesh source (file or procedural spec) could not be read or is invalid.
    /// `origin` is the file path or spec as the user wrote it; `problem` names the line or element.
    #[error("{origin}: {problem}")]
    Input { origin: String, problem: String },
    /// An output file could not be written. Nothing partial is left behind.
    #[error("{path}: cannot write: {problem}")]
    Output { path: String, problem: String },
    /// A command-line or spec value that does not parse: unknown method, bad parameter, bad cache
    /// or view-set name.
    #[error("{0}")]
    Usage(String),
    /// An experiment spec that is malformed or inconsistent.
    #[error("{path}: {problem}")]
    Spec { path: String, problem: String },
    /// The GPU could not be opened or failed while measuring: no adapter, a lost device, a mesh or
    /// image over the device's limits. The message says what to do.
    #[error("GPU: {0}")]
    Gpu(String),
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    pub fn input(origin: impl fmt::Display, problem: impl fmt::Display) -> Self {
        Error::Input { origin: origin.to_string(), problem: problem.to_string() }
    }

    pub fn output(path: &Path, problem: impl fmt::Display) -> Self {
        Error::Output { path: path.display().to_string(), problem: problem.to_string() }
    }

    pub fn usage(message: impl fmt::Display) -> Self {
        Error::Usage(message.to_string())
    }

    pub fn spec(path: &Path, problem: impl fmt::Display) -> Self {
        Error::Spec { path: path.display().to_string(), problem: problem.to_string() }
    }
}

/// `text` with control characters other than line breaks and tabs (a NUL, an escape sequence
/// from a file's bytes) written as escapes, so no message carries them raw to a terminal.
pub fn printable(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_control() && c != '\n' && c != '\t' { c.escape_default().to_string() } else { c.to_string() })
        .collect()
}
