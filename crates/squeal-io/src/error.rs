//! [`IoError`]: what can go wrong reading or writing operator files.

use std::path::PathBuf;
use thiserror::Error;

/// A file that cannot be read or written, or whose content is not what squeal expects.
///
/// Every variant names the file (its path as given), the 1-based line where one applies,
/// and what was expected.
#[derive(Debug, Error)]
pub enum IoError {
    /// The file or directory cannot be opened, read or created.
    #[error("{}: cannot {action}: {source}", file.display())]
    Io {
        /// The file or directory.
        file: PathBuf,
        /// What was attempted ("read", "write", "create directory", ...).
        action: &'static str,
        /// The operating-system error.
        source: std::io::Error,
    },
    /// A line that does not have the expected syntax (banner, size line, entry, index).
    #[error("{}:{line}: {problem}; expected {expected}", file.display())]
    Syntax {
        /// The file.
        file: PathBuf,
        /// 1-based line number.
        line: usize,
        /// What is wrong.
        problem: String,
        /// What the line should look like.
        expected: String,
    },
    /// A valid Matrix Market header for a kind of file squeal does not read.
    #[error(
        "{}:{line}: unsupported Matrix Market {what} `{got}`; expected {expected}",
        file.display()
    )]
    Unsupported {
        /// The file.
        file: PathBuf,
        /// 1-based line number (the banner).
        line: usize,
        /// Which header field ("object", "format", "field", "symmetry").
        what: &'static str,
        /// Its value in the file.
        got: String,
        /// What squeal reads.
        expected: &'static str,
    },
    /// An entry whose 1-based index lies outside the declared size.
    #[error(
        "{}:{line}: entry ({row}, {col}) is outside the declared {nrows} x {ncols} matrix; \
         expected 1-based indices 1..={nrows} (row) and 1..={ncols} (column)",
        file.display()
    )]
    IndexOutOfRange {
        /// The file.
        file: PathBuf,
        /// 1-based line number.
        line: usize,
        /// Row index as written (1-based).
        row: usize,
        /// Column index as written (1-based).
        col: usize,
        /// Declared number of rows.
        nrows: usize,
        /// Declared number of columns.
        ncols: usize,
    },
    /// An entry above the diagonal in a `symmetric` file, which stores the lower triangle.
    #[error(
        "{}:{line}: entry ({row}, {col}) lies above the diagonal in a `symmetric` file; \
         expected only the lower triangle (row >= column)",
        file.display()
    )]
    UpperTriangle {
        /// The file.
        file: PathBuf,
        /// 1-based line number.
        line: usize,
        /// Row index as written (1-based).
        row: usize,
        /// Column index as written (1-based).
        col: usize,
    },
    /// Fewer or more entries than the size line declares.
    #[error(
        "{}:{line}: found {found} entries{more}; the size line declares {declared}",
        file.display(),
        more = if *found > *declared { " or more" } else { "" }
    )]
    EntryCount {
        /// The file.
        file: PathBuf,
        /// 1-based line of the first surplus entry, or the last line when entries are
        /// missing.
        line: usize,
        /// Entries declared on the size line.
        declared: usize,
        /// Entries found (for surplus entries: the count up to the first surplus one).
        found: usize,
    },
    /// A NaN or infinite value.
    #[error(
        "{}{}: value `{value}` at ({row}, {col}) is not finite; expected a finite real number",
        file.display(),
        at_line(line)
    )]
    NonFinite {
        /// The file.
        file: PathBuf,
        /// 1-based line number; `None` when writing a matrix.
        line: Option<usize>,
        /// Row index (1-based).
        row: usize,
        /// Column index (1-based).
        col: usize,
        /// The value as written.
        value: String,
    },
    /// A matrix whose size differs from the one required.
    #[error(
        "{}: matrix is {nrows} x {ncols}; expected {expected}",
        file.display()
    )]
    Shape {
        /// The file.
        file: PathBuf,
        /// Rows found.
        nrows: usize,
        /// Columns found.
        ncols: usize,
        /// What was required ("a square matrix", "12 x 12 like Mc.mtx", ...).
        expected: String,
    },
    /// A required file of an operator directory is absent.
    #[error("{}: required file is missing; expected {expected}", file.display())]
    Missing {
        /// The path that was looked for.
        file: PathBuf,
        /// What the file should hold.
        expected: String,
    },
    /// An index map `T` that does not map onto the constrained DOFs.
    #[error("{}{}: {problem}; expected {expected}", file.display(), at_line(line))]
    IndexMap {
        /// The file.
        file: PathBuf,
        /// 1-based line number; `None` for a defect of the whole map.
        line: Option<usize>,
        /// What is wrong.
        problem: String,
        /// What a valid map looks like.
        expected: String,
    },
    /// A Gmsh MSH file that is not a readable MSH 4.1 ASCII hexahedral mesh (or a mesh
    /// that cannot be written as one).
    #[error("{}{}: {problem}; expected {expected}", file.display(), at_line(line))]
    Msh {
        /// The file.
        file: PathBuf,
        /// 1-based line number; `None` for a defect of the whole file.
        line: Option<usize>,
        /// What is wrong.
        problem: String,
        /// What squeal reads.
        expected: String,
    },
    /// A MAT-file that is not a readable Level 5 file, or a variable in it that is not a
    /// real 2-D matrix.
    #[error("{}{}: {problem}; expected {expected}", file.display(), in_variable(variable))]
    Mat {
        /// The file.
        file: PathBuf,
        /// The variable; `None` for a defect of the whole file.
        variable: Option<String>,
        /// What is wrong.
        problem: String,
        /// What squeal reads.
        expected: String,
    },
    /// A parametric operator description (`operator.toml`) that is invalid, or a value of
    /// its parameter at which the operator cannot be formed.
    #[error("{}: {field}: {problem}; expected {expected}", file.display())]
    Parametric {
        /// The description file (or the directory).
        file: PathBuf,
        /// The key, term or part concerned (`K[2].coeff`, `parameter`, `M`, ...).
        field: String,
        /// What is wrong.
        problem: String,
        /// What would be valid.
        expected: String,
    },
    /// Operator metadata that cannot be written faithfully (e.g. a non-finite mu).
    #[error("{}: {problem}", file.display())]
    Meta {
        /// The file being written.
        file: PathBuf,
        /// What is wrong.
        problem: String,
    },
}

/// `" (variable `name`)"`, or nothing.
fn in_variable(v: &Option<String>) -> String {
    v.as_ref()
        .map(|v| format!(" (variable `{v}`)"))
        .unwrap_or_default()
}

/// `":<line>"`, or nothing.
fn at_line(line: &Option<usize>) -> String {
    line.map(|l| format!(":{l}")).unwrap_or_default()
}

impl From<IoError> for squeal_core::Error {
    fn from(e: IoError) -> Self {
        squeal_core::Error::Backend(Box::new(e))
    }
}
