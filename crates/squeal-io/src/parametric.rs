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

use crate::expr::Expr;
use crate::mat::MatFile;
use crate::mtx::read_mtx;
use crate::operator::{read_operator_dir, FILE_META};
use crate::IoError;
use faer::sparse::{SymbolicSparseColMat, Triplet};
use squeal_core::linalg::{add_scaled, norm1, Cholesky};
use squeal_core::{FrictionalOperator, SparseMat};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The `format` value of a parametric operator description.
pub const PARAMETRIC_FORMAT: &str = "squeal-parametric-operator";

/// The parts an `operator.toml` may define, in [`FrictionalOperator`] order.
pub const PARTS: [&str; 6] = ["M", "C", "K", "FM", "FC", "FK"];

const TOP_KEYS: [&str; 7] = [
    "format",
    "version",
    "parameter",
    "range",
    "mat",
    "components",
    "U",
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
    dim: usize,
    friction_loads: Option<SparseMat>,
    t: Option<Vec<usize>>,
}

fn perr(
    file: &Path,
    field: impl Into<String>,
    problem: impl Into<String>,
    expected: &str,
) -> IoError {
    IoError::Parametric {
        file: file.to_path_buf(),
        field: field.into(),
        problem: problem.into(),
        expected: expected.to_string(),
    }
}

fn zero(n: usize) -> SparseMat {
    SparseMat::new(
        SymbolicSparseColMat::new_checked(n, n, vec![0; n + 1], None, Vec::new()),
        Vec::new(),
    )
}

/// Component sources, cached by (file, variable).
struct Loader<'a> {
    dir: &'a Path,
    file: &'a Path,
    components: BTreeMap<String, (PathBuf, Option<String>)>,
    default_mat: Option<PathBuf>,
    mats: BTreeMap<PathBuf, MatFile>,
    cache: BTreeMap<(PathBuf, Option<String>), Arc<SparseMat>>,
}

impl Loader<'_> {
    /// `(file, variable)` of component `name` (module docs of `docs/operators.md`).
    fn locate(&self, name: &str) -> Result<(PathBuf, Option<String>), IoError> {
        if let Some(src) = self.components.get(name) {
            return Ok(src.clone());
        }
        let mtx = self.dir.join(format!("{name}.mtx"));
        if mtx.exists() {
            return Ok((mtx, None));
        }
        let mat = self.dir.join(format!("{name}.mat"));
        if mat.exists() {
            return Ok((mat, Some(name.to_string())));
        }
        if let Some(m) = &self.default_mat {
            return Ok((m.clone(), Some(name.to_string())));
        }
        Err(IoError::Missing {
            file: mtx,
            expected: format!(
                "component `{name}`: {name}.mtx or {name}.mat in the directory, an entry of \
                 [components] in {}, or a variable of the file named by `mat`",
                self.file.display()
            ),
        })
    }

    fn load(&mut self, name: &str) -> Result<(Arc<SparseMat>, String), IoError> {
        let (path, var) = self.locate(name)?;
        let source = match &var {
            Some(v) => format!("{}:{v}", path.display()),
            None => path.display().to_string(),
        };
        let key = (path.clone(), var.clone());
        if let Some(a) = self.cache.get(&key) {
            return Ok((a.clone(), source));
        }
        let a = match &var {
            None => read_mtx(&path)?,
            Some(v) => {
                if !self.mats.contains_key(&path) {
                    let m = MatFile::open(&path)?;
                    self.mats.insert(path.clone(), m);
                }
                self.mats[&path].matrix(v)?
            }
        };
        let a = Arc::new(a);
        self.cache.insert(key, a.clone());
        Ok((a, source))
    }
}

/// The parameter's name and its declared range, from an operator.toml.
type Header = (Option<String>, Option<(f64, f64)>);

impl ParametricOperator {
    /// Reads the operator directory `dir`: its `operator.toml` when that declares
    /// `format = "squeal-parametric-operator"`, else (no description, or the summary
    /// written by [`crate::write_operator_dir`]) the plain operator files as constant parts
    /// ([`read_operator_dir`]).
    ///
    /// # Errors
    /// [`IoError::Parametric`] naming the file and key of an invalid description (unknown
    /// key, bad formula, a name other than the parameter, a part without terms, a missing
    /// `M` or `K`, a bad range); [`IoError::Missing`] for a component that cannot be
    /// found; the errors of the Matrix Market and MAT readers; [`IoError::Shape`] for a
    /// component that is not square of the common size.
    pub fn read(dir: impl AsRef<Path>) -> Result<Self, IoError> {
        let dir = dir.as_ref();
        let file = dir.join(FILE_META);
        let text = match std::fs::read_to_string(&file) {
            Ok(t) => Some(t),
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => None,
            Err(e) => return Err(crate::mtx::io_err(&file, "read", e)),
        };
        let table: Option<toml::Table> = match &text {
            Some(t) => Some(t.parse().map_err(|e: toml::de::Error| {
                perr(
                    &file,
                    "toml",
                    e.message().to_string(),
                    "a valid TOML document",
                )
            })?),
            None => None,
        };
        let parametric = table
            .as_ref()
            .is_some_and(|t| t.get("format").and_then(|f| f.as_str()) == Some(PARAMETRIC_FORMAT));
        if !parametric {
            return Self::constant(dir, read_operator_dir(dir)?);
        }
        Self::from_table(dir, &file, &table.expect("parametric implies a table"))
    }

    /// A parameter-free operator from fixed parts.
    fn constant(dir: &Path, op: FrictionalOperator) -> Result<Self, IoError> {
        let term = |name: &str, a: SparseMat| Term {
            matrix: name.to_string(),
            source: dir.display().to_string(),
            coeff_text: "1".into(),
            coeff: Expr::constant(1.0),
            a: Arc::new(a),
        };
        let FrictionalOperator {
            mc,
            cc,
            kc,
            fm,
            fc,
            fk,
            t,
            friction_loads,
        } = op;
        let dim = mc.nrows();
        Ok(Self {
            file: dir.to_path_buf(),
            parameter: None,
            range: None,
            parts: [
                vec![term("Mc", mc)],
                cc.map(|c| vec![term("Cc", c)]).unwrap_or_default(),
                vec![term("Kc", kc)],
                vec![term("FM", fm)],
                fc.map(|c| vec![term("FC", c)]).unwrap_or_default(),
                vec![term("FK", fk)],
            ],
            dim,
            friction_loads,
            t,
        })
    }

    /// Checks the top-level keys and the version; returns the parameter's name and range.
    fn header(file: &Path, t: &toml::Table) -> Result<Header, IoError> {
        let expected_keys = format!("{} or a part {}", TOP_KEYS.join(", "), PARTS.join(", "));
        for k in t.keys() {
            if !TOP_KEYS.contains(&k.as_str()) && !PARTS.contains(&k.as_str()) {
                return Err(perr(file, k, "unknown key", &expected_keys));
            }
        }
        match t.get("version").map(|v| v.as_integer()) {
            None | Some(Some(1)) => {}
            Some(other) => {
                return Err(perr(file, "version", format!("{other:?}"), "version = 1"));
            }
        }
        let parameter = match t.get("parameter") {
            None => None,
            Some(toml::Value::String(s))
                if !s.is_empty()
                    && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
                    && !s.starts_with(|c: char| c.is_ascii_digit()) =>
            {
                Some(s.clone())
            }
            Some(v) => {
                return Err(perr(
                    file,
                    "parameter",
                    format!("{v}"),
                    "a name of letters, digits and `_` (e.g. \"W\")",
                ))
            }
        };
        let range = match t.get("range") {
            None => None,
            Some(v) => {
                let r: Option<Vec<f64>> = v.as_array().map(|a| {
                    a.iter()
                        .filter_map(|x| x.as_float().or_else(|| x.as_integer().map(|i| i as f64)))
                        .collect()
                });
                match r.as_deref() {
                    Some([lo, hi]) if lo.is_finite() && hi.is_finite() && lo <= hi => {
                        Some((*lo, *hi))
                    }
                    _ => {
                        return Err(perr(
                            file,
                            "range",
                            format!("{v}"),
                            "two numbers [lo, hi] with lo <= hi",
                        ))
                    }
                }
            }
        };
        if range.is_some() && parameter.is_none() {
            return Err(perr(
                file,
                "range",
                "given without a parameter",
                "`parameter` too",
            ));
        }
        Ok((parameter, range))
    }

    /// The `[components]` table: each component's file and variable.
    fn component_sources(
        dir: &Path,
        file: &Path,
        t: &toml::Table,
    ) -> Result<BTreeMap<String, (PathBuf, Option<String>)>, IoError> {
        let mut components = BTreeMap::new();
        if let Some(c) = t.get("components") {
            let c = c
                .as_table()
                .ok_or_else(|| perr(file, "components", "not a table", "[components]"))?;
            for (name, v) in c {
                let field = format!("components.{name}");
                let src = match v {
                    toml::Value::String(f) if f.ends_with(".mat") => {
                        (dir.join(f), Some(name.clone()))
                    }
                    toml::Value::String(f) => (dir.join(f), None),
                    toml::Value::Table(tb) => {
                        for k in tb.keys() {
                            if k != "file" && k != "variable" {
                                return Err(perr(
                                    file,
                                    &field,
                                    format!("unknown key `{k}`"),
                                    "file, variable",
                                ));
                            }
                        }
                        let f = tb.get("file").and_then(|f| f.as_str()).ok_or_else(|| {
                            perr(
                                file,
                                &field,
                                "no `file`",
                                "{ file = \"x.mat\", variable = \"K\" }",
                            )
                        })?;
                        let var = match tb.get("variable") {
                            None if f.ends_with(".mat") => Some(name.clone()),
                            None => None,
                            Some(toml::Value::String(s)) => Some(s.clone()),
                            Some(v) => {
                                return Err(perr(
                                    file,
                                    &field,
                                    format!("variable = {v}"),
                                    "a string",
                                ))
                            }
                        };
                        (dir.join(f), var)
                    }
                    other => {
                        return Err(perr(
                            file,
                            &field,
                            format!("{other}"),
                            "a file name or { file = ..., variable = ... }",
                        ))
                    }
                };
                components.insert(name.clone(), src);
            }
        }
        Ok(components)
    }

    /// One term of a part, `field` in messages: its component name, its coefficient as
    /// written and parsed.
    fn term(
        file: &Path,
        field: &str,
        item: &toml::Value,
        parameter: Option<&str>,
    ) -> Result<(String, String, Expr), IoError> {
        let (name, coeff_text) = match item {
            toml::Value::String(s) => (s.clone(), "1".to_string()),
            toml::Value::Table(tb) => {
                for k in tb.keys() {
                    if k != "matrix" && k != "coeff" {
                        return Err(perr(
                            file,
                            field,
                            format!("unknown key `{k}`"),
                            "matrix, coeff",
                        ));
                    }
                }
                let name = tb.get("matrix").and_then(|m| m.as_str()).ok_or_else(|| {
                    perr(
                        file,
                        field,
                        "no `matrix`",
                        "{ matrix = \"KGeo\", coeff = \"W^2\" }",
                    )
                })?;
                let coeff = match tb.get("coeff") {
                    None => "1".to_string(),
                    Some(toml::Value::String(s)) => s.clone(),
                    Some(toml::Value::Float(x)) => format!("{x:?}"),
                    Some(toml::Value::Integer(x)) => format!("{x}"),
                    Some(v) => {
                        return Err(perr(
                            file,
                            format!("{field}.coeff"),
                            format!("{v}"),
                            "a number or a formula string",
                        ))
                    }
                };
                (name.to_string(), coeff)
            }
            other => {
                return Err(perr(
                    file,
                    field,
                    format!("{other}"),
                    "a component name or { matrix = ..., coeff = ... }",
                ))
            }
        };
        let coeff = Expr::parse(&coeff_text, parameter).map_err(|e| {
            perr(
                file,
                format!("{field}.coeff"),
                e,
                "a formula of numbers, + - * / ^, ( ) and the parameter",
            )
        })?;
        Ok((name, coeff_text, coeff))
    }

    fn from_table(dir: &Path, file: &Path, t: &toml::Table) -> Result<Self, IoError> {
        let (parameter, range) = Self::header(file, t)?;
        let default_mat = match t.get("mat") {
            None => None,
            Some(toml::Value::String(s)) => Some(dir.join(s)),
            Some(v) => return Err(perr(file, "mat", format!("{v}"), "a file name (string)")),
        };
        let components = Self::component_sources(dir, file, t)?;
        let mut loader = Loader {
            dir,
            file,
            components,
            default_mat,
            mats: BTreeMap::new(),
            cache: BTreeMap::new(),
        };
        let mut parts: [Vec<Term>; 6] = Default::default();
        let mut dim: Option<(usize, String)> = None;
        for (p, part) in PARTS.iter().enumerate() {
            let Some(v) = t.get(*part) else {
                if *part == "M" || *part == "K" {
                    return Err(perr(file, *part, "missing", "a list of terms for M and K"));
                }
                continue;
            };
            let list = v.as_array().ok_or_else(|| {
                perr(
                    file,
                    *part,
                    "not a list",
                    "a list of terms [\"A\", { matrix = \"B\", coeff = \"W^2\" }]",
                )
            })?;
            if list.is_empty() {
                return Err(perr(
                    file,
                    *part,
                    "empty list",
                    "at least one term (omit an absent part)",
                ));
            }
            for (i, item) in list.iter().enumerate() {
                let field = format!("{part}[{i}]");
                let (name, coeff_text, coeff) =
                    Self::term(file, &field, item, parameter.as_deref())?;
                let (a, source) = loader.load(&name)?;
                if dim.is_none() {
                    dim = Some((a.nrows(), source.clone()));
                }
                let (n, first) = dim.clone().expect("set above");
                if a.nrows() != n || a.ncols() != n {
                    return Err(IoError::Shape {
                        file: PathBuf::from(&source),
                        nrows: a.nrows(),
                        ncols: a.ncols(),
                        expected: format!("{n} x {n} like {first} (component `{name}` of {part})"),
                    });
                }
                parts[p].push(Term {
                    matrix: name,
                    source,
                    coeff_text,
                    coeff,
                    a,
                });
            }
        }
        let (dim, _) = dim.expect("M is required");
        let friction_loads = match t.get("U") {
            None => None,
            Some(toml::Value::String(name)) => {
                let (u, source) = loader.load(name)?;
                if u.nrows() != dim {
                    return Err(IoError::Shape {
                        file: PathBuf::from(source),
                        nrows: u.nrows(),
                        ncols: u.ncols(),
                        expected: format!("{dim} x nA (friction load directions)"),
                    });
                }
                Some((*u).clone())
            }
            Some(v) => return Err(perr(file, "U", format!("{v}"), "a component name")),
        };
        Ok(Self {
            file: file.to_path_buf(),
            parameter,
            range,
            parts,
            dim,
            friction_loads,
            t: None,
        })
    }

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
            if terms.is_empty() {
                continue;
            }
            let mut acc = zero(n);
            for (i, term) in terms.iter().enumerate() {
                let c = term.coeff(value);
                if !c.is_finite() {
                    return Err(perr(
                        &self.file,
                        format!("{}[{i}].coeff", PARTS[p]),
                        format!(
                            "`{}` of `{}` is {c} at {name} = {value}",
                            term.coeff_text, term.matrix
                        ),
                        "a finite coefficient at this value",
                    ));
                }
                acc = add_scaled(acc.as_ref(), 1.0, term.a.as_ref().as_ref(), c).map_err(|e| {
                    perr(
                        &self.file,
                        PARTS[p],
                        e.to_string(),
                        "components of one size",
                    )
                })?;
            }
            out[p] = Some(acc);
        }
        let [m, c, k, fm, fc, fk] = out;
        let m = m.expect("M is required");
        self.check_mass(&m, value)?;
        Ok(FrictionalOperator {
            mc: m,
            cc: c,
            kc: k.expect("K is required"),
            fm: fm.unwrap_or_else(|| zero(n)),
            fc,
            fk: fk.unwrap_or_else(|| zero(n)),
            t: self.t.clone(),
            friction_loads: self.friction_loads.clone(),
        })
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
