//! The [`ContactLaw`] plugin trait: how the normal reaction of a pair relates to its gap.

/// How the normal reaction of a pair relates to its gap.
pub trait ContactLaw: Send + Sync {
    /// Plugin name (as registered).
    fn name(&self) -> &str;
    /// Normal stiffness per pair (N/m) of a penalty law; `None` for the exact
    /// unilateral (Signorini) constraint.
    fn normal_stiffness(&self) -> Option<f64>;
    /// Normal compliance per pair (m/N) that the law adds to the contact flexibility:
    /// a closed pair satisfies `g + compliance * Rn = 0` instead of `g = 0`.
    fn compliance(&self) -> f64 {
        self.normal_stiffness().map_or(0.0, |k| 1.0 / k)
    }
}
