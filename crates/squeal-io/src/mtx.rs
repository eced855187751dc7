//! Matrix Market `coordinate` files: a strict reader with precise errors and a writer whose
//! output SciPy reads and whose round trip is bit-identical.

use crate::IoError;
use faer::sparse::SymbolicSparseColMat;
use squeal_core::SparseMat;
use std::fs::File;
use std::io::{BufRead, BufReader, BufWriter, Write};
use std::path::Path;

/// The banner squeal writes (SciPy's `mmread` requires this exact spelling of the keyword).
const BANNER: &str = "%%MatrixMarket matrix coordinate real general";
const EXPECTED_BANNER: &str =
    "`%%MatrixMarket matrix coordinate real general` (or `... real symmetric`)";
const EXPECTED_SIZE: &str = "`<rows> <columns> <entries>`, three non-negative integers";
const EXPECTED_ENTRY: &str =
    "`<row> <column> <value>` with 1-based integer indices and a real value";

pub(crate) fn io_err(file: &Path, action: &'static str, source: std::io::Error) -> IoError {
    IoError::Io {
        file: file.to_path_buf(),
        action,
        source,
    }
}

/// Reads a Matrix Market file `%%MatrixMarket matrix coordinate real|integer
/// general|symmetric`.
///
/// A `symmetric` file stores the lower triangle (row >= column) and is expanded to the
/// full matrix; an entry above its diagonal is an error. Duplicate entries are summed (in
/// file order), as SciPy does. Comment (`%`) and blank lines may appear anywhere after
/// the banner. The result has sorted row indices in every column.
///
/// # Errors
/// [`IoError`] naming the file and line: unreadable file, bad banner, unsupported object,
/// format (`array`), field (`complex`, `pattern`) or symmetry, bad size line or entry,
/// index out of range, NaN/inf value, fewer or more entries than declared.
pub fn read_mtx(path: impl AsRef<Path>) -> Result<SparseMat, IoError> {
    let path = path.as_ref();
    let f = File::open(path).map_err(|e| io_err(path, "open for reading", e))?;
    read_mtx_from(BufReader::new(f), path)
}

/// Reads a Matrix Market file that must be square, and `n x n` when `expected_dim` is
/// `Some(n)`.
///
/// # Errors
/// Those of [`read_mtx`], and [`IoError::Shape`] for a non-square matrix or one of
/// another size.
pub fn read_square_mtx(
    path: impl AsRef<Path>,
    expected_dim: Option<usize>,
) -> Result<SparseMat, IoError> {
    let path = path.as_ref();
    let expected = match expected_dim {
        Some(n) => format!("a square {n} x {n} matrix"),
        None => "a square matrix".to_string(),
    };
    read_square_with(path, expected_dim, &expected)
}

/// [`read_square_mtx`] with the wording of the expectation chosen by the caller.
pub(crate) fn read_square_with(
    path: &Path,
    expected_dim: Option<usize>,
    expected: &str,
) -> Result<SparseMat, IoError> {
    let m = read_mtx(path)?;
    let bad = m.nrows() != m.ncols() || expected_dim.is_some_and(|n| n != m.nrows());
    if bad {
        return Err(IoError::Shape {
            file: path.to_path_buf(),
            nrows: m.nrows(),
            ncols: m.ncols(),
            expected: expected.to_string(),
        });
    }
    Ok(m)
}

/// Shortens a line for an error message.
fn shown(line: &str) -> String {
    const MAX: usize = 80;
    let t = line.trim();
    if t.chars().count() <= MAX {
        t.to_string()
    } else {
        let s: String = t.chars().take(MAX).collect();
        format!("{s}...")
    }
}

/// A syntax error at `line` of `file`.
fn syntax_at(file: &Path, line: usize, problem: String, expected: &str) -> IoError {
    IoError::Syntax {
        file: file.to_path_buf(),
        line,
        problem,
        expected: expected.to_string(),
    }
}

/// Checks the banner line `buf` of `file`; whether the matrix is stored symmetric.
fn banner(file: &Path, buf: &str) -> Result<bool, IoError> {
    let syntax =
        |line: usize, problem: String, expected: &str| syntax_at(file, line, problem, expected);
    let tokens: Vec<String> = buf
        .split_whitespace()
        .map(|t| t.to_ascii_lowercase())
        .collect();
    if tokens.first().map(String::as_str) != Some("%%matrixmarket") {
        return Err(syntax(
            1,
            format!("`{}` is not a Matrix Market banner", shown(buf)),
            EXPECTED_BANNER,
        ));
    }
    if tokens.len() != 5 {
        return Err(syntax(
            1,
            format!(
                "banner `{}` has {} words instead of 5",
                shown(buf),
                tokens.len()
            ),
            EXPECTED_BANNER,
        ));
    }
    let unsupported =
        |what: &'static str, got: &str, expected: &'static str| IoError::Unsupported {
            file: file.to_path_buf(),
            line: 1,
            what,
            got: got.to_string(),
            expected,
        };
    if tokens[1] != "matrix" {
        return Err(unsupported("object", &tokens[1], "`matrix`"));
    }
    if tokens[2] != "coordinate" {
        return Err(unsupported(
            "format",
            &tokens[2],
            "`coordinate` (sparse triplets); dense `array` files are not read",
        ));
    }
    if tokens[3] != "real" && tokens[3] != "integer" {
        return Err(unsupported(
            "field",
            &tokens[3],
            "`real` (or `integer`); complex and pattern matrices are not read",
        ));
    }
    let symmetric = match tokens[4].as_str() {
        "general" => false,
        "symmetric" => true,
        other => {
            return Err(unsupported(
                "symmetry",
                other,
                "`general` or `symmetric` (lower triangle stored)",
            ))
        }
    };

    Ok(symmetric)
}

/// One entry line `t` (line `lineno` of `file`) of a matrix of `size`: 1-based row,
/// column and value, checked.
fn entry(
    file: &Path,
    lineno: usize,
    t: &str,
    size: [usize; 2],
    symmetric: bool,
) -> Result<(usize, usize, f64), IoError> {
    let [nrows, ncols] = size;
    let syntax =
        |line: usize, problem: String, expected: &str| syntax_at(file, line, problem, expected);
    let parts: Vec<&str> = t.split_whitespace().collect();
    if parts.len() != 3 {
        return Err(syntax(
            lineno,
            format!(
                "entry `{}` has {} fields instead of 3",
                shown(t),
                parts.len()
            ),
            EXPECTED_ENTRY,
        ));
    }
    let index = |s: &str, what: &str| {
        s.parse::<usize>().map_err(|_| {
            syntax(
                lineno,
                format!(
                    "{what} index `{s}` in `{}` is not a non-negative integer",
                    shown(t)
                ),
                EXPECTED_ENTRY,
            )
        })
    };
    let row = index(parts[0], "row")?;
    let col = index(parts[1], "column")?;
    let val: f64 = parts[2].parse().map_err(|_| {
        syntax(
            lineno,
            format!(
                "value `{}` in `{}` is not a real number",
                parts[2],
                shown(t)
            ),
            EXPECTED_ENTRY,
        )
    })?;
    if row == 0 || col == 0 || row > nrows || col > ncols {
        return Err(IoError::IndexOutOfRange {
            file: file.to_path_buf(),
            line: lineno,
            row,
            col,
            nrows,
            ncols,
        });
    }
    if !val.is_finite() {
        return Err(IoError::NonFinite {
            file: file.to_path_buf(),
            line: Some(lineno),
            row,
            col,
            value: parts[2].to_string(),
        });
    }
    if symmetric && row < col {
        return Err(IoError::UpperTriangle {
            file: file.to_path_buf(),
            line: lineno,
            row,
            col,
        });
    }
    Ok((row, col, val))
}

/// Reads Matrix Market text from any buffered reader; `file` names the source in errors.
///
/// # Errors
/// As [`read_mtx`].
pub fn read_mtx_from<R: BufRead>(mut reader: R, file: &Path) -> Result<SparseMat, IoError> {
    let syntax =
        |line: usize, problem: String, expected: &str| syntax_at(file, line, problem, expected);
    let mut buf = String::new();
    let mut lineno = 0usize;
    // Reads the next line into `buf`; false at end of file.
    let mut next = |buf: &mut String, lineno: &mut usize| -> Result<bool, IoError> {
        buf.clear();
        let n = reader.read_line(buf).map_err(|e| io_err(file, "read", e))?;
        if n > 0 {
            *lineno += 1;
        }
        Ok(n > 0)
    };

    // Banner.
    if !next(&mut buf, &mut lineno)? {
        return Err(syntax(1, "the file is empty".into(), EXPECTED_BANNER));
    }
    let symmetric = banner(file, &buf)?;

    // Size line (after comments and blank lines).
    let (nrows, ncols, declared) = loop {
        if !next(&mut buf, &mut lineno)? {
            return Err(syntax(
                lineno + 1,
                "the file ends before the size line".into(),
                EXPECTED_SIZE,
            ));
        }
        let t = buf.trim();
        if t.is_empty() || t.starts_with('%') {
            continue;
        }
        let parts: Vec<&str> = t.split_whitespace().collect();
        let nums: Vec<Option<usize>> = parts.iter().map(|p| p.parse().ok()).collect();
        match nums.as_slice() {
            [Some(r), Some(c), Some(n)] => break (*r, *c, *n),
            _ => {
                return Err(syntax(
                    lineno,
                    format!("size line `{}` is not valid", shown(t)),
                    EXPECTED_SIZE,
                ))
            }
        }
    };
    if symmetric && nrows != ncols {
        return Err(IoError::Shape {
            file: file.to_path_buf(),
            nrows,
            ncols,
            expected: "a square matrix (the banner says `symmetric`)".into(),
        });
    }

    // Entries.
    let cap = declared.min(1 << 24) * if symmetric { 2 } else { 1 };
    let mut trip: Vec<(usize, usize, f64)> = Vec::with_capacity(cap);
    let mut found = 0usize;
    while next(&mut buf, &mut lineno)? {
        let t = buf.trim();
        if t.is_empty() || t.starts_with('%') {
            continue;
        }
        if found == declared {
            return Err(IoError::EntryCount {
                file: file.to_path_buf(),
                line: lineno,
                declared,
                found: found + 1,
            });
        }
        let (row, col, val) = entry(file, lineno, t, [nrows, ncols], symmetric)?;
        trip.push((row - 1, col - 1, val));
        if symmetric && row != col {
            trip.push((col - 1, row - 1, val));
        }
        found += 1;
    }
    if found < declared {
        return Err(IoError::EntryCount {
            file: file.to_path_buf(),
            line: lineno,
            declared,
            found,
        });
    }
    Ok(csc_from_triplets(nrows, ncols, trip))
}

/// Compressed-column matrix from in-range triplets: rows sorted in each column, duplicates
/// summed in input order (a single entry keeps its exact bits, `-0.0` included).
fn csc_from_triplets(nrows: usize, ncols: usize, mut trip: Vec<(usize, usize, f64)>) -> SparseMat {
    // Stable sort keeps the file order of duplicates.
    trip.sort_by_key(|&(i, j, _)| (j, i));
    let mut col_ptr = vec![0usize; ncols + 1];
    let mut row_idx: Vec<usize> = Vec::with_capacity(trip.len());
    let mut val: Vec<f64> = Vec::with_capacity(trip.len());
    let mut last: Option<(usize, usize)> = None;
    for (i, j, v) in trip {
        if last == Some((i, j)) {
            *val.last_mut().expect("a previous entry") += v;
        } else {
            row_idx.push(i);
            val.push(v);
            col_ptr[j + 1] += 1;
            last = Some((i, j));
        }
    }
    for j in 0..ncols {
        col_ptr[j + 1] += col_ptr[j];
    }
    let symbolic = SymbolicSparseColMat::new_checked(nrows, ncols, col_ptr, None, row_idx);
    SparseMat::new(symbolic, val)
}

/// Writes `m` as `%%MatrixMarket matrix coordinate real general`, 1-based indices, values
/// as `{:.17e}` (read back bit-identically), entries column by column in storage order.
///
/// `comment` goes after the banner, each of its lines prefixed with `% `; an empty
/// comment writes no comment line. The output contains no date, so it is reproducible.
/// SciPy's `scipy.io.mmread` reads the result.
///
/// # Errors
/// [`IoError::NonFinite`] (nothing written) if `m` holds NaN or inf;
/// [`IoError::Io`] if the file cannot be created or written.
pub fn write_mtx(path: impl AsRef<Path>, m: &SparseMat, comment: &str) -> Result<(), IoError> {
    let path = path.as_ref();
    check_finite(m, path)?;
    let f = File::create(path).map_err(|e| io_err(path, "create", e))?;
    let mut w = BufWriter::new(f);
    write_mtx_to(&mut w, m, comment).map_err(|e| io_err(path, "write", e))?;
    w.flush().map_err(|e| io_err(path, "write", e))?;
    Ok(())
}

/// Fails with [`IoError::NonFinite`] on the first NaN/inf of `m`.
pub(crate) fn check_finite(m: &SparseMat, file: &Path) -> Result<(), IoError> {
    for j in 0..m.ncols() {
        for (i, v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
            if !v.is_finite() {
                return Err(IoError::NonFinite {
                    file: file.to_path_buf(),
                    line: None,
                    row: i + 1,
                    col: j + 1,
                    value: v.to_string(),
                });
            }
        }
    }
    Ok(())
}

/// Writes the Matrix Market text of `m` (see [`write_mtx`]) to any writer.
///
/// Non-finite values are written as they are (`NaN`, `inf`), which no reader accepts;
/// [`write_mtx`] checks for them first.
///
/// # Errors
/// The writer's errors.
pub fn write_mtx_to<W: Write>(w: &mut W, m: &SparseMat, comment: &str) -> std::io::Result<()> {
    writeln!(w, "{BANNER}")?;
    if !comment.is_empty() {
        for line in comment.lines() {
            if line.is_empty() {
                writeln!(w, "%")?;
            } else {
                writeln!(w, "% {line}")?;
            }
        }
    }
    writeln!(w, "{} {} {}", m.nrows(), m.ncols(), m.compute_nnz())?;
    for j in 0..m.ncols() {
        for (i, v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
            writeln!(w, "{} {} {:.17e}", i + 1, j + 1, v)?;
        }
    }
    Ok(())
}
