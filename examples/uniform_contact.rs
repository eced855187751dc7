//! The paper's uniform-contact validation through the library, on the coarse rig: one
//! prepared model, a mu sweep through the `cms` basis with mode tracking (the couplings
//! and what they are made of), then one contact set solved at full order and compared
//! with the basis, mode by mode, by the library's comparison (the one `squeal validate`
//! and `squeal bench` use).
//!
//! ```text
//! cargo run --release --example uniform_contact
//! ```
//!
//! The same chain on the 172k-DOF default rig is `squeal validate`; replace the scene
//! name below to run it here.

use squeal::analysis::bench::compare;
use squeal::analysis::mu_sweep::{mu_list, run_sweep, MuSweepSettings};
use squeal::analysis::pipeline::{Method, Prepared};
use squeal::core::{EigenParams, Params};
use squeal::scene::Scene;

/// Runs the example (public so that `tests/examples.rs` runs it too).
pub fn main() -> Result<(), Box<dyn std::error::Error>> {
    let reg = squeal::registry();
    let name = "pin-on-disc-coarse";
    let prep = Prepared::new(&reg, Scene::builtin(name)?, name)?;
    let band = [0.0, 5000.0];

    // the mu sweep through `cms`: equilibrium, operator and reduced modes per mu
    let settings = MuSweepSettings::new(mu_list(0.0, 0.8, 0.05)?, "cms", band);
    let sweep = run_sweep(&reg, &prep, &settings, None, |_| {})?;
    println!(
        "{name}: {} mu points in {:.1} s, {} couplings (DvR > {:e})",
        sweep.points.len(),
        sweep.time_s,
        sweep.couplings.len(),
        settings.dvr_margin
    );
    for c in &sweep.couplings {
        let made_of: Vec<String> = c
            .free_interface_mac
            .iter()
            .map(|(mode, mac)| format!("{mode} (MAC {mac:.2})"))
            .collect();
        println!(
            "  {:7.1} Hz unstable for mu {:.2}-{:.2}, max DvR {:.2e}: {}",
            c.freq_hz,
            c.mu_from,
            c.mu_to,
            c.max_dvr,
            made_of.join(", ")
        );
    }

    // one contact set at full order against the basis
    let mu = 0.7;
    let eq = prep.equilibrium(&reg, "lcp", "lagrange", mu)?;
    let op = prep.operator(&eq.eq.active)?;
    let params = EigenParams {
        fmin_hz: band[0],
        fmax_hz: band[1],
        tol: settings.tol,
        ..EigenParams::default()
    };
    let mut full = Method::new(
        &reg,
        "none",
        &Params::new(),
        "arpack",
        "arpack",
        params.clone(),
    )?;
    let (reference, _, _) = full.solve(&op, mu, true)?;
    let mut cms = Method::new(&reg, "cms", &Params::new(), "dense", "arpack", params)?;
    cms.prepare_stage_on(&prep)?;
    let (modes, size, _) = cms.solve(&op, mu, true)?;
    let e = compare(&reference, &modes, band, settings.dvr_margin);
    println!(
        "mu = {mu}: {} of {} pairs active; `cms` ({size} vectors) against full-order `arpack` \
         ({} modes): max df/f {:.1e}, max dDvR {:.1e}, missed {}, missed unstable {}",
        eq.eq.active.iter().filter(|&&a| a).count(),
        eq.eq.active.len(),
        e.reference_modes,
        e.max_rel_freq_err,
        e.max_abs_dvr_err,
        e.missed_modes,
        e.missed_unstable
    );
    Ok(())
}
