//! # squeal-materials
//!
//! Linear elastic [`Material`] plugins:
//!
//! - [`Isotropic`] (registered as `"isotropic"`): Young's modulus, Poisson's ratio,
//!   density;
//! - [`TransverselyIsotropic`] (registered as `"transversely_isotropic"`): isotropic in
//!   the plane normal to a unit `axis`, different along it. This is the usual model of
//!   a pressed friction lining: the pressing direction is the axis.
//!
//! Constants are validated on construction: a live material always has a symmetric
//! positive definite elasticity matrix. Invalid constants give
//! [`squeal_core::Error::Material`] naming the offending field.
//!
//! Voigt order `(xx, yy, zz, xy, yz, zx)` with engineering shear strains, as everywhere
//! in squeal ([`squeal_core::material`]).
//!
//! [`Material`]: squeal_core::Material

mod isotropic;
mod transverse;
mod voigt;

pub use isotropic::{isotropic_elasticity, Isotropic};
pub use transverse::{huber_shear_modulus, TransverselyIsotropic};
pub use voigt::{bond_stress_matrix, frame_with_axis, rotate_elasticity};

use squeal_core::{Error, Material, Registry};

/// Registers `"isotropic"` and `"transversely_isotropic"` into `reg.materials`.
///
/// Parameters of `"isotropic"` (all required): `youngs_modulus_pa`, `poisson_ratio`,
/// `density_kg_m3`.
///
/// Parameters of `"transversely_isotropic"`: `youngs_modulus_in_plane_pa`,
/// `youngs_modulus_axial_pa`, `poisson_ratio_in_plane`, `poisson_ratio_axial`
/// (`nu_pz`, see [`TransverselyIsotropic`]), `density_kg_m3` (required);
/// `shear_modulus_axial_pa` (optional, default [`huber_shear_modulus`]); `axis` (list of
/// three numbers, default `[0, 0, 1]`).
pub fn register(reg: &mut Registry) {
    reg.materials.register(
        "isotropic",
        "isotropic linear elasticity (youngs_modulus_pa, poisson_ratio, density_kg_m3)",
        |p| {
            Isotropic::new(
                p.num("youngs_modulus_pa")?,
                p.num("poisson_ratio")?,
                p.num("density_kg_m3")?,
            )
            .map(|m| Box::new(m) as Box<dyn Material>)
            .map_err(scene_names)
        },
    );
    reg.materials.register(
        "transversely_isotropic",
        "transversely isotropic linear elasticity about `axis` (in-plane and axial \
         moduli and Poisson ratios, optional axial shear modulus, density)",
        |p| {
            let g = p.num_opt("shear_modulus_axial_pa")?;
            let axis = p.list_or("axis", &[0.0, 0.0, 1.0])?;
            let axis: [f64; 3] = axis.as_slice().try_into().map_err(|_| {
                Error::param(
                    "axis",
                    format!("expected a list of 3 numbers, got {} numbers", axis.len()),
                )
            })?;
            TransverselyIsotropic::new(
                p.num("youngs_modulus_in_plane_pa")?,
                p.num("youngs_modulus_axial_pa")?,
                p.num("poisson_ratio_in_plane")?,
                p.num("poisson_ratio_axial")?,
                g,
                axis,
                p.num("density_kg_m3")?,
            )
            .map(|m| Box::new(m) as Box<dyn Material>)
            .map_err(scene_names)
        },
    );
}

/// A material error with the constant named as the scene writes it
/// (`shear_modulus_axial_pa`, not the law's symbol `g_axial`).
fn scene_names(e: Error) -> Error {
    match e {
        Error::Material {
            material,
            field,
            value,
            expected,
        } => {
            let field = match field.as_str() {
                "youngs_modulus" => "youngs_modulus_pa",
                "density" => "density_kg_m3",
                "e_in_plane" => "youngs_modulus_in_plane_pa",
                "e_axial" => "youngs_modulus_axial_pa",
                "g_axial" => "shear_modulus_axial_pa",
                "nu_in_plane" => "poisson_ratio_in_plane",
                "nu_axial" => "poisson_ratio_axial",
                other => other,
            }
            .to_string();
            Error::Material {
                material,
                field,
                value,
                expected,
            }
        }
        other => other,
    }
}

/// A [`squeal_core::Error::Material`].
pub(crate) fn invalid(material: &str, field: &str, value: f64, expected: &str) -> Error {
    Error::Material {
        material: material.to_string(),
        field: field.to_string(),
        value,
        expected: expected.to_string(),
    }
}

/// Checks `value > 0` and finite.
pub(crate) fn positive(material: &str, field: &str, value: f64) -> squeal_core::Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(invalid(material, field, value, "a finite value > 0"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use squeal_core::{Material, ParamValue, Params};

    fn reg() -> Registry {
        let mut r = Registry::new();
        register(&mut r);
        r
    }

    #[test]
    fn registered_names() {
        assert_eq!(
            reg().materials.names(),
            vec![
                "isotropic".to_string(),
                "transversely_isotropic".to_string()
            ]
        );
    }

    #[test]
    fn isotropic_from_params() {
        let p = Params::new()
            .with_num("youngs_modulus_pa", 210e9)
            .with_num("poisson_ratio", 0.3)
            .with_num("density_kg_m3", 7850.0);
        let m = reg().materials.create("isotropic", &p).unwrap();
        assert_eq!(m.name(), "isotropic");
        assert_eq!(m.density(), 7850.0);
        assert_eq!(m.elasticity(), isotropic_elasticity(210e9, 0.3));
    }

    #[test]
    fn isotropic_params_errors_name_the_key() {
        let r = reg();
        let base = Params::new()
            .with_num("youngs_modulus_pa", 210e9)
            .with_num("poisson_ratio", 0.3);
        let e = r
            .materials
            .create("isotropic", &base)
            .unwrap_err()
            .to_string();
        assert!(e.contains("density_kg_m3") && e.contains("missing"), "{e}");
        let typo = base.clone().with_num("density", 7850.0);
        let e = r
            .materials
            .create("isotropic", &typo)
            .unwrap_err()
            .to_string();
        assert!(e.contains("`density`"), "{e}");
        let bad = base.with_num("density_kg_m3", -1.0);
        let e = r
            .materials
            .create("isotropic", &bad)
            .unwrap_err()
            .to_string();
        assert!(e.contains("density"), "{e}");
    }

    fn pad_params() -> Params {
        Params::new()
            .with_num("youngs_modulus_in_plane_pa", 15.3e9)
            .with_num("youngs_modulus_axial_pa", 5.4e9)
            .with_num("poisson_ratio_in_plane", 0.15)
            .with_num("poisson_ratio_axial", 0.15)
            .with_num("density_kg_m3", 4000.0)
    }

    #[test]
    fn transverse_from_params_with_defaults() {
        let r = reg();
        let m = r
            .materials
            .create("transversely_isotropic", &pad_params())
            .unwrap();
        let direct =
            TransverselyIsotropic::new(15.3e9, 5.4e9, 0.15, 0.15, None, [0.0, 0.0, 1.0], 4000.0)
                .unwrap();
        assert_eq!(m.elasticity(), direct.elasticity());
        assert_eq!(m.density(), 4000.0);
        assert_eq!(m.name(), "transversely_isotropic");

        let p = pad_params()
            .with_num("shear_modulus_axial_pa", 3e9)
            .with("axis", ParamValue::List(vec![1.0, 0.0, 0.0]));
        let m = r.materials.create("transversely_isotropic", &p).unwrap();
        let direct = TransverselyIsotropic::new(
            15.3e9,
            5.4e9,
            0.15,
            0.15,
            Some(3e9),
            [1.0, 0.0, 0.0],
            4000.0,
        )
        .unwrap();
        assert_eq!(m.elasticity(), direct.elasticity());
    }

    #[test]
    fn transverse_params_errors() {
        let r = reg();
        let p = pad_params().with("axis", ParamValue::List(vec![1.0, 0.0]));
        let e = r
            .materials
            .create("transversely_isotropic", &p)
            .unwrap_err()
            .to_string();
        assert!(e.contains("axis") && e.contains('3'), "{e}");
        let mut p = pad_params();
        p.0.remove("poisson_ratio_axial");
        let e = r
            .materials
            .create("transversely_isotropic", &p)
            .unwrap_err()
            .to_string();
        assert!(e.contains("poisson_ratio_axial"), "{e}");
        let p = pad_params().with_num("shear_modulus_axial_pa", 0.0);
        let e = r
            .materials
            .create("transversely_isotropic", &p)
            .unwrap_err()
            .to_string();
        assert!(e.contains("shear_modulus_axial_pa"), "{e}");
        let p = pad_params().with_num("poisson_ratio", 0.2);
        let e = r
            .materials
            .create("transversely_isotropic", &p)
            .unwrap_err()
            .to_string();
        assert!(e.contains("`poisson_ratio`"), "{e}");
    }
}
