//! The bodies: disc (and its hat), pin and plates, each with the check of its table.

use super::{field_error, positive_length, MaterialSpec, MeshImport, Scene};
use crate::Result;
use serde::{Deserialize, Serialize};

/// An annular disc about the z axis, its top face (z = 0) the friction face. Without a
/// hat it is clamped on its inner cylinder; with one, at the hat's lower end.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Disc {
    /// Inner radius of the disc ring (m): the clamped face when there is no hat.
    pub inner_radius_m: f64,
    /// Outer radius (m).
    pub outer_radius_m: f64,
    /// Thickness (m); the disc spans z in [-thickness, 0].
    pub thickness_m: f64,
    /// Hat joining the ring to the clamp (optional).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hat: Option<Hat>,
    /// Material (of ring and hat).
    pub material: MaterialSpec,
    /// The disc's mesh imported from a Gmsh file instead of generated (optional); the
    /// dimensions above then only document the disc and place the pin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<MeshImport>,
}

/// A hat: a thin cylindrical wall under the disc ring, from `radius_m` (default: the
/// ring's inner radius) outwards by `thickness_m`, `height_m` deep, clamped at its
/// lower end. It is the compliant
/// mounting that sets the rig disc's low rocking and in-plane (ovalling) modes.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Hat {
    /// Inner radius of the wall (m); absent means `disc.inner_radius_m`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius_m: Option<f64>,
    /// Wall height below the ring (m).
    pub height_m: f64,
    /// Wall thickness (m), less than the ring's radial width.
    pub thickness_m: f64,
    /// An annular plate closing the wall's lower end, clamped at its bore (a bolted hub
    /// flange); absent: the wall's lower end is clamped.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub flange: Option<Flange>,
}

/// The hat's bottom plate: from the wall inward to `inner_radius_m`, where it is
/// clamped, `thickness_m` thick, under the wall.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Flange {
    /// Bore radius (m), where the flange is clamped; less than the wall's inner radius.
    pub inner_radius_m: f64,
    /// Plate thickness (m).
    pub thickness_m: f64,
}

/// The pin: a rectangular block standing on the disc's friction face.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pin {
    /// Radius of the pin face centre (the mean friction radius) (m).
    pub center_radius_m: f64,
    /// Face size along the sliding direction x (m).
    pub size_x_m: f64,
    /// Face size along the radius y (m).
    pub size_y_m: f64,
    /// Height (m).
    pub height_m: f64,
    /// Material (the pad's, transversely isotropic about z).
    pub material: MaterialSpec,
    /// The pin's mesh imported from a Gmsh file instead of generated (optional); the
    /// dimensions above then only document the pin.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mesh: Option<MeshImport>,
}

/// A rectangular plate centred over the pin.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Plate {
    /// Length along x (m).
    pub length_x_m: f64,
    /// Width along y (m).
    pub width_y_m: f64,
    /// Thickness (m).
    pub thickness_m: f64,
    /// Which pair of edges of the thin plate is fixed (the thick plate is not fixed:
    /// `None` there); `None` on the thin plate means the two x ends.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clamp: Option<Clamp>,
    /// Material.
    pub material: MaterialSpec,
}

/// The fixed edges of the thin plate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Clamp {
    /// The two ends across x (x = +-length_x / 2): the plate bends along x.
    #[default]
    X,
    /// The two edges across y (y = centre +- width_y / 2): the plate bends along y.
    Y,
    /// All four edges.
    Xy,
}

impl Clamp {
    /// The node sets of a generated block that this clamp fixes.
    pub fn node_sets(self) -> &'static [&'static str] {
        match self {
            Clamp::X => &["xmin", "xmax"],
            Clamp::Y => &["ymin", "ymax"],
            Clamp::Xy => &["xmin", "xmax", "ymin", "ymax"],
        }
    }
}

/// Checks the `[disc]` table and its hat.
pub(super) fn validate_disc(scene: &Scene, file: &str) -> Result<()> {
    let field = |f: &str, m: String| field_error(file, f, m);
    let positive = |f: &str, v: f64| positive_length(file, f, v);
    if let Some(d) = &scene.disc {
        positive("disc.inner_radius_m", d.inner_radius_m)?;
        positive("disc.outer_radius_m", d.outer_radius_m)?;
        if d.inner_radius_m >= d.outer_radius_m {
            return Err(field(
                "disc.inner_radius_m",
                format!(
                    "{} m: expected less than disc.outer_radius_m = {} m",
                    d.inner_radius_m, d.outer_radius_m
                ),
            ));
        }
        positive("disc.thickness_m", d.thickness_m)?;
        if let Some(hat) = &d.hat {
            positive("disc.hat.height_m", hat.height_m)?;
            positive("disc.hat.thickness_m", hat.thickness_m)?;
            let r0 = hat.radius_m.unwrap_or(d.inner_radius_m);
            if r0 < d.inner_radius_m || r0 + hat.thickness_m >= d.outer_radius_m {
                return Err(field(
                    "disc.hat.radius_m",
                    format!(
                        "the wall ({r0} to {} m) must lie under the ring ({} to {} m)",
                        r0 + hat.thickness_m,
                        d.inner_radius_m,
                        d.outer_radius_m
                    ),
                ));
            }
            if let Some(fl) = &hat.flange {
                positive("disc.hat.flange.inner_radius_m", fl.inner_radius_m)?;
                positive("disc.hat.flange.thickness_m", fl.thickness_m)?;
                if fl.inner_radius_m >= r0 {
                    return Err(field(
                        "disc.hat.flange.inner_radius_m",
                        format!(
                            "expected less than the wall's inner radius {r0} m, got {}",
                            fl.inner_radius_m
                        ),
                    ));
                }
            }
            if hat.thickness_m >= d.outer_radius_m - d.inner_radius_m {
                return Err(field(
                    "disc.hat.thickness_m",
                    format!(
                        "expected less than the ring width {} m, got {}",
                        d.outer_radius_m - d.inner_radius_m,
                        hat.thickness_m
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Checks the `[pin]` table: its sizes, and its face on the disc face.
pub(super) fn validate_pin(scene: &Scene, file: &str) -> Result<()> {
    let field = |f: &str, m: String| field_error(file, f, m);
    let positive = |f: &str, v: f64| positive_length(file, f, v);
    if let Some(p) = &scene.pin {
        positive("pin.center_radius_m", p.center_radius_m)?;
        positive("pin.size_x_m", p.size_x_m)?;
        positive("pin.size_y_m", p.size_y_m)?;
        positive("pin.height_m", p.height_m)?;
        if let Some(d) = &scene.disc {
            let (r0, r1) = (
                p.center_radius_m - p.size_y_m / 2.0,
                p.center_radius_m + p.size_y_m / 2.0,
            );
            let rmax = (r1 * r1 + p.size_x_m * p.size_x_m / 4.0).sqrt();
            let wall = d.hat.as_ref().map_or(d.inner_radius_m, |h| {
                h.radius_m.unwrap_or(d.inner_radius_m) + h.thickness_m
            });
            if r0 <= wall || rmax >= d.outer_radius_m {
                return Err(field(
                    "pin.center_radius_m",
                    format!(
                        "the pin face (radii {r0:.4} to {rmax:.4} m) must lie on the disc face \
                         between radius {wall} (inner radius or hat wall) and \
                         disc.outer_radius_m = {}",
                        d.outer_radius_m
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// Checks the `[thin_plate]` and `[thick_plate]` tables and what they need.
pub(super) fn validate_plates(scene: &Scene, file: &str) -> Result<()> {
    let field = |f: &str, m: String| field_error(file, f, m);
    let positive = |f: &str, v: f64| positive_length(file, f, v);
    for (name, plate) in [
        ("thin_plate", &scene.thin_plate),
        ("thick_plate", &scene.thick_plate),
    ] {
        if let Some(pl) = plate {
            positive(&format!("{name}.length_x_m"), pl.length_x_m)?;
            positive(&format!("{name}.width_y_m"), pl.width_y_m)?;
            positive(&format!("{name}.thickness_m"), pl.thickness_m)?;
            if name == "thick_plate" && pl.clamp.is_some() {
                return Err(field(
                    "thick_plate.clamp",
                    "only the thin plate is fixed: remove `clamp` from [thick_plate]".into(),
                ));
            }
            if let Some(p) = &scene.pin {
                if pl.length_x_m < p.size_x_m || pl.width_y_m < p.size_y_m {
                    return Err(field(
                        &format!("{name}.length_x_m"),
                        format!(
                            "the plate ({} x {} m) must cover the pin face ({} x {} m)",
                            pl.length_x_m, pl.width_y_m, p.size_x_m, p.size_y_m
                        ),
                    ));
                }
            }
        }
    }
    if (scene.thin_plate.is_some() || scene.thick_plate.is_some()) && scene.pin.is_none() {
        return Err(field(
            "pin",
            "plates are placed over the pin: a [pin] table is required".into(),
        ));
    }
    if scene.thick_plate.is_some() && scene.thin_plate.is_none() {
        return Err(field(
            "thin_plate",
            "the thick plate sits on the thin plate: a [thin_plate] table is required".into(),
        ));
    }
    Ok(())
}
