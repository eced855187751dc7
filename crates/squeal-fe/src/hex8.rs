//! # Eight-node hexahedron with incompatible modes
//!
//! Element matrices of the trilinear hexahedron enriched with Wilson's incompatible
//! (bubble) modes and Taylor's correction, the element known in the literature as
//! Q1/E9, "HEX8 with incompatible modes" or Abaqus C3D8I.
//!
//! ## Geometry
//!
//! Node order is the VTK / Abaqus C3D8 one: nodes 0..3 on the face `zeta = -1` at
//! `(xi, eta) = (-1,-1), (1,-1), (1,1), (-1,1)`, nodes 4..7 the same on `zeta = +1`
//! ([`NODE_NATURAL`]). With the trilinear shape functions
//!
//! ```text
//! N_i(xi, eta, zeta) = 1/8 (1 + xi_i xi) (1 + eta_i eta) (1 + zeta_i zeta),
//! x(xi) = sum_i N_i(xi) x_i,
//! ```
//!
//! the Jacobian is `J_ab = d x_b / d xi_a = sum_i dN_i/dxi_a x_ib` and the physical
//! gradients are `grad_x N_i = J^-1 grad_xi N_i`. DOFs are node-major: node `i`
//! carries `3i, 3i+1, 3i+2 = (ux, uy, uz)`.
//!
//! ## Stiffness
//!
//! Strains are in Voigt order `(xx, yy, zz, xy, yz, zx)` with engineering shears
//! (see [`squeal_core::material`]). The displacement field is
//!
//! ```text
//! u(xi) = sum_i N_i(xi) u_i + sum_m P_m(xi) a_m,
//! P_1 = 1 - xi^2,  P_2 = 1 - eta^2,  P_3 = 1 - zeta^2,
//! ```
//!
//! with nine internal amplitudes `a_m` (three modes, three components), the incompatible
//! modes of Wilson, Taylor, Doherty & Ghaboussi (1973). They let the element bend without
//! the parasitic shear (shear locking) of the plain trilinear element. Following Taylor,
//! Beresford & Wilson (1976), their strain-displacement matrix is built with the
//! Jacobian at the element centre `J0` and scaled by `det J0 / det J`:
//!
//! ```text
//! grad_x P_m  :=  (det J0 / det J(xi)) J0^-1 grad_xi P_m(xi),
//! ```
//!
//! so that `int_V B_a dV = det J0 J0^-1 int grad_xi P dxi = 0` on any shape: constant
//! stress does no work on the internal modes, and the element passes the patch test
//! even when distorted. With `B_u` (6x24) and `B_a` (6x9) the strain operators,
//!
//! ```text
//! [Kuu Kua; Kau Kaa] = sum_gp [B_u B_a]^T D [B_u B_a] det J(xi_gp)   (2x2x2 Gauss),
//! Ke = Kuu - Kua Kaa^-1 Kau                                          (static condensation).
//! ```
//!
//! The condensation is Gaussian elimination of the nine internal DOFs on the
//! symmetric 33x33 matrix (no pivoting: `Kaa` is positive definite for a valid element
//! and material). Rigid-body motions give zero strain in the compatible part, so
//! `Ke` has exactly six zero-energy modes.
//!
//! ## Mass
//!
//! Consistent mass from the trilinear shape functions only (the internal modes carry no
//! mass), `Me[3i+c][3j+c] = rho sum_gp N_i N_j det J`, 2x2x2 Gauss (exact for an affine
//! element). The volume `sum_gp det J` is exact for any trilinear hexahedron.
//!
//! ## Validity
//!
//! The matrices are meaningful only if `det J > 0` at every Gauss point: check
//! [`Hex8Matrices::min_det_j`] (or [`min_det_jacobian`]). [`scaled_jacobian`] is the
//! corner-based quality measure (1 for a cube, <= 0 for an inverted corner).
//! All routines work on fixed-size arrays and allocate nothing.
//!
//! ## References
//!
//! - E. L. Wilson, R. L. Taylor, W. P. Doherty, J. Ghaboussi (1973), *Incompatible
//!   displacement models*, in Numerical and Computer Methods in Structural Mechanics,
//!   Academic Press, 43-57.
//! - R. L. Taylor, P. J. Beresford, E. L. Wilson (1976), *A non-conforming element for
//!   stress analysis*, Int. J. Numer. Meth. Engng 10, 1211-1219.
//! - T. J. R. Hughes (1987), *The Finite Element Method*, section 4.7.
use squeal_core::Voigt6;

/// Natural coordinates `(xi, eta, zeta)` of the eight nodes (VTK / Abaqus C3D8 order).
pub const NODE_NATURAL: [[f64; 3]; 8] = [
    [-1.0, -1.0, -1.0],
    [1.0, -1.0, -1.0],
    [1.0, 1.0, -1.0],
    [-1.0, 1.0, -1.0],
    [-1.0, -1.0, 1.0],
    [1.0, -1.0, 1.0],
    [1.0, 1.0, 1.0],
    [-1.0, 1.0, 1.0],
];

/// `1 / sqrt(3)`, the abscissa of 2-point Gauss-Legendre (weights 1).
const G: f64 = 0.577_350_269_189_625_8;

/// The 2x2x2 Gauss points (all weights are 1).
const GAUSS: [[f64; 3]; 8] = [
    [-G, -G, -G],
    [G, -G, -G],
    [G, G, -G],
    [-G, G, -G],
    [-G, -G, G],
    [G, -G, G],
    [G, G, G],
    [-G, G, G],
];

/// For each corner, its three neighbours along the edges, ordered so that the three
/// edge vectors form a right-handed triple on a valid element.
const CORNER_EDGES: [[usize; 3]; 8] = [
    [1, 3, 4],
    [2, 0, 5],
    [3, 1, 6],
    [0, 2, 7],
    [7, 5, 0],
    [4, 6, 1],
    [5, 7, 2],
    [6, 4, 3],
];

/// The 12 edges of a hexahedron as corner pairs (bottom face, top face, verticals).
pub const EDGES: [(usize, usize); 12] = [
    (0, 1),
    (1, 2),
    (2, 3),
    (3, 0),
    (4, 5),
    (5, 6),
    (6, 7),
    (7, 4),
    (0, 4),
    (1, 5),
    (2, 6),
    (3, 7),
];

/// Lengths of the 12 [`EDGES`] of a hexahedron with corners `x`.
pub fn edge_lengths(x: &[[f64; 3]; 8]) -> [f64; 12] {
    EDGES.map(|(a, c)| {
        (0..3)
            .map(|k| (x[a][k] - x[c][k]).powi(2))
            .sum::<f64>()
            .sqrt()
    })
}

/// Element matrices of one hexahedron.
#[derive(Debug, Clone)]
pub struct Hex8Matrices {
    /// Stiffness, 24 x 24, node-major DOFs (node i: 3i, 3i+1, 3i+2).
    pub ke: [[f64; 24]; 24],
    /// Consistent mass, 24 x 24.
    pub me: [[f64; 24]; 24],
    /// Volume (m^3).
    pub volume: f64,
    /// Smallest Jacobian determinant over the 8 Gauss points (m^3 per unit reference
    /// volume, the reference cube having volume 8). The matrices are meaningless when
    /// it is `<= 0` (inverted or degenerate element).
    pub min_det_j: f64,
}

/// Which internal modes enrich the trilinear field (only `TaylorCorrected` is public;
/// the others exist to show, in the tests, what the correction and the modes buy).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(not(test), allow(dead_code))]
enum Bubbles {
    /// Wilson's modes with Taylor's centre-Jacobian correction.
    TaylorCorrected,
    /// Wilson's 1973 modes, gradients with the local Jacobian (fails the patch test
    /// on distorted elements).
    Uncorrected,
    /// Plain trilinear element.
    None,
}

/// Derivatives `dN_i / dxi_a` at natural point `p`: `dn[i][a]`.
#[inline(always)]
fn shape_derivatives(p: &[f64; 3]) -> [[f64; 3]; 8] {
    let mut dn = [[0.0; 3]; 8];
    for (d, s) in dn.iter_mut().zip(NODE_NATURAL.iter()) {
        let a = 1.0 + s[0] * p[0];
        let b = 1.0 + s[1] * p[1];
        let c = 1.0 + s[2] * p[2];
        *d = [
            0.125 * s[0] * b * c,
            0.125 * s[1] * a * c,
            0.125 * s[2] * a * b,
        ];
    }
    dn
}

/// Shape functions `N_i` at natural point `p`.
#[inline(always)]
fn shape_functions(p: &[f64; 3]) -> [f64; 8] {
    let mut n = [0.0; 8];
    for (v, s) in n.iter_mut().zip(NODE_NATURAL.iter()) {
        *v = 0.125 * (1.0 + s[0] * p[0]) * (1.0 + s[1] * p[1]) * (1.0 + s[2] * p[2]);
    }
    n
}

/// `J[a][b] = d x_b / d xi_a`.
#[inline(always)]
fn jacobian(x: &[[f64; 3]; 8], dn: &[[f64; 3]; 8]) -> [[f64; 3]; 3] {
    let mut j = [[0.0; 3]; 3];
    for (xi, di) in x.iter().zip(dn.iter()) {
        for a in 0..3 {
            for b in 0..3 {
                j[a][b] += di[a] * xi[b];
            }
        }
    }
    j
}

#[inline(always)]
fn det3(m: &[[f64; 3]; 3]) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1])
        - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
        + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
}

/// Inverse and determinant of a 3x3 matrix (cofactors; non-finite if singular).
#[inline(always)]
fn inverse3(m: &[[f64; 3]; 3]) -> ([[f64; 3]; 3], f64) {
    let c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1];
    let c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2];
    let c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
    let det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
    let r = 1.0 / det;
    let inv = [
        [
            c00 * r,
            (m[0][2] * m[2][1] - m[0][1] * m[2][2]) * r,
            (m[0][1] * m[1][2] - m[0][2] * m[1][1]) * r,
        ],
        [
            c01 * r,
            (m[0][0] * m[2][2] - m[0][2] * m[2][0]) * r,
            (m[0][2] * m[1][0] - m[0][0] * m[1][2]) * r,
        ],
        [
            c02 * r,
            (m[0][1] * m[2][0] - m[0][0] * m[2][1]) * r,
            (m[0][0] * m[1][1] - m[0][1] * m[1][0]) * r,
        ],
    ];
    (inv, det)
}

/// `D B` for the strain operator of one scalar field with physical gradient `g`
/// (a 6x3 block; column `c` is the displacement component).
#[inline(always)]
fn d_times_b(d: &Voigt6, g: &[f64; 3]) -> [[f64; 3]; 6] {
    let mut out = [[0.0; 3]; 6];
    for (o, dr) in out.iter_mut().zip(d.iter()) {
        *o = [
            dr[0] * g[0] + dr[3] * g[1] + dr[5] * g[2],
            dr[1] * g[1] + dr[3] * g[0] + dr[4] * g[2],
            dr[2] * g[2] + dr[4] * g[1] + dr[5] * g[0],
        ];
    }
    out
}

/// `B^T Y` for the strain operator `B` of gradient `g` and a 6x3 block `Y`.
#[inline(always)]
fn bt_times(g: &[f64; 3], y: &[[f64; 3]; 6]) -> [[f64; 3]; 3] {
    let mut out = [[0.0; 3]; 3];
    for c in 0..3 {
        out[0][c] = g[0] * y[0][c] + g[1] * y[3][c] + g[2] * y[5][c];
        out[1][c] = g[1] * y[1][c] + g[0] * y[3][c] + g[2] * y[4][c];
        out[2][c] = g[2] * y[2][c] + g[1] * y[4][c] + g[0] * y[5][c];
    }
    out
}

/// Stiffness and mass of an 8-node hexahedron with incompatible modes.
///
/// `x`: nodal coordinates in the C3D8 order of [`NODE_NATURAL`]; `d`: elasticity
/// matrix (Voigt `(xx, yy, zz, xy, yz, zx)`, engineering shears); `rho`: density.
/// See the [module documentation](self) for the formulation. Check
/// [`Hex8Matrices::min_det_j`]` > 0` before using the result.
///
/// ```
/// use squeal_fe::hex8::hex8_matrices;
/// let x = [
///     [0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0],
///     [0.0, 0.0, 1.0], [1.0, 0.0, 1.0], [1.0, 1.0, 1.0], [0.0, 1.0, 1.0],
/// ];
/// let mut d = [[0.0; 6]; 6];
/// for i in 0..6 { d[i][i] = 1.0; }
/// let m = hex8_matrices(&x, &d, 2.0);
/// assert!((m.volume - 1.0).abs() < 1e-14);
/// assert!(m.min_det_j > 0.0);
/// ```
pub fn hex8_matrices(x: &[[f64; 3]; 8], d: &Voigt6, rho: f64) -> Hex8Matrices {
    element(x, d, rho, Bubbles::TaylorCorrected)
}

/// The element for a choice of internal modes.
#[inline(always)]
fn element(x: &[[f64; 3]; 8], d: &Voigt6, rho: f64, bubbles: Bubbles) -> Hex8Matrices {
    // 8 nodes and, with internal modes, 3 bubble "nodes", each a 3-DOF block.
    let nb = if bubbles == Bubbles::None { 8 } else { 11 };
    let mut k = [[0.0f64; 33]; 33];
    let mut ms = [[0.0f64; 8]; 8];
    let mut volume = 0.0;
    let mut min_det_j = f64::INFINITY;
    let (j0inv, det0) = inverse3(&jacobian(x, &shape_derivatives(&[0.0; 3])));

    for p in GAUSS.iter() {
        let dn = shape_derivatives(p);
        let (jinv, det) = inverse3(&jacobian(x, &dn));
        min_det_j = min_det_j.min(det);
        volume += det;

        let mut g = [[0.0; 3]; 11];
        for (gi, di) in g.iter_mut().zip(dn.iter()) {
            for a in 0..3 {
                gi[a] = jinv[a][0] * di[0] + jinv[a][1] * di[1] + jinv[a][2] * di[2];
            }
        }
        // dP_m/dxi = -2 xi_m e_m, so J^-1 grad_xi P_m is column m of J^-1 times -2 xi_m.
        let (jb, scale) = match bubbles {
            Bubbles::TaylorCorrected => (&j0inv, det0 / det),
            _ => (&jinv, 1.0),
        };
        if bubbles != Bubbles::None {
            for m in 0..3 {
                let f = -2.0 * p[m] * scale;
                g[8 + m] = [jb[0][m] * f, jb[1][m] * f, jb[2][m] * f];
            }
        }

        let mut db = [[[0.0; 3]; 6]; 11];
        for l in 0..nb {
            db[l] = d_times_b(d, &g[l]);
        }
        for a in 0..nb {
            for b in a..nb {
                let blk = bt_times(&g[a], &db[b]);
                for r in 0..3 {
                    for c in 0..3 {
                        k[3 * a + r][3 * b + c] += det * blk[r][c];
                    }
                }
            }
        }

        let n = shape_functions(p);
        for i in 0..8 {
            let f = rho * det * n[i];
            for j in i..8 {
                ms[i][j] += f * n[j];
            }
        }
    }

    // Static condensation of the internal DOFs 24..33 on the upper triangle.
    if bubbles != Bubbles::None {
        for p in (24..33).rev() {
            let piv = k[p][p];
            for i in 0..p {
                let f = k[i][p] / piv;
                if f == 0.0 {
                    continue;
                }
                for j in i..p {
                    k[i][j] -= f * k[j][p];
                }
            }
        }
    }

    let mut ke = [[0.0; 24]; 24];
    for i in 0..24 {
        for j in i..24 {
            ke[i][j] = k[i][j];
            ke[j][i] = k[i][j];
        }
    }
    let mut me = [[0.0; 24]; 24];
    for i in 0..8 {
        for j in i..8 {
            for c in 0..3 {
                me[3 * i + c][3 * j + c] = ms[i][j];
                me[3 * j + c][3 * i + c] = ms[i][j];
            }
        }
    }
    Hex8Matrices {
        ke,
        me,
        volume,
        min_det_j,
    }
}

/// Smallest Jacobian determinant `det J` over the 2x2x2 Gauss points, the value stored
/// in [`Hex8Matrices::min_det_j`] (m^3 per unit reference volume: a cube of side `h`
/// gives `h^3 / 8`). `<= 0` means an inverted or degenerate element.
pub fn min_det_jacobian(x: &[[f64; 3]; 8]) -> f64 {
    GAUSS
        .iter()
        .map(|p| det3(&jacobian(x, &shape_derivatives(p))))
        .fold(f64::INFINITY, f64::min)
}

/// Scaled Jacobian: minimum over the 8 corners of the determinant of the three unit
/// edge vectors leaving that corner (ordered right-handed for a valid element).
///
/// 1 for a rectangular box, `|det(a, b, c)| / (|a||b||c|)` for a parallelepiped of
/// edges `a, b, c`, `<= 0` when a corner is inverted or an edge has zero length.
/// This is the corner part of the Verdict hexahedron metric of the same name.
pub fn scaled_jacobian(x: &[[f64; 3]; 8]) -> f64 {
    let mut q = f64::INFINITY;
    for (c, nb) in CORNER_EDGES.iter().enumerate() {
        let mut e = [[0.0; 3]; 3];
        for (ek, &n) in e.iter_mut().zip(nb.iter()) {
            let v = [x[n][0] - x[c][0], x[n][1] - x[c][1], x[n][2] - x[c][2]];
            let len = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if len <= 0.0 || !len.is_finite() {
                return 0.0;
            }
            *ek = [v[0] / len, v[1] / len, v[2] / len];
        }
        q = q.min(det3(&e));
    }
    q
}

#[cfg(test)]
mod tests {
    use super::*;

    use squeal_materials::isotropic_elasticity as iso_d;

    /// A warped, non-affine hexahedron (no parallel faces, non-planar faces).
    fn distorted() -> [[f64; 3]; 8] {
        [
            [0.0, 0.0, 0.0],
            [1.1, 0.05, -0.1],
            [1.3, 1.2, 0.1],
            [-0.1, 0.9, 0.05],
            [0.1, -0.1, 1.0],
            [1.0, 0.1, 1.2],
            [1.25, 1.1, 0.9],
            [0.05, 1.0, 1.1],
        ]
    }

    fn box_coords(lx: f64, ly: f64, lz: f64) -> [[f64; 3]; 8] {
        std::array::from_fn(|i| {
            let s = NODE_NATURAL[i];
            [0.5 * lx * s[0], 0.5 * ly * s[1], 0.5 * lz * s[2]]
        })
    }

    fn matvec(a: &[[f64; 24]; 24], u: &[f64; 24]) -> [f64; 24] {
        std::array::from_fn(|i| (0..24).map(|j| a[i][j] * u[j]).sum())
    }

    fn dot(a: &[f64; 24], b: &[f64; 24]) -> f64 {
        a.iter().zip(b).map(|(x, y)| x * y).sum()
    }

    fn frob(a: &[[f64; 24]; 24]) -> f64 {
        a.iter().flatten().map(|v| v * v).sum::<f64>().sqrt()
    }

    /// Nodal values of `u(x) = A x + c`.
    fn linear_field(x: &[[f64; 3]; 8], a: &[[f64; 3]; 3], c: &[f64; 3]) -> [f64; 24] {
        let mut u = [0.0; 24];
        for i in 0..8 {
            for r in 0..3 {
                u[3 * i + r] = c[r] + (0..3).map(|s| a[r][s] * x[i][s]).sum::<f64>();
            }
        }
        u
    }

    /// Eigenvalues of a symmetric matrix, cyclic Jacobi.
    fn sym_eigenvalues(m: &[[f64; 24]; 24]) -> Vec<f64> {
        let n = 24;
        let mut a = *m;
        for _sweep in 0..100 {
            let off: f64 = (0..n)
                .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
                .map(|(i, j)| a[i][j] * a[i][j])
                .sum();
            let diag: f64 = (0..n).map(|i| a[i][i] * a[i][i]).sum();
            if off <= 1e-30 * diag {
                break;
            }
            for p in 0..n {
                for q in p + 1..n {
                    if a[p][q] == 0.0 {
                        continue;
                    }
                    let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                    let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                    let c = 1.0 / (t * t + 1.0).sqrt();
                    let s = t * c;
                    for r in 0..n {
                        let (arp, arq) = (a[r][p], a[r][q]);
                        a[r][p] = c * arp - s * arq;
                        a[r][q] = s * arp + c * arq;
                    }
                    for r in 0..n {
                        let (apr, aqr) = (a[p][r], a[q][r]);
                        a[p][r] = c * apr - s * aqr;
                        a[q][r] = s * apr + c * aqr;
                    }
                }
            }
        }
        let mut ev: Vec<f64> = (0..n).map(|i| a[i][i]).collect();
        ev.sort_by(|x, y| x.partial_cmp(y).unwrap());
        ev
    }

    fn rigid_modes(x: &[[f64; 3]; 8]) -> Vec<[f64; 24]> {
        let mut modes = Vec::new();
        for t in 0..3 {
            let mut c = [0.0; 3];
            c[t] = 1.0;
            modes.push(linear_field(x, &[[0.0; 3]; 3], &c));
        }
        // Infinitesimal rotations u = w x X: skew-symmetric A.
        let skews = [
            [[0.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]],
            [[0.0, 0.0, 1.0], [0.0, 0.0, 0.0], [-1.0, 0.0, 0.0]],
            [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]],
        ];
        for a in &skews {
            modes.push(linear_field(x, a, &[0.3, -0.2, 0.1]));
        }
        modes
    }

    #[test]
    fn rigid_body_modes_and_no_spurious_zero_energy_mode() {
        let x = distorted();
        let d = iso_d(210e9, 0.3);
        let m = hex8_matrices(&x, &d, 7800.0);
        assert!(m.min_det_j > 0.0);
        let norm = frob(&m.ke);
        for (r, u) in rigid_modes(&x).iter().enumerate() {
            let f = matvec(&m.ke, u);
            let fn_ = f.iter().map(|v| v * v).sum::<f64>().sqrt();
            let un = dot(u, u).sqrt();
            assert!(fn_ <= 1e-10 * norm * un, "rigid mode {r}: |K u| = {fn_:e}");
        }
        let ev = sym_eigenvalues(&m.ke);
        let max = ev[23];
        let zeros = ev.iter().filter(|&&l| l.abs() < 1e-8 * max).count();
        assert_eq!(
            zeros,
            6,
            "eigenvalues / max: {:?}",
            ev.iter().map(|l| l / max).collect::<Vec<_>>()
        );
        assert!(ev[0] > -1e-10 * max, "negative eigenvalue {}", ev[0] / max);
        eprintln!(
            "ke eigenvalues / max: |6 smallest| <= {:.1e}, 7th = {:.3e}",
            ev[..6].iter().fold(0.0f64, |a, l| a.max(l.abs())) / max,
            ev[6] / max
        );
        // The first non-zero eigenvalue is well separated from round-off.
        assert!(ev[6] > 1e-4 * max, "{}", ev[6] / max);
    }

    #[test]
    fn plain_trilinear_has_six_zero_modes_too() {
        let m = element(&distorted(), &iso_d(1.0, 0.25), 1.0, Bubbles::None);
        let ev = sym_eigenvalues(&m.ke);
        let zeros = ev.iter().filter(|&&l| l.abs() < 1e-8 * ev[23]).count();
        assert_eq!(zeros, 6);
    }

    #[test]
    fn stiffness_and_mass_are_symmetric() {
        let m = hex8_matrices(&distorted(), &iso_d(3.0e9, 0.35), 1200.0);
        let (nk, nm) = (frob(&m.ke), frob(&m.me));
        for i in 0..24 {
            for j in 0..24 {
                assert!((m.ke[i][j] - m.ke[j][i]).abs() <= 1e-14 * nk);
                assert!((m.me[i][j] - m.me[j][i]).abs() <= 1e-14 * nm);
            }
            assert!(m.ke[i][i] > 0.0 && m.me[i][i] > 0.0);
        }
    }

    #[test]
    fn mass_sums_to_rho_volume_and_volumes_are_exact() {
        // Parallelepiped of edges a, b, c: volume |det(a, b, c)|.
        let (a, b, c) = ([2.0, 0.3, -0.1], [0.4, 1.5, 0.2], [0.3, -0.2, 0.8]);
        let o = [1.0, -2.0, 0.5];
        let x: [[f64; 3]; 8] = std::array::from_fn(|i| {
            let s = NODE_NATURAL[i].map(|v| 0.5 * (v + 1.0));
            std::array::from_fn(|k| o[k] + s[0] * a[k] + s[1] * b[k] + s[2] * c[k])
        });
        let v_exact = det3(&[a, b, c]);
        let rho = 2700.0;
        let m = hex8_matrices(&x, &iso_d(70e9, 0.33), rho);
        assert!((m.volume - v_exact).abs() < 1e-14 * v_exact, "{}", m.volume);
        assert!((m.min_det_j - v_exact / 8.0).abs() < 1e-14 * v_exact);
        for dir in 0..3 {
            let s: f64 = (0..8)
                .flat_map(|i| (0..8).map(move |j| (i, j)))
                .map(|(i, j)| m.me[3 * i + dir][3 * j + dir])
                .sum();
            assert!((s - rho * v_exact).abs() < 1e-12 * rho * v_exact, "{s}");
        }
        // No coupling between directions.
        assert_eq!(m.me[0][1], 0.0);
        assert_eq!(m.me[3][5], 0.0);

        // Cube of side h: consistent-mass diagonal rho V / 27.
        let h = 0.5;
        let mc = hex8_matrices(&box_coords(h, h, h), &iso_d(1.0, 0.0), rho);
        let vc = h * h * h;
        assert!((mc.me[0][0] - rho * vc / 27.0).abs() < 1e-12 * rho * vc);
        assert!((mc.me[0][3 * 6] - rho * vc / 216.0).abs() < 1e-12 * rho * vc);

        // Frustum of a square pyramid (non-affine, planar faces): h/3 (a^2 + ab + b^2).
        let (sa, sb, hz) = (2.0, 1.0, 1.5);
        let xf: [[f64; 3]; 8] = std::array::from_fn(|i| {
            let s = NODE_NATURAL[i];
            let half = if s[2] < 0.0 { 0.5 * sa } else { 0.5 * sb };
            [half * s[0], half * s[1], 0.5 * hz * (s[2] + 1.0)]
        });
        let vf = hz / 3.0 * (sa * sa + sa * sb + sb * sb);
        let mf = hex8_matrices(&xf, &iso_d(1.0, 0.2), 1.0);
        assert!((mf.volume - vf).abs() < 1e-14 * vf);
        let s: f64 = (0..24)
            .step_by(3)
            .flat_map(|i| (0..24).step_by(3).map(move |j| mf.me[i][j]))
            .sum();
        assert!((s - vf).abs() < 1e-12 * vf);
    }

    fn strain_of(a: &[[f64; 3]; 3]) -> [f64; 6] {
        [
            a[0][0],
            a[1][1],
            a[2][2],
            a[0][1] + a[1][0],
            a[1][2] + a[2][1],
            a[2][0] + a[0][2],
        ]
    }

    /// Relative errors (energy, nodal forces) of the single-element constant-strain test.
    fn patch_errors(m: &Hex8Matrices, x: &[[f64; 3]; 8], d: &Voigt6) -> (f64, f64) {
        let a = [
            [1.0e-3, 0.4e-3, -0.7e-3],
            [-0.2e-3, -0.5e-3, 0.9e-3],
            [0.6e-3, 0.3e-3, 0.8e-3],
        ];
        let u = linear_field(x, &a, &[0.01, -0.02, 0.03]);
        let eps = strain_of(&a);
        let sig: [f64; 6] = std::array::from_fn(|r| (0..6).map(|s| d[r][s] * eps[s]).sum());
        let exact = m.volume * (0..6).map(|r| eps[r] * sig[r]).sum::<f64>();
        let f = matvec(&m.ke, &u);
        let energy = dot(&u, &f);
        // Consistent nodal forces of the constant stress: f_ia = sum_b sig_ab int dN_i/dx_b dV.
        let s3 = [
            [sig[0], sig[3], sig[5]],
            [sig[3], sig[1], sig[4]],
            [sig[5], sig[4], sig[2]],
        ];
        let mut fc = [0.0; 24];
        for p in GAUSS.iter() {
            let dn = shape_derivatives(p);
            let (jinv, det) = inverse3(&jacobian(x, &dn));
            for i in 0..8 {
                let g: [f64; 3] =
                    std::array::from_fn(|r| (0..3).map(|s| jinv[r][s] * dn[i][s]).sum());
                for r in 0..3 {
                    fc[3 * i + r] += det * (0..3).map(|s| s3[r][s] * g[s]).sum::<f64>();
                }
            }
        }
        let fmax = fc.iter().fold(0.0f64, |acc, v| acc.max(v.abs()));
        let ferr = f
            .iter()
            .zip(&fc)
            .fold(0.0f64, |acc, (a, b)| acc.max((a - b).abs()))
            / fmax;
        ((energy - exact).abs() / exact, ferr)
    }

    #[test]
    fn single_element_patch_test_on_distorted_shape() {
        let x = distorted();
        let d = iso_d(210e9, 0.3);
        let m = hex8_matrices(&x, &d, 1.0);
        let (e_err, f_err) = patch_errors(&m, &x, &d);
        eprintln!("patch test (isotropic): energy error {e_err:.2e}, force error {f_err:.2e}");
        assert!(e_err < 1e-10, "energy error {e_err:e}");
        assert!(f_err < 1e-10, "force error {f_err:e}");

        // An anisotropic (full) D as well.
        let mut da = iso_d(50e9, 0.2);
        for i in 0..6 {
            for j in 0..6 {
                if i != j {
                    da[i][j] += 1e9 * (1.0 + (i + j) as f64 * 0.1);
                }
            }
        }
        let ma = hex8_matrices(&x, &da, 1.0);
        let (e_err, f_err) = patch_errors(&ma, &x, &da);
        assert!(e_err < 1e-10 && f_err < 1e-10, "{e_err:e} {f_err:e}");

        // Without Taylor's correction the same test fails: the test has teeth.
        let mu = element(&x, &d, 1.0, Bubbles::Uncorrected);
        let (e_err, _) = patch_errors(&mu, &x, &d);
        eprintln!("patch test without Taylor's correction: energy error {e_err:.2e}");
        assert!(e_err > 1e-4, "uncorrected energy error {e_err:e}");
    }

    /// `u^T K u / (E I kappa^2 L)` for one 2x1x1 element in pure bending about z,
    /// with the nodal values of the exact 3D pure-bending field.
    fn bending_ratio(bubbles: Bubbles, nu: f64) -> f64 {
        let (l, h, b) = (2.0, 1.0, 1.0);
        let x = box_coords(l, h, b);
        let e = 1.0e9;
        let kappa = 1.0e-3;
        let m = element(&x, &iso_d(e, nu), 1.0, bubbles);
        let mut u = [0.0; 24];
        for (i, p) in x.iter().enumerate() {
            let (px, py, pz) = (p[0], p[1], p[2]);
            // Sections rotate by kappa x (linear in x); v carries the beam deflection and
            // the anticlastic Poisson terms; w the Poisson contraction.
            u[3 * i] = -kappa * px * py;
            u[3 * i + 1] = 0.5 * kappa * (px * px + nu * (py * py - pz * pz));
            u[3 * i + 2] = nu * kappa * py * pz;
        }
        let inertia = b * h * h * h / 12.0;
        dot(&u, &matvec(&m.ke, &u)) / (e * inertia * kappa * kappa * l)
    }

    #[test]
    fn pure_bending_incompatible_modes_vs_trilinear() {
        for nu in [0.0, 0.3] {
            let r_im = bending_ratio(Bubbles::TaylorCorrected, nu);
            let r_q1 = bending_ratio(Bubbles::None, nu);
            eprintln!(
                "nu = {nu}: energy / beam theory: incompatible {r_im:.12}, trilinear {r_q1:.6}"
            );
            assert!(
                (r_im - 1.0).abs() < 0.02,
                "incompatible-mode element: {r_im}"
            );
            assert!(r_q1 > 1.5, "trilinear element should lock: {r_q1}");
        }
    }

    #[test]
    fn quality_measures() {
        let cube = box_coords(1.0, 1.0, 1.0);
        assert!((scaled_jacobian(&cube) - 1.0).abs() < 1e-14);
        assert!((min_det_jacobian(&cube) - 0.125).abs() < 1e-15);
        assert!((scaled_jacobian(&box_coords(3.0, 0.1, 2.0)) - 1.0).abs() < 1e-14);
        // Sheared parallelepiped: edges (1,0,0), (0,1,0), (s,0,1).
        let s = 0.75;
        let sheared: [[f64; 3]; 8] = std::array::from_fn(|i| {
            let p = cube[i];
            [p[0] + s * (p[2] + 0.5), p[1], p[2]]
        });
        let expect = 1.0 / (1.0f64 + s * s).sqrt();
        assert!((scaled_jacobian(&sheared) - expect).abs() < 1e-14);
        assert!((min_det_jacobian(&sheared) - 0.125).abs() < 1e-14);
        let q = scaled_jacobian(&distorted());
        assert!(q > 0.5 && q < 1.0, "{q}");
        // Inverted: top and bottom faces swapped.
        let mut inv = cube;
        inv.swap(0, 4);
        inv.swap(1, 5);
        inv.swap(2, 6);
        inv.swap(3, 7);
        assert!(scaled_jacobian(&inv) < 0.0);
        assert!(min_det_jacobian(&inv) < 0.0);
        assert!(hex8_matrices(&inv, &iso_d(1.0, 0.3), 1.0).min_det_j < 0.0);
        // Collapsed edge.
        let mut col = cube;
        col[1] = col[0];
        assert_eq!(scaled_jacobian(&col), 0.0);
    }

    #[test]
    fn invariant_under_rigid_translation() {
        let x = distorted();
        let xt: [[f64; 3]; 8] =
            std::array::from_fn(|i| [x[i][0] + 10.0, x[i][1] - 3.0, x[i][2] + 0.5]);
        let d = iso_d(1.0, 0.3);
        let (a, b) = (hex8_matrices(&x, &d, 1.0), hex8_matrices(&xt, &d, 1.0));
        let n = frob(&a.ke);
        for i in 0..24 {
            for j in 0..24 {
                assert!((a.ke[i][j] - b.ke[i][j]).abs() < 1e-10 * n);
            }
        }
    }
}
