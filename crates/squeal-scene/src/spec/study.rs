//! The study (friction, band, rotation) and the damping of the stability analysis.

use super::{field_error, Scene};
use crate::{Result, SceneError};
use serde::{Deserialize, Serialize};

/// Friction and band of the study.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Study {
    /// Coulomb friction coefficient.
    pub mu: f64,
    /// Frequency band of the stability analysis (Hz): every command's default `--band`.
    /// Default 0-5 kHz, where the paper's couplings lie; the mesh resolves up to
    /// `mesh.max_freq_hz`.
    pub band_hz: [f64; 2],
    /// Rotation sense of the disc about +z: `1` counter-clockwise, `-1` clockwise.
    pub rotation: f64,
}

impl Default for Study {
    fn default() -> Self {
        Self {
            mu: 0.3,
            band_hz: [0.0, 5_000.0],
            rotation: 1.0,
        }
    }
}

/// Damping of the stability analysis: `C = alpha M + beta K + C_t`, where `C_t` holds
/// viscous tangential dashpots between the pin and disc nodes of every closed contact
/// pair. None of it changes the static sliding equilibrium. Absent or all zero means
/// undamped (`C = 0`), the paper's setting.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct Damping {
    /// Rayleigh mass-proportional coefficient `alpha` (1/s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rayleigh_alpha_per_s: Option<f64>,
    /// Rayleigh stiffness-proportional coefficient `beta` (s).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rayleigh_beta_s: Option<f64>,
    /// Rayleigh damping given instead as a modal damping ratio (dimensionless) reached at
    /// both frequencies of `rayleigh_freqs_hz`; excludes `rayleigh_alpha_per_s` and
    /// `rayleigh_beta_s`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rayleigh_ratio: Option<f64>,
    /// The two frequencies (Hz) where the modal damping ratio equals `rayleigh_ratio`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rayleigh_freqs_hz: Option<[f64; 2]>,
    /// Viscous tangential contact damping per unit contact area (N s/m^3): each closed
    /// pair gets a dashpot `c = value x tributary area` on the relative in-plane velocity
    /// of its pin and disc nodes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contact_tangential_n_s_per_m3: Option<f64>,
}

impl Damping {
    /// Whether no damping is given (the scene is undamped).
    pub fn is_none(&self) -> bool {
        *self == Damping::default()
    }

    /// The Rayleigh coefficients `(alpha (1/s), beta (s))`; a ratio `zeta` at
    /// `f1`, `f2` gives `alpha = 2 zeta w1 w2 / (w1 + w2)`, `beta = 2 zeta / (w1 + w2)`.
    pub fn rayleigh(&self) -> (f64, f64) {
        match (self.rayleigh_ratio, self.rayleigh_freqs_hz) {
            (Some(z), Some([f1, f2])) => {
                let (w1, w2) = (
                    2.0 * std::f64::consts::PI * f1,
                    2.0 * std::f64::consts::PI * f2,
                );
                (2.0 * z * w1 * w2 / (w1 + w2), 2.0 * z / (w1 + w2))
            }
            _ => (
                self.rayleigh_alpha_per_s.unwrap_or(0.0),
                self.rayleigh_beta_s.unwrap_or(0.0),
            ),
        }
    }

    /// Contact dashpot coefficient per unit area (N s/m^3), 0 when absent.
    pub fn contact_tangential(&self) -> f64 {
        self.contact_tangential_n_s_per_m3.unwrap_or(0.0)
    }

    /// One line for reports: `none`, or the Rayleigh coefficients and the contact
    /// dashpots with their units.
    pub fn describe(&self) -> String {
        if self.is_zero() {
            return "none".into();
        }
        let (a, b) = self.rayleigh();
        let mut parts = Vec::new();
        if a != 0.0 || b != 0.0 {
            let from = match (self.rayleigh_ratio, self.rayleigh_freqs_hz) {
                (Some(z), Some([f1, f2])) => format!(" (ratio {z} at {f1} and {f2} Hz)"),
                _ => String::new(),
            };
            parts.push(format!(
                "Rayleigh alpha = {a:.6e} 1/s, beta = {b:.6e} s{from}"
            ));
        }
        let c = self.contact_tangential();
        if c != 0.0 {
            parts.push(format!("contact tangential {c:e} N s/m^3"));
        }
        parts.join("; ")
    }

    /// Whether the damping matrix is zero.
    pub fn is_zero(&self) -> bool {
        let (a, b) = self.rayleigh();
        a == 0.0 && b == 0.0 && self.contact_tangential() == 0.0
    }

    pub(super) fn validate(&self, file: &str) -> Result<()> {
        let field = |f: &str, m: String| SceneError::Field {
            file: file.into(),
            field: format!("damping.{f}"),
            message: m,
        };
        let non_negative = |f: &str, v: Option<f64>, unit: &str| -> Result<()> {
            match v {
                Some(v) if !(v.is_finite() && v >= 0.0) => Err(field(
                    f,
                    format!("expected a finite value >= 0 in {unit}, got {v}"),
                )),
                _ => Ok(()),
            }
        };
        non_negative("rayleigh_alpha_per_s", self.rayleigh_alpha_per_s, "1/s")?;
        non_negative("rayleigh_beta_s", self.rayleigh_beta_s, "s")?;
        non_negative(
            "contact_tangential_n_s_per_m3",
            self.contact_tangential_n_s_per_m3,
            "N s/m^3",
        )?;
        match (self.rayleigh_ratio, self.rayleigh_freqs_hz) {
            (None, None) => Ok(()),
            (Some(z), Some([f1, f2])) => {
                if self.rayleigh_alpha_per_s.is_some() || self.rayleigh_beta_s.is_some() {
                    return Err(field(
                        "rayleigh_ratio",
                        "give either rayleigh_ratio with rayleigh_freqs_hz or                          rayleigh_alpha_per_s / rayleigh_beta_s, not both"
                            .into(),
                    ));
                }
                if !(z.is_finite() && (0.0..1.0).contains(&z)) {
                    return Err(field(
                        "rayleigh_ratio",
                        format!("expected a damping ratio in [0, 1), got {z}"),
                    ));
                }
                if !(f1.is_finite() && f2.is_finite() && f1 > 0.0 && f2 > 0.0) {
                    return Err(field(
                        "rayleigh_freqs_hz",
                        format!("expected two positive frequencies in Hz, got [{f1}, {f2}]"),
                    ));
                }
                Ok(())
            }
            (Some(_), None) => Err(field(
                "rayleigh_freqs_hz",
                "rayleigh_ratio needs rayleigh_freqs_hz = [f1, f2] (Hz)".into(),
            )),
            (None, Some(_)) => Err(field(
                "rayleigh_ratio",
                "rayleigh_freqs_hz needs rayleigh_ratio (the damping ratio at both)".into(),
            )),
        }
    }
}

/// Checks the `[study]` table.
pub(super) fn validate_study(scene: &Scene, file: &str) -> Result<()> {
    let field = |f: &str, m: String| field_error(file, f, m);
    let st = &scene.study;
    if !(st.mu.is_finite() && st.mu >= 0.0) {
        return Err(field(
            "study.mu",
            format!("expected a friction coefficient >= 0, got {}", st.mu),
        ));
    }
    if !(st.band_hz[0].is_finite()
        && st.band_hz[1].is_finite()
        && st.band_hz[0] >= 0.0
        && st.band_hz[0] < st.band_hz[1])
    {
        return Err(field(
            "study.band_hz",
            format!(
                "expected [fmin, fmax] in Hz with 0 <= fmin < fmax, got {:?}",
                st.band_hz
            ),
        ));
    }
    if st.rotation != 1.0 && st.rotation != -1.0 {
        return Err(field(
            "study.rotation",
            format!(
                "expected 1 (counter-clockwise about +z) or -1, got {}",
                st.rotation
            ),
        ));
    }
    Ok(())
}
