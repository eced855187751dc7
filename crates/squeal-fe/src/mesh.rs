//! Hexahedral meshes: structured generators (blocks, annuli), gluing of bodies and
//! named node sets.
//!
//! Node order of a hexahedron is VTK's / Abaqus C3D8: nodes 0-3 on the bottom face
//! counter-clockwise seen from +zeta, nodes 4-7 above them. Coordinates in metres.

use std::collections::{BTreeMap, HashMap};

/// A hexahedral mesh of one or several bodies.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Node coordinates (m).
    pub nodes: Vec<[f64; 3]>,
    /// Element connectivity.
    pub hexes: Vec<[usize; 8]>,
    /// Body index of each element (into the list of body materials).
    pub hex_body: Vec<usize>,
    /// Named node sets (clamped faces, contact faces...), sorted node indices.
    pub node_sets: BTreeMap<String, Vec<usize>>,
}

/// `n + 1` equally spaced values from `a` to `b`.
pub fn linspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..=n).map(|i| a + (b - a) * i as f64 / n as f64).collect()
}

/// Concatenates coordinate segments, dropping the repeated joint values:
/// `join(&[linspace(0,1,2), linspace(1,3,2)])` = `[0, 0.5, 1, 2, 3]`.
pub fn join(segments: &[Vec<f64>]) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::new();
    for s in segments {
        for &v in s {
            if out
                .last()
                .is_none_or(|&l| (v - l).abs() > 1e-12 * (1.0 + v.abs()))
            {
                out.push(v);
            }
        }
    }
    out
}

/// Steps that grow geometrically by `ratio` from `h0` up to `h` and then stay at most
/// `h`, covering exactly `len`: the grading away from a refined zone. The geometric
/// steps are rescaled when the remainder would be a sliver.
pub fn graded_steps(len: f64, h0: f64, h: f64, ratio: f64) -> Vec<f64> {
    if len <= 0.0 {
        return Vec::new();
    }
    let ratio = ratio.max(1.0 + 1e-6);
    let mut steps = Vec::new();
    let mut total = 0.0;
    let mut s = h0;
    while s * ratio < h {
        s *= ratio;
        if total + s > len {
            break;
        }
        steps.push(s);
        total += s;
    }
    let rem = len - total;
    let last = steps.last().copied().unwrap_or(h0);
    if rem < 0.5 * last && !steps.is_empty() {
        let f = len / total;
        steps.iter_mut().for_each(|x| *x *= f);
    } else if rem > 0.0 {
        let n = ((rem / h) - 1e-9).ceil().max(1.0) as usize;
        steps.extend(std::iter::repeat_n(rem / n as f64, n));
    }
    steps
}

/// Volume of a trilinear hexahedron (2x2x2 Gauss rule, exact for it).
pub fn hex_volume(x: &[[f64; 3]; 8]) -> f64 {
    const S: [[f64; 3]; 8] = crate::hex8::NODE_NATURAL;
    let g = 1.0 / 3f64.sqrt();
    let mut vol = 0.0;
    for q in S {
        let p = [q[0] * g, q[1] * g, q[2] * g];
        let mut j = [[0.0; 3]; 3];
        for (a, s) in S.iter().enumerate() {
            let dn = [
                s[0] * (1.0 + s[1] * p[1]) * (1.0 + s[2] * p[2]) / 8.0,
                s[1] * (1.0 + s[0] * p[0]) * (1.0 + s[2] * p[2]) / 8.0,
                s[2] * (1.0 + s[0] * p[0]) * (1.0 + s[1] * p[1]) / 8.0,
            ];
            for r in 0..3 {
                for c in 0..3 {
                    j[r][c] += dn[r] * x[a][c];
                }
            }
        }
        vol += j[0][0] * (j[1][1] * j[2][2] - j[1][2] * j[2][1])
            - j[0][1] * (j[1][0] * j[2][2] - j[1][2] * j[2][0])
            + j[0][2] * (j[1][0] * j[2][1] - j[1][1] * j[2][0]);
    }
    vol
}

/// Ties the nodes `slaves` to a face of a coarser mesh: the `masters` nodes, which form a
/// tensor grid on the lines `xs` x `ys` (increasing, one node per intersection, to `1e-9`
/// of the grid's size in x and y), one plane of it. Each slave gets the bilinear weights
/// of the grid cell over its (x, y) (one weight 1 where it sits on a master). A slave
/// outside the grid, or a grid intersection without a master node, is an error message.
pub fn face_ties(
    mesh: &Mesh,
    slaves: &[usize],
    masters: &[usize],
    xs: &[f64],
    ys: &[f64],
) -> Result<Vec<crate::dofs::Tie>, String> {
    let (nx, ny) = (xs.len(), ys.len());
    if nx < 2 || ny < 2 {
        return Err(format!("a master grid needs 2 x 2 lines, got {nx} x {ny}"));
    }
    let size = (xs[nx - 1] - xs[0]).max(ys[ny - 1] - ys[0]);
    let tol = 1e-9 * size;
    let line = |v: &[f64], x: f64| {
        let i = v.partition_point(|&l| l < x - tol);
        (i < v.len() && (v[i] - x).abs() <= tol).then_some(i)
    };
    let mut at = vec![usize::MAX; nx * ny];
    for &m in masters {
        let p = mesh.nodes[m];
        if let (Some(i), Some(j)) = (line(xs, p[0]), line(ys, p[1])) {
            if at[j * nx + i] != usize::MAX && at[j * nx + i] != m {
                return Err(format!(
                    "two master nodes ({} and {m}) at grid point ({:e}, {:e}) m",
                    at[j * nx + i],
                    p[0],
                    p[1]
                ));
            }
            at[j * nx + i] = m;
        }
    }
    if let Some(k) = at.iter().position(|&m| m == usize::MAX) {
        return Err(format!(
            "no master node at grid point ({:e}, {:e}) m",
            xs[k % nx],
            ys[k / nx]
        ));
    }
    // cell index and local coordinate in [0, 1] along one axis
    let cell = |v: &[f64], x: f64| -> Option<(usize, f64)> {
        if x < v[0] - tol || x > v[v.len() - 1] + tol {
            return None;
        }
        let i = (v.partition_point(|&l| l <= x).max(1) - 1).min(v.len() - 2);
        Some((i, ((x - v[i]) / (v[i + 1] - v[i])).clamp(0.0, 1.0)))
    };
    slaves
        .iter()
        .map(|&s| {
            let p = mesh.nodes[s];
            let (Some((i, u)), Some((j, v))) = (cell(xs, p[0]), cell(ys, p[1])) else {
                return Err(format!(
                    "node {s} at ({:e}, {:e}) m lies outside the master grid [{:e}, {:e}] x \
                     [{:e}, {:e}] m",
                    p[0],
                    p[1],
                    xs[0],
                    xs[nx - 1],
                    ys[0],
                    ys[ny - 1]
                ));
            };
            let w = [
                (i, j, (1.0 - u) * (1.0 - v)),
                (i + 1, j, u * (1.0 - v)),
                (i, j + 1, (1.0 - u) * v),
                (i + 1, j + 1, u * v),
            ];
            let masters = w
                .iter()
                .filter(|c| c.2.abs() > 1e-12)
                .map(|&(a, b, wt)| (at[b * nx + a], wt))
                .collect();
            Ok(crate::dofs::Tie { slave: s, masters })
        })
        .collect()
}

impl Mesh {
    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.nodes.len()
    }

    /// A structured block on the tensor grid `xs x ys x zs` (strictly increasing), body 0.
    /// Node sets: `xmin`, `xmax`, `ymin`, `ymax`, `zmin`, `zmax`.
    pub fn block(xs: &[f64], ys: &[f64], zs: &[f64]) -> Mesh {
        let (nx, ny, nz) = (xs.len(), ys.len(), zs.len());
        let id = |i: usize, j: usize, k: usize| (k * ny + j) * nx + i;
        let mut mesh = Mesh::default();
        for &z in zs {
            for &y in ys {
                for &x in xs {
                    mesh.nodes.push([x, y, z]);
                }
            }
        }
        for k in 0..nz - 1 {
            for j in 0..ny - 1 {
                for i in 0..nx - 1 {
                    mesh.hexes.push([
                        id(i, j, k),
                        id(i + 1, j, k),
                        id(i + 1, j + 1, k),
                        id(i, j + 1, k),
                        id(i, j, k + 1),
                        id(i + 1, j, k + 1),
                        id(i + 1, j + 1, k + 1),
                        id(i, j + 1, k + 1),
                    ]);
                }
            }
        }
        mesh.hex_body = vec![0; mesh.hexes.len()];
        let sets: [(&str, usize, usize); 6] = [
            ("xmin", 0, 0),
            ("xmax", 0, nx - 1),
            ("ymin", 1, 0),
            ("ymax", 1, ny - 1),
            ("zmin", 2, 0),
            ("zmax", 2, nz - 1),
        ];
        for (name, axis, at) in sets {
            let mut v = Vec::new();
            for k in 0..nz {
                for j in 0..ny {
                    for i in 0..nx {
                        if [i, j, k][axis] == at {
                            v.push(id(i, j, k));
                        }
                    }
                }
            }
            mesh.node_sets.insert(name.to_string(), v);
        }
        mesh
    }

    /// A structured annulus about the z axis: radii `rs` (increasing), `n_theta`
    /// equal sectors (periodic), heights `zs` (increasing), body 0.
    /// Node sets: `inner` (r = `rs[0]`), `outer`, `zmin`, `zmax`.
    pub fn annulus(rs: &[f64], n_theta: usize, zs: &[f64]) -> Mesh {
        let thetas: Vec<f64> = (0..n_theta)
            .map(|t| 2.0 * std::f64::consts::PI * t as f64 / n_theta as f64)
            .collect();
        Mesh::annulus_mapped(rs, &thetas, zs, &|r, th| [r * th.cos(), r * th.sin()])
    }

    /// A structured annulus on the polar grid `rs x thetas x zs` whose in-plane node
    /// positions come from `map(r, theta)` (polar coordinates, or a blend of polar and
    /// Cartesian as for a contact patch). `thetas` is increasing, spans less than one turn
    /// and is closed periodically. Node sets as for [`annulus`](Self::annulus).
    pub fn annulus_mapped(
        rs: &[f64],
        thetas: &[f64],
        zs: &[f64],
        map: &dyn Fn(f64, f64) -> [f64; 2],
    ) -> Mesh {
        let (nr, nz, n_theta) = (rs.len(), zs.len(), thetas.len());
        let id = |i: usize, t: usize, k: usize| (k * n_theta + (t % n_theta)) * nr + i;
        let mut mesh = Mesh::default();
        for &z in zs {
            for &th in thetas {
                for &r in rs {
                    let [x, y] = map(r, th);
                    mesh.nodes.push([x, y, z]);
                }
            }
        }
        for k in 0..nz - 1 {
            for t in 0..n_theta {
                for i in 0..nr - 1 {
                    // (r, theta, z) right-handed like (x, y, z)
                    mesh.hexes.push([
                        id(i, t, k),
                        id(i + 1, t, k),
                        id(i + 1, t + 1, k),
                        id(i, t + 1, k),
                        id(i, t, k + 1),
                        id(i + 1, t, k + 1),
                        id(i + 1, t + 1, k + 1),
                        id(i, t + 1, k + 1),
                    ]);
                }
            }
        }
        mesh.hex_body = vec![0; mesh.hexes.len()];
        let mut set = |name: &str, pred: &dyn Fn(usize, usize) -> bool| {
            let mut v = Vec::new();
            for k in 0..nz {
                for t in 0..n_theta {
                    for i in 0..nr {
                        if pred(i, k) {
                            v.push(id(i, t, k));
                        }
                    }
                }
            }
            v.sort_unstable();
            mesh.node_sets.insert(name.to_string(), v);
        };
        set("inner", &|i, _| i == 0);
        set("outer", &|i, _| i == nr - 1);
        set("zmin", &|_, k| k == 0);
        set("zmax", &|_, k| k == nz - 1);
        mesh
    }

    /// Sets every element's body index.
    pub fn with_body(mut self, body: usize) -> Self {
        self.hex_body.iter_mut().for_each(|b| *b = body);
        self
    }

    /// Appends `other`. With `glue = Some(tol)`, its nodes closer than `tol` (m) to
    /// existing nodes are merged with them (a perfect bond, as for the glued pin); with
    /// `None` the bodies stay separate even where they touch (the pin on the disc).
    /// Node sets of `other` are renamed `prefix` + name. Returns the new index of each
    /// node of `other`.
    pub fn append(&mut self, other: &Mesh, prefix: &str, glue: Option<f64>) -> Vec<usize> {
        let tol = glue.unwrap_or(1.0);
        let key = |p: &[f64; 3]| {
            [
                (p[0] / tol).round() as i64,
                (p[1] / tol).round() as i64,
                (p[2] / tol).round() as i64,
            ]
        };
        let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
        for (i, p) in self.nodes.iter().enumerate().filter(|_| glue.is_some()) {
            grid.entry(key(p)).or_default().push(i);
        }
        let find = |p: &[f64; 3]| -> Option<usize> {
            let k = key(p);
            for dx in -1..=1 {
                for dy in -1..=1 {
                    for dz in -1..=1 {
                        if let Some(c) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                            for &i in c {
                                let q = self.nodes[i];
                                let d2 = (0..3).map(|a| (p[a] - q[a]).powi(2)).sum::<f64>();
                                if d2 <= tol * tol {
                                    return Some(i);
                                }
                            }
                        }
                    }
                }
            }
            None
        };
        let mut map = Vec::with_capacity(other.nodes.len());
        let mut new_nodes = Vec::new();
        for p in &other.nodes {
            match find(p) {
                Some(i) => map.push(i),
                None => {
                    map.push(self.nodes.len() + new_nodes.len());
                    new_nodes.push(*p);
                }
            }
        }
        self.nodes.extend(new_nodes);
        for h in &other.hexes {
            self.hexes.push(h.map(|n| map[n]));
        }
        self.hex_body.extend_from_slice(&other.hex_body);
        for (name, set) in &other.node_sets {
            let mut v: Vec<usize> = set.iter().map(|&n| map[n]).collect();
            v.sort_unstable();
            v.dedup();
            self.node_sets.insert(format!("{prefix}{name}"), v);
        }
        map
    }

    /// Corner coordinates of element `e`.
    pub fn hex_coords(&self, e: usize) -> [[f64; 3]; 8] {
        self.hexes[e].map(|n| self.nodes[n])
    }

    /// Node set by name, or an error message listing the known sets.
    pub fn node_set(&self, name: &str) -> Result<&[usize], String> {
        self.node_sets
            .get(name)
            .map(|v| v.as_slice())
            .ok_or_else(|| {
                format!(
                    "no node set `{name}`; known: {}",
                    self.node_sets
                        .keys()
                        .cloned()
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            })
    }

    /// Nodes used by elements of `body`, sorted.
    pub fn body_nodes(&self, body: usize) -> Vec<usize> {
        let mut v: Vec<usize> = self
            .hexes
            .iter()
            .zip(&self.hex_body)
            .filter(|(_, &b)| b == body)
            .flat_map(|(h, _)| h.iter().copied())
            .collect();
        v.sort_unstable();
        v.dedup();
        v
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn block_counts_and_sets() {
        let m = Mesh::block(
            &linspace(0.0, 2.0, 4),
            &linspace(0.0, 1.0, 2),
            &linspace(0.0, 1.0, 1),
        );
        assert_eq!(m.n_nodes(), 5 * 3 * 2);
        assert_eq!(m.hexes.len(), 4 * 2);
        assert_eq!(m.node_set("xmin").unwrap().len(), 3 * 2);
        assert!(m.node_set("nope").unwrap_err().contains("xmin"));
    }

    #[test]
    fn annulus_is_periodic_and_right_handed() {
        let m = Mesh::annulus(&linspace(0.05, 0.1, 2), 12, &linspace(0.0, 0.01, 1));
        assert_eq!(m.n_nodes(), 3 * 12 * 2);
        assert_eq!(m.hexes.len(), 2 * 12);
        // every node used, outer nodes on the circle
        for &n in m.node_set("outer").unwrap() {
            let p = m.nodes[n];
            approx::assert_relative_eq!((p[0] * p[0] + p[1] * p[1]).sqrt(), 0.1, epsilon = 1e-14);
        }
        // positive orientation: (n1 - n0) x (n3 - n0) . (n4 - n0) > 0
        for e in 0..m.hexes.len() {
            let x = m.hex_coords(e);
            let d = |a: usize| [x[a][0] - x[0][0], x[a][1] - x[0][1], x[a][2] - x[0][2]];
            let (a, b, c) = (d(1), d(3), d(4));
            let cross = [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ];
            assert!(cross[0] * c[0] + cross[1] * c[1] + cross[2] * c[2] > 0.0);
        }
    }

    #[test]
    fn append_glues_coincident_nodes() {
        let mut a = Mesh::block(
            &linspace(0.0, 1.0, 2),
            &linspace(0.0, 1.0, 2),
            &linspace(0.0, 1.0, 1),
        );
        let b = Mesh::block(
            &linspace(0.0, 1.0, 2),
            &linspace(0.0, 1.0, 2),
            &linspace(1.0, 2.0, 1),
        )
        .with_body(1);
        let map = a.append(&b, "top.", Some(1e-9));
        assert_eq!(a.n_nodes(), 9 * 3);
        assert_eq!(a.hexes.len(), 8);
        // the bottom face of b is the top face of a
        for &n in b.node_set("zmin").unwrap() {
            assert!(map[n] < 18);
        }
        assert_eq!(a.body_nodes(1).len(), 18);
        assert!(a.node_sets.contains_key("top.zmax"));
    }

    #[test]
    fn volume_of_annulus_and_sheared_block() {
        let m = Mesh::annulus(&linspace(0.05, 0.1, 4), 64, &linspace(0.0, 0.01, 1));
        let v: f64 = (0..m.hexes.len())
            .map(|e| hex_volume(&m.hex_coords(e)))
            .sum();
        // polygonal annulus: n/2 sin(2 pi/n) (R^2 - r^2) h
        let n = 64.0;
        let exact = n / 2.0 * (2.0 * std::f64::consts::PI / n).sin() * (0.01 - 0.0025) * 0.01;
        approx::assert_relative_eq!(v, exact, max_relative = 1e-12);
        let mut x = Mesh::block(&[0.0, 2.0], &[0.0, 1.0], &[0.0, 1.0]).hex_coords(0);
        for p in x.iter_mut() {
            p[0] += 0.5 * p[2];
        }
        approx::assert_relative_eq!(hex_volume(&x), 2.0, max_relative = 1e-14);
    }

    #[test]
    fn join_drops_repeated_joints() {
        let v = join(&[linspace(0.0, 1.0, 2), linspace(1.0, 3.0, 2)]);
        assert_eq!(v, vec![0.0, 0.5, 1.0, 2.0, 3.0]);
    }
}
