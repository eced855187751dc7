//! From a scene to an FE model with no more elements than the band needs.
//!
//! **Size rule.** For a plate-like body of thickness `t`, the shortest wave at the band
//! top `f` is the bending wave `lambda_b = 2 pi (D / (rho t))^(1/4) / sqrt(2 pi f)`,
//! `D = E t^3 / (12 (1 - nu^2))`. Element edges are at most
//! `lambda_b / mesh.elements_per_wavelength`, with at least `mesh.min_layers` layers
//! through each thickness. The pin face has `mesh.pin_face_elements` elements a side
//! (the contact grid); the plates share the pin's grid lines so the glued interfaces
//! conform. Orthotropic materials use the in-plane `E`, `nu` read off their compliance.
//!
//! Geometry: the disc spans z in [-thickness, 0] about the z axis; the pin face is
//! centred on (0, center_radius) on z = 0, x being the sliding direction and y the
//! radius there; the thin plate lies on the pin and the thick plate on the thin plate.

use crate::{Result, Scene, SceneError};
use squeal_core::{Material, Registry, SparseMat};
use squeal_fe::mesh::join;
use squeal_fe::{assemble, DofMap, Mesh};
use std::time::Instant;

/// Which bodies to build.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BodyKind {
    /// The disc alone.
    Disc,
    /// The pin with its thin and thick plates.
    Pin,
    /// Everything in the scene.
    All,
}

/// The element size chosen for one body and why.
#[derive(Debug, Clone, PartialEq)]
pub struct SizeRule {
    /// Body name.
    pub body: String,
    /// Bending wavelength at the band top (m).
    pub wavelength_m: f64,
    /// Target element edge (m).
    pub element_size_m: f64,
    /// Elements in each direction (r, theta, z for the disc; x, y, z for blocks); for an
    /// imported mesh `[0, 0, 0]` (the disc) or the pin face's `[nx, ny, 0]`.
    pub divisions: [usize; 3],
}

/// An assembled model on the free DOFs.
pub struct Model {
    /// The mesh of every built body.
    pub mesh: Mesh,
    /// Body names, indexed by `mesh.hex_body`.
    pub body_names: Vec<String>,
    /// DOF numbering (Dirichlet DOFs eliminated).
    pub dofs: DofMap,
    /// Stiffness (N/m).
    pub k: SparseMat,
    /// Mass (kg).
    pub m: SparseMat,
    /// Total mass (kg).
    pub total_mass: f64,
    /// Element sizes and their reasons.
    pub sizes: Vec<SizeRule>,
    /// Build time (s): meshing and assembly.
    pub build_time_s: f64,
    /// The node-to-node contact pairs between the pin face and the disc, when both are
    /// built.
    pub contact: Option<ContactGrid>,
}

/// Size and quality of one body of a built model.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyStats {
    /// Body name.
    pub body: String,
    /// Elements.
    pub elements: usize,
    /// Nodes (a node glued to an earlier body counts for that body).
    pub nodes: usize,
    /// Free DOFs on those nodes.
    pub dofs: usize,
    /// Smallest and largest element edge (m).
    pub edge_range_m: (f64, f64),
    /// Minimum scaled Jacobian over the body's elements (1 for a cube).
    pub min_scaled_jacobian: f64,
}

impl Model {
    /// Per-body sizes and mesh quality.
    pub fn body_stats(&self) -> Vec<BodyStats> {
        let mut owner = vec![usize::MAX; self.mesh.n_nodes()];
        let mut out: Vec<BodyStats> = self
            .body_names
            .iter()
            .map(|b| BodyStats {
                body: b.clone(),
                elements: 0,
                nodes: 0,
                dofs: 0,
                edge_range_m: (f64::INFINITY, 0.0),
                min_scaled_jacobian: f64::INFINITY,
            })
            .collect();
        for (e, h) in self.mesh.hexes.iter().enumerate() {
            let b = self.mesh.hex_body[e];
            let st = &mut out[b];
            st.elements += 1;
            let x = self.mesh.hex_coords(e);
            st.min_scaled_jacobian = st
                .min_scaled_jacobian
                .min(squeal_fe::hex8::scaled_jacobian(&x));
            for l in squeal_fe::hex8::edge_lengths(&x) {
                st.edge_range_m = (st.edge_range_m.0.min(l), st.edge_range_m.1.max(l));
            }
            for &n in h {
                if owner[n] == usize::MAX {
                    owner[n] = b;
                }
            }
        }
        for (n, &b) in owner.iter().enumerate() {
            if b != usize::MAX {
                out[b].nodes += 1;
                out[b].dofs += (0..3)
                    .filter(|k| self.dofs.free_of_full[3 * n + k].is_some())
                    .count();
            }
        }
        out
    }
}

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

/// The node count of a build, checked before each block of nodes is made.
struct NodeBudget {
    max_dofs: usize,
    parts: Vec<(&'static str, usize)>,
}

impl NodeBudget {
    fn new(max_dofs: usize) -> Self {
        Self {
            max_dofs,
            parts: Vec::new(),
        }
    }

    /// Accounts for a block of `dims` nodes of `what`; refuses the build when the total
    /// passes the budget.
    fn take(&mut self, what: &'static str, dims: &[usize], file: &str) -> Result<()> {
        let n = dims.iter().fold(1usize, |a, &d| a.saturating_mul(d));
        self.parts.push((what, n));
        let total: usize = self
            .parts
            .iter()
            .map(|p| p.1)
            .fold(0, usize::saturating_add);
        if total.saturating_mul(3) > self.max_dofs {
            let list: Vec<String> = self
                .parts
                .iter()
                .map(|(w, n)| format!("{w} {}", n.saturating_mul(3)))
                .collect();
            return Err(SceneError::Field {
                file: file.into(),
                field: "mesh.max_dofs".into(),
                message: format!(
                    "the mesh rule asks for more than {} DOFs ({} so far); expected at most \
                     mesh.max_dofs = {}: check mesh.max_freq_hz and the element counts, or \
                     raise mesh.max_dofs for a deliberately large model",
                    total.saturating_mul(3),
                    list.join(", "),
                    self.max_dofs
                ),
            });
        }
        Ok(())
    }
}

/// Appends an imported body mesh as body `body` (node sets prefixed `prefix`) and fixes
/// the nodes of its `fixed_groups`; an unknown group is an error message.
fn append_imported(
    mesh: &mut Mesh,
    fixed_nodes: &mut Vec<usize>,
    im: &crate::ImportedMesh,
    fixed_groups: &[String],
    body: usize,
    prefix: &str,
) -> std::result::Result<(), String> {
    let part = (*im.mesh).clone().with_body(body);
    let map = mesh.append(&part, prefix, None);
    for g in fixed_groups {
        fixed_nodes.extend(part.node_set(g)?.iter().map(|&n| map[n]));
    }
    Ok(())
}

/// Bending-wave element size for a plate of `thickness` made of `mat` at `freq_hz`.
pub fn element_size(
    mat: &dyn Material,
    thickness: f64,
    freq_hz: f64,
    per_wavelength: f64,
) -> (f64, f64) {
    let (e, nu) = in_plane_constants(mat);
    let d = e * thickness.powi(3) / (12.0 * (1.0 - nu * nu));
    let omega = 2.0 * std::f64::consts::PI * freq_hz;
    let lambda =
        2.0 * std::f64::consts::PI * (d / (mat.density() * thickness)).powf(0.25) / omega.sqrt();
    (lambda, lambda / per_wavelength)
}

/// In-plane Young's modulus and Poisson ratio (x direction) from the compliance.
fn in_plane_constants(mat: &dyn Material) -> (f64, f64) {
    let s = invert6(mat.elasticity());
    (1.0 / s[0][0], -s[0][1] / s[0][0])
}

fn invert6(d: [[f64; 6]; 6]) -> [[f64; 6]; 6] {
    let mut a = d;
    let mut inv = [[0.0; 6]; 6];
    for (i, row) in inv.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for c in 0..6 {
        let p = (c..6)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap();
        a.swap(c, p);
        inv.swap(c, p);
        let piv = a[c][c];
        for j in 0..6 {
            a[c][j] /= piv;
            inv[c][j] /= piv;
        }
        for r in 0..6 {
            if r != c {
                let f = a[r][c];
                for j in 0..6 {
                    a[r][j] -= f * a[c][j];
                    inv[r][j] -= f * inv[c][j];
                }
            }
        }
    }
    inv
}

/// Divides each interval between consecutive `breaks` into equal parts no longer than
/// `size` (at least one).
fn graded(breaks: &[f64], size: &dyn Fn(f64, f64) -> f64) -> Vec<f64> {
    let mut b = breaks.to_vec();
    b.sort_by(f64::total_cmp);
    b.dedup_by(|x, y| (*x - *y).abs() < 1e-12);
    let segs: Vec<Vec<f64>> = b
        .windows(2)
        .map(|w| {
            let n = ((w[1] - w[0]) / size(w[0], w[1]) - 1e-9).ceil().max(1.0) as usize;
            squeal_fe::mesh::linspace(w[0], w[1], n)
        })
        .collect();
    join(&segs)
}

fn within(v: &[f64], lo: f64, hi: f64) -> Vec<f64> {
    let eps = 1e-12 * (1.0 + hi.abs().max(lo.abs()));
    v.iter()
        .copied()
        .filter(|&x| x >= lo - eps && x <= hi + eps)
        .collect()
}

/// Makes `edge` a line of the increasing grid `v`: the nearest line outside the contact
/// grid `fixed` moves onto it when that keeps the neighbouring elements at least 40 % of
/// their former size, otherwise a new line is inserted.
fn insert_edge(v: &mut Vec<f64>, fixed: &[f64], edge: f64) {
    let eps = 1e-12 * (1.0 + edge.abs());
    let i = v.partition_point(|&x| x < edge);
    let near = [i.checked_sub(1), (i < v.len()).then_some(i)]
        .into_iter()
        .flatten()
        .min_by(|&a, &b| (v[a] - edge).abs().total_cmp(&(v[b] - edge).abs()));
    let Some(j) = near else { return };
    if (v[j] - edge).abs() <= eps {
        return;
    }
    let (lo, hi) = (fixed[0] - eps, fixed[fixed.len() - 1] + eps);
    let movable = (v[j] < lo || v[j] > hi) && j > 0 && j + 1 < v.len();
    if movable {
        let (a, b) = (v[j - 1], v[j + 1]);
        if edge - a >= 0.4 * (v[j] - a) && b - edge >= 0.4 * (b - v[j]) {
            v[j] = edge;
            return;
        }
    }
    v.insert(i, edge);
}

/// The contact patch: the pin face's Cartesian grid `xs x ys` (sliding direction x,
/// radius y), which the disc mesh reproduces exactly under the pin.
struct Patch {
    /// Grid lines along x (m), increasing.
    xs: Vec<f64>,
    /// Grid lines along y (m), increasing.
    ys: Vec<f64>,
    /// Centre radius (m).
    yc: f64,
    /// Grid step (m).
    step: f64,
}

/// The grid lines `(xs, ys)` of a face's nodes: their distinct x and y (to `1e-9` of the
/// face size), checked to form a full tensor grid with one node at each intersection.
fn face_grid(mesh: &Mesh, face: &[usize]) -> std::result::Result<(Vec<f64>, Vec<f64>), String> {
    let pts: Vec<[f64; 3]> = face.iter().map(|&n| mesh.nodes[n]).collect();
    let extent = |a: usize| {
        let (lo, hi) = pts
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| {
                (l.min(p[a]), h.max(p[a]))
            });
        hi - lo
    };
    let tol = 1e-9 * extent(0).max(extent(1));
    let lines = |a: usize| {
        let mut v: Vec<f64> = pts.iter().map(|p| p[a]).collect();
        v.sort_by(f64::total_cmp);
        let mut out: Vec<f64> = Vec::new();
        for x in v {
            if out.last().is_none_or(|&l| x - l > tol) {
                out.push(x);
            }
        }
        out
    };
    let (xs, ys) = (lines(0), lines(1));
    let find = |v: &[f64], x: f64| v.iter().position(|&l| (l - x).abs() <= tol);
    let mut hit = vec![0usize; xs.len() * ys.len()];
    for p in &pts {
        if let (Some(i), Some(j)) = (find(&xs, p[0]), find(&ys, p[1])) {
            hit[j * xs.len() + i] += 1;
        }
    }
    let empty = hit.iter().filter(|&&h| h == 0).count();
    let doubled = hit.iter().filter(|&&h| h > 1).count();
    if xs.len() < 2 || ys.len() < 2 || empty > 0 || doubled > 0 {
        return Err(format!(
            "its {} nodes do not form a full tensor grid in (x, y): {} x-lines x {} y-lines, \
             {empty} intersections without a node, {doubled} with several; contact zones \
             need a grid (at least 2 x 2)",
            pts.len(),
            xs.len(),
            ys.len()
        ));
    }
    Ok((xs, ys))
}

impl Patch {
    /// The patch of an imported pin face with grid lines `xs`, `ys` (see [`face_grid`]).
    fn from_grid(xs: Vec<f64>, ys: Vec<f64>) -> Self {
        let step = xs
            .windows(2)
            .chain(ys.windows(2))
            .map(|w| w[1] - w[0])
            .fold(f64::INFINITY, f64::min);
        let yc = 0.5 * (ys[0] + ys[ys.len() - 1]);
        Patch { xs, ys, yc, step }
    }

    fn new(p: &crate::Pin, n: usize) -> Self {
        let (a, b, yc) = (p.size_x_m, p.size_y_m, p.center_radius_m);
        Patch {
            xs: squeal_fe::mesh::linspace(-a / 2.0, a / 2.0, n),
            ys: squeal_fe::mesh::linspace(yc - b / 2.0, yc + b / 2.0, n),
            yc,
            step: a.min(b) / n as f64,
        }
    }

    /// The patch with lines every `r.element_m` or less inside `r.region_m` (face
    /// coordinates), widened outward to this patch's lines; this patch's lines elsewhere.
    fn refined(&self, r: &crate::ContactRefinement) -> Patch {
        let lines = |v: &[f64], lo: f64, hi: f64| {
            let tol = 1e-9 * (v[v.len() - 1] - v[0]);
            let a = v.iter().rposition(|&x| x <= lo + tol).unwrap_or(0);
            let b = v.iter().position(|&x| x >= hi - tol).unwrap_or(v.len() - 1);
            let n = ((v[b] - v[a]) / r.element_m - 1e-9).ceil().max(1.0) as usize;
            let mut out = v[..a].to_vec();
            out.extend(squeal_fe::mesh::linspace(v[a], v[b], n));
            out.extend_from_slice(&v[b + 1..]);
            out
        };
        let [x0, y0, a, b] = r.region_m;
        let (cx, cy) = (self.xs[0], self.ys[0]);
        let mut p = Patch::from_grid(
            lines(&self.xs, cx + x0, cx + x0 + a),
            lines(&self.ys, cy + y0, cy + y0 + b),
        );
        p.yc = self.yc;
        p
    }

    /// Half the angle the patch spans at its centre radius.
    fn half_angle(&self) -> f64 {
        self.xs[self.xs.len() - 1] / self.yc
    }

    /// Angular grid: the patch lines at `theta = pi/2 - x/yc`, graded by `ratio` up to
    /// `dtheta` around the rest of the turn. Increasing, less than one turn.
    fn thetas(&self, dtheta: f64, ratio: f64) -> Vec<f64> {
        let c = std::f64::consts::FRAC_PI_2;
        let mut th: Vec<f64> = self.xs.iter().rev().map(|x| c - x / self.yc).collect();
        let span = 2.0 * std::f64::consts::PI - 2.0 * self.half_angle();
        let half = squeal_fe::mesh::graded_steps(span / 2.0, self.step / self.yc, dtheta, ratio);
        let mut steps = half.clone();
        steps.extend(half.iter().rev());
        let mut t = th[th.len() - 1];
        for st in &steps[..steps.len() - 1] {
            t += st;
            th.push(t);
        }
        th
    }

    /// The in-plane map: Cartesian `(-yc phi, r)` on the patch (`phi = theta - pi/2`),
    /// polar far from it, a smooth blend over one patch size around it that vanishes
    /// before the hat wall and the outer edge (which stays a true circle).
    fn blend(&self, r_wall: f64, r_out: f64) -> Blend {
        let (r0, r1) = (self.ys[0], self.ys[self.ys.len() - 1]);
        let b = r1 - r0;
        Blend {
            r0,
            r1,
            yc: self.yc,
            half: self.half_angle(),
            dr_in: b.min(0.8 * (r0 - r_wall)),
            dr_out: b.min(0.8 * (r_out - r1)),
            dphi: (2.0 * self.half_angle()).min(0.5 * (std::f64::consts::PI - self.half_angle())),
        }
    }
}

/// See [`Patch::blend`].
struct Blend {
    r0: f64,
    r1: f64,
    yc: f64,
    half: f64,
    dr_in: f64,
    dr_out: f64,
    dphi: f64,
}

impl Blend {
    fn map(&self, r: f64, th: f64) -> [f64; 2] {
        let polar = [r * th.cos(), r * th.sin()];
        let mut phi = th - std::f64::consts::FRAC_PI_2;
        while phi > std::f64::consts::PI {
            phi -= 2.0 * std::f64::consts::PI;
        }
        while phi <= -std::f64::consts::PI {
            phi += 2.0 * std::f64::consts::PI;
        }
        let tr = if r < self.r0 {
            (self.r0 - r) / self.dr_in
        } else if r > self.r1 {
            (r - self.r1) / self.dr_out
        } else {
            0.0
        };
        let tp = ((phi.abs() - self.half) / self.dphi).max(0.0);
        // smooth step: 1 at t <= 0, 0 at t >= 1, zero slope at both ends
        let step = |t: f64| {
            if t <= 1e-12 {
                1.0
            } else if t >= 1.0 {
                0.0
            } else {
                1.0 - t * t * (3.0 - 2.0 * t)
            }
        };
        let w = step(tr) * step(tp);
        if w == 1.0 {
            [-self.yc * phi, r]
        } else if w == 0.0 {
            polar
        } else {
            [
                w * (-self.yc * phi) + (1.0 - w) * polar[0],
                w * r + (1.0 - w) * polar[1],
            ]
        }
    }
}

/// Appends the contact layer `layer` of `body` (node sets `{body}_layer.*`) and ties its
/// face `tied` to the face `master` of the coarse body (`{body}.{master}`, on the coarse
/// patch grid); returns the ties and the layer's size rule (`nl` element layers).
#[allow(clippy::too_many_arguments)]
fn contact_layer(
    mesh: &mut Mesh,
    layer: &Mesh,
    body: &str,
    tied: &str,
    master: &str,
    coarse: &Patch,
    fine: &Patch,
    nl: usize,
) -> std::result::Result<(Vec<squeal_fe::Tie>, SizeRule), String> {
    mesh.append(layer, &format!("{body}_layer."), None);
    let ties = squeal_fe::mesh::face_ties(
        mesh,
        mesh.node_set(&format!("{body}_layer.{tied}"))?,
        mesh.node_set(&format!("{body}.{master}"))?,
        &coarse.xs,
        &coarse.ys,
    )
    .map_err(|m| format!("{body} contact layer: {m}"))?;
    let rule = SizeRule {
        body: format!("{body} contact layer"),
        wavelength_m: f64::NAN,
        element_size_m: fine.step,
        divisions: [fine.xs.len() - 1, fine.ys.len() - 1, nl],
    };
    Ok((ties, rule))
}

/// Builds the bodies of `scene` selected by `which`, with materials from `registry`;
/// `file` names the scene in errors.
pub fn build(scene: &Scene, which: BodyKind, registry: &Registry, file: &str) -> Result<Model> {
    let start = Instant::now();
    let rule = &scene.mesh;
    let mat = |spec: &crate::MaterialSpec, field: &str| -> Result<Box<dyn Material>> {
        let params = spec.params(file, field)?;
        registry
            .materials
            .create(&spec.kind, &params)
            .map_err(|source| SceneError::Core {
                file: file.into(),
                context: field.into(),
                source: Box::new(source),
            })
    };
    let missing = |field: &str| SceneError::Field {
        file: file.into(),
        field: field.into(),
        message: "this body is asked for but the scene has no such table".into(),
    };
    let mut mesh = Mesh::default();
    let mut budget = NodeBudget::new(rule.max_dofs);
    let mut materials: Vec<Box<dyn Material>> = Vec::new();
    let mut body_names = Vec::new();
    let mut sizes = Vec::new();
    let mut fixed_nodes: Vec<usize> = Vec::new();
    // Imported meshes: read by Scene::from_file, else now (relative to the working
    // directory).
    let import = |imp: Option<&crate::MeshImport>,
                  field: &str|
     -> Result<Option<(crate::MeshImport, crate::ImportedMesh)>> {
        match imp {
            None => Ok(None),
            Some(imp) => {
                let im = match &imp.loaded {
                    Some(l) => l.clone(),
                    None => imp.load(None, file, field)?,
                };
                Ok(Some((imp.clone(), im)))
            }
        }
    };
    let disc_import = import(
        scene.disc.as_ref().and_then(|d| d.mesh.as_ref()),
        "disc.mesh",
    )?;
    let pin_import = import(scene.pin.as_ref().and_then(|p| p.mesh.as_ref()), "pin.mesh")?;
    let group_field = |body: &str, f: &str, message: String| SceneError::Field {
        file: file.into(),
        field: format!("{body}.mesh.{f}"),
        message,
    };
    // The contact patch under the pin: a Cartesian grid blended into the polar disc; the
    // grid lines of an imported pin's contact group when the scene has a disc.
    let patch = match (&scene.pin, &pin_import) {
        (Some(_), Some((imp, im))) if scene.disc.is_some() => {
            let g = imp.contact_group.as_deref().ok_or_else(|| {
                group_field(
                    "pin",
                    "contact_group",
                    "expected the pin face's group".into(),
                )
            })?;
            let set = im
                .mesh
                .node_set(g)
                .map_err(|m| group_field("pin", "contact_group", m))?;
            let (xs, ys) = face_grid(&im.mesh, set).map_err(|m| {
                group_field(
                    "pin",
                    "contact_group",
                    format!("group `{g}` of {}: {m}", im.path.display()),
                )
            })?;
            Some(Patch::from_grid(xs, ys))
        }
        (Some(p), _) => Some(Patch::new(p, rule.pin_face_elements)),
        (None, _) => None,
    };
    // Contact refinement: the fine contact grid, carried by tied contact layers; the disc
    // layer (element_m thick) lifts the pin assembly by `lift`.
    let fine = match (&rule.contact_refinement, &patch) {
        (Some(r), Some(pa)) if pin_import.is_none() && disc_import.is_none() => {
            Some((pa.refined(r), r.element_m))
        }
        _ => None,
    };
    let lift = fine.as_ref().map_or(0.0, |f| f.1);
    let mut ties: Vec<squeal_fe::Tie> = Vec::new();
    let tie_error = |m: String| SceneError::Field {
        file: file.into(),
        field: "mesh.contact_refinement".into(),
        message: m,
    };

    let disc_built = which == BodyKind::Disc || (which == BodyKind::All && scene.disc.is_some());
    if let (true, Some((imp, im))) = (disc_built, &disc_import) {
        let d = scene.disc.as_ref().ok_or_else(|| missing("disc"))?;
        let m = mat(&d.material, "disc.material")?;
        let (lambda, h) = element_size(
            m.as_ref(),
            d.thickness_m,
            rule.max_freq_hz,
            rule.elements_per_wavelength,
        );
        append_imported(
            &mut mesh,
            &mut fixed_nodes,
            im,
            &imp.fixed_groups,
            materials.len(),
            "disc.",
        )
        .map_err(|msg| group_field("disc", "fixed_groups", msg))?;
        // the rule's target size, for comparison with the imported elements
        sizes.push(SizeRule {
            body: "disc".into(),
            wavelength_m: lambda,
            element_size_m: h,
            divisions: [0; 3],
        });
        materials.push(m);
        body_names.push("disc".to_string());
    } else if disc_built {
        let d = scene.disc.as_ref().ok_or_else(|| missing("disc"))?;
        let m = mat(&d.material, "disc.material")?;
        if let (Some(pa), Some((_, im))) = (&patch, &pin_import) {
            let (x0, x1) = (pa.xs[0], pa.xs[pa.xs.len() - 1]);
            if (x0 + x1).abs() > 1e-9 * (x1 - x0) {
                return Err(group_field(
                    "pin",
                    "contact_group",
                    format!(
                        "the generated disc reproduces the pin face centred on x = 0, but the \
                         pin face of {} spans x in [{x0:e}, {x1:e}] m; centre it on x = 0 or \
                         import the disc mesh too",
                        im.path.display()
                    ),
                ));
            }
        }
        let (lambda, h) = element_size(
            m.as_ref(),
            d.thickness_m,
            rule.max_freq_hz,
            rule.elements_per_wavelength,
        );
        let nt =
            ((2.0 * std::f64::consts::PI * d.outer_radius_m / h / 4.0).ceil() as usize * 4).max(16);
        let body = materials.len();
        let layer = d.thickness_m / rule.min_layers as f64;
        let zs = graded(&[-d.thickness_m, 0.0], &|_, _| h.min(layer));
        // radial grid: the hat wall's radii are grid lines of the ring, so they conform
        let wall = d.hat.as_ref().map(|hat| {
            let (lw, hw) = element_size(
                m.as_ref(),
                hat.thickness_m,
                rule.max_freq_hz,
                rule.elements_per_wavelength,
            );
            (lw, hw, hat.thickness_m / rule.min_layers as f64)
        });
        let mut rb = vec![d.inner_radius_m];
        let r_in_wall = d
            .hat
            .as_ref()
            .and_then(|hat| hat.radius_m)
            .unwrap_or(d.inner_radius_m);
        let r_wall = d
            .hat
            .as_ref()
            .map_or(d.inner_radius_m, |hat| r_in_wall + hat.thickness_m);
        if d.hat.is_some() {
            rb.extend([r_in_wall, r_wall]);
        }
        let size = |lo: f64, hi: f64| match wall {
            Some((_, _, t)) if lo >= r_in_wall - 1e-12 && hi <= r_wall + 1e-12 => t,
            _ => h,
        };
        let q = rule.grading_ratio;
        let (rs, thetas) = match &patch {
            None => {
                rb.push(d.outer_radius_m);
                let thetas: Vec<f64> = (0..nt)
                    .map(|t| 2.0 * std::f64::consts::PI * t as f64 / nt as f64)
                    .collect();
                (graded(&rb, &size), thetas)
            }
            Some(pa) => {
                let mut rs = if rb.len() > 1 {
                    graded(&rb, &size)
                } else {
                    rb.clone()
                };
                let r_a = *rs.last().unwrap();
                let down = squeal_fe::mesh::graded_steps(pa.ys[0] - r_a, pa.step, h, q);
                let mut r = pa.ys[0];
                let mut inward: Vec<f64> = down
                    .iter()
                    .take(down.len().saturating_sub(1))
                    .map(|st| {
                        r -= st;
                        r
                    })
                    .collect();
                inward.reverse();
                rs.extend(inward);
                rs.extend(&pa.ys);
                let up = squeal_fe::mesh::graded_steps(
                    d.outer_radius_m - pa.ys[pa.ys.len() - 1],
                    pa.step,
                    h,
                    q,
                );
                let mut r = pa.ys[pa.ys.len() - 1];
                for (i, st) in up.iter().enumerate() {
                    r = if i + 1 == up.len() {
                        d.outer_radius_m
                    } else {
                        r + st
                    };
                    rs.push(r);
                }
                (rs, pa.thetas(2.0 * std::f64::consts::PI / nt as f64, q))
            }
        };
        let blend = patch.as_ref().map(|pa| pa.blend(r_wall, d.outer_radius_m));
        let xy_map = |r: f64, th: f64| match &blend {
            Some(b) => b.map(r, th),
            None => [r * th.cos(), r * th.sin()],
        };
        let nt = thetas.len();
        budget.take("disc", &[rs.len(), thetas.len(), zs.len()], file)?;
        let ring = Mesh::annulus_mapped(&rs, &thetas, &zs, &xy_map).with_body(body);
        let map = mesh.append(&ring, "disc.", None);
        if let (Some((fp, t)), Some(pa)) = (&fine, &patch) {
            // the disc's contact layer on the ring's top under the pin face, its bottom
            // tied to the ring's patch grid
            budget.take("disc contact layer", &[fp.xs.len(), fp.ys.len(), 2], file)?;
            let layer = Mesh::block(&fp.xs, &fp.ys, &[0.0, *t]).with_body(body);
            let (layer_ties, rule) =
                contact_layer(&mut mesh, &layer, "disc", "zmin", "zmax", pa, fp, 1)
                    .map_err(tie_error)?;
            ties.extend(layer_ties);
            sizes.push(rule);
        }
        let mut divisions = [rs.len() - 1, nt, zs.len() - 1];
        let mut hat_rule = None;
        match (&d.hat, wall) {
            (Some(hat), Some((lw, hw, _))) => {
                let nzh = ((hat.height_m / hw.min(h)).ceil() as usize).max(rule.min_layers);
                let wall_rs = within(&rs, r_in_wall, r_wall);
                budget.take("disc hat", &[wall_rs.len(), thetas.len(), nzh + 1], file)?;
                let hat_mesh = Mesh::annulus_mapped(
                    &wall_rs,
                    &thetas,
                    &squeal_fe::mesh::linspace(-d.thickness_m - hat.height_m, -d.thickness_m, nzh),
                    &xy_map,
                )
                .with_body(body);
                let hmap = mesh.append(&hat_mesh, "disc.hat.", Some(1e-9 * d.outer_radius_m));
                match &hat.flange {
                    None => fixed_nodes
                        .extend(hat_mesh.node_set("zmin").unwrap().iter().map(|&n| hmap[n])),
                    Some(fl) => {
                        // an annular plate under the wall, inward to its clamped bore
                        let z0 = -d.thickness_m - hat.height_m;
                        let (_, hf) = element_size(
                            m.as_ref(),
                            fl.thickness_m,
                            rule.max_freq_hz,
                            rule.elements_per_wavelength,
                        );
                        let mut frs = graded(&[fl.inner_radius_m, r_in_wall], &|_, _| hf.min(h));
                        frs.extend(wall_rs.iter().skip(1));
                        let nzf = ((fl.thickness_m / hf).ceil() as usize).max(rule.min_layers);
                        budget.take("disc flange", &[frs.len(), thetas.len(), nzf + 1], file)?;
                        let flange = Mesh::annulus_mapped(
                            &frs,
                            &thetas,
                            &squeal_fe::mesh::linspace(z0 - fl.thickness_m, z0, nzf),
                            &xy_map,
                        )
                        .with_body(body);
                        let fmap =
                            mesh.append(&flange, "disc.hat.flange.", Some(1e-9 * d.outer_radius_m));
                        fixed_nodes
                            .extend(flange.node_set("inner").unwrap().iter().map(|&n| fmap[n]));
                    }
                }
                divisions[2] += nzh;
                hat_rule = Some(SizeRule {
                    body: "disc hat".into(),
                    wavelength_m: lw,
                    element_size_m: hw.min(h),
                    divisions: [wall_rs.len() - 1, nt, nzh],
                });
            }
            _ => fixed_nodes.extend(ring.node_set("inner").unwrap().iter().map(|&n| map[n])),
        }
        sizes.push(SizeRule {
            body: "disc".into(),
            wavelength_m: lambda,
            element_size_m: h,
            divisions,
        });
        sizes.extend(hat_rule);
        materials.push(m);
        body_names.push("disc".to_string());
    }

    let pin_built = which == BodyKind::Pin || (which == BodyKind::All && scene.pin.is_some());
    if let (true, Some((imp, im))) = (pin_built, &pin_import) {
        let p = scene.pin.as_ref().ok_or_else(|| missing("pin"))?;
        let pin_mat = mat(&p.material, "pin.material")?;
        append_imported(
            &mut mesh,
            &mut fixed_nodes,
            im,
            &imp.fixed_groups,
            materials.len(),
            "pin.",
        )
        .map_err(|msg| group_field("pin", "fixed_groups", msg))?;
        let face = patch.as_ref().filter(|_| scene.disc.is_some());
        sizes.push(SizeRule {
            body: "pin".into(),
            wavelength_m: f64::NAN,
            element_size_m: face.map_or(f64::NAN, |pa| pa.step),
            divisions: face.map_or([0; 3], |pa| [pa.xs.len() - 1, pa.ys.len() - 1, 0]),
        });
        materials.push(pin_mat);
        body_names.push("pin".into());
    } else if pin_built {
        let p = scene.pin.as_ref().ok_or_else(|| missing("pin"))?;
        let pin_mat = mat(&p.material, "pin.material")?;
        let (a, b, yc) = (p.size_x_m, p.size_y_m, p.center_radius_m);
        let face = rule.pin_face_elements as f64;
        let h_pin = a.min(b) / face;
        let plates: Vec<(&str, &crate::Plate)> = [
            ("thin_plate", &scene.thin_plate),
            ("thick_plate", &scene.thick_plate),
        ]
        .into_iter()
        .filter_map(|(n, p)| p.as_ref().map(|p| (n, p)))
        .collect();
        let mut plate_mats = Vec::new();
        let mut h_plate = f64::INFINITY;
        for (name, pl) in &plates {
            let m = mat(&pl.material, &format!("{name}.material"))?;
            let (lambda, h) = element_size(
                m.as_ref(),
                pl.thickness_m,
                rule.max_freq_hz,
                rule.plate_elements_per_wavelength
                    .unwrap_or(rule.elements_per_wavelength),
            );
            h_plate = h_plate.min(h);
            plate_mats.push((m, lambda, h));
        }
        let pa = patch.as_ref().expect("a pin has a patch");
        // common grid lines in x and y: the pin face's contact grid, plates graded away
        // from it; the plates' grids contain the pin's, so glued faces conform
        let (lx, ly) = plates.iter().fold((a, b), |(lx, ly), (_, pl)| {
            (lx.max(pl.length_x_m), ly.max(pl.width_y_m))
        });
        let around = |grid: &[f64], lo: f64, hi: f64| -> Vec<f64> {
            let mut v: Vec<f64> = Vec::new();
            let mut x = grid[0];
            for st in
                squeal_fe::mesh::graded_steps(grid[0] - lo, pa.step, h_plate, rule.grading_ratio)
            {
                x -= st;
                v.push(x);
            }
            if let Some(last) = v.last_mut() {
                *last = lo;
            }
            v.reverse();
            v.extend_from_slice(grid);
            let mut x = grid[grid.len() - 1];
            let up = squeal_fe::mesh::graded_steps(hi - x, pa.step, h_plate, rule.grading_ratio);
            for (i, st) in up.iter().enumerate() {
                x = if i + 1 == up.len() { hi } else { x + st };
                v.push(x);
            }
            v
        };
        let mut xs = around(&pa.xs, -lx / 2.0, lx / 2.0);
        let mut ys = around(&pa.ys, yc - ly / 2.0, yc + ly / 2.0);
        // every plate's own edges are grid lines, so a plate smaller than the largest
        // keeps its true size
        for (_, pl) in &plates {
            insert_edge(&mut xs, &pa.xs, -pl.length_x_m / 2.0);
            insert_edge(&mut xs, &pa.xs, pl.length_x_m / 2.0);
            insert_edge(&mut ys, &pa.ys, yc - pl.width_y_m / 2.0);
            insert_edge(&mut ys, &pa.ys, yc + pl.width_y_m / 2.0);
        }
        // through the pin height: the face step at the contact, graded up to the size the
        // band needs in the pad material
        let (_, h_pin_z) = element_size(
            pin_mat.as_ref(),
            a.min(b),
            rule.max_freq_hz,
            rule.elements_per_wavelength,
        );
        let h_pin_z = h_pin_z.min(p.height_m / rule.min_layers as f64).max(h_pin);
        let mut zp = vec![0.0];
        let z_steps =
            squeal_fe::mesh::graded_steps(p.height_m - h_pin, h_pin, h_pin_z, rule.grading_ratio);
        zp.push(h_pin.min(p.height_m));
        let mut z = zp[1];
        for (i, st) in z_steps.iter().enumerate() {
            z = if i + 1 == z_steps.len() {
                p.height_m
            } else {
                z + st
            };
            zp.push(z);
        }
        let nzp = zp.len() - 1;
        match &fine {
            None => {
                budget.take("pin", &[pa.xs.len(), pa.ys.len(), zp.len()], file)?;
                let pin = Mesh::block(&pa.xs, &pa.ys, &zp).with_body(materials.len());
                mesh.append(&pin, "pin.", None);
            }
            Some((fp, t)) => {
                // the pin's first layer becomes the fine contact layer, its top tied to
                // the coarse pin above it; everything sits `lift` higher
                if zp.len() < 3 {
                    return Err(tie_error(format!(
                        "the pin ({} m high) has a single element layer; the contact layer \
                         needs a second one (raise mesh.min_layers)",
                        p.height_m
                    )));
                }
                let up: Vec<f64> = zp[1..].iter().map(|z| z + lift).collect();
                let nl = (zp[1] / (2.0 * t) - 1e-9).ceil().max(1.0) as usize;
                budget.take("pin", &[pa.xs.len(), pa.ys.len(), up.len()], file)?;
                budget.take(
                    "pin contact layer",
                    &[fp.xs.len(), fp.ys.len(), nl + 1],
                    file,
                )?;
                let pin = Mesh::block(&pa.xs, &pa.ys, &up).with_body(materials.len());
                mesh.append(&pin, "pin.", None);
                let layer = Mesh::block(
                    &fp.xs,
                    &fp.ys,
                    &squeal_fe::mesh::linspace(lift, lift + zp[1], nl),
                )
                .with_body(materials.len());
                let (layer_ties, rule) =
                    contact_layer(&mut mesh, &layer, "pin", "zmax", "zmin", pa, fp, nl)
                        .map_err(tie_error)?;
                ties.extend(layer_ties);
                sizes.push(rule);
            }
        }
        sizes.push(SizeRule {
            body: "pin".into(),
            wavelength_m: f64::NAN,
            element_size_m: h_pin,
            divisions: [
                rule.pin_face_elements,
                rule.pin_face_elements,
                nzp - usize::from(fine.is_some()),
            ],
        });
        materials.push(pin_mat);
        body_names.push("pin".into());
        let mut z = p.height_m + lift;
        for ((name, pl), (m, lambda, h)) in plates.iter().zip(plate_mats) {
            let nz = ((pl.thickness_m / h).ceil() as usize).max(rule.min_layers);
            let xs_p = within(&xs, -pl.length_x_m / 2.0, pl.length_x_m / 2.0);
            let ys_p = within(&ys, yc - pl.width_y_m / 2.0, yc + pl.width_y_m / 2.0);
            budget.take(
                if *name == "thin_plate" {
                    "thin plate"
                } else {
                    "thick plate"
                },
                &[xs_p.len(), ys_p.len(), nz + 1],
                file,
            )?;
            let block = Mesh::block(
                &xs_p,
                &ys_p,
                &squeal_fe::mesh::linspace(z, z + pl.thickness_m, nz),
            )
            .with_body(materials.len());
            let map = mesh.append(
                &block,
                &format!("{name}."),
                Some(1e-9 * (1.0 + pl.length_x_m)),
            );
            if *name == "thin_plate" {
                for set in pl.clamp.unwrap_or_default().node_sets() {
                    fixed_nodes.extend(block.node_set(set).unwrap().iter().map(|&n| map[n]));
                }
            }
            sizes.push(SizeRule {
                body: name.to_string(),
                wavelength_m: lambda,
                element_size_m: h,
                divisions: [xs_p.len() - 1, ys_p.len() - 1, nz],
            });
            materials.push(m);
            body_names.push(name.to_string());
            z += pl.thickness_m;
        }
    }

    let contact = match (&patch, which) {
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
            let (pin_face, disc_face) = match &fine {
                None => (
                    face("pin", &pin_import, "zmin"),
                    face("disc", &disc_import, "zmax"),
                ),
                Some(_) => (
                    ("pin_layer.zmin".to_string(), String::new()),
                    ("disc_layer.zmax".to_string(), String::new()),
                ),
            };
            let named = (pin_import.is_some() || disc_import.is_some())
                .then(|| format!(" (pin face: {}; disc face: {})", pin_face.1, disc_face.1));
            Some(contact_grid(
                &mesh,
                fine.as_ref().map_or(pa, |f| &f.0),
                [&pin_face.0, &disc_face.0],
                named.as_deref().unwrap_or(""),
                file,
            )?)
        }
        _ => None,
    };
    fixed_nodes.sort_unstable();
    fixed_nodes.dedup();
    let dofs =
        DofMap::with_ties(&mesh, &DofMap::node_dofs(&fixed_nodes), &ties).map_err(tie_error)?;
    let refs: Vec<&dyn Material> = materials.iter().map(|m| m.as_ref()).collect();
    let asm = assemble(&mesh, &dofs, &refs).map_err(|source| SceneError::Core {
        file: file.into(),
        context: "assembly".into(),
        source: Box::new(source),
    })?;
    Ok(Model {
        mesh,
        body_names,
        dofs,
        k: asm.k,
        m: asm.m,
        total_mass: asm.total_mass,
        sizes,
        build_time_s: start.elapsed().as_secs_f64(),
        contact,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn graded_respects_breaks_and_size() {
        let v = graded(&[0.0, 1.0, 0.25], &|_, _| 0.1);
        assert!(v.iter().any(|&x| (x - 0.25).abs() < 1e-14));
        assert!(v.windows(2).all(|w| w[1] - w[0] <= 0.1 + 1e-12));
        assert_eq!(v.first(), Some(&0.0));
        assert_eq!(v.last(), Some(&1.0));
    }

    #[test]
    fn invert6_inverts() {
        let mut d = [[0.0; 6]; 6];
        for i in 0..6 {
            d[i][i] = 2.0 + i as f64;
            if i > 0 {
                d[i][i - 1] = 0.5;
                d[i - 1][i] = 0.5;
            }
        }
        let inv = invert6(d);
        for i in 0..6 {
            for j in 0..6 {
                let s: f64 = (0..6).map(|k| d[i][k] * inv[k][j]).sum();
                approx::assert_abs_diff_eq!(s, if i == j { 1.0 } else { 0.0 }, epsilon = 1e-13);
            }
        }
    }
}
