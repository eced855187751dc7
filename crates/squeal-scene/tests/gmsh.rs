//! Bodies meshed in Gmsh: an imported mesh builds the same model as the generated one it
//! was written from, imported pin and disc faces pair up, and every bad import names the
//! field, the file and what was expected.

use squeal_core::{Registry, SparseMat};
use squeal_fe::Mesh;
use squeal_scene::{build, BodyKind, MeshImport, Model, Scene};
use std::path::{Path, PathBuf};

fn registry() -> Registry {
    let mut r = Registry::new();
    squeal_materials::register(&mut r);
    r
}

/// A fresh directory for one test.
fn tmp(name: &str) -> PathBuf {
    let d = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("squeal-scene-gmsh")
        .join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn scenes_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// The mesh of one body of `m`: its nodes (in order), elements and the node sets named
/// `prefix` + name, renamed by `rename` (old name without prefix, new name).
fn body_mesh(m: &Mesh, body: usize, prefix: &str, rename: &[(&str, &str)]) -> Mesh {
    let nodes = m.body_nodes(body);
    let mut idx = vec![usize::MAX; m.n_nodes()];
    for (i, &n) in nodes.iter().enumerate() {
        idx[n] = i;
    }
    let mut out = Mesh {
        nodes: nodes.iter().map(|&n| m.nodes[n]).collect(),
        ..Mesh::default()
    };
    for (h, &b) in m.hexes.iter().zip(&m.hex_body) {
        if b == body {
            out.hexes.push(h.map(|n| idx[n]));
        }
    }
    out.hex_body = vec![0; out.hexes.len()];
    for (old, new) in rename {
        let set = m.node_set(&format!("{prefix}{old}")).unwrap();
        let v: Vec<usize> = set.iter().map(|&n| idx[n]).collect();
        assert!(v.iter().all(|&n| n != usize::MAX), "{old} lies in the body");
        out.node_sets.insert(new.to_string(), v);
    }
    out
}

fn import(file: &str, contact: Option<&str>, fixed: &[&str], scale: f64) -> Option<MeshImport> {
    Some(MeshImport {
        file: file.into(),
        contact_group: contact.map(String::from),
        fixed_groups: fixed.iter().map(|s| s.to_string()).collect(),
        scale,
        loaded: None,
    })
}

/// Writes `scene` as `scene.toml` in `dir` and reads it back (resolving its mesh files).
fn via_file(scene: &Scene, dir: &Path) -> squeal_scene::Result<(Scene, String)> {
    let path = dir.join("scene.toml");
    std::fs::write(&path, scene.to_toml()).unwrap();
    Scene::from_file(&path).map(|s| (s, path.display().to_string()))
}

fn sorted_diagonal(a: &SparseMat) -> Vec<f64> {
    let a = a.as_ref();
    let mut d: Vec<f64> = (0..a.ncols())
        .map(|j| {
            a.row_idx_of_col(j)
                .zip(a.val_of_col(j))
                .filter(|(i, _)| *i == j)
                .map(|(_, v)| *v)
                .sum()
        })
        .collect();
    d.sort_by(f64::total_cmp);
    d
}

/// Same DOF count, sparsity and (to `rel`) the same total mass and sorted diagonals.
fn assert_same_model(a: &Model, b: &Model, rel: f64) {
    assert_eq!(a.dofs.n_free(), b.dofs.n_free());
    assert_eq!(a.mesh.hexes.len(), b.mesh.hexes.len());
    assert_eq!(a.k.compute_nnz(), b.k.compute_nnz());
    assert_eq!(a.m.compute_nnz(), b.m.compute_nnz());
    approx::assert_relative_eq!(a.total_mass, b.total_mass, max_relative = rel);
    for (x, y) in [(&a.k, &b.k), (&a.m, &b.m)] {
        let (dx, dy) = (sorted_diagonal(x), sorted_diagonal(y));
        assert_eq!(dx.len(), dy.len());
        for (p, q) in dx.iter().zip(&dy) {
            approx::assert_relative_eq!(*p, *q, max_relative = rel);
        }
    }
}

#[test]
fn imported_disc_builds_the_generated_model() {
    let base = Scene::from_file(&scenes_dir().join("disc-only.toml")).unwrap();
    let reg = registry();
    let generated = build(&base, BodyKind::Disc, &reg, "disc-only").unwrap();
    let dir = tmp("disc_only");
    let disc = body_mesh(
        &generated.mesh,
        0,
        "disc.",
        &[("inner", "bore"), ("zmax", "friction")],
    );
    // in metres, and in millimetres with scale = 0.001
    let mut mm = disc.clone();
    mm.nodes
        .iter_mut()
        .for_each(|p| p.iter_mut().for_each(|x| *x *= 1e3));
    squeal_io::write_msh(&disc, &dir.join("disc.msh"), &["bore", "friction"]).unwrap();
    squeal_io::write_msh(&mm, &dir.join("disc-mm.msh"), &["bore"]).unwrap();
    for (file, scale, rel) in [("disc.msh", 1.0, 1e-14), ("disc-mm.msh", 1e-3, 1e-9)] {
        let mut s = base.clone();
        s.disc.as_mut().unwrap().mesh = import(file, Some("friction"), &["bore"], scale);
        if scale != 1.0 {
            s.disc
                .as_mut()
                .unwrap()
                .mesh
                .as_mut()
                .unwrap()
                .contact_group = None;
        }
        let (s, name) = via_file(&s, &dir).unwrap();
        let imported = build(&s, BodyKind::All, &reg, &name).unwrap();
        assert_same_model(&generated, &imported, rel);
        assert_eq!(imported.body_names, ["disc"]);
        assert!(imported.contact.is_none());
        // the bore is clamped: its nodes carry no DOF
        let bore = imported.mesh.node_set("disc.bore").unwrap();
        assert_eq!(
            bore.len(),
            generated.mesh.node_set("disc.inner").unwrap().len()
        );
        assert!(bore
            .iter()
            .all(|&n| imported.dofs.free_of_full[3 * n].is_none()));
    }
}

/// The coarse rig without plates, a 4 x 4 pin face, built with generated meshes, and its
/// disc and pin written to `dir` as `disc.msh` (groups `friction`, `clamp`) and `pin.msh`
/// (group `face`), the pin shifted along x by `shift` pin face elements.
fn rig(dir: &Path, shift: f64) -> (Scene, Model) {
    let mut s = Scene::builtin("pin-on-disc-coarse").unwrap();
    s.thin_plate = None;
    s.thick_plate = None;
    s.mesh.pin_face_elements = 4;
    // the hat clamped at its lower end (the clamp group below), no flange
    s.disc.as_mut().unwrap().hat.as_mut().unwrap().flange = None;
    let g = build(&s, BodyKind::All, &registry(), "rig").unwrap();
    assert_eq!(g.body_names, ["disc", "pin"]);
    let disc = body_mesh(
        &g.mesh,
        0,
        "disc.",
        &[("zmax", "friction"), ("hat.zmin", "clamp")],
    );
    let mut pin = body_mesh(&g.mesh, 1, "pin.", &[("zmin", "face"), ("ymin", "side")]);
    let step = s.pin.as_ref().unwrap().size_x_m / 4.0;
    pin.nodes.iter_mut().for_each(|p| p[0] += shift * step);
    squeal_io::write_msh(&disc, &dir.join("disc.msh"), &["friction", "clamp"]).unwrap();
    squeal_io::write_msh(&pin, &dir.join("pin.msh"), &["face", "side"]).unwrap();
    (s, g)
}

#[test]
fn imported_pin_and_disc_pair_up() {
    let dir = tmp("rig");
    let (base, generated) = rig(&dir, 0.0);
    let reg = registry();
    let mut s = base.clone();
    s.disc.as_mut().unwrap().hat = None;
    s.disc.as_mut().unwrap().mesh = import("disc.msh", Some("friction"), &["clamp"], 1.0);
    s.pin.as_mut().unwrap().mesh = import("pin.msh", Some("face"), &[], 1.0);
    let (s, name) = via_file(&s, &dir).unwrap();
    let model = build(&s, BodyKind::All, &reg, &name).unwrap();
    assert_same_model(&generated, &model, 1e-14);
    let (c, g) = (
        model.contact.as_ref().unwrap(),
        generated.contact.as_ref().unwrap(),
    );
    assert_eq!(c.len(), 25);
    assert_eq!(c.len(), g.len());
    assert_eq!((c.xs.len(), c.ys.len()), (5, 5));
    for k in 0..c.len() {
        assert_eq!(c.ij[k], [k % 5, k / 5], "pairs ordered j nx + i");
        let (p, d) = (
            model.mesh.nodes[c.pin_nodes[k]],
            model.mesh.nodes[c.disc_nodes[k]],
        );
        assert!((p[0] - d[0]).hypot(p[1] - d[1]) <= 1e-12);
        assert_ne!(c.pin_nodes[k], c.disc_nodes[k]);
        approx::assert_abs_diff_eq!(c.xy[k][0], g.xy[k][0], epsilon = 1e-15);
        approx::assert_abs_diff_eq!(c.xy[k][1], g.xy[k][1], epsilon = 1e-15);
    }

    // an imported pin on the generated disc: the disc's patch follows the pin's face
    let mut s2 = base.clone();
    s2.pin.as_mut().unwrap().mesh = import("pin.msh", Some("face"), &[], 1.0);
    let (s2, name2) = via_file(&s2, &dir).unwrap();
    let model2 = build(&s2, BodyKind::All, &reg, &name2).unwrap();
    assert_same_model(&generated, &model2, 1e-12);
    assert_eq!(model2.contact.as_ref().unwrap().len(), 25);

    // the generated pin on the imported disc
    let mut s3 = base.clone();
    s3.disc.as_mut().unwrap().hat = None;
    s3.disc.as_mut().unwrap().mesh = import("disc.msh", Some("friction"), &["clamp"], 1.0);
    let (s3, name3) = via_file(&s3, &dir).unwrap();
    let model3 = build(&s3, BodyKind::All, &reg, &name3).unwrap();
    assert_same_model(&generated, &model3, 1e-14);
    assert_eq!(model3.contact.as_ref().unwrap(), g);
}

#[test]
fn shifted_pin_lists_the_unmatched_nodes() {
    let dir = tmp("shifted");
    let (base, _) = rig(&dir, 0.3);
    let mut s = base.clone();
    s.disc.as_mut().unwrap().hat = None;
    s.disc.as_mut().unwrap().mesh = import("disc.msh", Some("friction"), &["clamp"], 1.0);
    s.pin.as_mut().unwrap().mesh = import("pin.msh", Some("face"), &[], 1.0);
    let (s, name) = via_file(&s, &dir).unwrap();
    let e = match build(&s, BodyKind::All, &registry(), &name) {
        Ok(_) => panic!("a shifted pin must not pair up"),
        Err(e) => e.to_string(),
    };
    for want in [
        "incompatible contact meshes",
        "group `face` of",
        "pin.msh",
        "group `friction` of",
        "disc.msh",
        "25 of 25 pin face nodes have no disc node",
        ") m; node ",
        "...",
        "scene.toml",
    ] {
        assert!(e.contains(want), "`{want}` in: {e}");
    }
    // first 8 listed, with coordinates
    assert_eq!(e.matches(") m").count(), 8, "{e}");
}

#[test]
fn bad_imports_name_the_field_and_file() {
    let dir = tmp("bad");
    let (base, _) = rig(&dir, 0.0);
    let disc_only = |imp: Option<MeshImport>| {
        let mut s = base.clone();
        s.pin = None;
        s.thin_plate = None;
        s.thick_plate = None;
        s.disc.as_mut().unwrap().hat = None;
        s.disc.as_mut().unwrap().mesh = imp;
        s
    };
    let check = |s: &Scene, want: &[&str]| {
        let e = match via_file(s, &dir) {
            Ok((s, name)) => match build(&s, BodyKind::All, &registry(), &name) {
                Ok(_) => panic!("expected an error with {want:?}"),
                Err(e) => e.to_string(),
            },
            Err(e) => e.to_string(),
        };
        for w in want {
            assert!(e.contains(w), "`{w}` in: {e}");
        }
    };
    // unknown group: names it and lists the available ones
    check(
        &disc_only(import("disc.msh", Some("contact"), &["clamp"], 1.0)),
        &[
            "disc.mesh.contact_group",
            "no physical group `contact`",
            "disc.msh",
            "available physical groups: `clamp`, `friction`",
        ],
    );
    check(
        &disc_only(import("disc.msh", None, &["clamp", "bolt"], 1.0)),
        &["disc.mesh.fixed_groups", "`bolt`", "`clamp`, `friction`"],
    );
    // missing file
    check(
        &disc_only(import("nowhere.msh", None, &[], 1.0)),
        &[
            "disc.mesh.file",
            "nowhere.msh",
            "not found",
            "expected a Gmsh MSH 4.1",
        ],
    );
    // scale <= 0
    check(
        &disc_only(import("disc.msh", None, &[], 0.0)),
        &["disc.mesh.scale", "expected a positive factor", "got 0"],
    );
    // a tetrahedral mesh
    std::fs::write(
        dir.join("tet.msh"),
        "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 4 1 4\n3 1 0 4\n1\n2\n3\n4\n\
         0 0 0\n1 0 0\n0 1 0\n0 0 1\n$EndNodes\n$Elements\n1 1 1 1\n3 1 4 1\n1 1 2 3 4\n\
         $EndElements\n",
    )
    .unwrap();
    check(
        &disc_only(import("tet.msh", None, &[], 1.0)),
        &[
            "disc.mesh.file",
            "tet.msh:18:",
            "4-node tetrahedron",
            "expected 8-node hexahedra (type 5)",
        ],
    );
    // both bodies present: the contact group is required
    let mut s = base.clone();
    s.thin_plate = None;
    s.thick_plate = None;
    s.pin.as_mut().unwrap().mesh = import("pin.msh", None, &[], 1.0);
    check(
        &s,
        &["pin.mesh.contact_group", "expected the physical group"],
    );
    // plates over an imported pin
    let mut s = base.clone();
    s.pin.as_mut().unwrap().mesh = import("pin.msh", Some("face"), &[], 1.0);
    s.thin_plate = Scene::builtin("pin-on-disc-coarse").unwrap().thin_plate;
    check(&s, &["field `thin_plate`", "pin.mesh"]);
    // a hat with an imported disc
    let mut s = disc_only(import("disc.msh", None, &["clamp"], 1.0));
    s.disc.as_mut().unwrap().hat = base.disc.as_ref().unwrap().hat.clone();
    check(&s, &["field `disc.hat`", "disc.mesh"]);
    // a pin contact group that is not a grid in (x, y): a side face
    let mut s = base.clone();
    s.thin_plate = None;
    s.thick_plate = None;
    s.pin.as_mut().unwrap().mesh = import("pin.msh", Some("side"), &[], 1.0);
    check(
        &s,
        &[
            "pin.mesh.contact_group",
            "group `side`",
            "pin.msh",
            "full tensor grid",
        ],
    );
}
