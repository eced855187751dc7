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
        if let Some(f) = &hat.flange {
            volume += polygon * (r1.powi(2) - f.inner_radius_m.powi(2)) * f.thickness_m;
        }
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
    // the clamped edges (the default clamps the two radial ends, y) are fixed, the others
    // free
    let clamp = scene.thin_plate.as_ref().unwrap().clamp.unwrap_or_default();
    assert_eq!(clamp, squeal_scene::Clamp::Y);
    for set in ["xmin", "xmax", "ymin", "ymax"] {
        let nodes = model.mesh.node_set(&format!("thin_plate.{set}")).unwrap();
        let fixed = clamp.node_sets().contains(&set);
        // nodes of this edge alone (not a corner shared with a clamped edge)
        let clamped: Vec<usize> = clamp
            .node_sets()
            .iter()
            .flat_map(|c| {
                model
                    .mesh
                    .node_set(&format!("thin_plate.{c}"))
                    .unwrap()
                    .to_vec()
            })
            .collect();
        let plate_only: Vec<usize> = nodes
            .iter()
            .copied()
            .filter(|n| fixed || !clamped.contains(n))
            .collect();
        assert!(!plate_only.is_empty());
        for &n in &plate_only {
            assert_eq!(
                model.dofs.free_of_full[3 * n].is_none(),
                fixed,
                "thin_plate.{set}: node {n} fixed = {}",
                !fixed
            );
        }
    }
    // the other orientation fixes the x ends instead
    let mut x = scene.clone();
    x.thin_plate.as_mut().unwrap().clamp = Some(squeal_scene::Clamp::X);
    let mx = build(&x, BodyKind::Pin, &registry(), "x").unwrap();
    let xmin = mx.mesh.node_set("thin_plate.xmin").unwrap();
    assert!(xmin.iter().all(|&n| mx.dofs.free_of_full[3 * n].is_none()));
    let ymin = mx.mesh.node_set("thin_plate.ymin").unwrap();
    assert!(ymin.iter().any(|&n| mx.dofs.free_of_full[3 * n].is_some()));
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
    // a pin face over the hat wall (the ring between 67.1 and 72 mm carries the wall)
    let mut on_wall = base.clone();
    on_wall.pin.as_mut().unwrap().center_radius_m = 0.078;
    let mut zone = base.clone();
    zone.contact.zone = squeal_scene::Zone::Rectangle {
        x0_m: 0.015,
        y0_m: 0.0,
        a_m: 0.010,
        b_m: 0.020,
    };
    let both = base.to_toml() + "\n[load]\nnormal_force_n = 200.0\ndisc_displacement_m = 1e-4\n";
    let mut mu = base.clone();
    mu.study.mu = -0.2;
    let mut band = base.clone();
    band.study.band_hz = [5000.0, 1000.0];
    let mut grading = base.clone();
    grading.mesh.grading_ratio = 5.0;
    let mut plates = base.clone();
    plates.mesh.plate_elements_per_wavelength = Some(1.0);
    let cases = [
        (thin.to_toml(), "disc.thickness_m"),
        (outside.to_toml(), "pin.center_radius_m"),
        (on_wall.to_toml(), "pin.center_radius_m"),
        (unknown, "wobble"),
        (zone.to_toml(), "contact.zone"),
        (both, "load"),
        (mu.to_toml(), "study.mu"),
        (band.to_toml(), "study.band_hz"),
        (grading.to_toml(), "mesh.grading_ratio"),
        (plates.to_toml(), "mesh.plate_elements_per_wavelength"),
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
    // and it builds the identical model
    let (a, b) = (
        build(&s, BodyKind::All, &registry(), "a").unwrap(),
        build(&again, BodyKind::All, &registry(), "b").unwrap(),
    );
    assert_eq!(a.mesh.nodes, b.mesh.nodes);
    assert_eq!(a.mesh.hexes, b.mesh.hexes);
    for (x, y) in [(&a.k, &b.k), (&a.m, &b.m)] {
        assert_eq!(x.as_ref().col_ptr(), y.as_ref().col_ptr());
        assert_eq!(x.as_ref().row_idx(), y.as_ref().row_idx());
        assert_eq!(x.as_ref().val(), y.as_ref().val());
    }
    assert_eq!(a.contact, b.contact);
}

#[test]
fn every_example_scene_builds() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut n = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "toml") {
            let scene = Scene::from_file(&path).unwrap();
            if scene.name == "pin-on-disc-paper" {
                continue; // 290k DOFs: built by the benchmarks, not the tests
            }
            let model = build(
                &scene,
                BodyKind::All,
                &registry(),
                &path.display().to_string(),
            )
            .unwrap();
            assert!(model.dofs.n_free() > 0);
            assert_eq!(
                model.contact.is_some(),
                scene.disc.is_some() && scene.pin.is_some()
            );
            n += 1;
        }
    }
    assert!(n >= 3, "found {n} example scenes");
    // the embedded ones match their files
    for name in squeal_scene::BUILTIN_SCENES {
        let file = Scene::from_file(&dir.join(format!("{name}.toml"))).unwrap();
        assert_eq!(Scene::builtin(name).unwrap(), file);
    }
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
    // each pair's cell holds it, and the cells tile the pin face
    let cells = c.cells();
    assert_eq!(cells.len(), c.len());
    let mut area = 0.0;
    for (cell, q) in cells.iter().zip(&c.xy) {
        assert!(cell[0] <= q[0] && q[0] <= cell[1] && cell[2] <= q[1] && q[1] <= cell[3]);
        area += (cell[1] - cell[0]) * (cell[3] - cell[2]);
    }
    approx::assert_relative_eq!(area, p.size_x_m * p.size_y_m, max_relative = 1e-12);
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

#[test]
fn masks_and_plateaus_are_checked_and_reproducible() {
    let base = Scene::builtin("pin-on-disc").unwrap();
    let n = (base.mesh.pin_face_elements + 1).pow(2);
    // inline mask with the wrong count
    let mut bad = base.clone();
    bad.contact.zone = squeal_scene::Zone::Mask {
        values: Some(vec![1; n - 1]),
        file: None,
    };
    let e = Scene::from_toml(&bad.to_toml(), "mask.toml")
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("mask.toml") && e.contains("contact.zone.values") && e.contains(&n.to_string()),
        "{e}"
    );
    // a mask file: read relative to the scene, wrong count and bad token named
    let dir = std::env::temp_dir().join(format!("squeal-mask-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut with_file = base.clone();
    with_file.contact.zone = squeal_scene::Zone::Mask {
        values: None,
        file: Some("m.txt".into()),
    };
    std::fs::write(dir.join("s.toml"), with_file.to_toml()).unwrap();
    std::fs::write(dir.join("m.txt"), "1 0 1\n").unwrap();
    let e = Scene::from_file(&dir.join("s.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("contact.zone.values") && e.contains("got 3"),
        "{e}"
    );
    std::fs::write(dir.join("m.txt"), "1 0 2\n").unwrap();
    let e = Scene::from_file(&dir.join("s.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("m.txt:1") && e.contains("`2`"), "{e}");
    let good: String = (0..n)
        .map(|i| if i % 2 == 0 { "1 " } else { "0 " })
        .collect();
    std::fs::write(dir.join("m.txt"), good).unwrap();
    let s = Scene::from_file(&dir.join("s.toml")).unwrap();
    match &s.contact.zone {
        squeal_scene::Zone::Mask {
            values: Some(v), ..
        } => {
            assert_eq!(v.iter().filter(|&&x| x == 1).count(), n.div_ceil(2))
        }
        z => panic!("{z:?}"),
    }
    let e = Scene::from_file(&dir.join("missing.toml"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing.toml"), "{e}");
    std::fs::remove_dir_all(&dir).ok();
    // plateaus: the same seed gives the same layout, another seed another one
    let z = |seed: u64| squeal_scene::Zone::Plateaus {
        patch_m: 0.002,
        seed,
        fraction: Some(0.3),
        count: None,
        region_m: None,
    };
    let size = [0.02, 0.02];
    let a = z(7).plateau_rectangles(size).unwrap();
    assert_eq!(a, z(7).plateau_rectangles(size).unwrap());
    assert_ne!(a, z(8).plateau_rectangles(size).unwrap());
    assert_eq!(a.len(), 30); // 30 % of 10 x 10 patches
    for r in &a {
        assert!(r[0] >= 0.0 && r[0] + r[2] <= 0.02 + 1e-12 && r[1] + r[3] <= 0.02 + 1e-12);
    }
    // a larger fraction with the same seed keeps every patch of the smaller one (the
    // layouts of a fraction study are nested)
    let at = |fraction: f64| squeal_scene::Zone::Plateaus {
        patch_m: 0.002,
        seed: 7,
        fraction: Some(fraction),
        count: None,
        region_m: None,
    };
    let more = at(0.6).plateau_rectangles(size).unwrap();
    assert_eq!(more.len(), 60);
    assert!(a.iter().all(|r| more.contains(r)));
    // each grid point belongs to one patch: the points in contact are the layout's
    // fraction of the region's points, whatever the patch side (here a 0.5 mm grid)
    let grid: Vec<[f64; 2]> = (0..41 * 41)
        .map(|k| [(k % 41) as f64 * 0.0005, (k / 41) as f64 * 0.0005])
        .collect();
    for patch_m in [0.0005, 0.001, 0.0015, 0.002, 0.003, 0.0035] {
        let z = squeal_scene::Zone::Plateaus {
            patch_m,
            seed: 3,
            fraction: Some(0.6),
            count: None,
            region_m: None,
        };
        let on = z.select(&grid, size).iter().filter(|&&x| x).count();
        let share = on as f64 / grid.len() as f64;
        assert!(
            (share - 0.6).abs() < 0.06,
            "patch {patch_m}: {on} of {} points",
            grid.len()
        );
        // and every point in contact lies in (or on the edge of) a patch in contact
        let rects = z.plateau_rectangles(size).unwrap();
        for (p, _) in grid.iter().zip(z.select(&grid, size)).filter(|(_, s)| *s) {
            assert!(rects.iter().any(|r| p[0] >= r[0] - 1e-12
                && p[0] <= r[0] + r[2] + 1e-12
                && p[1] >= r[1] - 1e-12
                && p[1] <= r[1] + r[3] + 1e-12));
        }
    }
    let mut bad = base.clone();
    bad.contact.zone = squeal_scene::Zone::Plateaus {
        patch_m: 0.05,
        seed: 1,
        fraction: Some(0.5),
        count: None,
        region_m: None,
    };
    let e = Scene::from_toml(&bad.to_toml(), "p.toml")
        .unwrap_err()
        .to_string();
    assert!(e.contains("contact.zone.patch_m"), "{e}");
}

#[test]
fn damping_is_parsed_checked_and_written_back() {
    let base = Scene::builtin("pin-on-disc").unwrap();
    assert!(base.damping.is_none() && base.damping.is_zero());
    assert!(
        !base.to_toml().contains("[damping]"),
        "undamped scenes write no table"
    );
    // a ratio at two frequencies: Rayleigh damping meets it at both, less in between
    let text = base.to_toml()
        + "\n[damping]\nrayleigh_ratio = 0.01\nrayleigh_freqs_hz = [1000.0, 8000.0]\n\
           contact_tangential_n_s_per_m3 = 2.5e4\n";
    let s = Scene::from_toml(&text, "damped.toml").unwrap();
    let (alpha, beta) = s.damping.rayleigh();
    let zeta = |f: f64| {
        let w = 2.0 * std::f64::consts::PI * f;
        alpha / (2.0 * w) + beta * w / 2.0
    };
    for f in [1000.0, 8000.0] {
        approx::assert_relative_eq!(zeta(f), 0.01, max_relative = 1e-12);
    }
    assert!(zeta(3000.0) < 0.01);
    assert_eq!(s.damping.contact_tangential(), 2.5e4);
    assert_eq!(base.damping.describe(), "none");
    let line = s.damping.describe();
    assert!(
        line.contains("1/s") && line.contains("ratio 0.01") && line.contains("2.5e4 N s/m^3"),
        "{line}"
    );
    assert_eq!(Scene::from_toml(&s.to_toml(), "again").unwrap(), s);
    let cases = [
        (
            "rayleigh_alpha_per_s = -1.0",
            "damping.rayleigh_alpha_per_s",
        ),
        ("rayleigh_ratio = 0.02", "damping.rayleigh_freqs_hz"),
        (
            "rayleigh_freqs_hz = [100.0, 200.0]",
            "damping.rayleigh_ratio",
        ),
        (
            "rayleigh_ratio = 0.02\nrayleigh_freqs_hz = [100.0, 200.0]\nrayleigh_beta_s = 1e-7",
            "damping.rayleigh_ratio",
        ),
        (
            "rayleigh_ratio = 1.5\nrayleigh_freqs_hz = [100.0, 200.0]",
            "damping.rayleigh_ratio",
        ),
        (
            "rayleigh_ratio = 0.01\nrayleigh_freqs_hz = [0.0, 200.0]",
            "damping.rayleigh_freqs_hz",
        ),
        (
            "contact_tangential_n_s_per_m3 = -3.0",
            "damping.contact_tangential",
        ),
        ("viscous = 1.0", "viscous"),
    ];
    for (body, field) in cases {
        let bad = base.to_toml() + "\n[damping]\n" + body + "\n";
        let e = Scene::from_toml(&bad, "bad.toml").unwrap_err().to_string();
        assert!(e.contains("bad.toml") && e.contains(field), "{body}: {e}");
    }
}

#[test]
fn tributary_areas_cover_the_pin_face() {
    let s = Scene::builtin("pin-on-disc-coarse").unwrap();
    let m = build(&s, BodyKind::All, &registry(), "coarse").unwrap();
    let grid = m.contact.as_ref().unwrap();
    let areas = grid.tributary_areas();
    let p = s.pin.as_ref().unwrap();
    approx::assert_relative_eq!(
        areas.iter().sum::<f64>(),
        p.size_x_m * p.size_y_m,
        max_relative = 1e-12
    );
    // corner pairs carry a quarter of an interior pair's area on a uniform grid
    let max = areas.iter().cloned().fold(0.0, f64::max);
    let min = areas.iter().cloned().fold(f64::INFINITY, f64::min);
    approx::assert_relative_eq!(min * 4.0, max, max_relative = 1e-9);
}

#[test]
fn hat_flange_is_glued_under_the_wall_and_clamped_at_its_bore() {
    let mut scene = Scene::builtin("pin-on-disc").unwrap();
    scene.disc.as_mut().unwrap().hat.as_mut().unwrap().flange = None;
    let plain = build(&scene, BodyKind::Disc, &registry(), "hat").unwrap();
    let d = scene.disc.as_mut().unwrap();
    let hat = d.hat.as_mut().unwrap();
    let (r0, tf, rf) = (hat.radius_m.unwrap_or(d.inner_radius_m), 0.006, 0.04);
    let r1 = r0 + hat.thickness_m;
    hat.flange = Some(squeal_scene::Flange {
        inner_radius_m: rf,
        thickness_m: tf,
    });
    let model = build(&scene, BodyKind::Disc, &registry(), "flange").unwrap();
    // the flange adds its annulus (rf to the wall's outer radius) of mass
    let added = 7850.0 * std::f64::consts::PI * (r1 * r1 - rf * rf) * tf;
    let rel = (model.total_mass - plain.total_mass) / added - 1.0;
    assert!((-3e-3..=0.0).contains(&rel), "flange mass error {rel:e}");
    // glued: the wall's lower nodes are flange nodes, not duplicates
    let wall_bottom = model.mesh.node_set("disc.hat.zmin").unwrap();
    let flange_top = model.mesh.node_set("disc.hat.flange.zmax").unwrap();
    assert!(wall_bottom.iter().all(|n| flange_top.contains(n)));
    // clamped at the bore only: the wall's lower end is free now
    let bore = model.mesh.node_set("disc.hat.flange.inner").unwrap().len();
    assert_eq!(model.dofs.n_free(), 3 * (model.mesh.n_nodes() - bore));
    let bad = scene
        .to_toml()
        .replace("inner_radius_m = 0.04", "inner_radius_m = 0.09");
    let e = Scene::from_toml(&bad, "bad.toml").unwrap_err().to_string();
    assert!(e.contains("disc.hat.flange.inner_radius_m"), "{e}");
}

/// The plates keep their own sizes (each plate's edges are grid lines of the shared
/// in-plane grid): the pin stack's mass is the sum of the three blocks' masses.
#[test]
fn plates_keep_their_sizes_in_the_shared_grid() {
    let base = Scene::builtin("pin-on-disc").unwrap();
    for (lx, wy) in [
        (0.040, 0.040),
        (0.033, 0.027),
        (0.040, 0.022),
        (0.021, 0.03),
    ] {
        let mut scene = base.clone();
        scene.thick_plate.as_mut().unwrap().length_x_m = lx;
        scene.thick_plate.as_mut().unwrap().width_y_m = wy;
        let model = build(&scene, BodyKind::Pin, &registry(), "plates").unwrap();
        let rho = |m: &squeal_scene::MaterialSpec| m.constants["density_kg_m3"].as_float().unwrap();
        let p = scene.pin.as_ref().unwrap();
        let (tp, kp) = (
            scene.thin_plate.as_ref().unwrap(),
            scene.thick_plate.as_ref().unwrap(),
        );
        let expected = rho(&p.material) * p.size_x_m * p.size_y_m * p.height_m
            + rho(&tp.material) * tp.length_x_m * tp.width_y_m * tp.thickness_m
            + rho(&kp.material) * kp.length_x_m * kp.width_y_m * kp.thickness_m;
        assert!(
            (model.total_mass - expected).abs() <= 1e-9 * expected,
            "thick plate {lx} x {wy} m: mass {} kg, expected {expected} kg",
            model.total_mass
        );
        let min_sj = model
            .body_stats()
            .iter()
            .map(|b| b.min_scaled_jacobian)
            .fold(f64::INFINITY, f64::min);
        assert!(
            min_sj > 0.99,
            "thick plate {lx} x {wy} m: min scaled Jacobian {min_sj}"
        );
    }
}
