//! Building the embedded scene and rejecting bad ones.

use squeal_core::Registry;
use squeal_scene::{build, BodyKind, Scene};

fn registry() -> Registry {
    let mut r = Registry::new();
    squeal_materials::register(&mut r);
    r
}

#[test]
fn default_disc_mass_and_clamp() {
    let scene = Scene::builtin("pin-on-disc").unwrap();
    let model = build(&scene, BodyKind::Disc, &registry(), "builtin").unwrap();
    let d = scene.disc.as_ref().unwrap();
    // the mesh is a polygon (graded in theta, blended into a Cartesian patch under the
    // pin): its area is a little below the circle's
    let polygon = std::f64::consts::PI;
    let mut volume =
        polygon * (d.outer_radius_m.powi(2) - d.inner_radius_m.powi(2)) * d.thickness_m;
    if let Some(hat) = &d.hat {
        let r0 = hat.radius_m.unwrap_or(d.inner_radius_m);
        let r1 = r0 + hat.thickness_m;
        volume += polygon * (r1.powi(2) - r0.powi(2)) * hat.height_m;
    }
    let rel = model.total_mass / (7850.0 * volume) - 1.0;
    assert!((-3e-3..=0.0).contains(&rel), "mass error {rel:e}");
    // and exactly rho times the elements' volume
    let v: f64 = (0..model.mesh.hexes.len())
        .map(|e| squeal_fe::mesh::hex_volume(&model.mesh.hex_coords(e)))
        .sum();
    approx::assert_relative_eq!(model.total_mass, 7850.0 * v, max_relative = 1e-10);
    // hub nodes are eliminated: 3 DOFs per node on the other nodes
    let clamp = if d.hat.is_some() {
        "disc.hat.zmin"
    } else {
        "disc.inner"
    };
    let hub = model.mesh.node_set(clamp).unwrap().len();
    assert_eq!(model.dofs.n_free(), 3 * (model.mesh.n_nodes() - hub));
    assert_eq!(model.k.nrows(), model.dofs.n_free());
}

#[test]
fn pin_stack_is_glued_and_fixed_at_the_plate_ends() {
    let scene = Scene::builtin("pin-on-disc").unwrap();
    let model = build(&scene, BodyKind::Pin, &registry(), "builtin").unwrap();
    assert_eq!(model.body_names, ["pin", "thin_plate", "thick_plate"]);
    let pin_top = model.mesh.node_set("pin.zmax").unwrap();
    let plate_bottom = model.mesh.node_set("thin_plate.zmin").unwrap();
    // every node of the pin's top face is a node of the plate's bottom face
    assert!(pin_top
        .iter()
        .all(|n| plate_bottom.binary_search(n).is_ok()));
    let ends = model.mesh.node_set("thin_plate.xmin").unwrap();
    for &n in ends {
        assert!(model.dofs.free_of_full[3 * n].is_none());
    }
    let p = scene.pin.as_ref().unwrap();
    let pin_nodes = model.mesh.body_nodes(0);
    let face = pin_nodes
        .iter()
        .filter(|&&n| model.mesh.nodes[n][2].abs() < 1e-12)
        .count();
    let k = scene.mesh.pin_face_elements + 1;
    assert_eq!(
        face,
        k * k,
        "pin face grid for {} x {} m",
        p.size_x_m,
        p.size_y_m
    );
}

#[test]
fn bad_scenes_name_their_field() {
    let base = Scene::builtin("pin-on-disc").unwrap();
    let mut thin = base.clone();
    thin.disc.as_mut().unwrap().thickness_m = -0.02;
    let mut outside = base.clone();
    outside.pin.as_mut().unwrap().center_radius_m = 0.3;
    let unknown = base.to_toml().replacen("[disc]", "[disc]\nwobble = 1", 1);
    let cases = [
        (thin.to_toml(), "disc.thickness_m"),
        (outside.to_toml(), "pin.center_radius_m"),
        (unknown, "wobble"),
    ];
    for (bad, field) in cases {
        let e = Scene::from_toml(&bad, "bad.toml").unwrap_err().to_string();
        assert!(e.contains("bad.toml") && e.contains(field), "{e}");
    }
    let mut s = Scene::builtin("pin-on-disc").unwrap();
    s.disc
        .as_mut()
        .unwrap()
        .material
        .constants
        .insert("poisson_ratio".into(), toml::Value::Float(0.5));
    let e = build(&s, BodyKind::Disc, &registry(), "nu.toml")
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("nu.toml") && e.contains("poisson_ratio"), "{e}");
}

#[test]
fn round_trip() {
    let s = Scene::builtin("pin-on-disc").unwrap();
    let again = Scene::from_toml(&s.to_toml(), "again").unwrap();
    assert_eq!(s, again);
}

#[test]
fn contact_grid_is_compatible_and_the_disc_stays_round() {
    let scene = Scene::builtin("pin-on-disc").unwrap();
    let model = build(&scene, BodyKind::All, &registry(), "builtin").unwrap();
    let c = model
        .contact
        .as_ref()
        .expect("disc and pin give contact pairs");
    let k = scene.mesh.pin_face_elements + 1;
    assert_eq!(c.len(), k * k);
    let p = scene.pin.as_ref().unwrap();
    let size = p.size_x_m.max(p.size_y_m);
    for q in 0..c.len() {
        let (a, b) = (
            model.mesh.nodes[c.pin_nodes[q]],
            model.mesh.nodes[c.disc_nodes[q]],
        );
        assert!((a[0] - b[0]).hypot(a[1] - b[1]) <= 1e-9 * size);
        assert!(a[2].abs() < 1e-15 && b[2].abs() < 1e-15);
        assert_ne!(
            c.pin_nodes[q], c.disc_nodes[q],
            "pin and disc are not glued"
        );
        // the grid covers the pin face
        let [i, j] = c.ij[q];
        approx::assert_abs_diff_eq!(
            a[0],
            -p.size_x_m / 2.0 + i as f64 * p.size_x_m / (k - 1) as f64,
            epsilon = 1e-12
        );
        approx::assert_abs_diff_eq!(
            a[1],
            p.center_radius_m - p.size_y_m / 2.0 + j as f64 * p.size_y_m / (k - 1) as f64,
            epsilon = 1e-12
        );
    }
    let d = scene.disc.as_ref().unwrap();
    for &n in model.mesh.node_set("disc.outer").unwrap() {
        let x = model.mesh.nodes[n];
        approx::assert_relative_eq!(x[0].hypot(x[1]), d.outer_radius_m, max_relative = 1e-12);
    }
    for b in model.body_stats() {
        assert!(
            b.min_scaled_jacobian > 0.5,
            "{}: min scaled Jacobian {}",
            b.body,
            b.min_scaled_jacobian
        );
    }
}
