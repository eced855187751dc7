//! The converged eigenpairs a thick-restart Lanczos run locks ([`Pairs`]).

use squeal_core::eigen::KernelOutput;
use squeal_core::faer::{Mat, MatRef};

/// Converged eigenpairs of `OP`: values, `M`-orthonormal vectors and `M` times them.
pub(crate) struct Pairs {
    pub(crate) n: usize,
    pub(crate) theta: Vec<f64>,
    pub(crate) x: Vec<f64>,
    pub(crate) mx: Vec<f64>,
}

impl Pairs {
    pub(crate) fn new(n: usize) -> Self {
        Self {
            n,
            theta: Vec::new(),
            x: Vec::new(),
            mx: Vec::new(),
        }
    }

    pub(crate) fn len(&self) -> usize {
        self.theta.len()
    }

    pub(crate) fn push(&mut self, theta: f64, x: &[f64], mx: &[f64]) {
        self.theta.push(theta);
        self.x.extend_from_slice(x);
        self.mx.extend_from_slice(mx);
    }

    pub(crate) fn x(&self, j: usize) -> &[f64] {
        &self.x[j * self.n..(j + 1) * self.n]
    }

    pub(crate) fn mx(&self, j: usize) -> &[f64] {
        &self.mx[j * self.n..(j + 1) * self.n]
    }

    pub(crate) fn x_mat(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.x, self.n, self.len())
    }

    pub(crate) fn mx_mat(&self) -> MatRef<'_, f64> {
        MatRef::from_column_major_slice(&self.mx, self.n, self.len())
    }

    pub(crate) fn min_theta(&self) -> f64 {
        self.theta.iter().copied().fold(f64::INFINITY, f64::min)
    }

    pub(crate) fn filtered(&self, keep: impl Fn(f64) -> bool) -> Self {
        let mut out = Self::new(self.n);
        for j in 0..self.len() {
            if keep(self.theta[j]) {
                out.push(self.theta[j], self.x(j), self.mx(j));
            }
        }
        out
    }

    /// The `count` largest pairs of `a` and `b` (mutually `M`-orthogonal sets).
    pub(crate) fn merged(a: &Self, b: &Self, count: usize) -> Self {
        let mut all: Vec<(f64, &Self, usize)> = (0..a.len())
            .map(|j| (a.theta[j], a, j))
            .chain((0..b.len()).map(|j| (b.theta[j], b, j)))
            .collect();
        all.sort_by(|p, q| q.0.total_cmp(&p.0));
        let mut out = Self::new(a.n);
        for &(t, set, j) in all.iter().take(count) {
            out.push(t, set.x(j), set.mx(j));
        }
        out
    }

    pub(crate) fn into_output(self, iterations: usize, all_converged: bool) -> KernelOutput {
        let n = self.n;
        let vectors = Mat::from_fn(n, self.len(), |i, j| self.x[j * n + i]);
        KernelOutput {
            theta: self.theta,
            vectors,
            iterations,
            all_converged,
        }
    }
}
