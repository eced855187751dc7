//! Helpers shared by the FE integration tests.

use squeal_core::{EigenSolver, Params, SparseRef};
use squeal_fe::Mesh;

/// The steel of every test: E = 210 GPa, nu = 0.3, rho = 7850 kg/m^3.
pub const E_STEEL: f64 = 210e9;
/// Poisson's ratio of the steel.
pub const NU_STEEL: f64 = 0.3;
/// Density of the steel (kg/m^3).
pub const RHO_STEEL: f64 = 7850.0;

/// The isotropic steel material.
pub fn steel() -> squeal_materials::Isotropic {
    squeal_materials::Isotropic::new(E_STEEL, NU_STEEL, RHO_STEEL).expect("valid steel")
}

/// An eigen solver from the facade registry.
pub fn solver(name: &str) -> Box<dyn EigenSolver> {
    squeal::registry()
        .eigen
        .create(name, &Params::new())
        .unwrap_or_else(|e| panic!("cannot create eigen solver `{name}`: {e}"))
}

/// A fixed pseudo-random sequence in [-1, 1) (xorshift64*), reproducible across runs.
pub struct Jitter(u64);

impl Jitter {
    /// Seeded sequence.
    pub fn new(seed: u64) -> Self {
        Self(seed.max(1))
    }

    /// Next value in [-1, 1).
    pub fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let r = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d);
        (r >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
}

/// Moves every node of `mesh` by up to `amp` times the local grid spacing `h` (per
/// axis) in each direction; nodes for which `keep(node)` is true are not moved.
pub fn perturb(mesh: &mut Mesh, h: [f64; 3], amp: f64, seed: u64, keep: &dyn Fn(usize) -> bool) {
    let mut j = Jitter::new(seed);
    for n in 0..mesh.n_nodes() {
        let d = [j.next(), j.next(), j.next()];
        if keep(n) {
            continue;
        }
        for c in 0..3 {
            mesh.nodes[n][c] += amp * h[c] * d[c];
        }
    }
}

/// Column `i` of a mode-shape matrix.
pub fn column(v: &squeal_core::faer::Mat<f64>, i: usize) -> Vec<f64> {
    (0..v.nrows()).map(|r| v[(r, i)]).collect()
}

/// `x^T A y`.
pub fn quad(a: SparseRef<'_>, x: &[f64], y: &[f64]) -> f64 {
    let mut ay = vec![0.0; a.nrows()];
    squeal_core::linalg::spmv(a, y, &mut ay);
    squeal_core::linalg::dot(x, &ay)
}

/// `||A||_1`, for relative residuals.
pub fn norm1(a: SparseRef<'_>) -> f64 {
    squeal_core::linalg::norm1(a)
}

/// Hz of an eigenvalue `omega^2`.
pub fn hz(omega2: f64) -> f64 {
    omega2.max(0.0).sqrt() / (2.0 * std::f64::consts::PI)
}

/// `[a, b, ...]` in scientific notation with 3 decimals.
pub fn sci(v: &[f64]) -> String {
    let items: Vec<String> = v.iter().map(|x| format!("{x:.3e}")).collect();
    format!("[{}]", items.join(", "))
}
