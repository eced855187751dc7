//! MATLAB Level 5 MAT-files (`save -v6` / `-v7`, `scipy.io.savemat`): real sparse and
//! dense numeric matrices.
//!
//! The format (MathWorks, "MAT-File Format", Level 5): a 128-byte header (text, subsystem
//! offset, version `0x0100`, endian indicator `IM`/`MI`), then data elements, each an
//! 8-byte tag (type, byte count) followed by its data padded to 8 bytes; a tag whose upper
//! 16 bits are nonzero is a "small element" holding up to 4 bytes in the tag itself.
//! A variable is an `miMATRIX` element, or an `miCOMPRESSED` one (zlib, MAT v7) holding
//! it. Its sub-elements: array flags (class, complex and logical bits, `nzmax`),
//! dimensions, name, then
//! - numeric classes (`double`, `single`, integers): the real part (any numeric storage
//!   type, e.g. a double array MATLAB stored as `uint8`), column-major;
//! - `mxSPARSE_CLASS`: `ir` (row indices, `nnz`), `jc` (column starts, `ncols + 1`),
//!   `pr` (values).
//!
//! Complex data, cells, structs, objects, characters and arrays of more than two
//! dimensions are refused with an error naming the file and the variable; so are the
//! HDF5-based v7.3 files and Level 4 files. Values must be finite.
//!
//! Written by hand: the `matfile` crate (0.5) parses but does not expose sparse arrays,
//! and the younger `matrw` (0.1) unwraps on malformed input.

use crate::mtx::io_err;
use crate::IoError;
use faer::sparse::Triplet;
use squeal_core::SparseMat;
use std::io::Read;
use std::path::{Path, PathBuf};

const MI_INT8: u32 = 1;
const MI_UINT8: u32 = 2;
const MI_INT16: u32 = 3;
const MI_UINT16: u32 = 4;
const MI_INT32: u32 = 5;
const MI_UINT32: u32 = 6;
const MI_SINGLE: u32 = 7;
const MI_DOUBLE: u32 = 9;
const MI_INT64: u32 = 12;
const MI_UINT64: u32 = 13;
const MI_MATRIX: u32 = 14;
const MI_COMPRESSED: u32 = 15;

const MX_CELL: u8 = 1;
const MX_STRUCT: u8 = 2;
const MX_OBJECT: u8 = 3;
const MX_CHAR: u8 = 4;
const MX_SPARSE: u8 = 5;

const FLAG_COMPLEX: u32 = 0x0800;

const EXPECTED_FILE: &str = "a MATLAB Level 5 MAT-file (save -v7 or -v6, scipy.io.savemat)";
const EXPECTED_VAR: &str = "a real 2-D numeric or sparse matrix";

/// The variables of a MAT-file, decompressed and indexed by name; matrices are decoded
/// on demand by [`MatFile::matrix`].
#[derive(Debug, Clone)]
pub struct MatFile {
    path: PathBuf,
    big_endian: bool,
    /// `(name, class, miMATRIX payload)` in file order.
    vars: Vec<(String, u8, Vec<u8>)>,
}

/// Reads the real matrix `variable` of the MAT-file `path` (see [`MatFile::matrix`]).
///
/// # Errors
/// Those of [`MatFile::open`] and [`MatFile::matrix`].
pub fn read_mat(path: impl AsRef<Path>, variable: &str) -> Result<SparseMat, IoError> {
    MatFile::open(path)?.matrix(variable)
}

fn mat_err(file: &Path, variable: Option<&str>, problem: String, expected: &str) -> IoError {
    IoError::Mat {
        file: file.to_path_buf(),
        variable: variable.map(str::to_string),
        problem,
        expected: expected.to_string(),
    }
}

/// A cursor over the bytes of one element list.
struct Reader<'a> {
    buf: &'a [u8],
    big: bool,
}

impl Reader<'_> {
    fn u32_at(&self, p: usize) -> Option<u32> {
        let b: [u8; 4] = self.buf.get(p..p + 4)?.try_into().ok()?;
        Some(if self.big {
            u32::from_be_bytes(b)
        } else {
            u32::from_le_bytes(b)
        })
    }

    /// The element at `p`: `(type, data, position of the next element)`. `pad` says
    /// whether the data is padded to 8 bytes (every element but a compressed one).
    fn element(&self, p: usize, pad: bool) -> Result<(u32, &[u8], usize), String> {
        let t = self
            .u32_at(p)
            .ok_or_else(|| format!("truncated element tag at byte {p}"))?;
        if t >> 16 != 0 {
            // small element: type and byte count in the first word, data in the second
            let (ty, n) = (t & 0xffff, (t >> 16) as usize);
            if n > 4 {
                return Err(format!("small element at byte {p} claims {n} > 4 bytes"));
            }
            let data = self
                .buf
                .get(p + 4..p + 4 + n)
                .ok_or_else(|| format!("truncated small element at byte {p}"))?;
            return Ok((ty, data, p + 8));
        }
        let n = self
            .u32_at(p + 4)
            .ok_or_else(|| format!("truncated element tag at byte {p}"))? as usize;
        let data = self.buf.get(p + 8..p + 8 + n).ok_or_else(|| {
            format!(
                "element at byte {p} claims {n} bytes, only {} left",
                self.buf.len().saturating_sub(p + 8)
            )
        })?;
        let next = if pad {
            p + 8 + n.div_ceil(8) * 8
        } else {
            p + 8 + n
        };
        Ok((t, data, next))
    }

    /// The numbers of a numeric element, converted to `f64`.
    fn numbers(&self, ty: u32, data: &[u8]) -> Result<Vec<f64>, String> {
        let big = self.big;
        macro_rules! conv {
            ($t:ty, $w:expr) => {{
                if !data.chunks_exact($w).remainder().is_empty() {
                    return Err(format!(
                        "numeric data of {} bytes is not a whole number of {}-byte values",
                        data.len(),
                        $w
                    ));
                }
                data.chunks_exact($w)
                    .map(|c| {
                        let b: [u8; $w] = c.try_into().expect("chunk of the element width");
                        (if big {
                            <$t>::from_be_bytes(b)
                        } else {
                            <$t>::from_le_bytes(b)
                        }) as f64
                    })
                    .collect()
            }};
        }
        Ok(match ty {
            MI_INT8 => conv!(i8, 1),
            MI_UINT8 => conv!(u8, 1),
            MI_INT16 => conv!(i16, 2),
            MI_UINT16 => conv!(u16, 2),
            MI_INT32 => conv!(i32, 4),
            MI_UINT32 => conv!(u32, 4),
            MI_SINGLE => conv!(f32, 4),
            MI_DOUBLE => conv!(f64, 8),
            MI_INT64 => conv!(i64, 8),
            MI_UINT64 => conv!(u64, 8),
            other => return Err(format!("data type {other} is not numeric")),
        })
    }

    /// Non-negative integer indices of an index element (`ir`, `jc`, dimensions).
    fn indices(&self, ty: u32, data: &[u8], what: &str) -> Result<Vec<usize>, String> {
        let v = self.numbers(ty, data)?;
        v.iter()
            .map(|&x| {
                if x >= 0.0 && x.fract() == 0.0 && x <= usize::MAX as f64 {
                    Ok(x as usize)
                } else {
                    Err(format!("{what} holds `{x}`, not a non-negative integer"))
                }
            })
            .collect()
    }
}

impl MatFile {
    /// Reads the header and every variable of `path` (compressed ones are inflated).
    ///
    /// # Errors
    /// [`IoError::Io`] if unreadable; [`IoError::Mat`] for a file that is not a Level 5
    /// MAT-file (too short, Level 4, HDF5-based v7.3, bad endian indicator), a corrupt
    /// compressed element or a malformed element list.
    pub fn open(path: impl AsRef<Path>) -> Result<Self, IoError> {
        let path = path.as_ref();
        let bytes = std::fs::read(path).map_err(|e| io_err(path, "read", e))?;
        let bad = |problem: String| mat_err(path, None, problem, EXPECTED_FILE);
        if bytes.len() < 128 {
            return Err(bad(format!(
                "{} bytes, shorter than the 128-byte header",
                bytes.len()
            )));
        }
        let text = String::from_utf8_lossy(&bytes[..116]);
        if text.starts_with("MATLAB 7.3") || bytes.get(512..520) == Some(b"\x89HDF\r\n\x1a\n") {
            return Err(bad(
                "an HDF5-based MAT v7.3 file; save it with `save -v7` (or scipy.io.savemat)".into(),
            ));
        }
        let big_endian = match &bytes[126..128] {
            b"IM" => false,
            b"MI" => true,
            other => {
                let hint = if bytes[..4].contains(&0) {
                    " (a Level 4 MAT-file? save with -v7)"
                } else {
                    ""
                };
                return Err(bad(format!(
                    "endian indicator {other:?} is neither `IM` nor `MI`{hint}"
                )));
            }
        };
        let top = Reader {
            buf: &bytes,
            big: big_endian,
        };
        let mut vars = Vec::new();
        let mut p = 128;
        while p + 8 <= bytes.len() {
            let (ty, data, next) = top.element(p, false).map_err(bad)?;
            let payload = match ty {
                MI_COMPRESSED => {
                    let mut out = Vec::new();
                    flate2::read::ZlibDecoder::new(data)
                        .read_to_end(&mut out)
                        .map_err(|e| bad(format!("compressed element at byte {p}: {e}")))?;
                    let inner = Reader {
                        buf: &out,
                        big: big_endian,
                    };
                    let (ity, idata, _) = inner.element(0, true).map_err(|e| {
                        bad(format!("inside the compressed element at byte {p}: {e}"))
                    })?;
                    (ity == MI_MATRIX).then(|| idata.to_vec())
                }
                MI_MATRIX => Some(data.to_vec()),
                _ => None,
            };
            // a matrix element is padded to 8 bytes; a compressed one is not
            p = if ty == MI_MATRIX {
                p + 8 + data.len().div_ceil(8) * 8
            } else {
                next
            };
            let Some(payload) = payload else { continue };
            if payload.is_empty() {
                continue;
            }
            let (name, class) = Self::header_of(&payload, big_endian)
                .map_err(|e| bad(format!("variable header: {e}")))?;
            vars.push((name, class, payload));
        }
        Ok(Self {
            path: path.to_path_buf(),
            big_endian,
            vars,
        })
    }

    /// Name and class of a matrix payload.
    fn header_of(payload: &[u8], big: bool) -> Result<(String, u8), String> {
        let r = Reader { buf: payload, big };
        let (_, flags, p) = r.element(0, true)?;
        let class = *flags.first().ok_or("empty array flags")?;
        let class = if big {
            *flags.get(3).ok_or("short array flags")?
        } else {
            class
        };
        let (_, _, p) = r.element(p, true)?;
        let (_, name, _) = r.element(p, true)?;
        Ok((String::from_utf8_lossy(name).into_owned(), class))
    }

    /// The file path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The variable names, in file order.
    pub fn names(&self) -> Vec<&str> {
        self.vars.iter().map(|v| v.0.as_str()).collect()
    }

    /// The real matrix `variable`: a sparse matrix as stored (duplicates summed), a dense
    /// numeric one converted to sparse (its zero entries dropped).
    ///
    /// # Errors
    /// [`IoError::Mat`] naming the file and the variable: absent (the message lists what
    /// the file holds), complex, not numeric (cell, struct, object, char), more than two
    /// dimensions, inconsistent sparse indices, a NaN or infinite value.
    pub fn matrix(&self, variable: &str) -> Result<SparseMat, IoError> {
        let Some((_, class, payload)) = self.vars.iter().find(|v| v.0 == variable) else {
            return Err(mat_err(
                &self.path,
                Some(variable),
                format!(
                    "no such variable; the file holds: {}",
                    if self.vars.is_empty() {
                        "nothing".to_string()
                    } else {
                        self.names().join(", ")
                    }
                ),
                EXPECTED_VAR,
            ));
        };
        let bad = |problem: String| mat_err(&self.path, Some(variable), problem, EXPECTED_VAR);
        let kind = match *class {
            MX_CELL => Some("a cell array"),
            MX_STRUCT => Some("a struct"),
            MX_OBJECT => Some("an object"),
            MX_CHAR => Some("a character array"),
            MX_SPARSE | 6..=15 => None,
            _ => Some("of an unknown class"),
        };
        if let Some(kind) = kind {
            return Err(bad(format!("is {kind} (class {class})")));
        }
        self.decode(payload, *class).map_err(bad)
    }

    fn decode(&self, payload: &[u8], class: u8) -> Result<SparseMat, String> {
        let r = Reader {
            buf: payload,
            big: self.big_endian,
        };
        let (_, flags, p) = r.element(0, true)?;
        let fw: [u8; 4] = flags
            .get(..4)
            .and_then(|b| b.try_into().ok())
            .ok_or("short array flags")?;
        let flags_word = if self.big_endian {
            u32::from_be_bytes(fw)
        } else {
            u32::from_le_bytes(fw)
        };
        if flags_word & FLAG_COMPLEX != 0 {
            return Err("is complex; squeal reads real matrices only".into());
        }
        let (dty, ddata, p) = r.element(p, true)?;
        let dims = r.indices(dty, ddata, "the dimensions")?;
        let (nrows, ncols) = match dims.as_slice() {
            [a, b] => (*a, *b),
            [a, b, rest @ ..] if rest.iter().all(|&d| d == 1) => (*a, *b),
            other => return Err(format!("has dimensions {other:?}, not a 2-D matrix")),
        };
        let (_, _, p) = r.element(p, true)?; // name
        let finite = |v: &[f64]| -> Result<(), String> {
            match v.iter().position(|x| !x.is_finite()) {
                Some(k) => Err(format!("value {} (stored entry {k}) is not finite", v[k])),
                None => Ok(()),
            }
        };
        if class == MX_SPARSE {
            let (ity, idata, p) = r.element(p, true)?;
            let ir = r.indices(ity, idata, "ir (row indices)")?;
            let (jty, jdata, p) = r.element(p, true)?;
            let jc = r.indices(jty, jdata, "jc (column starts)")?;
            if jc.len() != ncols + 1 {
                return Err(format!(
                    "jc has {} entries for {ncols} columns (expected {})",
                    jc.len(),
                    ncols + 1
                ));
            }
            let nnz = jc[ncols];
            if jc[0] != 0 || jc.windows(2).any(|w| w[0] > w[1]) {
                return Err("jc (column starts) does not start at 0 and never decrease".into());
            }
            if ir.len() < nnz {
                return Err(format!("ir has {} entries for {nnz} nonzeros", ir.len()));
            }
            // a logical sparse matrix may come without values: every stored entry is 1
            let pr = if p < payload.len() {
                let (pty, pdata, _) = r.element(p, true)?;
                r.numbers(pty, pdata)?
            } else {
                vec![1.0; nnz]
            };
            if pr.len() < nnz {
                return Err(format!("pr has {} values for {nnz} nonzeros", pr.len()));
            }
            finite(&pr[..nnz])?;
            let mut t = Vec::with_capacity(nnz);
            for j in 0..ncols {
                for k in jc[j]..jc[j + 1] {
                    if ir[k] >= nrows {
                        return Err(format!(
                            "row index {} (0-based) of column {j} is outside the {nrows} rows",
                            ir[k]
                        ));
                    }
                    t.push(Triplet::new(ir[k], j, pr[k]));
                }
            }
            return SparseMat::try_new_from_triplets(nrows, ncols, &t)
                .map_err(|e| format!("cannot build the sparse matrix: {e:?}"));
        }
        let (vty, vdata, _) = r.element(p, true)?;
        let v = r.numbers(vty, vdata)?;
        if v.len() != nrows * ncols {
            return Err(format!(
                "holds {} values for a {nrows} x {ncols} matrix",
                v.len()
            ));
        }
        finite(&v)?;
        let mut t = Vec::new();
        for j in 0..ncols {
            for i in 0..nrows {
                let x = v[j * nrows + i];
                if x != 0.0 {
                    t.push(Triplet::new(i, j, x));
                }
            }
        }
        SparseMat::try_new_from_triplets(nrows, ncols, &t)
            .map_err(|e| format!("cannot build the sparse matrix: {e:?}"))
    }
}
