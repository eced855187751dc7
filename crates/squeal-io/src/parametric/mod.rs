//! Parametric operators: `M`, `C`, `K` (and the friction parts `FM`, `FC`, `FK`) as sums
//! of component matrices with coefficients that are formulas of one named parameter,
//! described by an `operator.toml` (format in `docs/operators.md`):
//!
//! ```toml
//! format = "squeal-parametric-operator"
//! version = 1
//! parameter = "W"
//! M = ["M"]
//! C = [{ matrix = "D1" }, { matrix = "DR", coeff = "1/W" }, { matrix = "DG", coeff = "W" }]
//! K = ["K1", "KR", { matrix = "KGeo", coeff = "W^2" }]
//! FK = ["FK"]
//! ```
//!
//! [`ParametricOperator::at`] forms the [`FrictionalOperator`] at one value of the
//! parameter; mu still applies on top through the friction parts
//! (`X~ = X(W) - mu F_X(W)`). Components may be non-symmetric or skew (gyroscopic,
//! circulatory); the mass is checked at every value: the symmetric part of `M` must be
//! positive definite (a singular or indefinite mass is an error).

mod read;

use read::{perr, zero};

use crate::expr::Expr;
use crate::mat::MatFile;
use crate::mtx::read_mtx;
use crate::operator::{read_operator_dir, FILE_META};
use crate::IoError;
use faer::sparse::{SymbolicSparseColMat, Triplet};
use squeal_core::linalg::{add_scaled, norm1, Cholesky};
use squeal_core::operator::RealModePair;
use squeal_core::{FrictionalOperator, SparseMat};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The `format` value of a parametric operator description.
pub const PARAMETRIC_FORMAT: &str = "squeal-parametric-operator";

/// The parts an `operator.toml` may define, in [`FrictionalOperator`] order.
pub const PARTS: [&str; 6] = ["M", "C", "K", "FM", "FC", "FK"];

const TOP_KEYS: [&str; 8] = [
    "format",
    "version",
    "parameter",
    "range",
    "mat",
    "components",
    "U",
    "modal",
];

/// Relative size of the smallest eigenvalue of the symmetric part of `M` (against
/// `||M||_1`) below which the mass counts as singular.
pub const SINGULAR_MASS_REL: f64 = 1e-12;

/// One term `coeff(p) * A` of a part.
#[derive(Debug, Clone)]
pub struct Term {
    /// Component name.
    pub matrix: String,
    /// Where it was read from.
    pub source: String,
    /// The coefficient formula as written.
    pub coeff_text: String,
    coeff: Expr,
    a: Arc<SparseMat>,
}

impl Term {
    /// The coefficient at `value`.
    pub fn coeff(&self, value: f64) -> f64 {
        self.coeff.eval(value)
    }
    /// The component matrix.
    pub fn matrix(&self) -> &SparseMat {
        &self.a
    }
}

/// An operator whose parts depend on one parameter (see the module docs).
#[derive(Debug, Clone)]
pub struct ParametricOperator {
    file: PathBuf,
    parameter: Option<String>,
    range: Option<(f64, f64)>,
    parts: [Vec<Term>; 6],
    /// The real-mode pair `[M, K]` of `[modal]`, when the description names one.
    modal: Option<[Vec<Term>; 2]>,
    dim: usize,
    friction_loads: Option<SparseMat>,
    t: Option<Vec<usize>>,
}

impl ParametricOperator {
    /// The parameter's name (`None` for a constant operator).
    pub fn parameter(&self) -> Option<&str> {
        self.parameter.as_deref()
    }

    /// The declared range of the parameter, if any.
    pub fn range(&self) -> Option<(f64, f64)> {
        self.range
    }

    /// Size of the operator.
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// The terms of a part (`"M"`, `"C"`, `"K"`, `"FM"`, `"FC"`, `"FK"`); empty when the
    /// part is absent or the name unknown.
    pub fn terms(&self, part: &str) -> &[Term] {
        PARTS
            .iter()
            .position(|p| *p == part)
            .map_or(&[], |i| &self.parts[i])
    }

    /// The operator at `parameter = value`: every part `sum coeff_i(value) A_i` (absent
    /// `C`, `FC`: `None`; absent `FM`, `FK`: zero), the optional friction loads `U`, no
    /// index map. Apply mu with [`FrictionalOperator::at`].
    ///
    /// # Errors
    /// [`IoError::Parametric`] for a non-finite value, a value outside the declared range,
    /// a coefficient that is not finite there (e.g. `1/W` at `W = 0`), or a mass whose
    /// symmetric part is not positive definite (indefinite, or singular to
    /// [`SINGULAR_MASS_REL`]).
    pub fn at(&self, value: f64) -> Result<FrictionalOperator, IoError> {
        let name = self.parameter.as_deref().unwrap_or("parameter");
        if !value.is_finite() {
            return Err(perr(
                &self.file,
                name,
                format!("value {value}"),
                "a finite number",
            ));
        }
        if let Some((lo, hi)) = self.range {
            if value < lo || value > hi {
                return Err(perr(
                    &self.file,
                    name,
                    format!("{name} = {value} is outside the declared range"),
                    &format!("{lo} <= {name} <= {hi}"),
                ));
            }
        }
        let n = self.dim;
        let mut out: [Option<SparseMat>; 6] = Default::default();
        for (p, terms) in self.parts.iter().enumerate() {
            if !terms.is_empty() {
                out[p] = Some(self.sum(terms, PARTS[p], value)?);
            }
        }
        let [m, c, k, fm, fc, fk] = out;
        let m = m.expect("M is required");
        self.check_mass(&m, value)?;
        let at = match &self.parameter {
            Some(name) => format!(" at {name} = {value}"),
            None => String::new(),
        };
        let modal = match &self.modal {
            Some([pm, pk]) => {
                let names = |terms: &[Term]| {
                    terms
                        .iter()
                        .map(|t| match t.coeff_text.as_str() {
                            "1" => t.matrix.clone(),
                            c => format!("({c}) {}", t.matrix),
                        })
                        .collect::<Vec<_>>()
                        .join(" + ")
                };
                RealModePair::lazy(
                    Some(self.sum(pk, "modal.K", value)?),
                    Some(self.sum(pm, "modal.M", value)?),
                    format!(
                        "[modal] of {}: K = {}, M = {}{at}",
                        self.file.display(),
                        names(pk),
                        names(pm)
                    ),
                )
            }
            None => RealModePair::lazy(
                None,
                None,
                format!(
                    "symmetric parts of K and M of {}{at} (no [modal] pair given)",
                    self.file.display()
                ),
            ),
        };
        Ok(FrictionalOperator {
            mc: m,
            cc: c,
            kc: k.expect("K is required"),
            fm: fm.unwrap_or_else(|| zero(n)),
            fc,
            fk: fk.unwrap_or_else(|| zero(n)),
            t: self.t.clone(),
            friction_loads: self.friction_loads.clone(),
            modal,
        })
    }

    /// `sum coeff_i(value) A_i` of the terms of the part `field`.
    fn sum(&self, terms: &[Term], field: &str, value: f64) -> Result<SparseMat, IoError> {
        let name = self.parameter.as_deref().unwrap_or("parameter");
        let mut acc = zero(self.dim);
        for (i, term) in terms.iter().enumerate() {
            let c = term.coeff(value);
            if !c.is_finite() {
                return Err(perr(
                    &self.file,
                    format!("{field}[{i}].coeff"),
                    format!(
                        "`{}` of `{}` is {c} at {name} = {value}",
                        term.coeff_text, term.matrix
                    ),
                    "a finite coefficient at this value",
                ));
            }
            acc = add_scaled(acc.as_ref(), 1.0, term.a.as_ref().as_ref(), c)
                .map_err(|e| perr(&self.file, field, e.to_string(), "components of one size"))?;
        }
        Ok(acc)
    }

    /// The symmetric part of `M` must be positive definite: a sparse Cholesky (fails on
    /// an indefinite matrix), then 20 steps of inverse iteration for the smallest
    /// eigenvalue (a positive semi-definite singular mass can pass the factorization with
    /// a tiny pivot).
    fn check_mass(&self, m: &SparseMat, value: f64) -> Result<(), IoError> {
        let n = m.nrows();
        let name = self.parameter.as_deref().unwrap_or("parameter");
        let at = if self.parameter.is_some() {
            format!(" at {name} = {value}")
        } else {
            String::new()
        };
        let mut t = Vec::with_capacity(2 * m.compute_nnz());
        for j in 0..n {
            for (i, v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
                t.push(Triplet::new(i, j, 0.5 * v));
                t.push(Triplet::new(j, i, 0.5 * v));
            }
        }
        let ms = SparseMat::try_new_from_triplets(n, n, &t)
            .map_err(|e| perr(&self.file, "M", format!("{e:?}"), "a valid sparse matrix"))?;
        let scale = norm1(ms.as_ref());
        let expected = "a mass whose symmetric part is positive definite";
        if scale == 0.0 {
            return Err(perr(
                &self.file,
                "M",
                format!("the mass is zero{at}"),
                expected,
            ));
        }
        let chol = Cholesky::new(ms.as_ref(), "M").map_err(|_| {
            perr(
                &self.file,
                "M",
                format!(
                    "the mass is indefinite or singular{at} (its Cholesky factorization fails)"
                ),
                expected,
            )
        })?;
        let mut x: Vec<f64> = (0..n)
            .map(|i| 1.0 + 0.37 * (i as f64 * 1.3).sin())
            .collect();
        let mut lmin = f64::INFINITY;
        for _ in 0..20 {
            let nx = x.iter().map(|v| v * v).sum::<f64>().sqrt();
            x.iter_mut().for_each(|v| *v /= nx);
            let mut y = x.clone();
            chol.solve_vec_in_place(&mut y);
            let ny = y.iter().map(|v| v * v).sum::<f64>().sqrt();
            if !(ny.is_finite() && ny > 0.0) {
                lmin = 0.0;
                break;
            }
            lmin = 1.0 / ny;
            x = y;
        }
        if lmin <= SINGULAR_MASS_REL * scale {
            return Err(perr(
                &self.file,
                "M",
                format!(
                    "the mass is numerically singular{at}: smallest eigenvalue of its \
                     symmetric part about {lmin:.3e} against ||M||_1 = {scale:.3e} \
                     (massless DOFs?)"
                ),
                expected,
            ));
        }
        Ok(())
    }
}
