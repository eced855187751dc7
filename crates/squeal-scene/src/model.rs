//! From a scene to an FE model with no more elements than the band needs.
//!
//! **Size rule.** For a plate-like body of thickness `t`, the shortest wave at the band
//! top `f` is the bending wave `lambda_b = 2 pi (D / (rho t))^(1/4) / sqrt(2 pi f)`,
//! `D = E t^3 / (12 (1 - nu^2))`. Element edges are at most
//! `lambda_b / mesh.elements_per_wavelength`, with at least `mesh.min_layers` layers
//! through each thickness. The pin face has `mesh.pin_face_elements` elements a side
//! (the contact grid); the plates share the pin's grid lines so the glued interfaces
//! conform. Orthotropic materials use the in-plane `E`, `nu` read off their compliance.
//!
//! Geometry: the disc spans z in [-thickness, 0] about the z axis; the pin face is
//! centred on (0, center_radius) on z = 0, x being the sliding direction and y the
//! radius there; the thin plate lies on the pin and the thick plate on the thin plate.

use crate::{Result, Scene, SceneError};
use squeal_core::{Material, Registry, SparseMat};
use squeal_fe::mesh::join;
use squeal_fe::{assemble, DofMap, Mesh};
use std::time::Instant;

/// Which bodies to build.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BodyKind {
    /// The disc alone.
    Disc,
    /// The pin with its thin and thick plates.
    Pin,
    /// Everything in the scene.
    All,
}

/// The element size chosen for one body and why.
#[derive(Debug, Clone, PartialEq)]
pub struct SizeRule {
    /// Body name.
    pub body: String,
    /// Bending wavelength at the band top (m).
    pub wavelength_m: f64,
    /// Target element edge (m).
    pub element_size_m: f64,
    /// Elements in each direction (r, theta, z for the disc; x, y, z for blocks).
    pub divisions: [usize; 3],
}

/// An assembled model on the free DOFs.
pub struct Model {
    /// The mesh of every built body.
    pub mesh: Mesh,
    /// Body names, indexed by `mesh.hex_body`.
    pub body_names: Vec<String>,
    /// DOF numbering (Dirichlet DOFs eliminated).
    pub dofs: DofMap,
    /// Stiffness (N/m).
    pub k: SparseMat,
    /// Mass (kg).
    pub m: SparseMat,
    /// Total mass (kg).
    pub total_mass: f64,
    /// Element sizes and their reasons.
    pub sizes: Vec<SizeRule>,
    /// Build time (s): meshing and assembly.
    pub build_time_s: f64,
}

/// Bending-wave element size for a plate of `thickness` made of `mat` at `freq_hz`.
pub fn element_size(
    mat: &dyn Material,
    thickness: f64,
    freq_hz: f64,
    per_wavelength: f64,
) -> (f64, f64) {
    let (e, nu) = in_plane_constants(mat);
    let d = e * thickness.powi(3) / (12.0 * (1.0 - nu * nu));
    let omega = 2.0 * std::f64::consts::PI * freq_hz;
    let lambda =
        2.0 * std::f64::consts::PI * (d / (mat.density() * thickness)).powf(0.25) / omega.sqrt();
    (lambda, lambda / per_wavelength)
}

/// In-plane Young's modulus and Poisson ratio (x direction) from the compliance.
fn in_plane_constants(mat: &dyn Material) -> (f64, f64) {
    let s = invert6(mat.elasticity());
    (1.0 / s[0][0], -s[0][1] / s[0][0])
}

fn invert6(d: [[f64; 6]; 6]) -> [[f64; 6]; 6] {
    let mut a = d;
    let mut inv = [[0.0; 6]; 6];
    for (i, row) in inv.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    for c in 0..6 {
        let p = (c..6)
            .max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))
            .unwrap();
        a.swap(c, p);
        inv.swap(c, p);
        let piv = a[c][c];
        for j in 0..6 {
            a[c][j] /= piv;
            inv[c][j] /= piv;
        }
        for r in 0..6 {
            if r != c {
                let f = a[r][c];
                for j in 0..6 {
                    a[r][j] -= f * a[c][j];
                    inv[r][j] -= f * inv[c][j];
                }
            }
        }
    }
    inv
}

/// Divides each interval between consecutive `breaks` into equal parts no longer than
/// `size` (at least one).
fn graded(breaks: &[f64], size: &dyn Fn(f64, f64) -> f64) -> Vec<f64> {
    let mut b = breaks.to_vec();
    b.sort_by(f64::total_cmp);
    b.dedup_by(|x, y| (*x - *y).abs() < 1e-12);
    let segs: Vec<Vec<f64>> = b
        .windows(2)
        .map(|w| {
            let n = ((w[1] - w[0]) / size(w[0], w[1]) - 1e-9).ceil().max(1.0) as usize;
            squeal_fe::mesh::linspace(w[0], w[1], n)
        })
        .collect();
    join(&segs)
}

fn within(v: &[f64], lo: f64, hi: f64) -> Vec<f64> {
    let eps = 1e-12 * (1.0 + hi.abs().max(lo.abs()));
    v.iter()
        .copied()
        .filter(|&x| x >= lo - eps && x <= hi + eps)
        .collect()
}

/// Builds the bodies of `scene` selected by `which`, with materials from `registry`;
/// `file` names the scene in errors.
pub fn build(scene: &Scene, which: BodyKind, registry: &Registry, file: &str) -> Result<Model> {
    let start = Instant::now();
    let rule = &scene.mesh;
    let mat = |spec: &crate::MaterialSpec, field: &str| -> Result<Box<dyn Material>> {
        let params = spec.params(file, field)?;
        registry
            .materials
            .create(&spec.kind, &params)
            .map_err(|source| SceneError::Core {
                file: file.into(),
                context: field.into(),
                source: Box::new(source),
            })
    };
    let missing = |field: &str| SceneError::Field {
        file: file.into(),
        field: field.into(),
        message: "this body is asked for but the scene has no such table".into(),
    };
    let mut mesh = Mesh::default();
    let mut materials: Vec<Box<dyn Material>> = Vec::new();
    let mut body_names = Vec::new();
    let mut sizes = Vec::new();
    let mut fixed_nodes: Vec<usize> = Vec::new();

    if matches!(which, BodyKind::Disc | BodyKind::All) {
        let d = scene.disc.as_ref().ok_or_else(|| missing("disc"))?;
        let m = mat(&d.material, "disc.material")?;
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
        let mut rb = vec![d.inner_radius_m, d.outer_radius_m];
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
        let rs = graded(&rb, &|lo, hi| match wall {
            Some((_, _, t)) if lo >= r_in_wall - 1e-12 && hi <= r_wall + 1e-12 => t,
            _ => h,
        });
        let ring = Mesh::annulus(&rs, nt, &zs).with_body(body);
        let map = mesh.append(&ring, "disc.", None);
        let mut divisions = [rs.len() - 1, nt, zs.len() - 1];
        let mut hat_rule = None;
        match (&d.hat, wall) {
            (Some(hat), Some((lw, hw, _))) => {
                let nzh = ((hat.height_m / hw.min(h)).ceil() as usize).max(rule.min_layers);
                let wall_rs = within(&rs, r_in_wall, r_wall);
                let hat_mesh = Mesh::annulus(
                    &wall_rs,
                    nt,
                    &squeal_fe::mesh::linspace(-d.thickness_m - hat.height_m, -d.thickness_m, nzh),
                )
                .with_body(body);
                let hmap = mesh.append(&hat_mesh, "disc.hat.", Some(1e-9 * d.outer_radius_m));
                fixed_nodes.extend(hat_mesh.node_set("zmin").unwrap().iter().map(|&n| hmap[n]));
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
    }

    if matches!(which, BodyKind::Pin | BodyKind::All) {
        let p = scene.pin.as_ref().ok_or_else(|| missing("pin"))?;
        let pin_mat = mat(&p.material, "pin.material")?;
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
        let mut plate_mats = Vec::new();
        let mut h_plate = f64::INFINITY;
        for (name, pl) in &plates {
            let m = mat(&pl.material, &format!("{name}.material"))?;
            let (lambda, h) = element_size(
                m.as_ref(),
                pl.thickness_m,
                rule.max_freq_hz,
                rule.elements_per_wavelength,
            );
            h_plate = h_plate.min(h);
            plate_mats.push((m, lambda, h));
        }
        // common grid lines in x and y: pin face finely, plates at their own size
        let mut xb = vec![-a / 2.0, a / 2.0];
        let mut yb = vec![yc - b / 2.0, yc + b / 2.0];
        for (_, pl) in &plates {
            xb.extend([-pl.length_x_m / 2.0, pl.length_x_m / 2.0]);
            yb.extend([yc - pl.width_y_m / 2.0, yc + pl.width_y_m / 2.0]);
        }
        let inside = |lo: f64, hi: f64, c0: f64, c1: f64| lo >= c0 - 1e-12 && hi <= c1 + 1e-12;
        let xs = graded(&xb, &|lo, hi| {
            if inside(lo, hi, -a / 2.0, a / 2.0) {
                h_pin
            } else {
                h_plate
            }
        });
        let ys = graded(&yb, &|lo, hi| {
            if inside(lo, hi, yc - b / 2.0, yc + b / 2.0) {
                h_pin
            } else {
                h_plate
            }
        });
        let nzp = ((p.height_m / h_pin).ceil() as usize).max(rule.min_layers);
        let pin = Mesh::block(
            &within(&xs, -a / 2.0, a / 2.0),
            &within(&ys, yc - b / 2.0, yc + b / 2.0),
            &squeal_fe::mesh::linspace(0.0, p.height_m, nzp),
        )
        .with_body(materials.len());
        mesh.append(&pin, "pin.", None);
        sizes.push(SizeRule {
            body: "pin".into(),
            wavelength_m: f64::NAN,
            element_size_m: h_pin,
            divisions: [rule.pin_face_elements, rule.pin_face_elements, nzp],
        });
        materials.push(pin_mat);
        body_names.push("pin".into());
        let mut z = p.height_m;
        for ((name, pl), (m, lambda, h)) in plates.iter().zip(plate_mats) {
            let nz = ((pl.thickness_m / h).ceil() as usize).max(rule.min_layers);
            let xs_p = within(&xs, -pl.length_x_m / 2.0, pl.length_x_m / 2.0);
            let ys_p = within(&ys, yc - pl.width_y_m / 2.0, yc + pl.width_y_m / 2.0);
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
                for set in ["xmin", "xmax"] {
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
    }

    fixed_nodes.sort_unstable();
    fixed_nodes.dedup();
    let dofs = DofMap::new(&mesh, &DofMap::node_dofs(&fixed_nodes));
    let refs: Vec<&dyn Material> = materials.iter().map(|m| m.as_ref()).collect();
    let asm = assemble(&mesh, &dofs, &refs).map_err(|source| SceneError::Core {
        file: file.into(),
        context: "assembly".into(),
        source: Box::new(source),
    })?;
    Ok(Model {
        mesh,
        body_names,
        dofs,
        k: asm.k,
        m: asm.m,
        total_mass: asm.total_mass,
        sizes,
        build_time_s: start.elapsed().as_secs_f64(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn graded_respects_breaks_and_size() {
        let v = graded(&[0.0, 1.0, 0.25], &|_, _| 0.1);
        assert!(v.iter().any(|&x| (x - 0.25).abs() < 1e-14));
        assert!(v.windows(2).all(|w| w[1] - w[0] <= 0.1 + 1e-12));
        assert_eq!(v.first(), Some(&0.0));
        assert_eq!(v.last(), Some(&1.0));
    }

    #[test]
    fn invert6_inverts() {
        let mut d = [[0.0; 6]; 6];
        for i in 0..6 {
            d[i][i] = 2.0 + i as f64;
            if i > 0 {
                d[i][i - 1] = 0.5;
                d[i - 1][i] = 0.5;
            }
        }
        let inv = invert6(d);
        for i in 0..6 {
            for j in 0..6 {
                let s: f64 = (0..6).map(|k| d[i][k] * inv[k][j]).sum();
                approx::assert_abs_diff_eq!(s, if i == j { 1.0 } else { 0.0 }, epsilon = 1e-13);
            }
        }
    }
}
