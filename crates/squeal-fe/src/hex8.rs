//! (being written by the element helper)
use squeal_core::Voigt6;

/// Element matrices of one hexahedron.
pub struct Hex8Matrices {
    /// Stiffness, 24 x 24, node-major DOFs (node i: 3i, 3i+1, 3i+2).
    pub ke: [[f64; 24]; 24],
    /// Consistent mass, 24 x 24.
    pub me: [[f64; 24]; 24],
    /// Volume (m^3).
    pub volume: f64,
}

/// Stiffness and mass of an 8-node hexahedron with incompatible modes.
pub fn hex8_matrices(_x: &[[f64; 3]; 8], _d: &Voigt6, _rho: f64) -> Hex8Matrices {
    unimplemented!()
}
