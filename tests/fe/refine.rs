//! Contact refinement (`mesh.contact_refinement`): fine contact layers tied to the coarse
//! bodies. On the coarse rig (pin face 4 x 4 elements of 5 mm, refined to 1 mm over a
//! 10 x 10 mm region): the grid lines, the compatible pairs on untied nodes, the mass
//! (the pin layer replaces the pin's first layer, the disc layer adds exactly its own),
//! and the bodies' modes, which must stay those of the unrefined rig (a loose layer would
//! add local modes far below them).

use crate::common::solver;
use squeal_core::{EigenParams, SymmetricProblem};
use squeal_scene::{build, BodyKind, ContactRefinement, Model, Scene};

const ELEMENT: f64 = 0.001;

fn scene(refined: bool) -> Scene {
    let mut s = Scene::builtin("pin-on-disc-coarse").expect("builtin scene");
    s.mesh.pin_face_elements = 4;
    if refined {
        s.mesh.contact_refinement = Some(ContactRefinement {
            region_m: [0.0052, 0.005, 0.0096, 0.0101],
            element_m: ELEMENT,
        });
    }
    s.validate("test").expect("valid scene");
    s
}

fn model(refined: bool) -> Model {
    build(&scene(refined), BodyKind::All, &squeal::registry(), "test").expect("model")
}

fn freqs(m: &Model) -> Vec<f64> {
    let modes = solver("arpack")
        .solve_symmetric(
            &SymmetricProblem {
                k: m.k.as_ref(),
                m: m.m.as_ref(),
            },
            &EigenParams {
                fmax_hz: 2500.0,
                ..Default::default()
            },
        )
        .expect("arpack");
    modes.freq_hz
}

#[test]
fn refined_contact_layers_are_tied_and_keep_the_rig() {
    let (coarse, fine) = (model(false), model(true));
    let grid = fine.contact.as_ref().expect("contact grid");
    // the region [5.2, 14.8] x [5, 15.1] mm widens to the coarse lines 5-15 x 5-20 mm
    let x0 = grid.xs[0];
    let lines: Vec<f64> = grid
        .xs
        .iter()
        .map(|x| ((x - x0) * 1e4).round() / 10.0)
        .collect();
    let mut want = vec![0.0];
    want.extend((5..=15).map(f64::from));
    want.push(20.0);
    assert_eq!(lines, want, "x lines (mm from the face corner)");
    let y0 = grid.ys[0];
    let ylines: Vec<f64> = grid
        .ys
        .iter()
        .map(|y| ((y - y0) * 1e4).round() / 10.0)
        .collect();
    let mut ywant = vec![0.0];
    ywant.extend((5..=20).map(f64::from));
    assert_eq!(ylines, ywant, "y lines (mm from the face corner)");
    assert_eq!(grid.len(), 13 * 17);
    assert_eq!(grid.max_mismatch_m, 0.0);
    // every pair on free (untied) DOFs
    for (&p, &d) in grid.pin_nodes.iter().zip(&grid.disc_nodes) {
        for c in 0..3 {
            assert!(fine.dofs.free_of_full[3 * p + c].is_some());
            assert!(fine.dofs.free_of_full[3 * d + c].is_some());
        }
    }
    // ties: the pin layer's top and the disc layer's bottom, 13 x 17 nodes each
    assert_eq!(fine.dofs.tied.len(), 3 * 2 * 13 * 17);
    // mass: the disc layer adds 20 x 20 mm x 1 mm of disc material, nothing else changes
    let s = scene(true);
    let p = s.pin.as_ref().unwrap();
    let rho_disc = 7850.0;
    let added = rho_disc * p.size_x_m * p.size_y_m * ELEMENT;
    let diff = fine.total_mass - coarse.total_mass;
    eprintln!(
        "refine: {} -> {} DOFs, {} pairs, mass {:.6} -> {:.6} kg (+{:.4e} kg, disc layer {:.4e} kg)",
        coarse.dofs.n_free(),
        fine.dofs.n_free(),
        grid.len(),
        coarse.total_mass,
        fine.total_mass,
        diff,
        added
    );
    assert!(
        (diff - added).abs() <= 1e-9 * fine.total_mass,
        "mass change {diff:e} kg, expected the disc layer's {added:e} kg"
    );
    // the bodies' modes (no contact coupling): the same rig
    let (fc, ff) = (freqs(&coarse), freqs(&fine));
    eprintln!("refine: coarse {fc:.1?} Hz");
    eprintln!("refine: refined {ff:.1?} Hz");
    assert!(fc.len() >= 6, "too few modes to compare: {fc:?}");
    assert!(
        ff[0] > 0.9 * fc[0],
        "a mode at {:.1} Hz below the rig's first ({:.1} Hz): a loose layer?",
        ff[0],
        fc[0]
    );
    for (a, b) in fc.iter().zip(&ff).take(6) {
        assert!(
            (b / a - 1.0).abs() < 0.05,
            "mode {a:.1} Hz moved to {b:.1} Hz with the refinement"
        );
    }
}

#[test]
fn bad_refinements_name_their_field() {
    let mut s = scene(true);
    s.mesh.contact_refinement.as_mut().unwrap().element_m = 0.006;
    let e = s.validate("f.toml").unwrap_err().to_string();
    assert!(e.contains("mesh.contact_refinement.element_m"), "{e}");
    let mut s = scene(true);
    s.mesh.contact_refinement.as_mut().unwrap().region_m = [0.015, 0.0, 0.01, 0.01];
    let e = s.validate("f.toml").unwrap_err().to_string();
    assert!(e.contains("mesh.contact_refinement.region_m"), "{e}");
}
