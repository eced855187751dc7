//! The pin assembly of the default scene (pin glued on the thin plate fixed at its ends,
//! thick plate on top): a handful of modes below 10 kHz, all attributed to the pin.

use crate::common::solver;
use squeal_analysis::modal::label_modes;
use squeal_core::{EigenParams, SymmetricProblem};
use squeal_scene::{build, BodyKind, Scene};

#[test]
fn pin_assembly_modes_below_10_khz() {
    let registry = squeal::registry();
    let scene = Scene::builtin("pin-on-disc").expect("builtin scene");
    let model = build(&scene, BodyKind::Pin, &registry, "builtin").expect("pin model");
    let problem = SymmetricProblem {
        k: model.k.as_ref(),
        m: model.m.as_ref(),
    };
    let params = EigenParams {
        fmax_hz: 10_000.0,
        ..Default::default()
    };
    let modes = solver("arpack")
        .solve_symmetric(&problem, &params)
        .expect("arpack");
    eprintln!(
        "pin: n = {} free DOFs, bodies {:?}, {} modes below {} Hz, solved in {:.2} s",
        model.dofs.n_free(),
        model.body_names,
        modes.freq_hz.len(),
        params.fmax_hz,
        modes.info.time_s
    );
    let records = label_modes(&model, &modes);
    for r in &records {
        eprintln!(
            "pin: mode {:2} {:9.2} Hz  {:<10} body {} residual {:.1e}",
            r.index, r.freq_hz, r.label, r.body, r.residual
        );
    }
    assert_eq!(records.len(), modes.freq_hz.len());
    for r in &records {
        assert_eq!(
            r.body, "pin",
            "mode {} ({:.1} Hz) attributed to {}",
            r.index, r.freq_hz, r.body
        );
        assert!(r.freq_hz > 0.0 && r.freq_hz <= params.fmax_hz);
        assert!(
            r.residual <= 1e-10,
            "mode {} residual {:e}",
            r.index,
            r.residual
        );
    }
    let n = records.len();
    assert!(
        (3..=12).contains(&n),
        "{n} pin modes below 10 kHz (the paper has 6)"
    );
}
