//! Errors that reach the user. Every error about an input names the file it came from,
//! and the line and element where there is one, so a researcher can fix the scene by hand.

use std::fmt;
use std::path::{Path, PathBuf};

/// Where in an input file something went wrong.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Location {
    pub file: PathBuf,
    /// 1-based line, when known.
    pub line: Option<u32>,
    /// The XML element (e.g. `<bsdf type="diffuse">`) or mesh record, when there is one.
    pub element: Option<String>,
}

impl Location {
    pub fn file(file: impl Into<PathBuf>) -> Self {
        Location {
            file: file.into(),
            line: None,
            element: None,
        }
    }

    pub fn at(file: impl Into<PathBuf>, line: u32, element: impl Into<String>) -> Self {
        Location {
            file: file.into(),
            line: Some(line),
            element: Some(element.into()),
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.file.display())?;
        if let Some(line) = self.line {
            write!(f, ":{line}")?;
        }
        if let Some(element) = &self.element {
            write!(f, ": {element}")?;
        }
        Ok(())
    }
}

/// The crate-wide error type.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A problem with an input file (scene XML, mesh, image), with its location.
    #[error("{location}: {message}")]
    Input { location: Location, message: String },
    /// An operating-system error while reading or writing a file.
    #[error("{}: {source}", path.display())]
    Io {
        path: PathBuf,
        source: std::io::Error,
    },
    /// A bad command-line argument or estimator parameter.
    #[error("{0}")]
    Usage(String),
}

impl Error {
    pub fn input(location: Location, message: impl Into<String>) -> Self {
        Error::Input {
            location,
            message: message.into(),
        }
    }

    pub fn io(path: &Path, source: std::io::Error) -> Self {
        Error::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    pub fn usage(message: impl Into<String>) -> Self {
        Error::Usage(message.into())
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;
