//! Contact: the zone of pairs that may carry load, and the load, each with its check.

use super::{field_error, Scene};
use crate::Result;
use serde::{Deserialize, Serialize};

/// Which contact pairs may carry load (the effective zone is then decided by the
/// equilibrium within them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, tag = "kind", rename_all = "snake_case")]
pub enum Zone {
    /// Every pair of the pin face.
    #[default]
    Uniform,
    /// Pairs inside the rectangle `[x0, x0 + a] x [y0, y0 + b]`, coordinates relative to
    /// the pin face's corner at (-size_x/2, center_radius - size_y/2) (m).
    Rectangle {
        /// Start along x (sliding direction) (m).
        x0_m: f64,
        /// Start along y (radius) (m).
        y0_m: f64,
        /// Length along x (m).
        a_m: f64,
        /// Width along y (m).
        b_m: f64,
    },
    /// Mesoscopic plateaus: the region (default the whole pin face; else the rectangle
    /// `region_m = [x0, y0, a, b]` as for `rectangle`) is cut into square patches of side
    /// `patch_m`, and a seeded random subset of them (`fraction` of the patches, or
    /// `count` patches) may touch. The same seed gives the same layout on every machine
    /// (splitmix64 + Fisher-Yates), and a larger fraction with the same seed keeps every
    /// patch of a smaller one.
    Plateaus {
        /// Patch side (m).
        patch_m: f64,
        /// Random seed.
        seed: u64,
        /// Fraction of the patches in contact, in (0, 1].
        #[serde(default, skip_serializing_if = "Option::is_none")]
        fraction: Option<f64>,
        /// Number of patches in contact.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        count: Option<usize>,
        /// Region cut into patches, `[x0, y0, a, b]` (m); absent: the whole face.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        region_m: Option<[f64; 4]>,
    },
    /// An explicit mask: one 0/1 per pair, row by row (along x) from the pin face's
    /// (-x, -y) corner, `(pin_face_elements + 1)^2` values; inline (`values`) or in a text
    /// file (`file`, whitespace or comma separated, relative to the scene file).
    Mask {
        /// The mask values.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        values: Option<Vec<u8>>,
        /// A mask file.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        file: Option<String>,
    },
}

impl Zone {
    /// Which of the points `xy` (m, relative to the pin face's corner, in grid order) lie
    /// in the zone on a face of `size = [size_x, size_y]`: a rectangle includes its edges
    /// (to `1e-9` of the face size); a point of a plateau region belongs to the one patch
    /// whose cell `[x, x + p) x [y, y + p)` holds it (the region's far edges closed), so the
    /// pairs in contact are the layout's fraction of the region's pairs whatever the patch
    /// side; a mask selects by index (`values[p] == 1`; the caller checks its length). The
    /// one inside test of contact sets, studies and maps.
    pub fn select(&self, xy: &[[f64; 2]], size: [f64; 2]) -> Vec<bool> {
        let eps = 1e-9 * (size[0] + size[1]);
        let in_rect = |p: &[f64; 2], r: &[f64; 4]| -> bool {
            p[0] >= r[0] - eps
                && p[0] <= r[0] + r[2] + eps
                && p[1] >= r[1] - eps
                && p[1] <= r[1] + r[3] + eps
        };
        let plateaus = self.plateau_layout(size);
        xy.iter()
            .enumerate()
            .map(|(i, p)| match self {
                Zone::Uniform => true,
                Zone::Rectangle {
                    x0_m,
                    y0_m,
                    a_m,
                    b_m,
                } => in_rect(p, &[*x0_m, *y0_m, *a_m, *b_m]),
                Zone::Plateaus { .. } => plateaus.as_ref().is_some_and(|l| l.holds(p, eps)),
                Zone::Mask { values, .. } => values.as_ref().is_some_and(|v| v.get(i) == Some(&1)),
            })
            .collect()
    }

    /// The rectangles `[x0, y0, a, b]` (m, from the pin face's corner) of a plateau
    /// layout on a face of `size = [size_x, size_y]`; `None` for other zones.
    pub fn plateau_rectangles(&self, size: [f64; 2]) -> Option<Vec<[f64; 4]>> {
        self.plateau_layout(size).map(|l| l.rectangles())
    }

    /// The patches of a plateau layout on a face of `size`, and which are in contact.
    fn plateau_layout(&self, size: [f64; 2]) -> Option<PlateauLayout> {
        let Zone::Plateaus {
            patch_m,
            seed,
            fraction,
            count,
            region_m,
        } = self
        else {
            return None;
        };
        let [x0, y0, a, b] = region_m.unwrap_or([0.0, 0.0, size[0], size[1]]);
        let nx = ((a / patch_m).round() as usize).max(1);
        let ny = ((b / patch_m).round() as usize).max(1);
        let (px, py) = (a / nx as f64, b / ny as f64);
        let total = nx * ny;
        let want = match (fraction, count) {
            (Some(f), _) => ((f * total as f64).round() as usize).clamp(1, total),
            (None, Some(c)) => (*c).clamp(1, total),
            (None, None) => total,
        };
        let mut state = *seed;
        let mut next = || {
            // splitmix64
            state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = state;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        };
        let mut idx: Vec<usize> = (0..total).collect();
        for i in (1..total).rev() {
            let j = (next() % (i as u64 + 1)) as usize;
            idx.swap(i, j);
        }
        let mut chosen: Vec<usize> = idx[..want].to_vec();
        chosen.sort_unstable();
        Some(PlateauLayout {
            origin: [x0, y0],
            patch: [px, py],
            count: [nx, ny],
            chosen,
        })
    }
}

/// A plateau layout: the region cut into `count` patches of side `patch` from `origin`
/// (m), and the indices (row by row along x) of those in contact, increasing.
struct PlateauLayout {
    origin: [f64; 2],
    patch: [f64; 2],
    count: [usize; 2],
    chosen: Vec<usize>,
}

impl PlateauLayout {
    /// The rectangles `[x0, y0, a, b]` of the patches in contact.
    fn rectangles(&self) -> Vec<[f64; 4]> {
        self.chosen
            .iter()
            .map(|&k| {
                let (i, j) = (k % self.count[0], k / self.count[0]);
                [
                    self.origin[0] + i as f64 * self.patch[0],
                    self.origin[1] + j as f64 * self.patch[1],
                    self.patch[0],
                    self.patch[1],
                ]
            })
            .collect()
    }

    /// Whether point `p` lies in a patch in contact: the patch whose half-open cell holds
    /// it, the region's far edges included (`eps`: the tolerance of the region's edges).
    fn holds(&self, p: &[f64; 2], eps: f64) -> bool {
        let cell = |d: usize| -> Option<usize> {
            let t = (p[d] - self.origin[d]) / self.patch[d];
            let n = self.count[d];
            let end = self.patch[d] * n as f64;
            if p[d] < self.origin[d] - eps || p[d] > self.origin[d] + end + eps {
                return None;
            }
            // a point on a patch boundary (to round-off) belongs to the patch it starts
            Some(((t + 1e-6).floor().max(0.0) as usize).min(n - 1))
        };
        match (cell(0), cell(1)) {
            (Some(i), Some(j)) => self.chosen.binary_search(&(j * self.count[0] + i)).is_ok(),
            _ => false,
        }
    }
}

/// Contact between the pin face and the disc.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields, default)]
pub struct ContactSpec {
    /// Pairs allowed to touch.
    pub zone: Zone,
}

/// The load: a target total normal force, or an imposed axial displacement of the disc
/// towards the pin (exactly one of the two).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Load {
    /// Target total normal force (N).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal_force_n: Option<f64>,
    /// Imposed axial displacement of the disc's clamped face towards the pin (m).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub disc_displacement_m: Option<f64>,
}

impl Default for Load {
    fn default() -> Self {
        Self {
            normal_force_n: Some(200.0),
            disc_displacement_m: None,
        }
    }
}

/// Checks the `[contact]` table: its zone against the pin face and the mesh.
pub(super) fn validate_contact(scene: &Scene, file: &str) -> Result<()> {
    let field = |f: &str, m: String| field_error(file, f, m);
    let m = &scene.mesh;
    if let (
        Zone::Rectangle {
            x0_m,
            y0_m,
            a_m,
            b_m,
        },
        Some(p),
    ) = (&scene.contact.zone, &scene.pin)
    {
        let ok = [*x0_m, *y0_m].iter().all(|v| v.is_finite() && *v >= 0.0)
            && *a_m > 0.0
            && *b_m > 0.0
            && x0_m + a_m <= p.size_x_m * (1.0 + 1e-9)
            && y0_m + b_m <= p.size_y_m * (1.0 + 1e-9);
        if !ok {
            return Err(field(
                "contact.zone",
                format!(
                    "rectangle x0_m = {x0_m}, y0_m = {y0_m}, a_m = {a_m}, b_m = {b_m} must \
                     have a, b > 0 and lie inside the pin face ({} x {} m)",
                    p.size_x_m, p.size_y_m
                ),
            ));
        }
    }
    match (&scene.contact.zone, &scene.pin) {
        (
            Zone::Plateaus {
                patch_m,
                fraction,
                count,
                region_m,
                ..
            },
            Some(p),
        ) => {
            let [x0, y0, a, b] = region_m.unwrap_or([0.0, 0.0, p.size_x_m, p.size_y_m]);
            let inside = x0 >= 0.0
                && y0 >= 0.0
                && a > 0.0
                && b > 0.0
                && x0 + a <= p.size_x_m * (1.0 + 1e-9)
                && y0 + b <= p.size_y_m * (1.0 + 1e-9);
            if !inside {
                return Err(field(
                    "contact.zone.region_m",
                    format!(
                        "expected [x0, y0, a, b] inside the pin face ({} x {} m), got {:?}",
                        p.size_x_m,
                        p.size_y_m,
                        [x0, y0, a, b]
                    ),
                ));
            }
            if !(patch_m.is_finite() && *patch_m > 0.0 && *patch_m <= a.min(b) * (1.0 + 1e-9)) {
                return Err(field(
                    "contact.zone.patch_m",
                    format!(
                        "expected a patch side in (0, {}] m, got {patch_m}",
                        a.min(b)
                    ),
                ));
            }
            match (fraction, count) {
                (Some(f), None) if *f > 0.0 && *f <= 1.0 => {}
                (None, Some(c)) if *c >= 1 => {}
                _ => {
                    return Err(field(
                        "contact.zone.fraction",
                        "give exactly one of fraction (in (0, 1]) and count (>= 1)".into(),
                    ))
                }
            }
        }
        (Zone::Mask { .. }, Some(_)) if m.contact_refinement.is_some() => {
            return Err(field(
                "contact.zone",
                "a mask zone lists the uniform grid's pairs; it cannot be combined with \
                 mesh.contact_refinement (use a rectangle or plateaus zone)"
                    .into(),
            ))
        }
        (Zone::Mask { values, file }, Some(_)) => {
            let want = (m.pin_face_elements + 1) * (m.pin_face_elements + 1);
            match (values, file) {
                (Some(v), _) => {
                    if v.len() != want {
                        return Err(field(
                            "contact.zone.values",
                            format!(
                                "expected {want} mask values ({0} x {0} pairs, row by row \
                                 from the (-x, -y) corner), got {1}",
                                m.pin_face_elements + 1,
                                v.len()
                            ),
                        ));
                    }
                    if let Some(bad) = v.iter().find(|&&x| x > 1) {
                        return Err(field(
                            "contact.zone.values",
                            format!("expected 0 or 1, got {bad}"),
                        ));
                    }
                }
                (None, Some(_)) => {
                    return Err(field(
                        "contact.zone.file",
                        "a mask file is read relative to the scene file: load the scene \
                         with Scene::from_file"
                            .into(),
                    ))
                }
                (None, None) => {
                    return Err(field(
                        "contact.zone",
                        "a mask needs `values` or `file`".into(),
                    ))
                }
            }
        }
        _ => {}
    }
    Ok(())
}

/// Checks the `[load]` table: exactly one positive load.
pub(super) fn validate_load(scene: &Scene, file: &str) -> Result<()> {
    let field = |f: &str, m: String| field_error(file, f, m);
    match (scene.load.normal_force_n, scene.load.disc_displacement_m) {
        (Some(f), None) if f.is_finite() && f > 0.0 => {}
        (None, Some(d)) if d.is_finite() && d > 0.0 => {}
        (Some(f), None) => {
            return Err(field(
                "load.normal_force_n",
                format!("expected a positive force in N, got {f}"),
            ))
        }
        (None, Some(d)) => {
            return Err(field(
                "load.disc_displacement_m",
                format!("expected a positive displacement in m towards the pin, got {d}"),
            ))
        }
        _ => {
            return Err(field(
                "load",
                "give exactly one of normal_force_n and disc_displacement_m".into(),
            ))
        }
    }
    Ok(())
}
