//! An operator from another code, through the library: a parametric operator directory
//! (component matrices from Matrix Market and MATLAB `.mat` files, and an `operator.toml`
//! that sums them with coefficients in the disc speed `W`: damping, a `1/W` damping, a
//! gyroscopic `W DG`, a `W^2` stiffening and a circulatory friction part), evaluated at a
//! few `W`, solved at full order, then handed to every registered basis and eigen solver by
//! the library's benchmark. The directory is the 84-DOF test operator that
//! `benches/parametric_operator.py` writes with numpy/scipy alone (`docs/operators.md`).
//!
//! ```text
//! cargo run --release --example imported_operator
//! ```

use squeal::analysis::bench::{bench_case, BenchOptions};
use squeal::core::{EigenParams, Params};
use squeal_io::ParametricOperator;

/// Runs the example (public so that `tests/examples.rs` runs it too).
pub fn main() -> Result<(), Box<dyn std::error::Error>> {
    let reg = squeal::registry();
    let dir = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/crates/squeal-io/tests/data/parametric-lattice"
    );
    let family = ParametricOperator::read(dir)?;
    let name = family.parameter().unwrap_or("-");
    println!(
        "parametric operator: {} DOFs, parameter {name} in {:?}",
        family.dim(),
        family.range()
    );

    // full order at a few speeds: which modes does friction destabilize?
    let (mu, band) = (0.6, [0.0, 1500.0]);
    let arpack = reg.eigen.create("arpack", &Params::new())?;
    let params = EigenParams {
        fmin_hz: band[0],
        fmax_hz: band[1],
        tol: 1e-10,
        ..EigenParams::default()
    };
    for w in [1.0, 5.0, 20.0, 50.0] {
        let op = family.at(w)?;
        let modes = arpack.solve_frictional(&op, mu, &params)?;
        let unstable: Vec<String> = (0..modes.len())
            .filter(|&i| modes.is_unstable(i, 1e-6))
            .map(|i| format!("{:.1} Hz (DvR {:.1e})", modes.freq_hz[i], modes.dvr[i]))
            .collect();
        println!(
            "{name} = {w:>4}, mu = {mu}: {} modes below {} Hz, unstable: {}",
            modes.len(),
            band[1],
            if unstable.is_empty() {
                "none".to_string()
            } else {
                unstable.join(", ")
            }
        );
    }

    // every basis and eigen solver on the operator at W = 5 against full-order `arpack`;
    // the bases that need a model (`cms`) are recorded as failed: a file brings none
    let op = family.at(5.0)?;
    let mut opts = BenchOptions::all(&reg);
    opts.band_hz = band;
    opts.vary = Vec::new();
    let (reference, runs) = bench_case(&reg, "W=5", &op, &Vec::new(), mu, &opts, None, |_| {})?;
    println!(
        "{name} = 5: reference `{}` {} modes, {} unstable; every method against it:",
        reference.eigen,
        reference.modes,
        reference.unstable.len()
    );
    for r in runs.iter().filter(|r| !r.reference) {
        let outcome = if r.status == "ok" {
            format!(
                "size {}, max df/f {:.1e}, max dDvR {:.1e}, {} missed",
                r.basis_size,
                r.errors.max_rel_freq_err,
                r.errors.max_abs_dvr_err,
                r.errors.missed_modes
            )
        } else {
            r.status.clone()
        };
        println!("  {}/{}: {outcome}", r.basis, r.eigen);
    }
    Ok(())
}
