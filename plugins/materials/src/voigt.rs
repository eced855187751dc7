//! Voigt-notation helpers: frames, the Bond transformation and a small Cholesky.

use squeal_core::Voigt6;

/// Index pairs of the Voigt order `(xx, yy, zz, xy, yz, zx)`.
const PAIRS: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (1, 2), (2, 0)];

/// A right-handed orthonormal frame whose third vector is `axis / |axis|`.
///
/// Returns `q` with `q[i][k]` = global component `i` of local base vector `k` (the
/// local-to-global rotation, columns are the local axes), or `None` if `axis` is zero or
/// not finite. The first local axis is the global axis least aligned with `axis`,
/// orthogonalized; for `axis = e_z` the frame is the identity.
pub fn frame_with_axis(axis: [f64; 3]) -> Option<[[f64; 3]; 3]> {
    let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
    if !n.is_finite() || n == 0.0 {
        return None;
    }
    let a = axis.map(|v| v / n);
    // Helper: the global axis with the smallest |a_i| (first one on ties).
    let mut h = 0;
    for i in 1..3 {
        if a[i].abs() < a[h].abs() {
            h = i;
        }
    }
    let mut e1 = [0.0; 3];
    e1[h] = 1.0;
    let p = a[h];
    for i in 0..3 {
        e1[i] -= p * a[i];
    }
    let l = (e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]).sqrt();
    let e1 = e1.map(|v| v / l);
    let e2 = [
        a[1] * e1[2] - a[2] * e1[1],
        a[2] * e1[0] - a[0] * e1[2],
        a[0] * e1[1] - a[1] * e1[0],
    ];
    Some([
        [e1[0], e2[0], a[0]],
        [e1[1], e2[1], a[1]],
        [e1[2], e2[2], a[2]],
    ])
}

/// Bond stress transformation `T` of the rotation `q` (`q[i][k]`: global component `i`
/// of local base vector `k`): `sigma_global = T sigma_local` in Voigt notation.
///
/// `T[I][K] = q[i][k] q[j][l] + q[i][l] q[j][k]` for a shear `K = (k, l)`, `k != l`, and
/// `q[i][k] q[j][k]` for a normal `K = (k, k)`, with `I = (i, j)`. With engineering
/// shear strains, `eps_local = T^T eps_global`.
pub fn bond_stress_matrix(q: &[[f64; 3]; 3]) -> Voigt6 {
    let mut t = [[0.0; 6]; 6];
    for (ti, &(i, j)) in t.iter_mut().zip(PAIRS.iter()) {
        for (tik, &(k, l)) in ti.iter_mut().zip(PAIRS.iter()) {
            *tik = q[i][k] * q[j][l];
            if k != l {
                *tik += q[i][l] * q[j][k];
            }
        }
    }
    t
}

/// Elasticity in the global frame from the local one: `D = T D_local T^T`, with `T`
/// the [`bond_stress_matrix`] of the local-to-global rotation `q`.
pub fn rotate_elasticity(d_local: &Voigt6, q: &[[f64; 3]; 3]) -> Voigt6 {
    let t = bond_stress_matrix(q);
    let mut td = [[0.0; 6]; 6];
    for i in 0..6 {
        for j in 0..6 {
            td[i][j] = (0..6).map(|k| t[i][k] * d_local[k][j]).sum();
        }
    }
    let mut d = [[0.0; 6]; 6];
    for i in 0..6 {
        for j in 0..6 {
            d[i][j] = (0..6).map(|k| td[i][k] * t[j][k]).sum();
        }
    }
    // Exact symmetry despite round-off.
    for i in 0..6 {
        for j in i + 1..6 {
            let m = 0.5 * (d[i][j] + d[j][i]);
            d[i][j] = m;
            d[j][i] = m;
        }
    }
    d
}

/// Lower Cholesky factor of a symmetric matrix, or `None` if it is not (numerically)
/// positive definite: a pivot `<= 1e-12` times the largest diagonal entry fails.
pub(crate) fn cholesky(a: &Voigt6) -> Option<Voigt6> {
    let scale = (0..6).map(|i| a[i][i].abs()).fold(0.0, f64::max);
    if !scale.is_finite() || scale == 0.0 {
        return None;
    }
    let mut l = [[0.0; 6]; 6];
    for j in 0..6 {
        let s = a[j][j] - (0..j).map(|k| l[j][k] * l[j][k]).sum::<f64>();
        if s.is_nan() || s <= 1e-12 * scale {
            return None;
        }
        l[j][j] = s.sqrt();
        for i in j + 1..6 {
            let s = a[i][j] - (0..j).map(|k| l[i][k] * l[j][k]).sum::<f64>();
            l[i][j] = s / l[j][j];
        }
    }
    Some(l)
}

/// Inverse of a symmetric positive definite matrix from its Cholesky factor.
pub(crate) fn spd_inverse(l: &Voigt6) -> Voigt6 {
    let mut inv = [[0.0; 6]; 6];
    for c in 0..6 {
        // Solve L y = e_c, then L^T x = y.
        let mut y = [0.0; 6];
        for i in 0..6 {
            let rhs = if i == c { 1.0 } else { 0.0 };
            y[i] = (rhs - (0..i).map(|k| l[i][k] * y[k]).sum::<f64>()) / l[i][i];
        }
        let mut x = [0.0; 6];
        for i in (0..6).rev() {
            x[i] = (y[i] - (i + 1..6).map(|k| l[k][i] * x[k]).sum::<f64>()) / l[i][i];
        }
        for r in 0..6 {
            inv[r][c] = x[r];
        }
    }
    for i in 0..6 {
        for j in i + 1..6 {
            let m = 0.5 * (inv[i][j] + inv[j][i]);
            inv[i][j] = m;
            inv[j][i] = m;
        }
    }
    inv
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frames_are_orthonormal_right_handed() {
        assert_eq!(
            frame_with_axis([0.0, 0.0, 2.0]).unwrap(),
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        );
        assert!(frame_with_axis([0.0; 3]).is_none());
        assert!(frame_with_axis([f64::NAN, 0.0, 1.0]).is_none());
        for axis in [
            [1.0, 0.0, 0.0],
            [0.3, -0.8, 0.5],
            [-1.0, 1.0, 1.0],
            [0.0, 1.0, 0.0],
        ] {
            let q = frame_with_axis(axis).unwrap();
            for a in 0..3 {
                for b in 0..3 {
                    let dot: f64 = (0..3).map(|i| q[i][a] * q[i][b]).sum();
                    let expect = if a == b { 1.0 } else { 0.0 };
                    assert!((dot - expect).abs() < 1e-15);
                }
            }
            let det = q[0][0] * (q[1][1] * q[2][2] - q[1][2] * q[2][1])
                - q[0][1] * (q[1][0] * q[2][2] - q[1][2] * q[2][0])
                + q[0][2] * (q[1][0] * q[2][1] - q[1][1] * q[2][0]);
            assert!((det - 1.0).abs() < 1e-15);
            let n = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
            for i in 0..3 {
                assert!((q[i][2] - axis[i] / n).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn bond_matrix_preserves_energy() {
        // sigma_g . eps_g = sigma_l . eps_l with sigma_g = T sigma_l, eps_l = T^T eps_g.
        let q = frame_with_axis([0.3, -0.8, 0.5]).unwrap();
        let t = bond_stress_matrix(&q);
        let s_l = [1.0, -2.0, 0.5, 0.3, -0.7, 1.1];
        let e_g = [0.2, 0.1, -0.4, 0.9, 0.05, -0.3];
        let s_g: Vec<f64> = (0..6)
            .map(|i| (0..6).map(|k| t[i][k] * s_l[k]).sum())
            .collect();
        let e_l: Vec<f64> = (0..6)
            .map(|k| (0..6).map(|i| t[i][k] * e_g[i]).sum())
            .collect();
        let w_g: f64 = (0..6).map(|i| s_g[i] * e_g[i]).sum();
        let w_l: f64 = (0..6).map(|i| s_l[i] * e_l[i]).sum();
        assert!((w_g - w_l).abs() < 1e-14);
        // Tensor check: sigma_g(ij) = q_ik q_jl sigma_l(kl).
        let full = |s: &[f64]| [[s[0], s[3], s[5]], [s[3], s[1], s[4]], [s[5], s[4], s[2]]];
        let sl = full(&s_l);
        let sg = full(&s_g);
        for i in 0..3 {
            for j in 0..3 {
                let mut v = 0.0;
                for k in 0..3 {
                    for l in 0..3 {
                        v += q[i][k] * q[j][l] * sl[k][l];
                    }
                }
                assert!((v - sg[i][j]).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn cholesky_inverse() {
        let mut a = [[0.0; 6]; 6];
        for i in 0..6 {
            for j in 0..6 {
                a[i][j] = 1.0 / (1.0 + i as f64 + j as f64);
            }
            a[i][i] += 1.0;
        }
        let inv = spd_inverse(&cholesky(&a).unwrap());
        for i in 0..6 {
            for j in 0..6 {
                let v: f64 = (0..6).map(|k| a[i][k] * inv[k][j]).sum();
                assert!((v - if i == j { 1.0 } else { 0.0 }).abs() < 1e-13);
            }
        }
        a[2][2] = -1.0;
        assert!(cholesky(&a).is_none());
    }
}
