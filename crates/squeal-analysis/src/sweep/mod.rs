//! Sweeps (of the friction coefficient, or of any parameter of an operator family, see
//! [`crate::family`]): mode tracking by MAC continuity and coupling detection.
//!
//! Every complex mode of a sweep point is summarized by its **signature**: its
//! coefficients on real reference modes `phi_k` (`M`-orthonormal), `c_k = phi_k^T M u` on
//! the full DOFs. For a scene the reference modes are the free-interface normal modes of
//! the bodies (no contact); for an operator without a model (a parametric operator
//! directory) they are the real modes of the symmetric part of its mass and stiffness at
//! the sweep's first value ([`crate::family::reference_modes`]). Two modes are compared by
//! the Hermitian MAC of their signatures, `|c_a^H c_b|^2 / (|c_a|^2 |c_b|^2)`, which is the
//! MAC of the modes projected on the reference basis: cheap to store (one short complex
//! vector per mode, however many DOFs), independent of the contact set (whose constrained
//! spaces differ from mu to mu), and for a scene it is also the paper's Figure 7 (MAC of
//! each unstable mode against the free-interface modes).
//!
//! **Tracking.** Branches are continued from one sweep point to the next by a greedy
//! assignment on the product of the signature MAC and a frequency-proximity factor; a mode
//! that matches no branch above `min_mac` starts a new branch. Disc doublets (two modes
//! with nearly the same frequency and signatures spanning the same pair of free-interface
//! modes) are the hard case: the greedy assignment takes the best MAC first, so a rotated
//! doublet stays on its two branches as long as the pair keeps its subspace.
//!
//! **Couplings.** A coupling is a maximal run of consecutive sweep points where a branch is
//! unstable (its real part above its forward error bound, and its DvR above the optional
//! physical margin: [`squeal_core::operator::classify`]); it reports the frequency at the largest DvR, the interval of
//! the swept value (first and last unstable value), the largest DvR and the partner
//! branch: the branch with the nearest frequency and the most negative DvR over the same
//! interval (the mode it merged with, whose DvR mirrors it).

use serde::{Deserialize, Serialize};

/// FNV-1a fingerprint of an active-set mask.
pub fn active_hash(active: &[bool]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &a in active {
        h ^= u64::from(a);
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h ^ (active.len() as u64)
}
use squeal_core::c64;
use squeal_core::operator::{classify, Stability, Verdict};

pub mod files;

/// One mode of a sweep point.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SweepMode {
    /// Frequency (Hz).
    pub freq_hz: f64,
    /// Real part of lambda (1/s).
    pub re: f64,
    /// Divergence rate `Re / Im`.
    pub dvr: f64,
    /// Backward error on the full operator.
    pub backward_error: f64,
    /// Condition number of the eigenvalue (`ComplexModes::cond`); NaN when not computed
    /// (and in checkpoints written before it was recorded).
    #[serde(
        default = "crate::jsonl::nan",
        deserialize_with = "crate::jsonl::null_as_nan"
    )]
    pub cond: f64,
    /// First-order estimate of the relative eigenvalue error, `cond * backward_error`
    /// (`ComplexModes::error_bound`); NaN when not computed.
    #[serde(
        default = "crate::jsonl::nan",
        deserialize_with = "crate::jsonl::null_as_nan"
    )]
    pub error_bound: f64,
    /// The smallest condition number the eigenvalue can have
    /// (`ComplexModes::cond_floor`); NaN in checkpoints written before it was recorded.
    #[serde(
        default = "crate::jsonl::nan",
        deserialize_with = "crate::jsonl::null_as_nan"
    )]
    pub cond_floor: f64,
    /// Coefficients on the reference modes of tracking (the free-interface modes of a
    /// scene): (re, im) pairs.
    pub signature: Vec<[f64; 2]>,
}

impl SweepMode {
    /// The eigenvalue `Re + i 2 pi f` (1/s).
    pub fn lambda(&self) -> c64 {
        c64::new(self.re, 2.0 * std::f64::consts::PI * self.freq_hz)
    }

    /// The stability class and the bound of the real part it was decided by
    /// ([`squeal_core::operator::classify`]).
    pub fn verdict(&self, dvr_margin: f64) -> Verdict {
        classify(
            self.lambda(),
            self.backward_error,
            self.cond,
            self.error_bound,
            self.cond_floor,
            dvr_margin,
        )
    }

    /// The stability class ([`SweepMode::verdict`]).
    pub fn stability(&self, dvr_margin: f64) -> Stability {
        self.verdict(dvr_margin).class
    }
}

impl SweepPoint {
    /// How many of the point's modes fall in each class, `[unstable, neutral, stable]`.
    pub fn class_counts(&self, dvr_margin: f64) -> [usize; 3] {
        let mut counts = [0; 3];
        for m in &self.modes {
            counts[m.stability(dvr_margin).index()] += 1;
        }
        counts
    }
}

/// Equal numbers, or both NaN (a quantity not computed on either side).
fn same_number(a: f64, b: f64) -> bool {
    a == b || (a.is_nan() && b.is_nan())
}

impl PartialEq for SweepMode {
    /// Field by field, a NaN equal to a NaN (`cond` and `error_bound` not computed).
    fn eq(&self, o: &Self) -> bool {
        same_number(self.freq_hz, o.freq_hz)
            && same_number(self.re, o.re)
            && same_number(self.dvr, o.dvr)
            && same_number(self.backward_error, o.backward_error)
            && same_number(self.cond, o.cond)
            && same_number(self.error_bound, o.error_bound)
            && same_number(self.cond_floor, o.cond_floor)
            && self.signature == o.signature
    }
}

/// One value of a sweep's parameter.
#[derive(Debug, Clone, Serialize, Deserialize, PartialEq)]
pub struct SweepPoint {
    /// The swept parameter's value (the friction coefficient of a mu sweep; NaN in
    /// checkpoints written before it was recorded, which [`Checkpoint::load`] sets to
    /// `mu`).
    #[serde(
        default = "crate::jsonl::nan",
        deserialize_with = "crate::jsonl::null_as_nan"
    )]
    pub value: f64,
    /// Friction coefficient.
    pub mu: f64,
    /// Active contact pairs.
    pub active_pairs: usize,
    /// Whether the contact set differs from the previous sweep point's (a new operator and,
    /// for bases fixed in mu, a new basis).
    pub rebuilt: bool,
    /// Fingerprint of the active set (FNV-1a of the mask), to recognise equal contact sets
    /// across resumed runs and shards.
    #[serde(default)]
    pub active_hash: u64,
    /// Basis size (0 for full order).
    pub basis_size: usize,
    /// Wall times (s): equilibrium, operator + basis, eigen solve.
    pub times_s: [f64; 3],
    /// Modes in the band, sorted by frequency.
    pub modes: Vec<SweepMode>,
}

/// A tracked branch: which mode it is at each sweep point (`None` where it is not found).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Branch {
    /// Branch number.
    pub id: usize,
    /// Mode index at each sweep point.
    pub modes: Vec<Option<usize>>,
}

/// A detected mode coupling (flutter).
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Coupling {
    /// Frequency at the largest DvR (Hz).
    pub freq_hz: f64,
    /// First unstable value of the swept parameter.
    pub from: f64,
    /// Last unstable value of the run.
    pub to: f64,
    /// Largest divergence rate.
    pub max_dvr: f64,
    /// The unstable branch and its partner branch (when found).
    pub partners: Vec<usize>,
}

/// Tuning of [`track`].
#[derive(Debug, Clone, PartialEq)]
pub struct TrackOptions {
    /// Minimum signature MAC to continue a branch.
    pub min_mac: f64,
    /// Relative frequency scale of the proximity factor `exp(-(df/f / scale)^2)`.
    pub freq_scale: f64,
}

impl Default for TrackOptions {
    fn default() -> Self {
        Self {
            min_mac: 0.5,
            freq_scale: 0.05,
        }
    }
}

/// Hermitian MAC of two signatures.
pub fn signature_mac(a: &[[f64; 2]], b: &[[f64; 2]]) -> f64 {
    let (mut re, mut im, mut na, mut nb) = (0.0, 0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        // conj(x) * y
        re += x[0] * y[0] + x[1] * y[1];
        im += x[0] * y[1] - x[1] * y[0];
        na += x[0] * x[0] + x[1] * x[1];
        nb += y[0] * y[0] + y[1] * y[1];
    }
    if na == 0.0 || nb == 0.0 {
        0.0
    } else {
        (re * re + im * im) / (na * nb)
    }
}

/// Signature of a full-DOF complex mode `u` on real `M`-orthonormal modes `phi`
/// (`phi` columns; `mphi = M phi` precomputed): `c_k = (M phi_k)^T u`.
pub fn signature(mphi: faer::MatRef<'_, f64>, u: &[c64]) -> Vec<[f64; 2]> {
    (0..mphi.ncols())
        .map(|k| {
            let (mut re, mut im) = (0.0, 0.0);
            for (r, z) in u.iter().enumerate() {
                let w = mphi[(r, k)];
                re += w * z.re;
                im += w * z.im;
            }
            [re, im]
        })
        .collect()
}

use squeal_core::faer;

/// Tracks modes along the sweep (points in increasing mu).
pub fn track(points: &[SweepPoint], opts: &TrackOptions) -> Vec<Branch> {
    let np = points.len();
    let mut branches: Vec<Branch> = Vec::new();
    // last seen mode of each branch: (point, mode)
    let mut last: Vec<(usize, usize)> = Vec::new();
    for (p, pt) in points.iter().enumerate() {
        let mut cand: Vec<(f64, usize, usize)> = Vec::new();
        for (b, &(lp, lm)) in last.iter().enumerate() {
            // only branches seen at the previous point (or two back) can continue
            if p - lp > 2 {
                continue;
            }
            let prev = &points[lp].modes[lm];
            for (m, md) in pt.modes.iter().enumerate() {
                let mac = signature_mac(&prev.signature, &md.signature);
                if mac < opts.min_mac {
                    continue;
                }
                let df = (md.freq_hz - prev.freq_hz).abs() / prev.freq_hz.max(1e-300);
                let prox = (-(df / opts.freq_scale).powi(2)).exp();
                cand.push((mac * prox, b, m));
            }
        }
        cand.sort_by(|a, b| b.0.total_cmp(&a.0));
        let mut taken_b = vec![false; last.len()];
        let mut taken_m = vec![false; pt.modes.len()];
        for (_, b, m) in cand {
            if taken_b[b] || taken_m[m] {
                continue;
            }
            taken_b[b] = true;
            taken_m[m] = true;
            branches[b].modes[p] = Some(m);
            last[b] = (p, m);
        }
        for m in (0..pt.modes.len()).filter(|&m| !taken_m[m]) {
            let mut modes = vec![None; np];
            modes[p] = Some(m);
            branches.push(Branch {
                id: branches.len(),
                modes,
            });
            last.push((p, m));
        }
    }
    branches
}

/// Detects couplings: runs of consecutive points where a branch is unstable
/// ([`SweepMode::stability`] with the physical margin `dvr_margin`).
pub fn couplings(points: &[SweepPoint], branches: &[Branch], dvr_margin: f64) -> Vec<Coupling> {
    let mut out = Vec::new();
    let dvr = |b: &Branch, p: usize| b.modes[p].map(|m| points[p].modes[m].dvr);
    let unstable = |b: &Branch, p: usize| {
        b.modes[p].is_some_and(|m| points[p].modes[m].stability(dvr_margin) == Stability::Unstable)
    };
    let freq = |b: &Branch, p: usize| b.modes[p].map(|m| points[p].modes[m].freq_hz);
    for b in branches {
        let mut p = 0;
        while p < points.len() {
            if !unstable(b, p) {
                p += 1;
                continue;
            }
            let start = p;
            while p < points.len() && unstable(b, p) {
                p += 1;
            }
            let end = p - 1;
            let (pk, dmax) = (start..=end)
                .map(|q| (q, dvr(b, q).unwrap()))
                .max_by(|a, c| a.1.total_cmp(&c.1))
                .unwrap();
            let f = freq(b, pk).unwrap();
            // partner: nearest frequency at the peak with the most negative DvR
            let partner = branches
                .iter()
                .filter(|o| o.id != b.id)
                .filter_map(|o| {
                    let (fo, d) = (freq(o, pk)?, dvr(o, pk)?);
                    let df = (fo - f).abs() / f;
                    (df < 0.02 && d < -0.5 * dmax).then_some((df, o.id))
                })
                .min_by(|a, c| a.0.total_cmp(&c.0))
                .map(|x| x.1);
            let mut partners = vec![b.id];
            partners.extend(partner);
            out.push(Coupling {
                freq_hz: f,
                from: points[start].value,
                to: points[end].value,
                max_dvr: dmax,
                partners,
            });
        }
    }
    out.sort_by(|a, b| {
        a.from
            .total_cmp(&b.from)
            .then(a.freq_hz.total_cmp(&b.freq_hz))
    });
    out
}

/// Appends finished points to a JSON-lines checkpoint and reads them back, so an
/// interrupted sweep resumes where it stopped and never loses a finished point.
pub struct Checkpoint {
    path: std::path::PathBuf,
}

impl Checkpoint {
    /// A checkpoint at `path` (created on first write).
    pub fn new(path: impl Into<std::path::PathBuf>) -> Self {
        Self { path: path.into() }
    }

    /// Points already computed (a truncated last line, from a crash mid-write, is
    /// ignored).
    pub fn load(&self) -> std::io::Result<Vec<SweepPoint>> {
        let mut points: Vec<SweepPoint> = crate::jsonl::load(&self.path)?;
        for p in points.iter_mut().filter(|p| p.value.is_nan()) {
            p.value = p.mu;
        }
        Ok(points)
    }

    /// Records the inputs the points depend on (scene, methods, band) next to the
    /// checkpoint, in `<name>.inputs.json`, or checks an existing record: resuming a
    /// checkpoint written with other inputs is an error naming the first difference, as
    /// is a checkpoint with points but no record.
    pub fn claim(&self, inputs: &serde_json::Value) -> Result<(), String> {
        let record = self.path.with_extension("inputs.json");
        let has_points = std::fs::metadata(&self.path).is_ok_and(|m| m.len() > 0);
        match std::fs::read_to_string(&record) {
            Ok(text) => {
                let have: serde_json::Value = serde_json::from_str(&text)
                    .map_err(|e| format!("{}: not valid JSON ({e})", record.display()))?;
                if &have != inputs {
                    return Err(format!(
                        "{} holds a sweep of other inputs (differs at {}): use another --out, \
                         or delete the directory to start over",
                        self.path.display(),
                        crate::jsonl::first_difference(&have, inputs)
                    ));
                }
                Ok(())
            }
            Err(_) if has_points => Err(format!(
                "{} holds points but no record of their inputs ({}): use another --out, or \
                 delete it to start over",
                self.path.display(),
                record.display()
            )),
            Err(_) => {
                let text = serde_json::to_string_pretty(inputs).map_err(|e| e.to_string())?;
                crate::jsonl::write_atomic(&record, text.as_bytes())
                    .map_err(|e| format!("{}: {e}", record.display()))
            }
        }
    }

    /// Appends one point (flushed before returning).
    pub fn append(&self, point: &SweepPoint) -> std::io::Result<()> {
        crate::jsonl::append(&self.path, point)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn mode(f: f64, dvr: f64, sig: &[f64]) -> SweepMode {
        SweepMode {
            freq_hz: f,
            re: dvr * 2.0 * std::f64::consts::PI * f,
            dvr,
            backward_error: 0.0,
            cond: f64::NAN,
            error_bound: f64::NAN,
            cond_floor: f64::NAN,
            signature: sig.iter().map(|&x| [x, 0.0]).collect(),
        }
    }

    fn point(mu: f64, modes: Vec<SweepMode>) -> SweepPoint {
        SweepPoint {
            value: mu,
            mu,
            active_pairs: 1,
            rebuilt: false,
            active_hash: 0,
            basis_size: 0,
            times_s: [0.0; 3],
            modes,
        }
    }

    /// Two modes approach, merge (flutter: equal frequency, DvR +-) and separate again;
    /// a third one crosses them in frequency with its own signature.
    fn synthetic() -> Vec<SweepPoint> {
        let mut pts = Vec::new();
        for k in 0..11 {
            let mu = 0.1 * k as f64;
            let (fa, fb) = (2000.0 + 40.0 * mu, 2100.0 - 40.0 * mu);
            let mut modes = Vec::new();
            if (0.4..0.75).contains(&mu) {
                let fm = 0.5 * (fa + fb);
                let d = 0.01 * (1.0 - ((mu - 0.55) / 0.2).powi(2));
                modes.push(mode(fm, d, &[0.7, 0.7, 0.0]));
                modes.push(mode(fm, -d, &[0.7, -0.7, 0.0]));
            } else {
                modes.push(mode(fa, 0.0, &[1.0, 0.1 * mu, 0.0]));
                modes.push(mode(fb, 0.0, &[0.1 * mu, 1.0, 0.0]));
            }
            modes.push(mode(1800.0 + 500.0 * mu, 0.0, &[0.0, 0.0, 1.0]));
            modes.sort_by(|a, b| a.freq_hz.total_cmp(&b.freq_hz));
            pts.push(point(mu, modes));
        }
        pts
    }

    #[test]
    fn tracking_follows_signatures_through_a_crossing() {
        let pts = synthetic();
        let br = track(&pts, &TrackOptions::default());
        // the crossing mode keeps one branch from start to end
        let crossing = br
            .iter()
            .find(|b| {
                b.modes
                    .iter()
                    .enumerate()
                    .all(|(p, m)| m.is_some_and(|m| pts[p].modes[m].signature[2][0] == 1.0))
            })
            .expect("the crossing mode is one branch");
        assert!(crossing.modes.iter().all(Option::is_some));
    }

    #[test]
    fn coupling_is_detected_with_interval_peak_and_partner() {
        let pts = synthetic();
        let br = track(&pts, &TrackOptions::default());
        let c = couplings(&pts, &br, 1e-6);
        assert_eq!(c.len(), 1, "{c:?}");
        let c = &c[0];
        approx::assert_abs_diff_eq!(c.from, 0.4, epsilon = 1e-12);
        approx::assert_abs_diff_eq!(c.to, 0.7, epsilon = 1e-12);
        approx::assert_abs_diff_eq!(c.freq_hz, 2050.0, epsilon = 1e-9);
        assert!(c.max_dvr > 0.009);
        assert_eq!(c.partners.len(), 2, "the stable mirror is the partner");
    }

    #[test]
    fn checkpoint_round_trip_ignores_a_torn_line() {
        let path = std::env::temp_dir().join(format!("squeal-ckpt-{}.jsonl", std::process::id()));
        std::fs::remove_file(&path).ok();
        let ck = Checkpoint::new(&path);
        assert!(ck.load().unwrap().is_empty());
        let pts = synthetic();
        ck.append(&pts[0]).unwrap();
        ck.append(&pts[1]).unwrap();
        // a crash mid-write leaves half a line
        use std::io::Write;
        let mut f = std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .unwrap();
        write!(f, "{{\"mu\": 0.2, \"act").unwrap();
        let back = ck.load().unwrap();
        assert_eq!(back, pts[..2].to_vec());
        std::fs::remove_file(&path).ok();
    }

    #[test]
    fn checkpoints_without_value_cond_or_error_bound_still_load() {
        let path =
            std::env::temp_dir().join(format!("squeal-ckpt-old-{}.jsonl", std::process::id()));
        // a point as written before the swept value and the error estimates were recorded
        let old = r#"{"mu":0.25,"active_pairs":3,"rebuilt":true,"active_hash":7,"basis_size":0,"times_s":[0.0,0.0,0.0],"modes":[{"freq_hz":1000.0,"re":-1.0,"dvr":-1e-4,"backward_error":1e-15,"signature":[[1.0,0.0]]}]}"#;
        std::fs::write(&path, format!("{old}\n")).unwrap();
        let back = Checkpoint::new(&path).load().unwrap();
        assert_eq!(back.len(), 1);
        assert_eq!(back[0].value, 0.25);
        let m = &back[0].modes[0];
        assert!(m.cond.is_nan() && m.error_bound.is_nan());
        // and a NaN written back (as null) reads as NaN: the point equals itself
        Checkpoint::new(&path).append(&back[0]).unwrap();
        let again = Checkpoint::new(&path).load().unwrap();
        assert_eq!(again.len(), 2);
        assert_eq!(again[1], back[0]);
        std::fs::remove_file(&path).ok();
    }

    #[test]
    fn mac_is_hermitian_and_phase_free() {
        let a = [[1.0, 0.0], [0.0, 1.0]];
        let b = [[0.0, 2.0], [-2.0, 0.0]]; // 2i * a
        approx::assert_relative_eq!(signature_mac(&a, &b), 1.0, max_relative = 1e-15);
        let c = [[1.0, 0.0], [0.0, -1.0]];
        assert!(signature_mac(&a, &c) < 1e-15);
    }

    #[test]
    fn a_checkpoint_refuses_points_of_other_inputs() {
        let dir = std::env::temp_dir().join(format!("squeal-claim-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let ck = Checkpoint::new(dir.join("sweep.partial.jsonl"));
        let a = serde_json::json!({"scene": "a", "basis": "enriched", "band_hz": [0.0, 1e4]});
        let b = serde_json::json!({"scene": "a", "basis": "residue", "band_hz": [0.0, 1e4]});
        ck.claim(&a).unwrap();
        ck.append(&point(0.1, vec![mode(1000.0, 0.0, &[1.0])]))
            .unwrap();
        // the same inputs resume; other ones are refused, naming the difference
        ck.claim(&a).unwrap();
        let err = ck.claim(&b).unwrap_err();
        assert!(err.contains("basis") && err.contains("residue"), "{err}");
        // points without a record of their inputs are refused too
        std::fs::remove_file(dir.join("sweep.partial.inputs.json")).unwrap();
        let err = ck.claim(&a).unwrap_err();
        assert!(err.contains("no record"), "{err}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
