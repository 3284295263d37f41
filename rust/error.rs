//! The one error type of the core. Library code returns `Result<_, CoreError>` and
//! never panics on user data; the binding layer maps each variant to a Python
//! exception.

use std::fmt;

#[derive(Debug, Clone, PartialEq)]
pub enum CoreError {
    /// An argument is outside its domain (maps to `ValueError`).
    InvalidArgument(String),
    /// Input data could not be parsed in strict mode (maps to `ValueError`).
    Parse(String),
    /// A numerical routine could not produce a result (maps to `ValueError`).
    Numerical(String),
    /// Reading or writing failed (maps to `OSError`).
    Io(String),
}

impl fmt::Display for CoreError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CoreError::InvalidArgument(msg)
            | CoreError::Parse(msg)
            | CoreError::Numerical(msg)
            | CoreError::Io(msg) => f.write_str(msg),
        }
    }
}

impl std::error::Error for CoreError {}

impl From<std::io::Error> for CoreError {
    fn from(err: std::io::Error) -> Self {
        CoreError::Io(err.to_string())
    }
}

pub type CoreResult<T> = Result<T, CoreError>;
