//! The contact pairs of a built model: pin face and disc nodes sharing (x, y).

use super::{BodyKind, Layout, Patch};
use crate::{Result, Scene, SceneError};
use squeal_fe::Mesh;

/// Compatible node-to-node contact pairs: pin face node and disc node sharing (x, y).
/// Pair `p = j (nx + 1) + i` sits on grid line `xs[i]` (sliding direction) and `ys[j]`
/// (radius).
#[derive(Debug, Clone, PartialEq)]
pub struct ContactGrid {
    /// Pin node of each pair (mesh node index).
    pub pin_nodes: Vec<usize>,
    /// Disc node of each pair (mesh node index).
    pub disc_nodes: Vec<usize>,
    /// (x, y) of each pair (m), the pin node's.
    pub xy: Vec<[f64; 2]>,
    /// Grid indices `[i, j]` of each pair.
    pub ij: Vec<[usize; 2]>,
    /// Grid lines along x (m).
    pub xs: Vec<f64>,
    /// Grid lines along y (m).
    pub ys: Vec<f64>,
    /// Largest in-plane distance between the two nodes of a pair (m).
    pub max_mismatch_m: f64,
}

/// The interval each of the sorted grid `lines` stands for: bounded by the midpoints to
/// its neighbours, and by `lo` before the first line and `hi` after the last (the face
/// edges). On a refined grid the intervals are as fine as the lines.
pub fn line_cells(lines: &[f64], lo: f64, hi: f64) -> Vec<[f64; 2]> {
    let n = lines.len();
    (0..n)
        .map(|i| {
            [
                if i > 0 {
                    0.5 * (lines[i - 1] + lines[i])
                } else {
                    lo
                },
                if i + 1 < n {
                    0.5 * (lines[i] + lines[i + 1])
                } else {
                    hi
                },
            ]
        })
        .collect()
}

impl ContactGrid {
    /// The area each pair stands for, `[x_min, x_max, y_min, y_max]` (m), pair by pair:
    /// bounded by the midlines to the neighbouring grid lines and by the outer lines (the
    /// face edges), so that the cells tile the contact face (see [`line_cells`]).
    pub fn cells(&self) -> Vec<[f64; 4]> {
        let bx = line_cells(&self.xs, self.xs[0], self.xs[self.xs.len() - 1]);
        let by = line_cells(&self.ys, self.ys[0], self.ys[self.ys.len() - 1]);
        self.ij
            .iter()
            .map(|&[i, j]| [bx[i][0], bx[i][1], by[j][0], by[j][1]])
            .collect()
    }

    /// Number of pairs.
    pub fn len(&self) -> usize {
        self.pin_nodes.len()
    }
    /// Whether there is no pair.
    pub fn is_empty(&self) -> bool {
        self.pin_nodes.is_empty()
    }

    /// Tributary area of each pair (m^2): half the distance to the neighbouring grid
    /// lines on each side, in x and in y; they sum to the face area.
    pub fn tributary_areas(&self) -> Vec<f64> {
        let width = |v: &[f64], i: usize| {
            let lo = if i == 0 {
                v[0]
            } else {
                0.5 * (v[i - 1] + v[i])
            };
            let hi = if i + 1 == v.len() {
                v[i]
            } else {
                0.5 * (v[i] + v[i + 1])
            };
            hi - lo
        };
        self.ij
            .iter()
            .map(|&[i, j]| width(&self.xs, i) * width(&self.ys, j))
            .collect()
    }
}

/// Pairs each node of the pin face (node set `faces[0]`) with the disc face node (set
/// `faces[1]`) at the same (x, y) to within `1e-9` of the patch size; an error lists the
/// unmatched nodes, and `named` (empty, or the faces' groups and files) says where they
/// come from.
fn contact_grid(
    mesh: &Mesh,
    pa: &Patch,
    faces: [&str; 2],
    named: &str,
    file: &str,
) -> Result<ContactGrid> {
    let size = (pa.xs[pa.xs.len() - 1] - pa.xs[0]).max(pa.ys[pa.ys.len() - 1] - pa.ys[0]);
    let tol = 1e-9 * size;
    let pin_face = mesh.node_set(faces[0]).map_err(|m| SceneError::Field {
        file: file.into(),
        field: "pin".into(),
        message: m,
    })?;
    let disc_face = mesh.node_set(faces[1]).map_err(|m| SceneError::Field {
        file: file.into(),
        field: "disc".into(),
        message: m,
    })?;
    let key = |p: &[f64; 3]| {
        (
            (p[0] / pa.step).round() as i64,
            (p[1] / pa.step).round() as i64,
        )
    };
    let mut by_cell: std::collections::HashMap<(i64, i64), Vec<usize>> = Default::default();
    for &n in disc_face {
        by_cell.entry(key(&mesh.nodes[n])).or_default().push(n);
    }
    let nx = pa.xs.len();
    let mut grid = ContactGrid {
        pin_nodes: vec![usize::MAX; nx * pa.ys.len()],
        disc_nodes: vec![usize::MAX; nx * pa.ys.len()],
        xy: vec![[0.0; 2]; nx * pa.ys.len()],
        ij: vec![[0; 2]; nx * pa.ys.len()],
        xs: pa.xs.clone(),
        ys: pa.ys.clone(),
        max_mismatch_m: 0.0,
    };
    let mut unmatched = Vec::new();
    for &n in pin_face {
        let p = mesh.nodes[n];
        let i = pa.xs.iter().position(|&x| (x - p[0]).abs() <= tol);
        let j = pa.ys.iter().position(|&y| (y - p[1]).abs() <= tol);
        let (k0, k1) = key(&p);
        let mut best: Option<(f64, usize)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for &m in by_cell.get(&(k0 + dx, k1 + dy)).into_iter().flatten() {
                    let q = mesh.nodes[m];
                    let d = ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2)).sqrt();
                    if best.is_none_or(|b| d < b.0) {
                        best = Some((d, m));
                    }
                }
            }
        }
        match (i, j, best) {
            (Some(i), Some(j), Some((d, m))) if d <= tol => {
                let k = j * nx + i;
                grid.pin_nodes[k] = n;
                grid.disc_nodes[k] = m;
                grid.xy[k] = [p[0], p[1]];
                grid.ij[k] = [i, j];
                grid.max_mismatch_m = grid.max_mismatch_m.max(d);
            }
            _ => unmatched.push(format!("node {n} at ({:.6e}, {:.6e}) m", p[0], p[1])),
        }
    }
    if !unmatched.is_empty() || grid.pin_nodes.contains(&usize::MAX) {
        let shown: Vec<String> = unmatched.iter().take(8).cloned().collect();
        return Err(SceneError::Field {
            file: file.into(),
            field: "pin".into(),
            message: format!(
                "incompatible contact meshes{named}: {} of {} pin face nodes have no disc \
                 node within {tol:.1e} m in (x, y){}{}",
                unmatched.len(),
                pin_face.len(),
                if shown.is_empty() {
                    String::new()
                } else {
                    format!(": {}", shown.join("; "))
                },
                if unmatched.len() > 8 { " ..." } else { "" }
            ),
        });
    }
    Ok(grid)
}

/// The contact grid of the built `mesh` (on the patch of `lay`, or its refinement), when
/// `which` built both bodies of a scene with a disc and a pin.
pub(super) fn pairs(
    mesh: &Mesh,
    lay: &Layout,
    scene: &Scene,
    which: BodyKind,
    file: &str,
) -> Result<Option<ContactGrid>> {
    Ok(match (&lay.patch, which) {
        (Some(pa), BodyKind::All) if scene.disc.is_some() => {
            let face = |body: &str,
                        import: &Option<(crate::MeshImport, crate::ImportedMesh)>,
                        generated: &str| match import {
                Some((imp, im)) => {
                    let g = imp.contact_group.clone().unwrap_or_default();
                    (
                        format!("{body}.{g}"),
                        format!("group `{g}` of {}", im.path.display()),
                    )
                }
                None => (
                    format!("{body}.{generated}"),
                    format!("the generated {body}"),
                ),
            };
            let (pin_face, disc_face) = match &lay.fine {
                None => (
                    face("pin", &lay.pin_import, "zmin"),
                    face("disc", &lay.disc_import, "zmax"),
                ),
                Some(_) => (
                    ("pin_layer.zmin".to_string(), String::new()),
                    ("disc_layer.zmax".to_string(), String::new()),
                ),
            };
            let named = (lay.pin_import.is_some() || lay.disc_import.is_some())
                .then(|| format!(" (pin face: {}; disc face: {})", pin_face.1, disc_face.1));
            Some(contact_grid(
                mesh,
                lay.fine.as_ref().map_or(pa, |f| &f.0),
                [&pin_face.0, &disc_face.0],
                named.as_deref().unwrap_or(""),
                file,
            )?)
        }
        _ => None,
    })
}
