//! Spectral transformations: the operators whose eigenvalues `theta` of largest modulus
//! are the wanted eigenvalues nearest a shift, behind one operator trait for real and
//! complex vectors ([`LinOp`], [`SpectralTransform`]), as SLEPc's `ST` and faer's
//! `LinOp`. Every Krylov kernel drives one of them; none factorizes anything itself.
//!
//! | transformation | problem | operator | shift plane |
//! |---|---|---|---|
//! | [`ShiftInvert`] | `K x = omega^2 M x` (symmetric) | `(K - sigma M)^-1 M`, sparse Cholesky | `omega^2` |
//! | [`QepShiftInvert`] | the QEP, any damping | companion form at a complex `sigma`, complex sparse LU of `Q(sigma)` | `lambda` |
//! | [`SquaredShift`] | the QEP with `C = 0` | `(K~ - s M~)^-1 M~` at a real `sigma_s`, real sparse LU or Woodbury on a symmetric factor ([`crate::lowrank`]) | `s = -lambda^2` |
//!
//! In every case the pencil's eigenvalue of an operator eigenvalue is `sigma + 1/theta`
//! ([`SpectralTransform::pencil_eigenvalue`]).

mod companion;
mod real;
mod squared;

pub use companion::{QepShiftInvert, QepSymbolic};
pub use real::ShiftInvert;
pub use squared::SquaredShift;

/// A linear operator `y = OP x` on `f64` or [`c64`](crate::c64) vectors (a spectral
/// transformation, a test matrix...).
pub trait LinOp<T>: Sync {
    /// Size of the operator.
    fn dim(&self) -> usize;
    /// `y = OP x`; `x` and `y` have length [`dim`](Self::dim).
    fn apply(&self, x: &[T], y: &mut [T]);
}

/// A real operator seen on real vectors and on complex ones (applied to their real and
/// imaginary parts), e.g. the squared transformation
/// [`SquaredShift`].
pub trait RealOp: Sync {
    /// The operator on real vectors.
    fn real(&self) -> &dyn LinOp<f64>;
    /// The same operator on complex vectors.
    fn complex(&self) -> &dyn LinOp<crate::c64>;
}

/// A spectral transformation `OP = (A - sigma B)^-1 B` of a pencil `(A, B)`: its shift,
/// the map from an operator eigenvalue back to the pencil's, and its cost so far.
pub trait SpectralTransform<T>: LinOp<T>
where
    T: Copy + From<f64> + std::ops::Add<Output = T> + std::ops::Div<Output = T>,
{
    /// The shift `sigma`, in the plane of the pencil's eigenvalues (table above).
    fn shift(&self) -> T;
    /// How many times the operator was applied (one factorized solve each).
    fn applications(&self) -> usize;
    /// The pencil's eigenvalue `sigma + 1/theta` of an operator eigenvalue `theta`.
    fn pencil_eigenvalue(&self, theta: T) -> T {
        self.shift() + T::from(1.0) / theta
    }
}
