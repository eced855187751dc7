//! The sliding equilibria of a prepared scene at several friction coefficients, written
//! as `equilibrium.json` (one object, or a list for several mu) and one CSV of per-pair
//! forces each (`squeal equilibrium`, `validate`). The contact force map is drawn by the
//! caller from the returned equilibria.

use crate::outdir::{self, RunError};
use crate::pipeline::Prepared;
use serde::Serialize;
use squeal_contact::{ContactSet, LoadedEquilibrium};
use squeal_core::{Params, Registry};
use std::io::Write;
use std::path::Path;

/// One equilibrium as written to `equilibrium.json`.
#[derive(Serialize, Clone)]
pub struct EquilibriumReport {
    /// The scene's name in messages.
    pub scene: String,
    /// Units of the numbers.
    pub units: &'static str,
    /// Equilibrium solver plugin.
    pub solver: String,
    /// Contact law plugin.
    pub law: String,
    /// Friction coefficient.
    pub mu: f64,
    /// Sum of the normal forces (N).
    pub total_normal_force_n: f64,
    /// Sum of the friction forces (N).
    pub total_tangential_force_n: f64,
    /// Resultant of the friction forces in the face's x, y (N).
    pub tangential_resultant_n: [f64; 2],
    /// Axial displacement of the disc's clamped face (m).
    pub disc_displacement_m: f64,
    /// Pairs in contact.
    pub active_pairs: usize,
    /// Candidate pairs.
    pub pairs: usize,
    /// Iterations of the solver.
    pub iterations: usize,
    /// Factorizations of the solver.
    pub factorizations: usize,
    /// Relative equilibrium residual.
    pub residual: f64,
    /// Relative complementarity residual.
    pub complementarity_residual: f64,
    /// Centroid of the normal forces on the face (m).
    pub centroid_m: [f64; 2],
    /// Sliding direction of the disc under the face's centre.
    pub sliding_direction: [f64; 2],
    /// Which edge of the face the disc enters by.
    pub leading_edge: String,
    /// Time to build the model (s).
    pub build_time_s: f64,
    /// Time of the contact condensation (s).
    pub condensation_time_s: f64,
    /// Time of this equilibrium (s).
    pub time_s: f64,
    /// The per-pair CSV file, relative to the output directory.
    pub csv: String,
}

/// Which edge of the pin face is the leading one for a disc rotating with sign
/// `rotation`.
pub fn leading_edge(rotation: f64) -> String {
    if rotation > 0.0 {
        "+x: the disc surface moves along -x under the pin and enters it at its +x edge".into()
    } else {
        "-x: the disc surface moves along +x under the pin and enters it at its -x edge".into()
    }
}

/// Writes the per-pair positions, forces and states of `eq` on `set` as CSV.
pub fn write_csv(path: &Path, set: &ContactSet, eq: &LoadedEquilibrium) -> Result<(), RunError> {
    let failed = |source| RunError::Write {
        path: path.to_path_buf(),
        source,
    };
    let mut f = std::io::BufWriter::new(std::fs::File::create(path).map_err(failed)?);
    let sci = |x: f64| crate::num::sci(x, 9);
    let mut text = String::from("x_m,y_m,rn_n,rt_n,active\n");
    for i in 0..set.len() {
        text += &format!(
            "{},{},{},{},{}\n",
            sci(set.xy[i][0]),
            sci(set.xy[i][1]),
            sci(eq.eq.rn[i]),
            sci(eq.eq.mu * eq.eq.rn[i]),
            u8::from(eq.eq.active[i])
        );
    }
    f.write_all(text.as_bytes())
        .and_then(|()| f.flush())
        .map_err(failed)
}

/// The equilibria of `prep` at `mus` through `solver` and `law`, written into `out`
/// (which must exist): `equilibrium.json` and a CSV each. Returns the reports and the
/// equilibria.
pub fn run_into(
    registry: &Registry,
    prep: &Prepared,
    mus: &[f64],
    solver: &str,
    law: &str,
    law_params: &Params,
    out: &Path,
) -> Result<(Vec<EquilibriumReport>, Vec<LoadedEquilibrium>), RunError> {
    let mut eqs = Vec::new();
    for &mu in mus {
        eqs.push(
            prep.equilibrium_with(registry, solver, law, law_params, mu)
                .map_err(outdir::stage(format!(
                    "equilibrium at mu = {mu} with `{solver}`"
                )))?,
        );
    }
    outdir::prepare(out)?;
    let c = prep.set.len() / 2;
    let dir = prep.set.direction[c];
    let mut reports = Vec::new();
    for eq in &eqs {
        let csv = if eqs.len() == 1 {
            "pairs.csv".to_string()
        } else {
            format!("pairs_mu{:.3}.csv", eq.eq.mu)
        };
        write_csv(&out.join(&csv), &prep.set, eq)?;
        reports.push(EquilibriumReport {
            scene: prep.file.clone(),
            units: "SI: forces in N, lengths in m, times in s",
            solver: solver.into(),
            law: law.into(),
            mu: eq.eq.mu,
            total_normal_force_n: eq.total_normal_force_n,
            total_tangential_force_n: eq.total_tangential_force_n,
            tangential_resultant_n: eq.tangential_resultant_n,
            disc_displacement_m: eq.displacement_m,
            active_pairs: eq.eq.active.iter().filter(|&&a| a).count(),
            pairs: prep.set.len(),
            iterations: eq.eq.iterations,
            factorizations: 1,
            residual: eq.eq.equilibrium_residual,
            complementarity_residual: eq.eq.complementarity_residual,
            centroid_m: eq.centroid_m,
            sliding_direction: [dir[0], dir[1]],
            leading_edge: leading_edge(prep.set.rotation),
            build_time_s: prep.build_time_s,
            condensation_time_s: prep.condensation.time_s,
            time_s: eq.eq.time_s,
            csv,
        });
    }
    let path = out.join("equilibrium.json");
    if let [one] = &reports[..] {
        outdir::write_json(&path, one)?;
    } else {
        outdir::write_json(&path, &reports)?;
    }
    Ok((reports, eqs))
}
