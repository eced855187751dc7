//! The [`Material`] plugin trait: a stateless linear elastic law.
//!
//! Stress and strain use Voigt notation in the order
//! `(xx, yy, zz, xy, yz, zx)` with engineering shear strains (`gamma_xy = 2 eps_xy`),
//! so `sigma = D eps` with a symmetric positive definite `D` in Pa.

/// A 6x6 matrix in Voigt notation.
pub type Voigt6 = [[f64; 6]; 6];

/// A linear elastic material: elasticity matrix and density, in the global frame.
///
/// Implementations validate their constants when constructed, so that `elasticity`
/// of a live object is always symmetric positive definite.
///
/// ```
/// use squeal_core::{Material, Voigt6};
/// #[derive(Debug)]
/// struct Rubber;
/// impl Material for Rubber {
///     fn name(&self) -> &str { "rubber" }
///     fn elasticity(&self) -> Voigt6 {
///         let mut d = [[0.0; 6]; 6];
///         for i in 0..6 { d[i][i] = 1e6; }
///         d
///     }
///     fn density(&self) -> f64 { 1100.0 }
/// }
/// assert_eq!(Rubber.density(), 1100.0);
/// ```
pub trait Material: Send + Sync + std::fmt::Debug {
    /// Plugin name (as registered).
    fn name(&self) -> &str;
    /// Elasticity matrix `D` (Pa) in the global frame, Voigt order `(xx, yy, zz, xy, yz, zx)`.
    fn elasticity(&self) -> Voigt6;
    /// Mass density (kg/m^3).
    fn density(&self) -> f64;
}
