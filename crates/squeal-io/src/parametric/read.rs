//! Reading an operator directory: its `operator.toml`, the components it names and
//! the terms of each part.

use super::*;

pub(super) fn perr(
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

pub(super) fn zero(n: usize) -> SparseMat {
    SparseMat::new(
        SymbolicSparseColMat::new_checked(n, n, vec![0; n + 1], None, Vec::new()),
        Vec::new(),
    )
}

/// Component sources, cached by (file, variable).
pub(super) struct Loader<'a> {
    pub(super) dir: &'a Path,
    pub(super) file: &'a Path,
    pub(super) components: BTreeMap<String, (PathBuf, Option<String>)>,
    pub(super) default_mat: Option<PathBuf>,
    pub(super) mats: BTreeMap<PathBuf, MatFile>,
    pub(super) cache: BTreeMap<(PathBuf, Option<String>), Arc<SparseMat>>,
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
pub(super) type Header = (Option<String>, Option<(f64, f64)>);

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
            modal: _,
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
            modal: None,
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
            parts[p] =
                Self::read_terms(file, part, v, parameter.as_deref(), &mut loader, &mut dim)?;
        }
        let modal = match t.get("modal") {
            None => None,
            Some(toml::Value::Table(tb)) => {
                for k in tb.keys() {
                    if k != "M" && k != "K" {
                        return Err(perr(
                            file,
                            format!("modal.{k}"),
                            "unknown key",
                            "M and K (the real-mode pair)",
                        ));
                    }
                }
                let mut pair: [Vec<Term>; 2] = Default::default();
                for (i, part) in ["M", "K"].iter().enumerate() {
                    let field = format!("modal.{part}");
                    let v = tb.get(*part).ok_or_else(|| {
                        perr(
                            file,
                            &field,
                            "missing",
                            "both M and K of the real-mode pair (e.g. M = [\"M\"], K = [\"K1\"])",
                        )
                    })?;
                    pair[i] = Self::read_terms(
                        file,
                        &field,
                        v,
                        parameter.as_deref(),
                        &mut loader,
                        &mut dim,
                    )?;
                }
                Some(pair)
            }
            Some(v) => {
                return Err(perr(
                    file,
                    "modal",
                    format!("{v}"),
                    "a table [modal] with M and K",
                ))
            }
        };
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
            modal,
            dim,
            friction_loads,
            t: None,
        })
    }

    /// The terms of the part `field` (a list of component names or `{ matrix, coeff }`
    /// tables), each component loaded and checked square of the common size `dim`
    /// (set by the first one).
    fn read_terms(
        file: &Path,
        field: &str,
        v: &toml::Value,
        parameter: Option<&str>,
        loader: &mut Loader<'_>,
        dim: &mut Option<(usize, String)>,
    ) -> Result<Vec<Term>, IoError> {
        let list = v.as_array().ok_or_else(|| {
            perr(
                file,
                field,
                "not a list",
                "a list of terms [\"A\", { matrix = \"B\", coeff = \"W^2\" }]",
            )
        })?;
        if list.is_empty() {
            return Err(perr(
                file,
                field,
                "empty list",
                "at least one term (omit an absent part)",
            ));
        }
        let mut out = Vec::with_capacity(list.len());
        for (i, item) in list.iter().enumerate() {
            let item_field = format!("{field}[{i}]");
            let (name, coeff_text, coeff) = Self::term(file, &item_field, item, parameter)?;
            let (a, source) = loader.load(&name)?;
            if dim.is_none() {
                *dim = Some((a.nrows(), source.clone()));
            }
            let (n, first) = dim.clone().expect("set above");
            if a.nrows() != n || a.ncols() != n {
                return Err(IoError::Shape {
                    file: PathBuf::from(&source),
                    nrows: a.nrows(),
                    ncols: a.ncols(),
                    expected: format!("{n} x {n} like {first} (component `{name}` of {field})"),
                });
            }
            out.push(Term {
                matrix: name,
                source,
                coeff_text,
                coeff,
                a,
            });
        }
        Ok(out)
    }
}
