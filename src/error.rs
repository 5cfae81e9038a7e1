//! One error type for the whole library. Every failure a caller can cause (bad file, bad
//! parameter, bad geometry, cancellation) is a value here, never a panic.

use std::fmt;
use std::path::{Path, PathBuf};

/// Everything that can go wrong in vstree, with enough detail to fix it.
#[derive(Debug)]
pub enum Error {
    /// The operating system refused a read or write.
    Io { path: PathBuf, source: std::io::Error },
    /// A file's content is not what its format requires.
    /// `location` is e.g. `"line 12"` or `"vertex element 17"`.
    Parse { path: PathBuf, location: String, message: String },
    /// The file extension names no format vstree reads or writes.
    UnsupportedFormat { path: PathBuf },
    /// A parameter is out of its documented range; `name` is the parameter's name.
    InvalidParameter { name: &'static str, message: String },
    /// The geometry cannot be processed (empty, NaN, index out of range, ...).
    InvalidInput(String),
    /// The result would exceed a hard size limit; refused before allocating.
    TooLarge(String),
    /// The progress callback asked to stop.
    Cancelled,
}

/// `Result` with [`Error`].
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    pub(crate) fn io(path: &Path, source: std::io::Error) -> Self {
        Error::Io { path: path.to_path_buf(), source }
    }

    pub(crate) fn parse(path: &Path, location: impl Into<String>, message: impl Into<String>) -> Self {
        Error::Parse { path: path.to_path_buf(), location: location.into(), message: message.into() }
    }

    pub(crate) fn param(name: &'static str, message: impl Into<String>) -> Self {
        Error::InvalidParameter { name, message: message.into() }
    }

    pub(crate) fn input(message: impl Into<String>) -> Self {
        Error::InvalidInput(message.into())
    }
}

/// `x` as messages show a parameter's value: plainly where that is short, else in exponent
/// form (1e300 rather than three hundred digits).
pub(crate) fn shown(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e6).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Io { path, source } => write!(f, "{}: {source}", path.display()),
            Error::Parse { path, location, message } => {
                write!(f, "{}: {location}: {message}", path.display())
            }
            Error::UnsupportedFormat { path } => {
                write!(f, "{}: unsupported file format (expected .ply, .obj, .off, .xyz or .pwn)", path.display())
            }
            Error::InvalidParameter { name, message } => write!(f, "parameter `{name}`: {message}"),
            Error::InvalidInput(message) => write!(f, "invalid input: {message}"),
            Error::TooLarge(message) => write!(f, "too large: {message}"),
            Error::Cancelled => write!(f, "cancelled"),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Io { source, .. } => Some(source),
            _ => None,
        }
    }
}
