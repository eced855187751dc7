//! The pin and its plates: the pin read from a mesh file, or the pin and plates generated
//! on the common grid lines of the pin face.

use super::*;

/// The pin from its mesh file (`imp`, read as `im`).
pub(super) fn imported(
    asm: &mut Assembly<'_>,
    imp: &crate::MeshImport,
    im: &crate::ImportedMesh,
    lay: &Layout,
) -> Result<()> {
    let cx = asm.cx;
    let scene = cx.scene;
    let Assembly {
        mesh,
        materials,
        body_names,
        sizes,
        fixed_nodes,
        ..
    } = asm;
    let Layout { patch, .. } = lay;
    let p = scene.pin.as_ref().ok_or_else(|| cx.missing("pin"))?;
    let pin_mat = cx.material(&p.material, "pin.material")?;
    append_imported(
        mesh,
        fixed_nodes,
        im,
        &imp.fixed_groups,
        materials.len(),
        "pin.",
    )
    .map_err(|msg| cx.group_error("pin", "fixed_groups", msg))?;
    let face = patch.as_ref().filter(|_| scene.disc.is_some());
    sizes.push(SizeRule {
        body: "pin".into(),
        wavelength_m: f64::NAN,
        element_size_m: face.map_or(f64::NAN, |pa| pa.step),
        divisions: face.map_or([0; 3], |pa| [pa.xs.len() - 1, pa.ys.len() - 1, 0]),
    });
    materials.push(pin_mat);
    body_names.push("pin".into());
    Ok(())
}

/// The generated pin and its plates: the pin block on the contact patch (its first
/// layer the fine contact layer under a refined contact grid), then the thin and thick
/// plates stacked on it, on grid lines that contain the pin face's.
pub(super) fn generated(asm: &mut Assembly<'_>, lay: &Layout) -> Result<()> {
    let cx = asm.cx;
    let (scene, file) = (cx.scene, cx.file);
    let rule = &scene.mesh;
    let Assembly {
        mesh,
        budget,
        materials,
        body_names,
        sizes,
        fixed_nodes,
        ties,
        ..
    } = asm;
    let Layout {
        patch, fine, lift, ..
    } = lay;
    let lift = *lift;
    let p = scene.pin.as_ref().ok_or_else(|| cx.missing("pin"))?;
    let pin_mat = cx.material(&p.material, "pin.material")?;
    let (a, b, yc) = (p.size_x_m, p.size_y_m, p.center_radius_m);
    let face = rule.pin_face_elements as f64;
    let h_pin = a.min(b) / face;
    let plates: Vec<(&str, &crate::Plate)> = [
        ("thin_plate", &scene.thin_plate),
        ("thick_plate", &scene.thick_plate),
    ]
    .into_iter()
    .filter_map(|(n, p)| p.as_ref().map(|p| (n, p)))
    .collect();
    let plate_mats = plate_materials(&cx, &plates)?;
    let h_plate = plate_mats.iter().map(|p| p.2).fold(f64::INFINITY, f64::min);
    let pa = patch.as_ref().expect("a pin has a patch");
    // common grid lines in x and y: the pin face's contact grid, plates graded away
    // from it; the plates' grids contain the pin's, so glued faces conform
    let (xs, ys) = plate_lines(pa, &plates, (a, b, yc), h_plate, rule.grading_ratio);
    // through the pin height: the face step at the contact, graded up to the size the
    // band needs in the pad material
    let (_, h_pin_z) = element_size(
        pin_mat.as_ref(),
        a.min(b),
        rule.max_freq_hz,
        rule.elements_per_wavelength,
    );
    let h_pin_z = h_pin_z.min(p.height_m / rule.min_layers as f64).max(h_pin);
    let zp = pin_heights(p.height_m, h_pin, h_pin_z, rule.grading_ratio);
    let nzp = zp.len() - 1;
    match &fine {
        None => {
            budget.take("pin", &[pa.xs.len(), pa.ys.len(), zp.len()], file)?;
            let pin = Mesh::block(&pa.xs, &pa.ys, &zp).with_body(materials.len());
            mesh.append(&pin, "pin.", None);
        }
        Some((fp, t)) => {
            // the pin's first layer becomes the fine contact layer, its top tied to
            // the coarse pin above it; everything sits `lift` higher
            if zp.len() < 3 {
                return Err(cx.refinement_error(format!(
                    "the pin ({} m high) has a single element layer; the contact layer \
                     needs a second one (raise mesh.min_layers)",
                    p.height_m
                )));
            }
            let up: Vec<f64> = zp[1..].iter().map(|z| z + lift).collect();
            let nl = (zp[1] / (2.0 * t) - 1e-9).ceil().max(1.0) as usize;
            budget.take("pin", &[pa.xs.len(), pa.ys.len(), up.len()], file)?;
            budget.take(
                "pin contact layer",
                &[fp.xs.len(), fp.ys.len(), nl + 1],
                file,
            )?;
            let pin = Mesh::block(&pa.xs, &pa.ys, &up).with_body(materials.len());
            mesh.append(&pin, "pin.", None);
            let layer = Mesh::block(
                &fp.xs,
                &fp.ys,
                &squeal_fe::mesh::linspace(lift, lift + zp[1], nl),
            )
            .with_body(materials.len());
            let (layer_ties, rule) = contact_layer(mesh, &layer, "pin", "zmax", "zmin", pa, fp, nl)
                .map_err(|m| cx.refinement_error(m))?;
            ties.extend(layer_ties);
            sizes.push(rule);
        }
    }
    sizes.push(SizeRule {
        body: "pin".into(),
        wavelength_m: f64::NAN,
        element_size_m: h_pin,
        divisions: [
            rule.pin_face_elements,
            rule.pin_face_elements,
            nzp - usize::from(fine.is_some()),
        ],
    });
    materials.push(pin_mat);
    body_names.push("pin".into());
    let mut z = p.height_m + lift;
    for ((name, pl), (m, lambda, h)) in plates.iter().zip(plate_mats) {
        let nz = ((pl.thickness_m / h).ceil() as usize).max(rule.min_layers);
        let xs_p = within(&xs, -pl.length_x_m / 2.0, pl.length_x_m / 2.0);
        let ys_p = within(&ys, yc - pl.width_y_m / 2.0, yc + pl.width_y_m / 2.0);
        budget.take(
            if *name == "thin_plate" {
                "thin plate"
            } else {
                "thick plate"
            },
            &[xs_p.len(), ys_p.len(), nz + 1],
            file,
        )?;
        let block = Mesh::block(
            &xs_p,
            &ys_p,
            &squeal_fe::mesh::linspace(z, z + pl.thickness_m, nz),
        )
        .with_body(materials.len());
        let map = mesh.append(
            &block,
            &format!("{name}."),
            Some(1e-9 * (1.0 + pl.length_x_m)),
        );
        if *name == "thin_plate" {
            for set in pl.clamp.unwrap_or_default().node_sets() {
                fixed_nodes.extend(block.node_set(set).unwrap().iter().map(|&n| map[n]));
            }
        }
        sizes.push(SizeRule {
            body: name.to_string(),
            wavelength_m: lambda,
            element_size_m: h,
            divisions: [xs_p.len() - 1, ys_p.len() - 1, nz],
        });
        materials.push(m);
        body_names.push(name.to_string());
        z += pl.thickness_m;
    }
    Ok(())
}

/// Each plate's material with the wavelength and element size the mesh rule gives it.
#[allow(clippy::type_complexity)]
fn plate_materials(
    cx: &Context<'_>,
    plates: &[(&str, &crate::Plate)],
) -> Result<Vec<(Box<dyn squeal_core::Material>, f64, f64)>> {
    let rule = &cx.scene.mesh;
    let mut out = Vec::new();
    for (name, pl) in plates {
        let m = cx.material(&pl.material, &format!("{name}.material"))?;
        let (lambda, h) = element_size(
            m.as_ref(),
            pl.thickness_m,
            rule.max_freq_hz,
            rule.plate_elements_per_wavelength
                .unwrap_or(rule.elements_per_wavelength),
        );
        out.push((m, lambda, h));
    }
    Ok(out)
}

/// The grid lines in x and y of the plates: the pin face's contact grid `pa`, graded away
/// from it (ratio `q`) up to `h_plate` to the largest plate's edges, with every plate's
/// own edges as lines (so a plate smaller than the largest keeps its true size). `pin`
/// is the pin face's `(size x, size y, centre radius)`.
fn plate_lines(
    pa: &Patch,
    plates: &[(&str, &crate::Plate)],
    pin: (f64, f64, f64),
    h_plate: f64,
    q: f64,
) -> (Vec<f64>, Vec<f64>) {
    let (a, b, yc) = pin;
    let (lx, ly) = plates.iter().fold((a, b), |(lx, ly), (_, pl)| {
        (lx.max(pl.length_x_m), ly.max(pl.width_y_m))
    });
    let around = |grid: &[f64], lo: f64, hi: f64| -> Vec<f64> {
        let mut v: Vec<f64> = Vec::new();
        let mut x = grid[0];
        for st in squeal_fe::mesh::graded_steps(grid[0] - lo, pa.step, h_plate, q) {
            x -= st;
            v.push(x);
        }
        if let Some(last) = v.last_mut() {
            *last = lo;
        }
        v.reverse();
        v.extend_from_slice(grid);
        let mut x = grid[grid.len() - 1];
        let up = squeal_fe::mesh::graded_steps(hi - x, pa.step, h_plate, q);
        for (i, st) in up.iter().enumerate() {
            x = if i + 1 == up.len() { hi } else { x + st };
            v.push(x);
        }
        v
    };
    let mut xs = around(&pa.xs, -lx / 2.0, lx / 2.0);
    let mut ys = around(&pa.ys, yc - ly / 2.0, yc + ly / 2.0);
    // every plate's own edges are grid lines, so a plate smaller than the largest
    // keeps its true size
    for (_, pl) in plates {
        insert_edge(&mut xs, &pa.xs, -pl.length_x_m / 2.0);
        insert_edge(&mut xs, &pa.xs, pl.length_x_m / 2.0);
        insert_edge(&mut ys, &pa.ys, yc - pl.width_y_m / 2.0);
        insert_edge(&mut ys, &pa.ys, yc + pl.width_y_m / 2.0);
    }
    (xs, ys)
}

/// The node heights through a pin of `height`: the face step `h_pin` at the contact,
/// then steps graded (ratio `q`) up to `h_pin_z`.
fn pin_heights(height: f64, h_pin: f64, h_pin_z: f64, q: f64) -> Vec<f64> {
    let mut zp = vec![0.0];
    let z_steps = squeal_fe::mesh::graded_steps(height - h_pin, h_pin, h_pin_z, q);
    zp.push(h_pin.min(height));
    let mut z = zp[1];
    for (i, st) in z_steps.iter().enumerate() {
        z = if i + 1 == z_steps.len() {
            height
        } else {
            z + st
        };
        zp.push(z);
    }
    zp
}
