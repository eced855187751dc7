//! Transversely isotropic linear elasticity.

use crate::voigt::{cholesky, frame_with_axis, rotate_elasticity, spd_inverse};
use crate::{invalid, positive};
use squeal_core::{Material, Result, Voigt6};

const NAME: &str = "transversely_isotropic";

/// Huber's approximation of the shear modulus in planes containing the axis:
///
/// ```text
/// G_pz = sqrt(E_p E_z) / (2 (1 + sqrt(nu_pz nu_zp))),   nu_zp = nu_pz E_z / E_p,
/// ```
///
/// (M. T. Huber, 1923, for orthotropic plates). It reduces to `E / (2 (1 + nu))` in the
/// isotropic limit. With the lining constants `E_p = 15.3 GPa`, `E_z = 5.4 GPa`,
/// `nu_pz = 0.15` it gives `G_pz = 4.17 GPa`.
pub fn huber_shear_modulus(e_in_plane: f64, e_axial: f64, nu_axial: f64) -> f64 {
    let nu_zp = nu_axial * e_axial / e_in_plane;
    (e_in_plane * e_axial).sqrt() / (2.0 * (1.0 + (nu_axial * nu_zp).sqrt()))
}

/// Transversely isotropic linear elastic material (plugin `"transversely_isotropic"`):
/// isotropic in the plane normal to the unit `axis` (subscript `p`), with different
/// properties along it (subscript `z`).
///
/// Constants, in the local frame where `axis` is `z`:
///
/// - `e_in_plane` = `E_p`, Young's modulus in the plane (Pa);
/// - `e_axial` = `E_z`, Young's modulus along the axis (Pa);
/// - `nu_in_plane` = `nu_p = -eps_y / eps_x` under uniaxial stress along `x` (in-plane);
/// - `nu_axial` = **`nu_pz = -eps_z / eps_p` under uniaxial stress along an in-plane
///   direction `p`** (Abaqus `nu_13` with 1 in the plane, 3 the axis). The reciprocal
///   ratio is `nu_zp = -eps_p / eps_z` under stress along the axis, `nu_zp = nu_pz E_z /
///   E_p` (see [`nu_zp`](Self::nu_zp)). Data given as `nu_zp` must be converted.
/// - `g_axial` = `G_pz`, shear modulus in planes containing the axis (Pa). When not given,
///   the documented default is Huber's approximation [`huber_shear_modulus`],
///   `sqrt(E_p E_z) / (2 (1 + sqrt(nu_pz nu_zp)))`, used because the reference paper gives
///   no shear modulus (its lining: `E_p = 15.3 GPa`, `E_z = 5.4 GPa`, all Poisson ratios
///   0.15, `rho = 4000 kg/m^3`, which gives `G_pz = 4.17 GPa`). The in-plane shear
///   modulus is `E_p / (2 (1 + nu_p))`.
/// - `density` (kg/m^3).
///
/// Local compliance (Voigt `(xx, yy, zz, xy, yz, zx)`, engineering shears):
///
/// ```text
/// S = [  1/Ep    -nu_p/Ep  -nu_pz/Ep                      ]
///     [ -nu_p/Ep  1/Ep     -nu_pz/Ep                      ]
///     [ -nu_pz/Ep -nu_pz/Ep  1/Ez                         ]
///     [                         2(1+nu_p)/Ep              ]
///     [                                      1/G_pz       ]
///     [                                             1/G_pz]
/// ```
///
/// It must be positive definite (`-1 < nu_p < 1` and `1 - nu_p - 2 nu_pz nu_zp > 0` for
/// positive moduli); `D_local = S^-1`, rotated to the global frame by the Bond
/// transformation `D = T D_local T^T` of a right-handed frame whose third axis is
/// `axis / |axis|` (the in-plane axes do not matter, the law being isotropic there).
///
/// ```
/// use squeal_core::Material;
/// use squeal_materials::TransverselyIsotropic;
/// let pad = TransverselyIsotropic::new(15.3e9, 5.4e9, 0.15, 0.15, None, [0.0, 0.0, 1.0], 4000.0)
///     .unwrap();
/// assert!((pad.g_axial() - 4.173e9).abs() < 1e6);
/// assert_eq!(pad.density(), 4000.0);
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct TransverselyIsotropic {
    e_in_plane: f64,
    e_axial: f64,
    nu_in_plane: f64,
    nu_axial: f64,
    g_axial: f64,
    axis: [f64; 3],
    density: f64,
    d_local: Voigt6,
    d: Voigt6,
}

impl TransverselyIsotropic {
    /// Validates and builds (see the type documentation for the meaning of each
    /// constant). `g_axial = None` selects [`huber_shear_modulus`]; `axis` need not be
    /// unit. Errors ([`squeal_core::Error::Material`]) name the field: `e_in_plane`,
    /// `e_axial`, `g_axial`, `density` (finite, `> 0`), `nu_in_plane`, `nu_axial`
    /// (finite), `axis` (non-zero, finite), `compliance` (not positive definite).
    pub fn new(
        e_in_plane: f64,
        e_axial: f64,
        nu_in_plane: f64,
        nu_axial: f64,
        g_axial: Option<f64>,
        axis: [f64; 3],
        density: f64,
    ) -> Result<Self> {
        positive(NAME, "e_in_plane", e_in_plane)?;
        positive(NAME, "e_axial", e_axial)?;
        for (field, nu) in [("nu_in_plane", nu_in_plane), ("nu_axial", nu_axial)] {
            if !nu.is_finite() {
                return Err(invalid(NAME, field, nu, "a finite Poisson ratio"));
            }
        }
        let g_axial = match g_axial {
            Some(g) => positive(NAME, "g_axial", g)?,
            None => huber_shear_modulus(e_in_plane, e_axial, nu_axial),
        };
        positive(NAME, "density", density)?;
        let norm = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
        let q = frame_with_axis(axis)
            .ok_or_else(|| invalid(NAME, "axis", norm, "a non-zero finite direction"))?;

        let mut s = [[0.0; 6]; 6];
        let (ep, ez) = (e_in_plane, e_axial);
        s[0][0] = 1.0 / ep;
        s[1][1] = 1.0 / ep;
        s[2][2] = 1.0 / ez;
        s[0][1] = -nu_in_plane / ep;
        s[1][0] = s[0][1];
        for i in 0..2 {
            s[i][2] = -nu_axial / ep;
            s[2][i] = s[i][2];
        }
        s[3][3] = 2.0 * (1.0 + nu_in_plane) / ep;
        s[4][4] = 1.0 / g_axial;
        s[5][5] = 1.0 / g_axial;
        let l = cholesky(&s).ok_or_else(|| {
            let nu_zp = nu_axial * ez / ep;
            let margin = (1.0 + nu_in_plane).min(1.0 - nu_in_plane - 2.0 * nu_axial * nu_zp);
            invalid(
                NAME,
                "compliance",
                margin,
                "positive definite compliance: check e_in_plane, e_axial, nu_in_plane, \
                 nu_axial, g_axial (the value is min(1 + nu_p, 1 - nu_p - 2 nu_pz nu_zp), \
                 which must be > 0)",
            )
        })?;
        let d_local = spd_inverse(&l);
        let d = rotate_elasticity(&d_local, &q);
        Ok(Self {
            e_in_plane,
            e_axial,
            nu_in_plane,
            nu_axial,
            g_axial,
            axis: [q[0][2], q[1][2], q[2][2]],
            density,
            d_local,
            d,
        })
    }

    /// `E_p`, Young's modulus in the plane normal to the axis (Pa).
    pub fn e_in_plane(&self) -> f64 {
        self.e_in_plane
    }

    /// `E_z`, Young's modulus along the axis (Pa).
    pub fn e_axial(&self) -> f64 {
        self.e_axial
    }

    /// `nu_p`, in-plane Poisson ratio.
    pub fn nu_in_plane(&self) -> f64 {
        self.nu_in_plane
    }

    /// `nu_pz = -eps_z / eps_p` under uniaxial in-plane stress (the input `nu_axial`).
    pub fn nu_axial(&self) -> f64 {
        self.nu_axial
    }

    /// `nu_zp = -eps_p / eps_z` under uniaxial stress along the axis,
    /// `nu_pz E_z / E_p` (reciprocity `nu_zp / E_z = nu_pz / E_p`).
    pub fn nu_zp(&self) -> f64 {
        self.nu_axial * self.e_axial / self.e_in_plane
    }

    /// `G_pz`, shear modulus in planes containing the axis (Pa), given or Huber's default.
    pub fn g_axial(&self) -> f64 {
        self.g_axial
    }

    /// The unit axis (global frame).
    pub fn axis(&self) -> [f64; 3] {
        self.axis
    }

    /// Elasticity matrix in the local frame (axis = local `z`), Pa.
    pub fn local_elasticity(&self) -> Voigt6 {
        self.d_local
    }
}

impl Material for TransverselyIsotropic {
    fn name(&self) -> &str {
        NAME
    }
    fn elasticity(&self) -> Voigt6 {
        self.d
    }
    fn density(&self) -> f64 {
        self.density
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::isotropic_elasticity;

    const Z: [f64; 3] = [0.0, 0.0, 1.0];

    fn pad(axis: [f64; 3]) -> TransverselyIsotropic {
        TransverselyIsotropic::new(15.3e9, 5.4e9, 0.15, 0.15, None, axis, 4000.0).unwrap()
    }

    fn max_abs(d: &Voigt6) -> f64 {
        d.iter().flatten().fold(0.0, |a, v| a.max(v.abs()))
    }

    fn assert_close(a: &Voigt6, b: &Voigt6, rel: f64) {
        let s = max_abs(b);
        for i in 0..6 {
            for j in 0..6 {
                assert!(
                    (a[i][j] - b[i][j]).abs() <= rel * s,
                    "[{i}][{j}]: {} vs {}",
                    a[i][j],
                    b[i][j]
                );
            }
        }
    }

    fn compliance(d: &Voigt6) -> Voigt6 {
        spd_inverse(&cholesky(d).expect("D must be SPD"))
    }

    #[test]
    fn axis_z_keeps_the_local_matrix() {
        let m = pad(Z);
        assert_eq!(m.elasticity(), m.local_elasticity());
        // Only the xy coupling of normal and shear terms is zero etc.: block structure.
        let d = m.elasticity();
        for i in 0..3 {
            for j in 3..6 {
                assert_eq!(d[i][j], 0.0);
            }
        }
        assert!((d[0][0] - d[1][1]).abs() <= 1e-15 * d[0][0]);
        // In-plane isotropy: D_xy,xy = (D_xx,xx - D_xx,yy) / 2.
        assert!((d[3][3] - 0.5 * (d[0][0] - d[0][1])).abs() <= 1e-12 * d[0][0]);
        // Same for a non-unit axis.
        assert_eq!(pad([0.0, 0.0, 3.0]).elasticity(), d);
    }

    #[test]
    fn axis_x_permutes_the_matrix() {
        let dl = pad(Z).local_elasticity();
        let dx = pad([2.0, 0.0, 0.0]).elasticity();
        // Global x is the local axis z; global y, z are in-plane directions.
        // Voigt map global -> local: xx->zz, yy->xx, zz->yy, xy->zx, yz->xy, zx->yz.
        let perm = [2, 0, 1, 5, 3, 4];
        let mut expect = [[0.0; 6]; 6];
        for i in 0..6 {
            for j in 0..6 {
                expect[i][j] = dl[perm[i]][perm[j]];
            }
        }
        assert_close(&dx, &expect, 1e-14);
        // And along y.
        let dy = pad([0.0, -1.0, 0.0]).elasticity();
        assert!((dy[1][1] - dl[2][2]).abs() <= 1e-14 * dl[2][2]);
        assert!((dy[0][0] - dl[0][0]).abs() <= 1e-14 * dl[0][0]);
        assert!((dy[5][5] - dl[3][3]).abs() <= 1e-14 * dl[3][3]); // zx is in-plane
    }

    #[test]
    fn isotropic_limit_is_isotropic_for_any_axis() {
        let (e, nu) = (70e9, 0.33);
        let g = e / (2.0 * (1.0 + nu));
        let iso = isotropic_elasticity(e, nu);
        for axis in [Z, [1.0, 0.0, 0.0], [0.3, -0.8, 0.5], [-1.0, 2.0, 0.1]] {
            let m = TransverselyIsotropic::new(e, e, nu, nu, Some(g), axis, 1.0).unwrap();
            assert_close(&m.elasticity(), &iso, 1e-13);
            // Huber's default is exact in the isotropic limit.
            let h = TransverselyIsotropic::new(e, e, nu, nu, None, axis, 1.0).unwrap();
            assert!((h.g_axial() - g).abs() < 1e-6 * g);
            assert_close(&h.elasticity(), &iso, 1e-13);
        }
    }

    #[test]
    fn rotated_matrix_is_spd_and_rotation_invariant_in_the_axis_direction() {
        let axis = [0.3, -0.8, 0.5];
        let m = pad(axis);
        let d = m.elasticity();
        for i in 0..6 {
            for j in 0..6 {
                assert_eq!(d[i][j], d[j][i]);
            }
        }
        assert!(cholesky(&d).is_some());
        // Uniaxial stress along the axis: strain along the axis is 1/E_z, transverse -nu_zp/E_z.
        let n = {
            let l = (axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]).sqrt();
            axis.map(|v| v / l)
        };
        assert_eq!(m.axis(), n);
        let sigma = [
            n[0] * n[0],
            n[1] * n[1],
            n[2] * n[2],
            n[0] * n[1],
            n[1] * n[2],
            n[2] * n[0],
        ];
        let s = compliance(&d);
        let eps: Vec<f64> = (0..6)
            .map(|i| (0..6).map(|j| s[i][j] * sigma[j]).sum())
            .collect();
        // eps_nn = n . eps n with engineering shears halved.
        let e_nn = eps[0] * n[0] * n[0]
            + eps[1] * n[1] * n[1]
            + eps[2] * n[2] * n[2]
            + eps[3] * n[0] * n[1]
            + eps[4] * n[1] * n[2]
            + eps[5] * n[2] * n[0];
        assert!((e_nn * 5.4e9 - 1.0).abs() < 1e-12, "{}", e_nn * 5.4e9);
        let trace = eps[0] + eps[1] + eps[2];
        let e_transverse = 0.5 * (trace - e_nn);
        assert!((-e_transverse / e_nn - m.nu_zp()).abs() < 1e-12);
    }

    #[test]
    fn poisson_convention_and_reciprocity() {
        let m = pad(Z);
        let s = compliance(&m.elasticity());
        // Uniaxial in-plane stress sigma_x: eps_x = 1/Ep, eps_y = -nu_p/Ep, eps_z = -nu_pz/Ep.
        assert!((s[0][0] * 15.3e9 - 1.0).abs() < 1e-12);
        assert!((-s[1][0] / s[0][0] - 0.15).abs() < 1e-12);
        assert!((-s[2][0] / s[0][0] - 0.15).abs() < 1e-12, "nu_pz");
        // Uniaxial axial stress sigma_z: eps_z = 1/Ez, eps_x = -nu_zp/Ez.
        assert!((s[2][2] * 5.4e9 - 1.0).abs() < 1e-12);
        let nu_zp = -s[0][2] / s[2][2];
        assert!((nu_zp - 0.15 * 5.4 / 15.3).abs() < 1e-12);
        assert!((m.nu_zp() - nu_zp).abs() < 1e-15);
        // Reciprocity nu_zp / Ez = nu_pz / Ep.
        assert!((nu_zp / 5.4e9 - 0.15 / 15.3e9).abs() < 1e-12 * 0.15 / 15.3e9);
        // Shear moduli: axial (given by Huber), in-plane E_p / (2 (1 + nu_p)).
        assert!((1.0 / s[4][4] - m.g_axial()).abs() < 1e-6 * m.g_axial());
        assert!((1.0 / s[5][5] - m.g_axial()).abs() < 1e-6 * m.g_axial());
        assert!((1.0 / s[3][3] - 15.3e9 / 2.3).abs() < 1e-3);
        let huber = (15.3e9f64 * 5.4e9).sqrt() / (2.0 * (1.0 + (0.15 * nu_zp).sqrt()));
        assert!((m.g_axial() - huber).abs() < 1e-6);
        assert!((m.g_axial() - 4.1729e9).abs() < 1e6, "{}", m.g_axial());
        // A given shear modulus is used as is.
        let g =
            TransverselyIsotropic::new(15.3e9, 5.4e9, 0.15, 0.15, Some(2e9), Z, 4000.0).unwrap();
        assert_eq!(g.g_axial(), 2e9);
        assert!((g.elasticity()[4][4] - 2e9).abs() < 1e-3);
    }

    fn err(
        ep: f64,
        ez: f64,
        nup: f64,
        nupz: f64,
        g: Option<f64>,
        axis: [f64; 3],
        rho: f64,
    ) -> String {
        TransverselyIsotropic::new(ep, ez, nup, nupz, g, axis, rho)
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn invalid_constants_name_the_field() {
        let e = err(0.0, 5.4e9, 0.15, 0.15, None, Z, 4000.0);
        assert!(
            e.contains("e_in_plane") && e.contains("transversely_isotropic"),
            "{e}"
        );
        let e = err(15.3e9, -5.4e9, 0.15, 0.15, None, Z, 4000.0);
        assert!(e.contains("e_axial"), "{e}");
        let e = err(15.3e9, 5.4e9, 0.15, 0.15, Some(-1.0), Z, 4000.0);
        assert!(e.contains("g_axial"), "{e}");
        let e = err(15.3e9, 5.4e9, 0.15, 0.15, None, Z, 0.0);
        assert!(e.contains("density"), "{e}");
        let e = err(15.3e9, 5.4e9, f64::NAN, 0.15, None, Z, 4000.0);
        assert!(e.contains("nu_in_plane"), "{e}");
        let e = err(15.3e9, 5.4e9, 0.15, f64::INFINITY, None, Z, 4000.0);
        assert!(e.contains("nu_axial"), "{e}");
        let e = err(15.3e9, 5.4e9, 0.15, 0.15, None, [0.0; 3], 4000.0);
        assert!(e.contains("axis") && e.contains("non-zero"), "{e}");

        // Non positive definite compliances.
        let pd = "positive definite compliance: check e_in_plane, e_axial, nu_in_plane, \
                  nu_axial, g_axial";
        // nu_p = 0.9 with a stiff axis: 1 - nu_p - 2 nu_pz nu_zp < 0.
        let e = err(15.3e9, 60e9, 0.9, 0.15, None, Z, 4000.0);
        assert!(e.contains("compliance") && e.contains(pd), "{e}");
        // nu_p = 0.9 with a soft axis but large nu_pz (nu_zp = nu_pz Ez / Ep).
        let e = err(15.3e9, 1e9, 0.9, 1.5, Some(1e9), Z, 4000.0);
        assert!(e.contains("compliance"), "{e}");
        // nu_p out of (-1, 1).
        for nup in [1.0, 1.2, -1.0, -1.5] {
            let e = err(15.3e9, 5.4e9, nup, 0.1, Some(1e9), Z, 4000.0);
            assert!(e.contains("compliance"), "nu_p = {nup}: {e}");
        }
        // Isotropic limit at nu = 0.5 is incompressible: rejected.
        let e = err(1e9, 1e9, 0.5, 0.5, Some(1e9 / 3.0), Z, 1.0);
        assert!(e.contains("compliance"), "{e}");
        // Borderline valid: nu_p = 0.9, small e_axial, moderate nu_pz.
        assert!(TransverselyIsotropic::new(15.3e9, 1e9, 0.9, 0.15, None, Z, 1.0).is_ok());
    }
}
