//! The checks of a calibration spec: its own fields, then against its base scene.

use super::spec::*;
use squeal_scene::Scene;

impl CalibrationSpec {
    /// Checks bounds, weights and targets against each other and against `scene`: every
    /// parameter path must be settable, every target's body present.
    pub fn check_against(&self, scene: &Scene, file: &str) -> Result<(), SpecError> {
        for (i, p) in self.parameters.iter().enumerate() {
            scene
                .with_values(&[(p.path.as_str(), self.start_value(i, scene))], file)
                .map_err(|e| SpecError::Field {
                    file: file.into(),
                    field: format!("parameter[{i}].path"),
                    message: strip_file(&e.to_string(), file),
                })?;
        }
        let rule: Vec<(&str, f64)> = self
            .search
            .rule
            .iter()
            .map(|(k, v)| (k.as_str(), *v))
            .collect();
        scene
            .with_values(&rule, file)
            .map_err(|e| SpecError::Field {
                file: file.into(),
                field: "search.rule".into(),
                message: strip_file(&e.to_string(), file),
            })?;
        for (i, t) in self.targets.iter().enumerate() {
            let field = |f: &str, message: String| SpecError::Field {
                file: file.into(),
                field: format!("target[{i}].{f}"),
                message,
            };
            match &t.kind {
                TargetKind::Mode { body, .. } | TargetKind::ModeCount { body, .. } => {
                    let present = match body.as_str() {
                        "disc" => scene.disc.is_some(),
                        "pin" => scene.pin.is_some(),
                        _ => false,
                    };
                    if !present {
                        return Err(field(
                            "body",
                            format!("`{body}`: expected a body of the scene (disc, pin)"),
                        ));
                    }
                }
                TargetKind::Stiffness { .. }
                | TargetKind::TiedMode { .. }
                | TargetKind::Coupling { .. } => {
                    if scene.disc.is_none() || scene.pin.is_none() {
                        return Err(field(
                            "kind",
                            "needs a scene with a disc and a pin in contact".into(),
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// The parameters' bounds, scales, starts and paths (each given once).
    fn check_parameters(&self, file: &str) -> Result<(), SpecError> {
        let field = |f: String, message: String| SpecError::Field {
            file: file.into(),
            field: f,
            message,
        };
        for (i, p) in self.parameters.iter().enumerate() {
            let f = |name: &str| format!("parameter[{i}].{name}");
            if !(p.min.is_finite() && p.max.is_finite() && p.min < p.max) {
                return Err(field(
                    f("max"),
                    format!(
                        "expected finite bounds with min < max, got [{}, {}] for `{}`",
                        p.min, p.max, p.path
                    ),
                ));
            }
            if p.scale == Scale::Log && p.min <= 0.0 {
                return Err(field(
                    f("min"),
                    format!("a log scale needs positive bounds, got min = {}", p.min),
                ));
            }
            if let Some(s) = p.start {
                if !(p.min..=p.max).contains(&s) {
                    return Err(field(
                        f("start"),
                        format!("{s} is outside [{}, {}]", p.min, p.max),
                    ));
                }
            }
            if self.parameters[..i].iter().any(|q| q.path == p.path) {
                return Err(field(f("path"), format!("`{}` is given twice", p.path)));
            }
        }
        Ok(())
    }

    pub(super) fn check(&self, file: &str) -> Result<(), SpecError> {
        let field = |f: String, message: String| SpecError::Field {
            file: file.into(),
            field: f,
            message,
        };
        if self.targets.is_empty() {
            return Err(field(
                "target".into(),
                "expected at least one [[target]]".into(),
            ));
        }
        self.check_parameters(file)?;
        for (i, t) in self.targets.iter().enumerate() {
            let f = |name: &str| format!("target[{i}].{name}");
            if !(t.within.is_finite() && (0.0..1.0).contains(&t.within)) {
                return Err(field(
                    f("within"),
                    format!("expected a relative tolerance in [0, 1), got {}", t.within),
                ));
            }
            if !(t.weight.is_finite() && t.weight >= 0.0) {
                return Err(field(
                    f("weight"),
                    format!("expected a weight >= 0, got {}", t.weight),
                ));
            }
            let positive = |name: &str, v: f64| {
                if v.is_finite() && v > 0.0 {
                    Ok(())
                } else {
                    Err(field(
                        f(name),
                        format!("expected a positive number, got {v}"),
                    ))
                }
            };
            match &t.kind {
                TargetKind::Stiffness { value_n_per_m } => {
                    positive("value_n_per_m", *value_n_per_m)?
                }
                TargetKind::Mode { freq_hz, .. } => positive("freq_hz", *freq_hz)?,
                TargetKind::Coupling { freq_hz, mu_range } => {
                    positive("freq_hz", *freq_hz)?;
                    let [a, b] = *mu_range;
                    if !(a.is_finite() && b.is_finite() && 0.0 <= a && a <= b) {
                        return Err(field(
                            f("mu_range"),
                            format!("expected [FROM, TO] with 0 <= FROM <= TO, got [{a}, {b}]"),
                        ));
                    }
                }
                TargetKind::ModeCount { below_hz, .. } => positive("below_hz", *below_hz)?,
                TargetKind::TiedMode {
                    mu,
                    makeup,
                    freq_hz,
                    window_hz,
                    makeup_lowest,
                } => {
                    if *makeup_lowest == Some(0) {
                        return Err(field(f("makeup_lowest"), "expected at least 1".into()));
                    }
                    positive("freq_hz", *freq_hz)?;
                    if let Some(mu) = mu {
                        if !(mu.is_finite() && *mu >= 0.0) {
                            return Err(field(f("mu"), format!("expected mu >= 0, got {mu}")));
                        }
                    }
                    if makeup.is_empty() {
                        return Err(field(
                            f("makeup"),
                            "expected a label prefix such as `pin:tilt-y`".into(),
                        ));
                    }
                    if let Some([a, b]) = window_hz {
                        if !(a.is_finite() && b.is_finite() && *a >= 0.0 && a < b) {
                            return Err(field(
                                f("window_hz"),
                                format!(
                                    "expected [FMIN, FMAX] with 0 <= FMIN < FMAX, got [{a}, {b}]"
                                ),
                            ));
                        }
                    }
                }
            }
        }
        let s = &self.search;
        let [from, to, step] = s.sweep.mu;
        if let Err(e) = crate::mu_sweep::mu_list(from, to, step) {
            return Err(field("search.sweep.mu".into(), e));
        }
        let [f0, f1] = s.sweep.band_hz;
        if !(f0.is_finite() && f1.is_finite() && 0.0 <= f0 && f0 < f1) {
            return Err(field(
                "search.sweep.band_hz".into(),
                format!("expected [FMIN, FMAX] with 0 <= FMIN < FMAX, got [{f0}, {f1}]"),
            ));
        }
        if s.max_evaluations == 0 {
            return Err(field(
                "search.max_evaluations".into(),
                "expected at least 1".into(),
            ));
        }
        if !(s.tolerance.is_finite() && s.tolerance > 0.0) {
            return Err(field(
                "search.tolerance".into(),
                format!("expected a positive fraction, got {}", s.tolerance),
            ));
        }
        if !(s.difference_step > 0.0 && s.difference_step <= 0.25) {
            return Err(field(
                "search.difference_step".into(),
                format!(
                    "expected a fraction in (0, 0.25], got {}",
                    s.difference_step
                ),
            ));
        }
        Ok(())
    }
}

/// A scene error re-worded for the spec's own field: drops the leading `file: `.
pub(super) fn strip_file(message: &str, file: &str) -> String {
    message
        .strip_prefix(&format!("{file}: "))
        .unwrap_or(message)
        .to_string()
}
