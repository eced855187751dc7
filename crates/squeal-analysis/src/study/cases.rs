//! The case list of a study, a pure function of its definition, and its warnings.

use super::{
    input, Axis, Case, CaseList, GridInfo, MacroSpec, MesoSpec, Result, Skipped, SolveSpec,
    StudyDef, StudySpec,
};
use squeal_scene::{Model, Zone};

/// The seed of layout `layout` of the patch side `patch_um` (um): splitmix64 of the three.
pub fn derive_seed(base: u64, patch_um: u64, layout: usize) -> u64 {
    let mix = |mut z: u64| {
        z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    };
    mix(mix(mix(base) ^ patch_um) ^ layout as u64)
}

fn um(v: f64) -> i64 {
    (v * 1e6).round() as i64
}

fn check_mu(mu: &[f64]) -> Result<()> {
    if mu.is_empty() {
        return Err(input(
            "study.mu",
            "expected at least one friction coefficient",
        ));
    }
    if let Some(m) = mu.iter().find(|m| !(m.is_finite() && **m >= 0.0)) {
        return Err(input(
            "study.mu",
            format!("expected friction coefficients >= 0, got {m} (reverse the scene's study.rotation instead of a negative mu)"),
        ));
    }
    Ok(())
}

fn positive(option: &str, v: &[f64], what: &str) -> Result<()> {
    if v.is_empty() {
        return Err(input(option, format!("expected at least one {what}")));
    }
    if let Some(x) = v.iter().find(|x| x.is_nan() || **x <= 0.0) {
        return Err(input(option, format!("expected {what}s > 0 m, got {x}")));
    }
    Ok(())
}

/// Every start and every length of one axis must fit in the face with at least one value
/// of the other list (combinations that do not fit are skipped and counted).
fn check_axis(
    start_opt: &str,
    len_opt: &str,
    starts: &Axis,
    lens: &[f64],
    size: f64,
    tol: f64,
) -> Result<()> {
    let min_len = lens.iter().copied().fold(f64::INFINITY, f64::min);
    if let Some(l) = lens.iter().find(|l| **l > size + tol) {
        return Err(input(
            len_opt,
            format!(
                "zone size {l} m is larger than the pin face ({size} m): expected values in (0, {size}] m"
            ),
        ));
    }
    if let Axis::Values(v) = starts {
        let min_start = v.iter().copied().fold(f64::INFINITY, f64::min);
        if let Some(x) = v.iter().find(|x| **x + min_len > size + tol) {
            return Err(input(
                start_opt,
                format!(
                    "a zone starting at {x} m leaves the pin face ({size} m) even with the \
                     smallest {len_opt} {min_len} m: expected {start_opt} in [0, {}] m (from \
                     the face corner)",
                    size - min_len
                ),
            ));
        }
        if let Some(l) = lens.iter().find(|l| min_start + **l > size + tol) {
            return Err(input(
                len_opt,
                format!(
                    "a zone of {l} m leaves the pin face ({size} m) even at the smallest \
                     {start_opt} {min_start} m: expected {len_opt} <= {} m",
                    size - min_start
                ),
            ));
        }
    }
    Ok(())
}

impl StudyDef {
    /// The definition of a study of `study` solved by `solve` on `model`, built from
    /// `scene` (named `file`), stamped with this crate's version.
    pub fn new(
        file: &str,
        scene: &squeal_scene::Scene,
        model: &Model,
        study: StudySpec,
        solve: SolveSpec,
    ) -> Result<Self> {
        Ok(Self {
            version: env!("CARGO_PKG_VERSION").to_string(),
            scene: file.to_string(),
            scene_toml: scene.to_toml(),
            dofs: model.dofs.n_free(),
            rotation: scene.study.rotation,
            damping: scene.damping.clone(),
            grid: GridInfo::of(model)?,
            study,
            solve,
        })
    }

    /// The case list (sorted by id), with the skipped zones counted. Errors name the
    /// field when no case is left or an input is out of range.
    pub fn cases(&self) -> Result<CaseList> {
        let mut list = match &self.study {
            StudySpec::Macro(s) => self.macro_cases(s)?,
            StudySpec::Meso(s) => self.meso_cases(s)?,
        };
        let cases = &mut list.cases;
        cases.sort_by(|a, b| a.id.cmp(&b.id));
        if let Some(w) = cases.windows(2).find(|w| w[0].id == w[1].id) {
            let option = match self.study {
                StudySpec::Macro(_) => "study.mu/study.x0/study.y0/study.a_m/study.b_m",
                StudySpec::Meso(_) => "study.mu/study.patch_m",
            };
            return Err(input(
                option,
                format!(
                    "two cases have the same id {} (duplicate values, or values closer than 1 um / 1e-4 in mu)",
                    w[0].id
                ),
            ));
        }
        Ok(list)
    }

    /// The zones of the macroscopic grid that fit in the face and hold a pair, unsorted.
    fn macro_cases(&self, s: &MacroSpec) -> Result<CaseList> {
        let face = self.grid.face_m;
        let tol = 1e-9 * (face[0] + face[1]);
        let mut cases = Vec::new();
        let mut skipped = Skipped::default();
        check_mu(&s.mu)?;
        positive("study.a_m", &s.a_m, "zone length")?;
        positive("study.b_m", &s.b_m, "zone width")?;
        check_axis("study.x0", "study.a_m", &s.x0, &s.a_m, face[0], tol)?;
        check_axis("study.y0", "study.b_m", &s.y0, &s.b_m, face[1], tol)?;
        for &mu in &s.mu {
            for &a in &s.a_m {
                for &b in &s.b_m {
                    for x0 in s.x0.offsets(face[0], a) {
                        for y0 in s.y0.offsets(face[1], b) {
                            let fits = x0 >= -tol
                                && y0 >= -tol
                                && x0 + a <= face[0] + tol
                                && y0 + b <= face[1] + tol;
                            if !fits {
                                skipped.outside_face += 1;
                                continue;
                            }
                            let (x0, y0) = (x0.max(0.0), y0.max(0.0));
                            let zone = Zone::Rectangle {
                                x0_m: x0,
                                y0_m: y0,
                                a_m: a,
                                b_m: b,
                            };
                            let pairs = self.grid.pairs_in(&zone);
                            if pairs == 0 {
                                skipped.no_pairs += 1;
                                continue;
                            }
                            cases.push(Case {
                                id: format!(
                                    "mu{:05}-x{:06}-y{:06}-a{:06}-b{:06}",
                                    (mu * 1e4).round() as i64,
                                    um(x0),
                                    um(y0),
                                    um(a),
                                    um(b)
                                ),
                                mu,
                                zone,
                                patch_m: None,
                                layout: None,
                                pairs,
                                area_m2: a * b,
                            });
                        }
                    }
                }
            }
        }
        if cases.is_empty() {
            return Err(input(
                "study.x0/study.y0/study.a_m/study.b_m",
                format!(
                    "no zone fits in the pin face ({} x {} mm) with a contact pair \
                     ({} outside the face, {} without a pair): zones are [x0, x0 + a] x \
                     [y0, y0 + b] in m from the face corner",
                    face[0] * 1e3,
                    face[1] * 1e3,
                    skipped.outside_face,
                    skipped.no_pairs
                ),
            ));
        }
        Ok(CaseList {
            cases,
            skipped,
            no_pairs_by_patch: Vec::new(),
            repeats_by_patch: Vec::new(),
        })
    }

    /// The plateau layouts of every patch size that hold a pair, unsorted.
    fn meso_cases(&self, s: &MesoSpec) -> Result<CaseList> {
        let face = self.grid.face_m;
        let tol = 1e-9 * (face[0] + face[1]);
        let mut cases = Vec::new();
        let mut skipped = Skipped::default();
        let mut no_pairs_by_patch = Vec::new();
        let mut repeats_by_patch = Vec::new();
        check_mu(&s.mu)?;
        let [x0, y0, a, b] = s.region_m;
        if !(x0 >= 0.0
            && y0 >= 0.0
            && a > 0.0
            && b > 0.0
            && x0 + a <= face[0] + tol
            && y0 + b <= face[1] + tol)
        {
            return Err(input(
                "study.region_m",
                format!(
                    "[{x0}, {y0}, {a}, {b}] must lie inside the pin face ({} x {} m) with a, b > 0",
                    face[0], face[1]
                ),
            ));
        }
        positive("study.patch_m", &s.patch_m, "patch side")?;
        if let Some(p) = s.patch_m.iter().find(|p| **p > a.min(b) * (1.0 + 1e-9)) {
            return Err(input(
                "study.patch_m",
                format!(
                    "patch side {p} m does not fit in the region ({a} x {b} m, study.region_m): \
                     expected patch sides <= {} m",
                    a.min(b)
                ),
            ));
        }
        let sp_in = self.grid.spacing_in(s.region_m);
        let sp = sp_in[0].max(sp_in[1]);
        if let Some(p) = s.patch_m.iter().find(|p| **p < sp * (1.0 - 1e-9)) {
            return Err(input(
                "study.patch_m",
                format!(
                    "patch side {:.3} mm is smaller than the contact grid spacing \
                     {:.3} mm of the scene in the region ({} x {} pairs on the face): \
                     expected patch sides >= {:.3} mm, or a scene with a finer contact \
                     grid there (mesh.contact_refinement = {{ region_m = [{}, {}, {}, \
                     {}], element_m = {} }}, or a larger mesh.pin_face_elements; the \
                     paper used 0.2 mm contact elements)",
                    p * 1e3,
                    sp * 1e3,
                    self.grid.n[0],
                    self.grid.n[1],
                    sp * 1e3,
                    x0,
                    y0,
                    a,
                    b,
                    p / 2.0
                ),
            ));
        }
        if s.layouts == 0 {
            return Err(input(
                "study.layouts",
                "expected at least one layout per patch size",
            ));
        }
        if !(s.fraction > 0.0 && s.fraction <= 1.0) {
            return Err(input(
                "study.fraction",
                format!(
                    "expected a fraction of the patches in (0, 1], got {}",
                    s.fraction
                ),
            ));
        }
        for &patch in &s.patch_m {
            let mut empty = 0;
            let mut repeats = 0;
            let mut seen = std::collections::HashSet::new();
            for l in 0..s.layouts {
                let zone = Zone::Plateaus {
                    patch_m: patch,
                    seed: derive_seed(s.seed, um(patch).unsigned_abs(), l),
                    fraction: Some(s.fraction),
                    count: None,
                    region_m: Some(s.region_m),
                };
                let pairs = self.grid.pairs_in(&zone);
                if pairs == 0 {
                    empty += 1;
                    continue;
                }
                let rects = zone.plateau_rectangles(face).unwrap_or_default();
                let key: Vec<[i64; 2]> = rects.iter().map(|r| [um(r[0]), um(r[1])]).collect();
                if !seen.insert(key) {
                    repeats += 1;
                }
                let area_m2 = rects.iter().map(|r| r[2] * r[3]).sum();
                for &mu in &s.mu {
                    cases.push(Case {
                        id: format!(
                            "mu{:05}-p{:06}-l{:05}",
                            (mu * 1e4).round() as i64,
                            um(patch),
                            l
                        ),
                        mu,
                        zone: zone.clone(),
                        patch_m: Some(patch),
                        layout: Some(l),
                        pairs,
                        area_m2,
                    });
                }
            }
            skipped.no_pairs += empty * s.mu.len();
            no_pairs_by_patch.push(empty);
            repeats_by_patch.push(repeats);
        }
        if cases.is_empty() {
            return Err(input(
                "study.patch_m",
                format!(
                    "no layout holds a contact pair: the patches are smaller than the \
                     contact grid spacing ({:.3} x {:.3} mm); raise mesh.pin_face_elements \
                     in the scene or use larger patches",
                    self.grid.spacing_m[0] * 1e3,
                    self.grid.spacing_m[1] * 1e3
                ),
            ));
        }
        Ok(CaseList {
            cases,
            skipped,
            no_pairs_by_patch,
            repeats_by_patch,
        })
    }

    /// Human-readable warnings (patches below the contact grid spacing, skipped cases).
    pub fn warnings(&self, list: &CaseList) -> Vec<String> {
        let mut w = Vec::new();
        if let StudySpec::Meso(s) = &self.study {
            for (i, &p) in s.patch_m.iter().enumerate() {
                if let Some(&n) = list.no_pairs_by_patch.get(i) {
                    if n > 0 {
                        w.push(format!(
                            "patch {:.3} mm: {n} of {} layouts hold no contact pair and were skipped",
                            p * 1e3,
                            s.layouts
                        ));
                    }
                }
                if let Some(&n) = list.repeats_by_patch.get(i) {
                    if n > 0 {
                        w.push(format!(
                            "patch {:.3} mm: {n} of {} layouts repeat an earlier one (the region \
                             holds few distinct layouts of this patch size; the fraction counts \
                             each repeat)",
                            p * 1e3,
                            s.layouts
                        ));
                    }
                }
            }
        }
        if list.skipped.outside_face > 0 {
            w.push(format!(
                "{} zones do not fit in the pin face and were skipped",
                list.skipped.outside_face
            ));
        }
        if list.skipped.no_pairs > 0 && matches!(self.study, StudySpec::Macro(_)) {
            w.push(format!(
                "{} zones hold no contact pair and were skipped",
                list.skipped.no_pairs
            ));
        }
        w
    }
}
