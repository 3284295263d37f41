//! The one error type of the core. Library code returns `Result<_, CoreError>` and
//! never panics on user data; the binding layer maps each variant to a Python
//! exception.

use std::fmt;

#[derive(Debug, Clone, PartialEq)]
pub enum CoreError {
    /// An argument is outside its domain (maps to `ValueError`).
    InvalidArgument(String),
    /// Input data could not be parsed in strict mode (maps to
    /// `imunoise.errors.ParseError`, a `ValueError`): the issue kind's name
    /// (`"bad_checksum"` ...), where (1-based line, 0-based byte offset) when
    /// known, and why.
    Parse {
        kind: &'static str,
        line: Option<u64>,
        offset: Option<u64>,
        reason: String,
    },
    /// A numerical routine could not produce a result (maps to `ValueError`).
    Numerical(String),
    /// Reading or writing failed (maps by `kind` to `FileNotFoundError`,
    /// `PermissionError` or `OSError`).
    Io {
        kind: std::io::ErrorKind,
        message: String,
    },
    /// The computation was stopped by a raised `Interrupt` (`interrupt.rs`; maps
    /// to `KeyboardInterrupt`).
    Interrupted,
}

impl fmt::Display for CoreError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CoreError::InvalidArgument(msg)
            | CoreError::Numerical(msg)
            | CoreError::Io { message: msg, .. } => f.write_str(msg),
            CoreError::Parse {
                kind,
                line,
                offset,
                reason,
            } => {
                match (line, offset) {
                    (Some(line), Some(offset)) => {
                        write!(f, "line {line} (byte offset {offset}): ")?
                    }
                    (Some(line), None) => write!(f, "line {line}: ")?,
                    (None, Some(offset)) => write!(f, "byte offset {offset}: ")?,
                    (None, None) => {}
                }
                write!(f, "{kind}: {reason}")
            }
            CoreError::Interrupted => f.write_str("interrupted"),
        }
    }
}

impl std::error::Error for CoreError {}

impl From<std::io::Error> for CoreError {
    fn from(err: std::io::Error) -> Self {
        CoreError::Io {
            kind: err.kind(),
            message: err.to_string(),
        }
    }
}

pub type CoreResult<T> = Result<T, CoreError>;
