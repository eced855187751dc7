//! # squeal-contact-laws
//!
//! How a pair's normal reaction relates to its gap:
//! - `lagrange`: the exact unilateral (Signorini) condition `0 <= Rn ⟂ g >= 0` with
//!   Coulomb sliding `Rt = mu Rn`;
//! - `penalty`: `Rn = kn max(0, -g)` (what commercial codes do); the equilibrium tends
//!   to the `lagrange` one like `1/kn` as the stiffness `kn_n_per_m` grows.

use squeal_core::{ContactLaw, Error, Registry, Result};

/// The exact unilateral contact law.
#[derive(Debug, Clone, Copy, Default)]
pub struct Lagrange;

impl ContactLaw for Lagrange {
    fn name(&self) -> &str {
        "lagrange"
    }
    fn normal_stiffness(&self) -> Option<f64> {
        None
    }
}

/// A penalty law with normal stiffness `kn` per pair (N/m).
#[derive(Debug, Clone, Copy)]
pub struct Penalty {
    kn: f64,
}

impl Penalty {
    /// A penalty law; `kn` must be positive and finite.
    pub fn new(kn: f64) -> Result<Self> {
        if kn.is_finite() && kn > 0.0 {
            Ok(Self { kn })
        } else {
            Err(Error::param(
                "kn_n_per_m",
                format!("expected a positive normal stiffness in N/m, got {kn}"),
            ))
        }
    }
}

impl ContactLaw for Penalty {
    fn name(&self) -> &str {
        "penalty"
    }
    fn normal_stiffness(&self) -> Option<f64> {
        Some(self.kn)
    }
}

/// Registers `lagrange` and `penalty`.
pub fn register(reg: &mut Registry) {
    reg.contact_laws.register(
        "lagrange",
        "exact unilateral contact (Signorini) with Coulomb sliding",
        |_| Ok(Box::new(Lagrange)),
    );
    reg.contact_laws.register(
        "penalty",
        "penalty contact, Rn = kn max(0, -g) per pair (kn_n_per_m, default 1e10 N/m)",
        |p| Ok(Box::new(Penalty::new(p.num_or("kn_n_per_m", 1e10)?)?)),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compliance_follows_the_law() {
        assert_eq!(Lagrange.compliance(), 0.0);
        let p = Penalty::new(1e9).unwrap();
        approx::assert_relative_eq!(p.compliance(), 1e-9);
        assert!(Penalty::new(-1.0)
            .unwrap_err()
            .to_string()
            .contains("kn_n_per_m"));
        assert!(Penalty::new(f64::NAN).is_err());
    }

    #[test]
    fn registered_by_name() {
        let mut reg = Registry::new();
        register(&mut reg);
        let mut p = squeal_core::Params::new();
        p.0.insert("kn_n_per_m".into(), squeal_core::ParamValue::Num(5e8));
        let law = reg.contact_laws.create("penalty", &p).unwrap();
        assert_eq!(law.normal_stiffness(), Some(5e8));
        let err = reg
            .contact_laws
            .create("lagrange", &p)
            .err()
            .expect("unknown key");
        assert!(err.to_string().contains("kn_n_per_m"));
    }
}
