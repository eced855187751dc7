//! Operator directories: the constrained frictional operator of one contact set as
//! Matrix Market files plus an optional index map, a README and a TOML summary.

use crate::mtx::{check_finite, io_err, read_mtx, read_square_with, write_mtx};
use crate::IoError;
use faer::sparse::SymbolicSparseColMat;
use squeal_core::operator::RealModePair;
use squeal_core::{FrictionalOperator, SparseMat};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// `M_c`, the mu-independent mass (kg). Required.
pub const FILE_MC: &str = "Mc.mtx";
/// `C_c`, the mu-independent damping (N s/m). Optional: absent means zero (undamped).
pub const FILE_CC: &str = "Cc.mtx";
/// `K_c`, the mu-independent stiffness (N/m). Required.
pub const FILE_KC: &str = "Kc.mtx";
/// `F_M`, the friction part of the mass. Optional: absent means zero.
pub const FILE_FM: &str = "FM.mtx";
/// `F_C`, the friction part of the damping. Optional: absent means zero.
pub const FILE_FC: &str = "FC.mtx";
/// `F_K`, the friction part of the stiffness. Optional: absent means zero.
pub const FILE_FK: &str = "FK.mtx";
/// The index map `T`, one 0-based integer per line. Optional.
pub const FILE_T: &str = "T.txt";
/// The friction load directions `U = T^T P~t^T` (`n x nA`, one column per active pair,
/// `F_X = U W_X^T`). Optional; with it an imported operator gets the low-rank
/// (Woodbury) solve path of large undamped problems, as the scene-built one does.
pub const FILE_U: &str = "U.mtx";
/// Human-readable description of the directory (written, never read).
pub const FILE_README: &str = "README.txt";
/// Machine-readable summary (written, never read by [`read_operator_dir`]).
pub const FILE_META: &str = "operator.toml";

/// What [`write_operator_dir`] records about an operator besides its matrices.
///
/// Everything here is text chosen by the caller; nothing is dated, so writing the same
/// operator twice gives identical files.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct OperatorMeta {
    /// Scene (model) name.
    pub scene: String,
    /// Friction coefficient of the equilibrium the contact set was computed at. The
    /// stored operator itself is mu-independent (`X~ = X_c - mu F_X` for any mu).
    pub mu: f64,
    /// Number of contact pairs in the active set (bilateral, sliding).
    pub active_pairs: usize,
    /// What produced the operator (program, version, methods), free text.
    pub source: String,
}

fn zero(n: usize) -> SparseMat {
    SparseMat::new(
        SymbolicSparseColMat::new_checked(n, n, vec![0; n + 1], None, Vec::new()),
        Vec::new(),
    )
}

/// Reads an operator directory written by [`write_operator_dir`] (or by hand).
///
/// `Mc.mtx` and `Kc.mtx` are required; `Cc.mtx`, `FM.mtx`, `FC.mtx`, `FK.mtx` are optional
/// and an absent one means zero (`cc`/`fc` become `None`, `fm`/`fk` empty matrices). All
/// matrices must be square and of the size of `Mc.mtx`. An optional `T.txt` gives the
/// index map `t` (see [`read_index_map`]). `README.txt` and `operator.toml` are not read.
///
/// # Errors
/// [`IoError::Missing`] for a missing directory, `Mc.mtx` or `Kc.mtx`; the errors of
/// [`crate::read_mtx`]; [`IoError::Shape`] naming the file whose size differs;
/// [`IoError::IndexMap`] for an invalid `T.txt`.
pub fn read_operator_dir(dir: impl AsRef<Path>) -> Result<FrictionalOperator, IoError> {
    let dir = dir.as_ref();
    if !dir.is_dir() {
        return Err(IoError::Missing {
            file: dir.to_path_buf(),
            expected: format!("an operator directory holding at least {FILE_MC} and {FILE_KC}"),
        });
    }
    let required = |name: &str, what: &str| -> Result<PathBuf, IoError> {
        let p = dir.join(name);
        if p.exists() {
            Ok(p)
        } else {
            Err(IoError::Missing {
                file: p,
                expected: format!("{what} in Matrix Market format (required)"),
            })
        }
    };
    let mc_path = required(FILE_MC, "the mass M_c (kg)")?;
    let mc = read_square_with(&mc_path, None, "a square matrix")?;
    let n = mc.nrows();
    let like = format!("{n} x {n} like {FILE_MC}");
    let kc = read_square_with(
        &required(FILE_KC, "the stiffness K_c (N/m)")?,
        Some(n),
        &like,
    )?;
    let optional = |name: &str| -> Result<Option<SparseMat>, IoError> {
        let p = dir.join(name);
        if p.exists() {
            read_square_with(&p, Some(n), &like).map(Some)
        } else {
            Ok(None)
        }
    };
    let cc = optional(FILE_CC)?;
    let fm = optional(FILE_FM)?.unwrap_or_else(|| zero(n));
    let fc = optional(FILE_FC)?;
    let fk = optional(FILE_FK)?.unwrap_or_else(|| zero(n));
    let t_path = dir.join(FILE_T);
    let t = if t_path.exists() {
        Some(read_index_map(&t_path, n)?)
    } else {
        None
    };
    let u_path = dir.join(FILE_U);
    let friction_loads = if u_path.exists() {
        let u = read_mtx(&u_path)?;
        if u.nrows() != n {
            return Err(IoError::Shape {
                file: u_path,
                nrows: u.nrows(),
                ncols: u.ncols(),
                expected: format!("{n} x nA like {FILE_MC} (one column per active contact pair)"),
            });
        }
        Some(u)
    } else {
        None
    };
    Ok(FrictionalOperator {
        mc,
        cc,
        kc,
        fm,
        fc,
        fk,
        t,
        friction_loads,
        modal: RealModePair::lazy(
            None,
            None,
            format!(
                "symmetric parts of {FILE_KC} and {FILE_MC} in {}",
                dir.display()
            ),
        ),
    })
}

/// Checks an index map against the operator size: `(line of the culprit, problem,
/// expectation)` on failure.
fn validate_index_map(t: &[usize], dim: usize) -> Result<(), (Option<usize>, String, String)> {
    if let Some((k, &j)) = t.iter().enumerate().find(|(_, &j)| j >= dim) {
        return Err((
            Some(k + 1),
            format!("entry {k} maps to constrained DOF {j}, outside the operator"),
            format!("0-based indices below the operator size {dim}"),
        ));
    }
    if t.len() < dim {
        return Err((
            None,
            format!(
                "the map has {} entries for an operator of size {dim}",
                t.len()
            ),
            format!("at least {dim} entries, one per unconstrained DOF"),
        ));
    }
    let mut hit = vec![false; dim];
    for &j in t {
        hit[j] = true;
    }
    if let Some(j) = hit.iter().position(|h| !h) {
        return Err((
            None,
            format!("constrained DOF {j} is the image of no unconstrained DOF"),
            format!("every index 0..{dim} to appear at least once (T of full column rank)"),
        ));
    }
    Ok(())
}

/// Reads an index map `T`: one 0-based integer per line, line `k + 1` holding the
/// constrained DOF that unconstrained DOF `k` maps to. Blank lines and lines starting
/// with `#` are skipped.
///
/// Valid iff every entry is below `dim`, there are at least `dim` entries, and every
/// constrained DOF `0..dim` is the image of some entry.
///
/// # Errors
/// [`IoError::Io`] if unreadable; [`IoError::IndexMap`] naming the line of a non-integer or
/// out-of-range entry, or the defect of the whole map.
pub fn read_index_map(path: impl AsRef<Path>, dim: usize) -> Result<Vec<usize>, IoError> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|e| io_err(path, "read", e))?;
    let mut t = Vec::new();
    let mut lines = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let s = line.trim();
        if s.is_empty() || s.starts_with('#') {
            continue;
        }
        let j: usize = s.parse().map_err(|_| IoError::IndexMap {
            file: path.to_path_buf(),
            line: Some(k + 1),
            problem: format!("`{s}` is not a non-negative integer"),
            expected: "one 0-based constrained DOF index per line".into(),
        })?;
        t.push(j);
        lines.push(k + 1);
    }
    validate_index_map(&t, dim).map_err(|(entry_line, problem, expected)| IoError::IndexMap {
        file: path.to_path_buf(),
        // `validate_index_map` counts entries; report the file's line.
        line: entry_line.map(|e| lines[e - 1]),
        problem,
        expected,
    })?;
    Ok(t)
}

/// Writes an index map, one 0-based integer per line (see [`read_index_map`]).
///
/// # Errors
/// [`IoError::Io`] if the file cannot be written.
pub fn write_index_map(path: impl AsRef<Path>, t: &[usize]) -> Result<(), IoError> {
    let path = path.as_ref();
    let mut s = String::with_capacity(8 * t.len());
    for j in t {
        writeln!(s, "{j}").expect("writing to a String");
    }
    std::fs::write(path, s).map_err(|e| io_err(path, "write", e))
}

/// True when `m` stores at least one nonzero value.
fn has_nonzero(m: &SparseMat) -> bool {
    (0..m.ncols()).any(|j| m.val_of_col(j).iter().any(|&v| v != 0.0))
}

/// A TOML basic string.
fn toml_str(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\t' => out.push_str("\\t"),
            '\r' => out.push_str("\\r"),
            c if c.is_control() => write!(out, "\\u{:04X}", c as u32).expect("String"),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// Writes `op` into `dir` (created if needed) as an operator directory that
/// [`read_operator_dir`] reads back bit-identically.
///
/// Files: `Mc.mtx` and `Kc.mtx` always; `Cc.mtx` and `FC.mtx` when `cc`/`fc` are `Some`;
/// `FM.mtx` and `FK.mtx` when they hold a nonzero value (absent means zero); `T.txt` when
/// `t` is `Some`; `README.txt` (files, sign and eigen conventions, units, `meta`) and
/// `operator.toml` (dofs, units, source, has_damping, ...). Optional files of an earlier
/// export that this operator does not have are removed from `dir`, so that a re-export
/// never leaves a stale part behind. No file contains a date: output is reproducible.
///
/// Everything is checked before anything is written.
///
/// # Errors
/// [`IoError::Shape`] naming the file of a matrix that is not `dim x dim`;
/// [`IoError::NonFinite`] for a NaN/inf value; [`IoError::IndexMap`] for an invalid `t`;
/// [`IoError::Meta`] for a non-finite `meta.mu`; [`IoError::Io`] on write failure.
pub fn write_operator_dir(
    dir: impl AsRef<Path>,
    op: &FrictionalOperator,
    meta: &OperatorMeta,
) -> Result<(), IoError> {
    let dir = dir.as_ref();
    let n = op.dim();
    let parts: [(&str, Option<&SparseMat>, bool); 6] = [
        (FILE_MC, Some(&op.mc), true),
        (FILE_CC, op.cc.as_ref(), op.cc.is_some()),
        (FILE_KC, Some(&op.kc), true),
        (FILE_FM, Some(&op.fm), has_nonzero(&op.fm)),
        (FILE_FC, op.fc.as_ref(), op.fc.is_some()),
        (FILE_FK, Some(&op.fk), has_nonzero(&op.fk)),
    ];
    for (name, m, _) in &parts {
        let Some(m) = m else { continue };
        let file = dir.join(name);
        if m.nrows() != n || m.ncols() != n {
            return Err(IoError::Shape {
                file,
                nrows: m.nrows(),
                ncols: m.ncols(),
                expected: format!("{n} x {n}, the operator size (from K_c)"),
            });
        }
        check_finite(m, &file)?;
    }
    if let Some(u) = &op.friction_loads {
        let file = dir.join(FILE_U);
        if u.nrows() != n {
            return Err(IoError::Shape {
                file,
                nrows: u.nrows(),
                ncols: u.ncols(),
                expected: format!("{n} x nA, the operator size (from K_c) by the active pairs"),
            });
        }
        check_finite(u, &file)?;
    }
    if let Some(t) = &op.t {
        validate_index_map(t, n).map_err(|(line, problem, expected)| IoError::IndexMap {
            file: dir.join(FILE_T),
            line,
            problem,
            expected,
        })?;
    }
    if !meta.mu.is_finite() {
        return Err(IoError::Meta {
            file: dir.join(FILE_META),
            problem: format!(
                "mu = {} is not finite; expected a finite friction coefficient",
                meta.mu
            ),
        });
    }

    std::fs::create_dir_all(dir).map_err(|e| io_err(dir, "create directory", e))?;
    let describe = |name: &str| match name {
        FILE_MC => "M_c, mu-independent mass (kg)",
        FILE_CC => "C_c, mu-independent damping (N s/m)",
        FILE_KC => "K_c, mu-independent stiffness (N/m)",
        FILE_FM => "F_M, friction part of the mass (kg)",
        FILE_FC => "F_C, friction part of the damping (N s/m)",
        _ => "F_K, friction part of the stiffness (N/m)",
    };
    let mut written = Vec::new();
    for (name, m, present) in &parts {
        let file = dir.join(name);
        match m {
            Some(m) if *present => {
                let comment = format!(
                    "squeal constrained frictional operator: {}\n\
                     scene: {}\n\
                     X~ = X_c - mu F_X; (lambda^2 M~ + lambda C~ + K~) u = 0",
                    describe(name),
                    meta.scene
                );
                write_mtx(&file, m, &comment)?;
                written.push(*name);
            }
            _ => remove_stale(&file)?,
        }
    }
    let u_file = dir.join(FILE_U);
    match &op.friction_loads {
        Some(u) => {
            let comment = format!(
                "squeal constrained frictional operator: U, friction load directions \
                 (n x nA, F_X = U W_X^T)\nscene: {}",
                meta.scene
            );
            write_mtx(&u_file, u, &comment)?;
            written.push(FILE_U);
        }
        None => remove_stale(&u_file)?,
    }
    let t_file = dir.join(FILE_T);
    match &op.t {
        Some(t) => write_index_map(&t_file, t)?,
        None => remove_stale(&t_file)?,
    }

    let has_damping = op.cc.is_some() || op.fc.is_some();
    let readme = readme_text(op, meta, &written, has_damping);
    let readme_path = dir.join(FILE_README);
    std::fs::write(&readme_path, readme).map_err(|e| io_err(&readme_path, "write", e))?;

    let mut toml = String::new();
    let _ = writeln!(
        toml,
        "# squeal constrained frictional operator; see {FILE_README}"
    );
    let _ = writeln!(toml, "format = \"squeal-operator\"");
    let _ = writeln!(toml, "version = 1");
    let _ = writeln!(toml, "scene = {}", toml_str(&meta.scene));
    let _ = writeln!(toml, "source = {}", toml_str(&meta.source));
    let _ = writeln!(toml, "mu_export = {:?}", meta.mu);
    let _ = writeln!(toml, "dofs = {n}");
    let _ = writeln!(toml, "full_dofs = {}", op.full_dim());
    let _ = writeln!(toml, "active_pairs = {}", meta.active_pairs);
    let _ = writeln!(toml, "has_damping = {has_damping}");
    let _ = writeln!(toml, "has_index_map = {}", op.t.is_some());
    let _ = writeln!(toml, "units = \"SI\"");
    let _ = writeln!(
        toml,
        "units_detail = {{ mass = \"kg\", damping = \"N s/m\", stiffness = \"N/m\" }}"
    );
    let _ = writeln!(toml, "sign = \"X~ = X_c - mu F_X\"");
    let files: Vec<String> = written
        .iter()
        .copied()
        .chain(op.t.as_ref().map(|_| FILE_T))
        .map(toml_str)
        .collect();
    let _ = writeln!(toml, "files = [{}]", files.join(", "));
    let meta_path = dir.join(FILE_META);
    std::fs::write(&meta_path, toml).map_err(|e| io_err(&meta_path, "write", e))?;
    Ok(())
}

/// Removes a file of an earlier export; absent is fine.
fn remove_stale(file: &Path) -> Result<(), IoError> {
    match std::fs::remove_file(file) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(io_err(file, "remove stale file", e)),
    }
}

fn readme_text(
    op: &FrictionalOperator,
    meta: &OperatorMeta,
    written: &[&str],
    has_damping: bool,
) -> String {
    let n = op.dim();
    let mut s = String::new();
    let yes_no = |b: bool| if b { "present" } else { "absent (zero)" };
    let present = |name: &str| yes_no(written.contains(&name));
    let _ = write!(
        s,
        "squeal constrained frictional operator
=======================================

scene:         {scene}
source:        {source}
mu at export:  {mu:?} (friction coefficient of the equilibrium that fixed the contact set)
dofs:          {n} (constrained), {full} (unconstrained)
active pairs:  {pairs}
damping:       {damping}

Files (Matrix Market `coordinate real general`, 1-based indices, full precision;
scipy.io.mmread reads them):
  {mc:<13} M_c  mu-independent mass (kg)               required
  {kc:<13} K_c  mu-independent stiffness (N/m)         required
  {cc:<13} C_c  mu-independent damping (N s/m)         {cc_p}
  {fm:<13} F_M  friction part of the mass (kg)         {fm_p}
  {fc:<13} F_C  friction part of the damping (N s/m)   {fc_p}
  {fk:<13} F_K  friction part of the stiffness (N/m)   {fk_p}
  {u:<13} U    friction load directions, n x nA (F_X = U W_X^T)  {u_p}
  {t:<13} T    index map u = T u_c, 0-based: line k+1 holds the constrained DOF
                     of unconstrained DOF k; {t_p}
  {toml:<13} machine-readable summary of this README
An absent C or F file means that part is zero; only present parts are written\n(Cc.mtx, FC.mtx when the operator has them; FM.mtx, FK.mtx when nonzero).

Sign convention: the operator at friction coefficient mu is
  X~ = X_c - mu F_X   for X in {{M, C, K}}
(the stored parts do not depend on mu; a mu sweep at this contact set needs no
re-assembly).

Eigen convention: U = u exp(lambda t),
  (lambda^2 M~ + lambda C~ + K~) u = 0,
unstable iff Re(lambda) > 0; frequency f = Im(lambda) / (2 pi) in Hz.

Units: SI. Mass kg, damping N s/m, stiffness N/m, displacements m, time s.
",
        scene = meta.scene,
        source = meta.source,
        mu = meta.mu,
        full = op.full_dim(),
        pairs = meta.active_pairs,
        damping = if has_damping { "yes" } else { "no (C~ = 0)" },
        mc = FILE_MC,
        kc = FILE_KC,
        cc = FILE_CC,
        fm = FILE_FM,
        fc = FILE_FC,
        fk = FILE_FK,
        t = FILE_T,
        toml = FILE_META,
        cc_p = present(FILE_CC),
        fm_p = present(FILE_FM),
        fc_p = present(FILE_FC),
        fk_p = present(FILE_FK),
        u = FILE_U,
        u_p = if op.friction_loads.is_some() {
            "present (low-rank solve path)"
        } else {
            "absent"
        },
        t_p = if op.t.is_some() {
            "present"
        } else {
            "absent (the operator's DOFs are the full DOFs)"
        },
    );
    s
}
