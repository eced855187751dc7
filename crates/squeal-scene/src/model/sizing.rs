//! Element sizes from the band (bending wavelength), graded grid lines, and the node
//! budget a build is checked against before each block of nodes is made.

use crate::{Result, SceneError};
use squeal_core::Material;
use squeal_fe::mesh::join;
use squeal_fe::Mesh;

/// The node count of a build, checked before each block of nodes is made.
pub(super) struct NodeBudget {
    max_dofs: usize,
    parts: Vec<(&'static str, usize)>,
}

impl NodeBudget {
    pub(super) fn new(max_dofs: usize) -> Self {
        Self {
            max_dofs,
            parts: Vec::new(),
        }
    }

    /// Accounts for a block of `dims` nodes of `what`; refuses the build when the total
    /// passes the budget.
    pub(super) fn take(&mut self, what: &'static str, dims: &[usize], file: &str) -> Result<()> {
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
pub(super) fn append_imported(
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
pub(super) fn graded(breaks: &[f64], size: &dyn Fn(f64, f64) -> f64) -> Vec<f64> {
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

pub(super) fn within(v: &[f64], lo: f64, hi: f64) -> Vec<f64> {
    let eps = 1e-12 * (1.0 + hi.abs().max(lo.abs()));
    v.iter()
        .copied()
        .filter(|&x| x >= lo - eps && x <= hi + eps)
        .collect()
}

/// Makes `edge` a line of the increasing grid `v`: the nearest line outside the contact
/// grid `fixed` moves onto it when that keeps the neighbouring elements at least 40 % of
/// their former size, otherwise a new line is inserted.
pub(super) fn insert_edge(v: &mut Vec<f64>, fixed: &[f64], edge: f64) {
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
