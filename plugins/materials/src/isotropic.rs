//! Isotropic linear elasticity.

use crate::{invalid, positive};
use squeal_core::{Material, Result, Voigt6};

/// Isotropic elasticity matrix (Pa) from Young's modulus `e` and Poisson's ratio `nu`:
/// `lambda + 2 mu` on the normal diagonal, `lambda` off it, `mu` on the (engineering)
/// shear diagonal, with `lambda = E nu / ((1 + nu)(1 - 2 nu))`, `mu = E / (2 (1 + nu))`.
/// No validation: see [`Isotropic::new`].
pub fn isotropic_elasticity(e: f64, nu: f64) -> Voigt6 {
    let lam = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e / (2.0 * (1.0 + nu));
    let mut d = [[0.0; 6]; 6];
    for i in 0..3 {
        for j in 0..3 {
            d[i][j] = lam;
        }
        d[i][i] = lam + 2.0 * mu;
        d[3 + i][3 + i] = mu;
    }
    d
}

/// Isotropic linear elastic material (plugin `"isotropic"`).
///
/// ```
/// use squeal_core::Material;
/// use squeal_materials::Isotropic;
/// let steel = Isotropic::new(210e9, 0.3, 7850.0).unwrap();
/// assert_eq!(steel.density(), 7850.0);
/// assert!(Isotropic::new(210e9, 0.5, 7850.0).is_err());
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct Isotropic {
    youngs_modulus: f64,
    poisson_ratio: f64,
    density: f64,
    d: Voigt6,
}

impl Isotropic {
    /// Validates and builds: `E > 0` finite (Pa), `-1 < nu < 0.5`, `rho > 0` finite
    /// (kg/m^3). The error names the field (`youngs_modulus`, `poisson_ratio`,
    /// `density`).
    pub fn new(youngs_modulus: f64, poisson_ratio: f64, density: f64) -> Result<Self> {
        const NAME: &str = "isotropic";
        positive(NAME, "youngs_modulus", youngs_modulus)?;
        if !(poisson_ratio > -1.0 && poisson_ratio < 0.5) {
            return Err(invalid(
                NAME,
                "poisson_ratio",
                poisson_ratio,
                "-1 < nu < 0.5",
            ));
        }
        positive(NAME, "density", density)?;
        Ok(Self {
            youngs_modulus,
            poisson_ratio,
            density,
            d: isotropic_elasticity(youngs_modulus, poisson_ratio),
        })
    }

    /// Young's modulus (Pa).
    pub fn youngs_modulus(&self) -> f64 {
        self.youngs_modulus
    }

    /// Poisson's ratio.
    pub fn poisson_ratio(&self) -> f64 {
        self.poisson_ratio
    }

    /// Shear modulus `E / (2 (1 + nu))` (Pa).
    pub fn shear_modulus(&self) -> f64 {
        self.youngs_modulus / (2.0 * (1.0 + self.poisson_ratio))
    }
}

impl Material for Isotropic {
    fn name(&self) -> &str {
        "isotropic"
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
    use crate::voigt::cholesky;

    fn err(e: f64, nu: f64, rho: f64) -> String {
        Isotropic::new(e, nu, rho).unwrap_err().to_string()
    }

    #[test]
    fn valid_material() {
        let m = Isotropic::new(200e9, 0.25, 7800.0).unwrap();
        let d = m.elasticity();
        // lambda = mu = 80 GPa for nu = 1/4.
        assert!((d[0][0] - 240e9).abs() < 1e-3);
        assert!((d[0][1] - 80e9).abs() < 1e-3);
        assert!((d[3][3] - 80e9).abs() < 1e-3);
        assert!((m.shear_modulus() - 80e9).abs() < 1e-3);
        assert_eq!(d[0][3], 0.0);
        assert!(cholesky(&d).is_some());
        // Uniaxial stress: eps_yy / eps_xx = -nu, sigma_xx / eps_xx = E.
        let s = crate::voigt::spd_inverse(&cholesky(&d).unwrap());
        assert!((s[0][0] * 200e9 - 1.0).abs() < 1e-12);
        assert!((-s[1][0] / s[0][0] - 0.25).abs() < 1e-12);
        assert!(Isotropic::new(1.0, -0.99, 1.0).is_ok());
        assert!(Isotropic::new(1.0, 0.499, 1.0).is_ok());
    }

    #[test]
    fn invalid_constants_name_the_field() {
        for nu in [0.5, 0.7, -1.0, -1.5, f64::NAN] {
            let e = err(210e9, nu, 7850.0);
            assert!(
                e.contains("poisson_ratio") && e.contains("-1 < nu < 0.5"),
                "{e}"
            );
        }
        for rho in [0.0, -7850.0, f64::INFINITY] {
            let e = err(210e9, 0.3, rho);
            assert!(e.contains("density") && e.contains("> 0"), "{e}");
        }
        for ym in [0.0, -1e9, f64::NAN, f64::INFINITY] {
            let e = err(ym, 0.3, 7850.0);
            assert!(e.contains("youngs_modulus"), "{e}");
        }
        let e = err(0.0, 0.3, 7850.0);
        assert!(e.contains("`isotropic`"), "{e}");
    }
}
