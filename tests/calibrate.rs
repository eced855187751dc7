//! `squeal calibrate`: a synthetic fit recovers known parameters of the coarse rig from
//! targets measured on it, and bad specs are refused with the field named.

use squeal::analysis::calibrate::{calibrate, evaluate, CalibrationSpec};
use squeal::scene::Scene;

/// Targets of the spec measured on `scene`, written back as the spec's target values.
fn spec_with_targets_of(text: &str, scene: &Scene) -> CalibrationSpec {
    let reg = squeal::registry();
    let mut spec = CalibrationSpec::from_toml(text, "synthetic.toml").unwrap();
    let e = evaluate(&reg, scene, "truth", &spec.targets, &spec.search).unwrap();
    for (t, m) in spec.targets.iter_mut().zip(&e.measured) {
        assert!(m.value.is_finite(), "{}: {}", t.label(), m.note);
        use squeal::analysis::calibrate::TargetKind::*;
        match &mut t.kind {
            Stiffness { value_n_per_m } => *value_n_per_m = m.value,
            Mode { freq_hz, .. } | TiedMode { freq_hz, .. } | Coupling { freq_hz, .. } => {
                *freq_hz = m.value
            }
            ModeCount { count, .. } => *count = m.value as usize,
        }
    }
    spec
}

const SPEC: &str = r#"
scene = "pin-on-disc-coarse"
[search]
max_evaluations = 40
tolerance = 1e-6

[[parameter]]
path = "thin_plate.thickness_m"
min = 0.002
max = 0.005
scale = "log"

[[parameter]]
path = "thick_plate.thickness_m"
min = 0.005
max = 0.02

[[target]]
kind = "stiffness"
value_n_per_m = 1.0

[[target]]
kind = "tied_mode"
makeup = "pin:tilt-y|pin:shift-x"
makeup_lowest = 1
freq_hz = 1.0
window_hz = [1000.0, 5000.0]

[[target]]
kind = "mode"
body = "pin"
label = "bounce-z"
freq_hz = 1.0

[[target]]
kind = "mode"
body = "pin"
label = "tilt-x"
freq_hz = 1.0
"#;

#[test]
fn a_synthetic_fit_recovers_the_parameters_it_was_made_from() {
    let reg = squeal::registry();
    let base = Scene::builtin("pin-on-disc-coarse").unwrap();
    // the truth: other plates than the scene's
    let truth = base
        .with_values(
            &[
                ("thin_plate.thickness_m", 0.0034),
                ("thick_plate.thickness_m", 0.013),
            ],
            "truth",
        )
        .unwrap();
    let spec = spec_with_targets_of(SPEC, &truth);
    spec.check_against(&base, "synthetic.toml").unwrap();
    // starting from the base scene (3 mm, 10 mm)
    let fit = calibrate(&reg, &spec, &base, "base", |_| {}).unwrap();
    let want = [0.0034, 0.013];
    for (i, (v, w)) in fit.values.iter().zip(want).enumerate() {
        assert!(
            (v / w - 1.0).abs() < 0.01,
            "parameter {i}: fitted {v}, truth {w} (start {}); stops {:?}",
            fit.start[i],
            fit.stops
        );
    }
    for m in &fit.confirmed.measured {
        assert!(m.residual.abs() < 1e-3, "{m:?}");
    }
    // every evaluation is recorded, the cost falls from the start to the fit
    let first = fit.steps.iter().find(|s| s.kind == "search").unwrap();
    let last = fit.steps.last().unwrap();
    assert!(
        last.cost < 1e-3 * first.cost,
        "{} -> {}",
        first.cost,
        last.cost
    );
    assert!(fit.steps.len() <= 40 + 1);
}

#[test]
fn a_cheap_search_rule_is_corrected_towards_the_scenes_own() {
    let reg = squeal::registry();
    let base = Scene::builtin("pin-on-disc-coarse").unwrap();
    let truth = base
        .with_values(&[("thin_plate.thickness_m", 0.0036)], "truth")
        .unwrap();
    let text = SPEC.replace(
        "[search]\n",
        "[search]\nrule = { \"mesh.elements_per_wavelength\" = 5.0 }\n",
    );
    let mut spec = spec_with_targets_of(&text, &truth);
    spec.parameters.truncate(1);
    let error = |corrections: usize| {
        let mut s = spec.clone();
        s.search.corrections = corrections;
        let fit = calibrate(&reg, &s, &base, "base", |_| {}).unwrap();
        // the scene's own rule at every round's start and at the end
        let own = fit.steps.iter().filter(|s| s.kind == "confirm").count();
        assert_eq!(own, corrections.max(1) + 1, "{:?}", fit.steps);
        assert!(fit.ratios.iter().all(|q| q.is_finite() && *q > 0.0));
        (fit.values[0] / 0.0036 - 1.0).abs()
    };
    let (one, two) = (error(1), error(2));
    eprintln!("thickness error with 1 and 2 correction rounds: {one:.2e}, {two:.2e}");
    assert!(two < 0.01, "two rounds: {two}");
    assert!(two <= one * 1.01, "{one} -> {two}");
}

#[test]
fn bad_specs_name_the_field() {
    let base = Scene::builtin("pin-on-disc-coarse").unwrap();
    let check = |text: &str| -> String {
        match CalibrationSpec::from_toml(text, "bad.toml") {
            Err(e) => e.to_string(),
            Ok(spec) => spec
                .check_against(&base, "bad.toml")
                .unwrap_err()
                .to_string(),
        }
    };
    let target = "[[target]]\nkind = \"stiffness\"\nvalue_n_per_m = 1.6e6\n";
    let param =
        |body: &str| format!("scene = \"pin-on-disc-coarse\"\n[[parameter]]\n{body}\n{target}");
    // unknown path
    let e = check(&param(
        "path = \"thin_plate.thicknes_m\"\nmin = 1e-3\nmax = 5e-3",
    ));
    assert!(
        e.contains("parameter[0].path") && e.contains("thicknes_m"),
        "{e}"
    );
    // empty bounds
    let e = check(&param(
        "path = \"thin_plate.thickness_m\"\nmin = 5e-3\nmax = 1e-3",
    ));
    assert!(
        e.contains("parameter[0].max") && e.contains("min < max"),
        "{e}"
    );
    // a log scale over non-positive bounds
    let e = check(&param(
        "path = \"thin_plate.thickness_m\"\nmin = 0.0\nmax = 1e-3\nscale = \"log\"",
    ));
    assert!(e.contains("parameter[0].min"), "{e}");
    // a target on a body the scene lacks
    let mut disc_only = base.clone();
    disc_only.pin = None;
    disc_only.thin_plate = None;
    disc_only.thick_plate = None;
    let spec = CalibrationSpec::from_toml(
        "scene = \"x\"\n[[target]]\nkind = \"mode\"\nbody = \"pin\"\nlabel = \"tilt-y\"\nfreq_hz = 1000.0\n",
        "bad.toml",
    )
    .unwrap();
    let e = spec
        .check_against(&disc_only, "bad.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("target[0].body") && e.contains("pin"), "{e}");
    let spec = CalibrationSpec::from_toml(&format!("scene = \"x\"\n{target}"), "bad.toml").unwrap();
    let e = spec
        .check_against(&disc_only, "bad.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("target[0].kind"), "{e}");
    let e = check(
        "scene = \"pin-on-disc-coarse\"\n[[target]]\nkind = \"mode\"\nbody = \"rotor\"\nlabel = \"a,0,2\"\nfreq_hz = 1000.0\n",
    );
    assert!(e.contains("target[0].body") && e.contains("rotor"), "{e}");
    // an unknown field of a target, and a target kind that does not exist
    let e = check("scene = \"x\"\n[[target]]\nkind = \"stiffness\"\nvalue = 1.0\n");
    assert!(e.contains("value"), "{e}");
    let e = check("scene = \"x\"\n[[target]]\nkind = \"speed\"\n");
    assert!(e.contains("speed"), "{e}");
    // no target at all
    let e = check("scene = \"x\"\ntarget = []\n");
    assert!(e.contains("target"), "{e}");
    // a search rule path that does not exist
    let e = check(&format!(
        "scene = \"pin-on-disc-coarse\"\n[search]\nrule = {{ \"mesh.layers\" = 2 }}\n{target}"
    ));
    assert!(e.contains("search.rule") && e.contains("layers"), "{e}");
}
