//! Source locations in model files. The one place where 0-based parser markers become 1-based
//! line and column numbers (rustc convention).

/// A 1-based line and column (in characters) in a model file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
pub struct Location {
    /// Line, starting at 1.
    pub line: u32,
    /// Column in characters, starting at 1.
    pub column: u32,
}

impl Location {
    /// Location from 0-based line and column markers (as YAML parsers report them).
    pub fn from_zero_based(line: usize, column: usize) -> Self {
        Self {
            line: line as u32 + 1,
            column: column as u32 + 1,
        }
    }

    /// The location `columns` characters to the right on the same line.
    pub fn offset(self, columns: usize) -> Self {
        Self {
            line: self.line,
            column: self.column + columns as u32,
        }
    }
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}", self.line, self.column)
    }
}

/// A value together with where it was written.
#[derive(Debug, Clone, PartialEq)]
pub struct Located<T> {
    /// The value.
    pub value: T,
    /// Where its text starts.
    pub location: Location,
}

impl<T> Located<T> {
    /// Wraps `value` found at `location`.
    pub fn new(value: T, location: Location) -> Self {
        Self { value, location }
    }
}
