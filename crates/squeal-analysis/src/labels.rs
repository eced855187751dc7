//! Automatic mode labels.
//!
//! **Disc** (Table 2 convention of the paper): `a,m,n` for axial-dominant modes with `m`
//! nodal circles and `n` nodal diameters, `r,n` radial and `c,n` circumferential. The
//! kind is the cylindrical component with the largest kinetic-energy share (nodal
//! weights = element volume shares); `n` is the circumferential harmonic holding most
//! of that component's energy (Parseval over each ring of nodes); `m` is the number of
//! sign changes along the radius of the axial harmonic-`n` profile on the friction face,
//! after aligning its phase and ignoring values below 10 % of the peak. In-plane modes
//! with one nodal diameter (a translation of the ring: radial and circumferential
//! energies equal) are called `c,1`, as in the paper.
//!
//! A label the mesh cannot support says so with `?` for the nodal diameters (`a,0,?`,
//! `r,?`): when the typical ring holds fewer than the `2n + 1` nodes harmonic `n` needs
//! ([`label_disc`]), and when two distinct modes or doublets of one solve would get the
//! same label ([`crate::modal::unresolve_repeated_labels`]): one of them at least is
//! wrong (an aliased harmonic, or an order the label does not show), and nothing tells
//! which.
//!
//! **Pin** (pin + plates): the pin block's best-fit rigid motion `t + w x (x - c)`
//! names the mode: `shift-x`, `shift-y`, `bounce-z`, `tilt-x`, `tilt-y` (rotation about
//! that axis) or `twist-z`, whichever moves the pin face most.

use serde::Serialize;
use squeal_fe::Mesh;
use std::collections::BTreeMap;
use std::fmt;

/// A disc mode label.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct DiscLabel {
    /// `'a'` axial, `'r'` radial, `'c'` circumferential.
    pub kind: char,
    /// Nodal circles (axial modes only).
    pub circles: Option<usize>,
    /// Nodal diameters (the best estimate when not [`resolved`](Self::resolved)).
    pub diameters: usize,
    /// Whether the mesh resolves `diameters`: the typical ring of nodes holds at least
    /// `2 diameters + 1` nodes. An unresolved count is written `?`.
    pub resolved: bool,
}

impl fmt::Display for DiscLabel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let n = if self.resolved {
            self.diameters.to_string()
        } else {
            "?".into()
        };
        match self.circles {
            Some(m) => write!(f, "{},{},{n}", self.kind, m),
            None => write!(f, "{},{n}", self.kind),
        }
    }
}

/// `label` with its nodal-diameter count (the last field) replaced by `?`: `a,0,1` ->
/// `a,0,?`, `c,1` -> `c,?`.
pub fn unresolved_label(label: &str) -> String {
    match label.rsplit_once(',') {
        Some((head, _)) => format!("{head},?"),
        None => format!("{label},?"),
    }
}

/// Nodal weights: each element's volume shared equally among its 8 nodes.
pub fn nodal_weights(mesh: &Mesh) -> Vec<f64> {
    let mut w = vec![0.0; mesh.n_nodes()];
    for (e, h) in mesh.hexes.iter().enumerate() {
        let v = squeal_fe::mesh::hex_volume(&mesh.hex_coords(e));
        for &n in h {
            w[n] += v / 8.0;
        }
    }
    w
}

/// Kinetic-energy-like share of each body (by `mesh.hex_body`) in a full-DOF vector.
pub fn body_shares(mesh: &Mesh, weights: &[f64], u: &[f64], n_bodies: usize) -> Vec<f64> {
    let mut node_body = vec![usize::MAX; mesh.n_nodes()];
    for (h, &b) in mesh.hexes.iter().zip(&mesh.hex_body) {
        for &n in h {
            node_body[n] = b;
        }
    }
    let mut e = vec![0.0; n_bodies];
    for (n, &b) in node_body.iter().enumerate() {
        if b < n_bodies {
            e[b] += weights[n] * (0..3).map(|c| u[3 * n + c].powi(2)).sum::<f64>();
        }
    }
    let total: f64 = e.iter().sum::<f64>().max(f64::MIN_POSITIVE);
    e.iter().map(|x| x / total).collect()
}

/// Labels a disc mode from its full-DOF shape `u`; `nodes` are the disc's nodes
/// (axis = z, friction face at the largest z).
pub fn label_disc(mesh: &Mesh, weights: &[f64], nodes: &[usize], u: &[f64]) -> DiscLabel {
    // cylindrical components and energy shares
    let mut energy = [0.0; 3]; // r, theta, z
    let cyl: Vec<(f64, f64, f64, [f64; 3])> = nodes
        .iter()
        .map(|&n| {
            let p = mesh.nodes[n];
            let (r, th) = (p[0].hypot(p[1]), p[1].atan2(p[0]));
            let (c, s) = (th.cos(), th.sin());
            let (ux, uy, uz) = (u[3 * n], u[3 * n + 1], u[3 * n + 2]);
            let v = [c * ux + s * uy, -s * ux + c * uy, uz];
            for k in 0..3 {
                energy[k] += weights[n] * v[k] * v[k];
            }
            (r, th, p[2], v)
        })
        .collect();
    let comp = (0..3)
        .max_by(|&a, &b| energy[a].total_cmp(&energy[b]))
        .unwrap();
    let kind = ['r', 'c', 'a'][comp];
    // Rings of nodes: same z, radii binned (the mesh may be graded in theta and blended
    // into a Cartesian patch under the pin, so radii on a ring are only nearly equal and
    // angles are not uniform). Fourier coefficients are nodal-weight quadratures of
    // `v exp(-i n theta)`, normalized per ring.
    let (rmin, rmax) = cyl.iter().fold((f64::INFINITY, 0.0f64), |(a, b), c| {
        (a.min(c.0), b.max(c.0))
    });
    let dr = ((rmax - rmin) / 24.0).max(1e-9);
    let key = |r: f64, z: f64| (((r - rmin) / dr).round() as i64, (z * 1e7).round() as i64);
    let mut rings: BTreeMap<(i64, i64), Vec<usize>> = BTreeMap::new();
    for (i, c) in cyl.iter().enumerate() {
        rings.entry(key(c.0, c.2)).or_default().push(i);
    }
    // A radius bin that catches only a few nodes (where the binning cuts across the
    // blended patch or a thin part such as the hat) is not a ring and would cap the
    // resolvable harmonic: keep the rings of at least a quarter of the median size.
    let mut sizes: Vec<usize> = rings.values().map(Vec::len).collect();
    sizes.sort_unstable();
    let median = sizes.get(sizes.len() / 2).copied().unwrap_or(0);
    rings.retain(|_, ring| 4 * ring.len() >= median);
    let mut sizes: Vec<usize> = rings.values().map(Vec::len).collect();
    sizes.sort_unstable();
    let typical = sizes.get(sizes.len() / 2).copied().unwrap_or(0);
    let ring_weight =
        |ring: &[usize]| -> f64 { ring.iter().map(|&i| weights[nodes[i]]).sum::<f64>() };
    let nmax = rings.values().map(|v| v.len()).min().unwrap_or(2) / 2;
    let coeff = |ring: &[usize], n: usize, k: usize| -> (f64, f64) {
        let (re, im) = ring.iter().fold((0.0, 0.0), |(re, im), &i| {
            let (_, th, _, v) = cyl[i];
            let w = weights[nodes[i]];
            let a = n as f64 * th;
            (re + w * v[k] * a.cos(), im - w * v[k] * a.sin())
        });
        let tot = ring_weight(ring).max(f64::MIN_POSITIVE);
        (re / tot, im / tot)
    };
    let mut best = (0usize, -1.0);
    for n in 0..=nmax {
        let mut e = 0.0;
        for ring in rings.values() {
            let (re, im) = coeff(ring, n, comp);
            let factor = if n == 0 { 1.0 } else { 2.0 };
            e += ring_weight(ring) * factor * (re * re + im * im);
        }
        if e > best.1 {
            best = (n, e);
        }
    }
    let diameters = best.0;
    // harmonic n needs 2n + 1 nodes around the ring; at or beyond the Nyquist limit it
    // cannot be told from its aliases
    let resolved = 2 * diameters < typical;
    // In-plane motion with one nodal diameter is the ring's translation, with equal
    // radial and circumferential energy; the paper (and common usage) calls it c,1.
    let kind = if kind == 'r' && diameters == 1 {
        'c'
    } else {
        kind
    };
    let circles = (kind == 'a').then(|| {
        let ztop = cyl.iter().map(|c| c.2).fold(f64::NEG_INFINITY, f64::max);
        let face: Vec<(f64, (f64, f64))> = rings
            .iter()
            .filter(|((_, z), _)| (*z as f64 * 1e-7 - ztop).abs() < 1e-9 + 1e-6 * ztop.abs())
            .filter(|(_, ring)| ring.len() > 2 * diameters)
            .map(|(_, ring)| (cyl[ring[0]].0, coeff(ring, diameters, 2)))
            .collect();
        // phase that makes the profile as real as possible: half the angle of sum C^2
        let (sr, si) = face.iter().fold((0.0, 0.0), |(a, b), (_, (re, im))| {
            (a + re * re - im * im, b + 2.0 * re * im)
        });
        let phi = 0.5 * si.atan2(sr);
        let prof: Vec<f64> = face
            .iter()
            .map(|(_, (re, im))| re * phi.cos() + im * phi.sin())
            .collect();
        let peak = prof.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
        let signs: Vec<bool> = prof
            .iter()
            .filter(|v| v.abs() > 0.1 * peak)
            .map(|&v| v > 0.0)
            .collect();
        signs.windows(2).filter(|w| w[0] != w[1]).count()
    });
    DiscLabel {
        kind,
        circles,
        diameters,
        resolved,
    }
}

/// Labels a mode of the pin assembly by the pin's best-fit rigid motion.
pub fn label_pin(mesh: &Mesh, pin_nodes: &[usize], u: &[f64]) -> String {
    let n = pin_nodes.len() as f64;
    let mut c = [0.0; 3];
    for &p in pin_nodes {
        for k in 0..3 {
            c[k] += mesh.nodes[p][k] / n;
        }
    }
    // least squares for [t; w]: u_p = t + w x d = t - [d]x w
    let mut a = [[0.0; 6]; 6];
    let mut b = [0.0; 6];
    let mut size: f64 = 0.0;
    for &p in pin_nodes {
        let d = [
            mesh.nodes[p][0] - c[0],
            mesh.nodes[p][1] - c[1],
            mesh.nodes[p][2] - c[2],
        ];
        size = size.max(d[0].abs()).max(d[1].abs());
        // rows: u_x = t_x + w_y d_z - w_z d_y, etc.
        let rows = [
            [1.0, 0.0, 0.0, 0.0, d[2], -d[1]],
            [0.0, 1.0, 0.0, -d[2], 0.0, d[0]],
            [0.0, 0.0, 1.0, d[1], -d[0], 0.0],
        ];
        for (k, row) in rows.iter().enumerate() {
            for i in 0..6 {
                b[i] += row[i] * u[3 * p + k];
                for j in 0..6 {
                    a[i][j] += row[i] * row[j];
                }
            }
        }
    }
    let x = solve6(a, b);
    let score = [
        x[0].abs(),
        x[1].abs(),
        x[2].abs(),
        x[3].abs() * size,
        x[4].abs() * size,
        x[5].abs() * size,
    ];
    let names = [
        "shift-x", "shift-y", "bounce-z", "tilt-x", "tilt-y", "twist-z",
    ];
    let i = (0..6)
        .max_by(|&i, &j| score[i].total_cmp(&score[j]))
        .unwrap();
    names[i].to_string()
}

fn solve6(mut a: [[f64; 6]; 6], mut b: [f64; 6]) -> [f64; 6] {
    for c in 0..6 {
        let p = (c..6)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap();
        a.swap(c, p);
        b.swap(c, p);
        let piv = a[c][c];
        if piv.abs() < 1e-300 {
            continue;
        }
        for r in c + 1..6 {
            let f = a[r][c] / piv;
            for j in c..6 {
                a[r][j] -= f * a[c][j];
            }
            b[r] -= f * b[c];
        }
    }
    let mut x = [0.0; 6];
    for c in (0..6).rev() {
        let s: f64 = (c + 1..6).map(|j| a[c][j] * x[j]).sum();
        x[c] = if a[c][c].abs() < 1e-300 {
            0.0
        } else {
            (b[c] - s) / a[c][c]
        };
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;
    use squeal_fe::mesh::linspace;

    fn disc() -> Mesh {
        Mesh::annulus(&linspace(0.05, 0.15, 6), 48, &linspace(-0.02, 0.0, 2))
    }

    /// Synthetic fields with known labels are labelled correctly.
    #[test]
    fn synthetic_disc_fields() {
        let m = disc();
        let w = nodal_weights(&m);
        let nodes: Vec<usize> = (0..m.n_nodes()).collect();
        let field = |f: &dyn Fn(f64, f64) -> [f64; 3]| -> Vec<f64> {
            let mut u = vec![0.0; 3 * m.n_nodes()];
            for (i, p) in m.nodes.iter().enumerate() {
                let (r, th) = (p[0].hypot(p[1]), p[1].atan2(p[0]));
                let [ur, ut, uz] = f(r, th);
                u[3 * i] = ur * th.cos() - ut * th.sin();
                u[3 * i + 1] = ur * th.sin() + ut * th.cos();
                u[3 * i + 2] = uz;
            }
            u
        };
        let l = label_disc(
            &m,
            &w,
            &nodes,
            &field(&|r, th| [0.0, 0.0, (r - 0.05) * (3.0 * th + 0.3).cos()]),
        );
        assert_eq!(l.to_string(), "a,0,3");
        let l = label_disc(
            &m,
            &w,
            &nodes,
            &field(&|r, th| [0.0, 0.0, (r - 0.11) * (2.0 * th).sin()]),
        );
        assert_eq!(l.to_string(), "a,1,2");
        let l = label_disc(&m, &w, &nodes, &field(&|r, _| [0.0, r, 0.0]));
        assert_eq!(l.to_string(), "c,0");
        let l = label_disc(
            &m,
            &w,
            &nodes,
            &field(&|r, th| [r * (2.0 * th).cos(), 0.2 * r * (2.0 * th).sin(), 0.0]),
        );
        assert_eq!(l.to_string(), "r,2");
    }

    /// A harmonic the rings cannot resolve is labelled with `?`, not with its alias.
    #[test]
    fn unresolvable_diameters_say_so() {
        // 8 nodes per ring: n = 3 is resolved, n = 4 (the Nyquist limit) is not
        let m = Mesh::annulus(&linspace(0.05, 0.15, 4), 8, &linspace(-0.02, 0.0, 2));
        let w = nodal_weights(&m);
        let nodes: Vec<usize> = (0..m.n_nodes()).collect();
        let axial = |n: f64| -> Vec<f64> {
            let mut u = vec![0.0; 3 * m.n_nodes()];
            for (i, p) in m.nodes.iter().enumerate() {
                let (r, th) = (p[0].hypot(p[1]), p[1].atan2(p[0]));
                u[3 * i + 2] = (r - 0.05) * (n * th).cos();
            }
            u
        };
        assert_eq!(label_disc(&m, &w, &nodes, &axial(3.0)).to_string(), "a,0,3");
        let l = label_disc(&m, &w, &nodes, &axial(4.0));
        assert!(!l.resolved, "{l:?}");
        assert_eq!(l.to_string(), "a,0,?");
    }

    #[test]
    fn unresolved_label_forms() {
        assert_eq!(unresolved_label("a,0,1"), "a,0,?");
        assert_eq!(unresolved_label("a,1,12"), "a,1,?");
        assert_eq!(unresolved_label("c,1"), "c,?");
        assert_eq!(unresolved_label("r,0"), "r,?");
    }

    #[test]
    fn pin_rigid_motions() {
        let m = Mesh::block(
            &linspace(-0.01, 0.01, 2),
            &linspace(0.09, 0.11, 2),
            &linspace(0.0, 0.015, 2),
        );
        let nodes: Vec<usize> = (0..m.n_nodes()).collect();
        let mut u = vec![0.0; 3 * m.n_nodes()];
        // rotation about y through the centre: u_x = w z', u_z = -w x'
        for (i, p) in m.nodes.iter().enumerate() {
            u[3 * i] = p[2] - 0.0075;
            u[3 * i + 2] = -p[0];
        }
        assert_eq!(label_pin(&m, &nodes, &u), "tilt-y");
        let mut v = vec![0.0; 3 * m.n_nodes()];
        for i in 0..m.n_nodes() {
            v[3 * i + 2] = 1.0;
        }
        assert_eq!(label_pin(&m, &nodes, &v), "bounce-z");
    }
}
