//! The unconstrained ("full") form of an operator on disk: `M.mtx`, `K.mtx`, optional
//! `C.mtx` (free DOFs, symmetric) and `pairs.csv`, the contact data. Reading it builds
//! the constrained operator with [`build_operator`], the same code
//! path as a scene, so a model assembled elsewhere runs through every solver.
//!
//! `pairs.csv` columns (one row per candidate pair, DOF indices 0-based into the
//! matrices): `pin_dof_x, pin_dof_y, pin_dof_z, disc_dof_x, disc_dof_y, disc_dof_z, x_m,
//! y_m, nx, ny, nz, ex, ey, ez, active`. Normals must be `+e_z` (flat disc face, from the
//! disc into the pin); `(ex, ey, ez)` is the unit sliding direction of the pair (the
//! disc's surface velocity there); `active` is 1 for pairs of the effective contact set.

use crate::{build_operator, ContactError, ContactSet, Result};
use squeal_core::{FrictionalOperator, SparseMat};
use std::fmt::Write as _;
use std::path::Path;

/// File names of the full form.
pub const FILE_M: &str = "M.mtx";
/// Stiffness file.
pub const FILE_K: &str = "K.mtx";
/// Damping file (optional).
pub const FILE_C: &str = "C.mtx";
/// Contact data file.
pub const FILE_PAIRS: &str = "pairs.csv";

const HEADER: &str = "pin_dof_x,pin_dof_y,pin_dof_z,disc_dof_x,disc_dof_y,disc_dof_z,x_m,y_m,nx,ny,nz,ex,ey,ez,active";

fn io(e: squeal_io::IoError) -> ContactError {
    ContactError::Core(e.into())
}

/// Writes the full form of `set` with the active mask `active` and matrices `m`, `c`, `k`.
pub fn write_full_form(
    dir: &Path,
    m: &SparseMat,
    c: Option<&SparseMat>,
    k: &SparseMat,
    set: &ContactSet,
    active: &[bool],
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|e| ContactError::Setup {
        field: dir.display().to_string(),
        message: format!("cannot create the directory: {e}"),
    })?;
    squeal_io::write_mtx(
        dir.join(FILE_M),
        m,
        "squeal full-form mass matrix (kg), free DOFs",
    )
    .map_err(io)?;
    squeal_io::write_mtx(
        dir.join(FILE_K),
        k,
        "squeal full-form stiffness matrix (N/m), free DOFs",
    )
    .map_err(io)?;
    if let Some(c) = c {
        squeal_io::write_mtx(
            dir.join(FILE_C),
            c,
            "squeal full-form damping matrix (N s/m)",
        )
        .map_err(io)?;
    }
    let mut s = String::from(HEADER);
    s.push('\n');
    for i in 0..set.len() {
        let (p, d, e) = (set.pin_dofs[i], set.disc_dofs[i], set.direction[i]);
        let _ = writeln!(
            s,
            "{},{},{},{},{},{},{:.17e},{:.17e},0,0,1,{:.17e},{:.17e},{:.17e},{}",
            p[0],
            p[1],
            p[2],
            d[0],
            d[1],
            d[2],
            set.xy[i][0],
            set.xy[i][1],
            e[0],
            e[1],
            e[2],
            u8::from(active[i])
        );
    }
    std::fs::write(dir.join(FILE_PAIRS), s).map_err(|e| ContactError::Setup {
        field: dir.join(FILE_PAIRS).display().to_string(),
        message: format!("cannot write: {e}"),
    })
}

/// Whether `dir` holds a full form.
pub fn is_full_form(dir: &Path) -> bool {
    dir.join(FILE_M).is_file() && dir.join(FILE_K).is_file() && dir.join(FILE_PAIRS).is_file()
}

/// Reads a full form and builds its constrained operator.
pub fn read_full_form(dir: &Path) -> Result<FrictionalOperator> {
    let m = squeal_io::read_square_mtx(dir.join(FILE_M), None).map_err(io)?;
    let n = m.nrows();
    let k = squeal_io::read_square_mtx(dir.join(FILE_K), Some(n)).map_err(io)?;
    let c = if dir.join(FILE_C).is_file() {
        Some(squeal_io::read_square_mtx(dir.join(FILE_C), Some(n)).map_err(io)?)
    } else {
        None
    };
    let path = dir.join(FILE_PAIRS);
    let name = path.display().to_string();
    let bad = |line: usize, message: String| ContactError::Setup {
        field: format!("{name}:{line}"),
        message,
    };
    let text = std::fs::read_to_string(&path).map_err(|e| bad(0, format!("cannot read: {e}")))?;
    let mut lines = text.lines().enumerate();
    match lines.next() {
        Some((_, h)) if h.trim() == HEADER => {}
        _ => return Err(bad(1, format!("expected the header `{HEADER}`"))),
    }
    let (mut xy, mut pin, mut disc, mut dir_e, mut active) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (l, line) in lines {
        let line_no = l + 1;
        if line.trim().is_empty() {
            continue;
        }
        let f: Vec<&str> = line.split(',').map(str::trim).collect();
        if f.len() != 15 {
            return Err(bad(line_no, format!("expected 15 fields, got {}", f.len())));
        }
        let int = |s: &str| -> Result<usize> {
            let v: usize = s
                .parse()
                .map_err(|_| bad(line_no, format!("`{s}` is not a DOF index")))?;
            if v >= n {
                return Err(bad(
                    line_no,
                    format!("DOF {v} out of range: the matrices are {n} x {n}"),
                ));
            }
            Ok(v)
        };
        let num = |s: &str| -> Result<f64> {
            let v: f64 = s
                .parse()
                .map_err(|_| bad(line_no, format!("`{s}` is not a number")))?;
            if !v.is_finite() {
                return Err(bad(line_no, format!("`{s}` is not finite")));
            }
            Ok(v)
        };
        pin.push([int(f[0])?, int(f[1])?, int(f[2])?]);
        disc.push([int(f[3])?, int(f[4])?, int(f[5])?]);
        xy.push([num(f[6])?, num(f[7])?]);
        let nrm = [num(f[8])?, num(f[9])?, num(f[10])?];
        if nrm != [0.0, 0.0, 1.0] {
            return Err(bad(
                line_no,
                format!("normal {nrm:?}: only +e_z normals (a flat disc face) are supported"),
            ));
        }
        let e = [num(f[11])?, num(f[12])?, num(f[13])?];
        let ne = (e[0] * e[0] + e[1] * e[1] + e[2] * e[2]).sqrt();
        if (ne - 1.0).abs() > 1e-9 || e[2].abs() > 1e-9 {
            return Err(bad(
                line_no,
                format!("sliding direction {e:?} must be a unit vector in the x-y plane"),
            ));
        }
        dir_e.push(e);
        active.push(match f[14] {
            "1" => true,
            "0" => false,
            other => {
                return Err(bad(
                    line_no,
                    format!("active must be 0 or 1, got `{other}`"),
                ))
            }
        });
    }
    if xy.is_empty() {
        return Err(bad(2, "no contact pair".into()));
    }
    let mut set = ContactSet::from_pairs(n, xy, pin, disc, 1.0)?;
    // the given directions, not recomputed ones: rebuild Pt
    set.direction = dir_e;
    set.rebuild_projections()?;
    build_operator(
        m.as_ref(),
        c.as_ref().map(|c| c.as_ref()),
        k.as_ref(),
        &set,
        &active,
    )
}
