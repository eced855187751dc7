//! # squeal-io
//!
//! Files that carry a frictional operator in and out of squeal.
//!
//! - [`read_mtx`], [`read_square_mtx`], [`write_mtx`]: Matrix Market
//!   `coordinate real general|symmetric` (reading also accepts `integer`), written with the
//!   banner SciPy's `scipy.io.mmread` expects, 1-based indices and `{:.17e}` values, so a
//!   write/read round trip is bit-identical.
//! - [`read_operator_dir`], [`write_operator_dir`]: a directory holding the constrained
//!   operator of one contact set, `Mc.mtx`, `Cc.mtx`, `Kc.mtx`, `FM.mtx`, `FC.mtx`,
//!   `FK.mtx` and the optional index map `T.txt`; the operator at friction coefficient mu
//!   is `X~ = X_c - mu F_X` (see [`squeal_core::FrictionalOperator`]).
//!
//! - [`read_msh`], [`write_msh`]: Gmsh MSH 4.1 ASCII meshes of 8-node hexahedra, physical
//!   groups becoming named node sets (see [`gmsh`]).
//! - [`read_mat`], [`MatFile`]: real sparse and dense matrices of MATLAB Level 5 MAT-files
//!   (`save -v7`, `scipy.io.savemat`), compressed or not (see [`mat`]).
//! - [`ParametricOperator`]: an operator directory whose `operator.toml` defines `M`, `C`,
//!   `K` and the friction parts as sums of `.mtx`/`.mat` components with coefficients
//!   that are formulas of one parameter ([`expr`]); `.at(value)` gives the
//!   [`squeal_core::FrictionalOperator`] (format in `docs/operators.md`).
//!
//! Every error ([`IoError`]) names the file, the line where one applies, and what was
//! expected. Units are SI (kg, N s/m, N/m).
//!
//! The reader is hand-written rather than `sprs::io::read_matrix_market` (sprs 0.11):
//! sprs panics on an out-of-range index, silently accepts NaN/inf and surplus entries, and
//! reports every other defect as a bare "Bad matrix market file" without file or line.
#![doc(html_no_source)]

mod error;
pub mod expr;
pub mod gmsh;
pub mod mat;
mod mtx;
mod operator;
pub mod parametric;

pub use error::IoError;
pub use gmsh::{msh_string, read_msh, read_msh_bytes, write_msh, VOLUME_GROUP};
pub use mat::{read_mat, MatFile};
pub use mtx::{read_mtx, read_mtx_from, read_square_mtx, write_mtx, write_mtx_to};
pub use operator::{
    read_index_map, read_operator_dir, write_index_map, write_operator_dir, OperatorMeta, FILE_CC,
    FILE_FC, FILE_FK, FILE_FM, FILE_KC, FILE_MC, FILE_META, FILE_README, FILE_T,
};
pub use parametric::{ParametricOperator, PARAMETRIC_FORMAT};
