//! The disc: read from a mesh file, or generated (ring, hat and flange, the contact
//! patch under the pin blended into its polar grid).

use super::*;

/// The disc from its mesh file (`imp`, read as `im`).
pub(super) fn imported(
    asm: &mut Assembly<'_>,
    imp: &crate::MeshImport,
    im: &crate::ImportedMesh,
) -> Result<()> {
    let cx = asm.cx;
    let scene = cx.scene;
    let rule = &scene.mesh;
    let Assembly {
        mesh,
        materials,
        body_names,
        sizes,
        fixed_nodes,
        ..
    } = asm;
    let d = scene.disc.as_ref().ok_or_else(|| cx.missing("disc"))?;
    let m = cx.material(&d.material, "disc.material")?;
    let (lambda, h) = element_size(
        m.as_ref(),
        d.thickness_m,
        rule.max_freq_hz,
        rule.elements_per_wavelength,
    );
    append_imported(
        mesh,
        fixed_nodes,
        im,
        &imp.fixed_groups,
        materials.len(),
        "disc.",
    )
    .map_err(|msg| cx.group_error("disc", "fixed_groups", msg))?;
    // the rule's target size, for comparison with the imported elements
    sizes.push(SizeRule {
        body: "disc".into(),
        wavelength_m: lambda,
        element_size_m: h,
        divisions: [0; 3],
    });
    materials.push(m);
    body_names.push("disc".to_string());
    Ok(())
}

/// The generated disc: the ring on a polar grid (the pin's contact patch blended into it
/// when there is a pin), its hat and flange when the scene has them, and the disc's
/// contact layer under a refined contact grid.
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
        patch,
        fine,
        pin_import,
        ..
    } = lay;
    let d = scene.disc.as_ref().ok_or_else(|| cx.missing("disc"))?;
    let m = cx.material(&d.material, "disc.material")?;
    check_centred_face(&cx, patch, pin_import)?;
    let (lambda, h) = element_size(
        m.as_ref(),
        d.thickness_m,
        rule.max_freq_hz,
        rule.elements_per_wavelength,
    );
    let nt =
        ((2.0 * std::f64::consts::PI * d.outer_radius_m / h / 4.0).ceil() as usize * 4).max(16);
    let body = materials.len();
    let layer = d.thickness_m / rule.min_layers as f64;
    let zs = graded(&[-d.thickness_m, 0.0], &|_, _| h.min(layer));
    // radial grid: the hat wall's radii are grid lines of the ring, so they conform
    let wall = d.hat.as_ref().map(|hat| {
        let (lw, hw) = element_size(
            m.as_ref(),
            hat.thickness_m,
            rule.max_freq_hz,
            rule.elements_per_wavelength,
        );
        (lw, hw, hat.thickness_m / rule.min_layers as f64)
    });
    let mut rb = vec![d.inner_radius_m];
    let r_in_wall = d
        .hat
        .as_ref()
        .and_then(|hat| hat.radius_m)
        .unwrap_or(d.inner_radius_m);
    let r_wall = d
        .hat
        .as_ref()
        .map_or(d.inner_radius_m, |hat| r_in_wall + hat.thickness_m);
    if d.hat.is_some() {
        rb.extend([r_in_wall, r_wall]);
    }
    let size = |lo: f64, hi: f64| match wall {
        Some((_, _, t)) if lo >= r_in_wall - 1e-12 && hi <= r_wall + 1e-12 => t,
        _ => h,
    };
    let q = rule.grading_ratio;
    let (rs, thetas) = ring_grid(d, patch.as_ref(), rb, &size, h, q, nt);
    let blend = patch.as_ref().map(|pa| pa.blend(r_wall, d.outer_radius_m));
    let xy_map = |r: f64, th: f64| match &blend {
        Some(b) => b.map(r, th),
        None => [r * th.cos(), r * th.sin()],
    };
    let nt = thetas.len();
    budget.take("disc", &[rs.len(), thetas.len(), zs.len()], file)?;
    let ring = Mesh::annulus_mapped(&rs, &thetas, &zs, &xy_map).with_body(body);
    let map = mesh.append(&ring, "disc.", None);
    if let (Some((fp, t)), Some(pa)) = (&fine, &patch) {
        // the disc's contact layer on the ring's top under the pin face, its bottom
        // tied to the ring's patch grid
        budget.take("disc contact layer", &[fp.xs.len(), fp.ys.len(), 2], file)?;
        let layer = Mesh::block(&fp.xs, &fp.ys, &[0.0, *t]).with_body(body);
        let (layer_ties, rule) = contact_layer(mesh, &layer, "disc", "zmin", "zmax", pa, fp, 1)
            .map_err(|m| cx.refinement_error(m))?;
        ties.extend(layer_ties);
        sizes.push(rule);
    }
    let mut divisions = [rs.len() - 1, nt, zs.len() - 1];
    let mut hat_rule = None;
    match (&d.hat, wall) {
        (Some(hat), Some((lw, hw, _))) => {
            let nzh = ((hat.height_m / hw.min(h)).ceil() as usize).max(rule.min_layers);
            let wall_rs = within(&rs, r_in_wall, r_wall);
            budget.take("disc hat", &[wall_rs.len(), thetas.len(), nzh + 1], file)?;
            let hat_mesh = Mesh::annulus_mapped(
                &wall_rs,
                &thetas,
                &squeal_fe::mesh::linspace(-d.thickness_m - hat.height_m, -d.thickness_m, nzh),
                &xy_map,
            )
            .with_body(body);
            let hmap = mesh.append(&hat_mesh, "disc.hat.", Some(1e-9 * d.outer_radius_m));
            match &hat.flange {
                None => {
                    fixed_nodes.extend(hat_mesh.node_set("zmin").unwrap().iter().map(|&n| hmap[n]))
                }
                Some(fl) => {
                    // an annular plate under the wall, inward to its clamped bore
                    let z0 = -d.thickness_m - hat.height_m;
                    let (_, hf) = element_size(
                        m.as_ref(),
                        fl.thickness_m,
                        rule.max_freq_hz,
                        rule.elements_per_wavelength,
                    );
                    let mut frs = graded(&[fl.inner_radius_m, r_in_wall], &|_, _| hf.min(h));
                    frs.extend(wall_rs.iter().skip(1));
                    let nzf = ((fl.thickness_m / hf).ceil() as usize).max(rule.min_layers);
                    budget.take("disc flange", &[frs.len(), thetas.len(), nzf + 1], file)?;
                    let flange = Mesh::annulus_mapped(
                        &frs,
                        &thetas,
                        &squeal_fe::mesh::linspace(z0 - fl.thickness_m, z0, nzf),
                        &xy_map,
                    )
                    .with_body(body);
                    let fmap =
                        mesh.append(&flange, "disc.hat.flange.", Some(1e-9 * d.outer_radius_m));
                    fixed_nodes.extend(flange.node_set("inner").unwrap().iter().map(|&n| fmap[n]));
                }
            }
            divisions[2] += nzh;
            hat_rule = Some(SizeRule {
                body: "disc hat".into(),
                wavelength_m: lw,
                element_size_m: hw.min(h),
                divisions: [wall_rs.len() - 1, nt, nzh],
            });
        }
        _ => fixed_nodes.extend(ring.node_set("inner").unwrap().iter().map(|&n| map[n])),
    }
    sizes.push(SizeRule {
        body: "disc".into(),
        wavelength_m: lambda,
        element_size_m: h,
        divisions,
    });
    sizes.extend(hat_rule);
    materials.push(m);
    body_names.push("disc".to_string());
    Ok(())
}

/// A generated disc reproduces the pin face centred on `x = 0`: an imported pin's face
/// must be centred there.
fn check_centred_face(cx: &Context<'_>, patch: &Option<Patch>, pin_import: &Import) -> Result<()> {
    if let (Some(pa), Some((_, im))) = (patch, pin_import) {
        let (x0, x1) = (pa.xs[0], pa.xs[pa.xs.len() - 1]);
        if (x0 + x1).abs() > 1e-9 * (x1 - x0) {
            return Err(cx.group_error(
                "pin",
                "contact_group",
                format!(
                    "the generated disc reproduces the pin face centred on x = 0, but the \
                     pin face of {} spans x in [{x0:e}, {x1:e}] m; centre it on x = 0 or \
                     import the disc mesh too",
                    im.path.display()
                ),
            ));
        }
    }
    Ok(())
}

/// The ring's radial and angular grid lines: graded between the breaks `rb` (the inner
/// radius and the hat wall's radii) by `size`, then, under a pin, the patch's radii with
/// steps graded from the patch step up to `h` (ratio `q`) on both sides and the patch's
/// angles; without a pin, `nt` even angles.
fn ring_grid(
    d: &crate::Disc,
    patch: Option<&Patch>,
    mut rb: Vec<f64>,
    size: &dyn Fn(f64, f64) -> f64,
    h: f64,
    q: f64,
    nt: usize,
) -> (Vec<f64>, Vec<f64>) {
    match patch {
        None => {
            rb.push(d.outer_radius_m);
            let thetas: Vec<f64> = (0..nt)
                .map(|t| 2.0 * std::f64::consts::PI * t as f64 / nt as f64)
                .collect();
            (graded(&rb, size), thetas)
        }
        Some(pa) => {
            let mut rs = if rb.len() > 1 {
                graded(&rb, size)
            } else {
                rb.clone()
            };
            let r_a = *rs.last().unwrap();
            let down = squeal_fe::mesh::graded_steps(pa.ys[0] - r_a, pa.step, h, q);
            let mut r = pa.ys[0];
            let mut inward: Vec<f64> = down
                .iter()
                .take(down.len().saturating_sub(1))
                .map(|st| {
                    r -= st;
                    r
                })
                .collect();
            inward.reverse();
            rs.extend(inward);
            rs.extend(&pa.ys);
            let up = squeal_fe::mesh::graded_steps(
                d.outer_radius_m - pa.ys[pa.ys.len() - 1],
                pa.step,
                h,
                q,
            );
            let mut r = pa.ys[pa.ys.len() - 1];
            for (i, st) in up.iter().enumerate() {
                r = if i + 1 == up.len() {
                    d.outer_radius_m
                } else {
                    r + st
                };
                rs.push(r);
            }
            (rs, pa.thetas(2.0 * std::f64::consts::PI / nt as f64, q))
        }
    }
}
