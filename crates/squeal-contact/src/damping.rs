//! The damping matrix of a scene's stability analysis (`[damping]`, `docs/scenes.md`).
//!
//! `C = alpha M + beta K + C_t`: Rayleigh damping of the structure plus viscous
//! tangential dashpots between the pin and disc nodes of every closed pair,
//! `c_i = c_A A_i` (`c_A` in N s/m^3, `A_i` the pair's tributary area), acting on the
//! relative in-plane velocity (x and y) of the two nodes. A normal dashpot would do
//! nothing here: the operator ties the pair's normal motion (`P~n u = 0`).
//!
//! `C` is symmetric and lives on the model's free DOFs; [`crate::build_operator`] splits
//! it into `C_c` and its friction part `F_C` like `M` and `K` (the dashpots have no
//! pin-normal row, so only the Rayleigh part has a friction part: `alpha F_M + beta F_K`).

use crate::{ContactError, ContactSet, Result};
use squeal_core::faer::sparse::Triplet;
use squeal_core::linalg::add_scaled;
use squeal_core::SparseMat;
use squeal_scene::{Damping, Model};

/// The damping matrix of `damping` for the closed pairs `active` of `set` (N s/m, free
/// DOFs), or `None` when the scene is undamped.
pub fn damping_matrix(
    model: &Model,
    set: &ContactSet,
    active: &[bool],
    damping: &Damping,
) -> Result<Option<SparseMat>> {
    if damping.is_zero() {
        return Ok(None);
    }
    let setup = |message: String| ContactError::Setup {
        field: "damping".into(),
        message,
    };
    if active.len() != set.len() {
        return Err(setup(format!(
            "active-set mask has {} entries, the contact set {} pairs",
            active.len(),
            set.len()
        )));
    }
    let (alpha, beta) = damping.rayleigh();
    let mut c = add_scaled(model.m.as_ref(), alpha, model.k.as_ref(), beta)?;
    let ct = damping.contact_tangential();
    if ct > 0.0 {
        let grid = model
            .contact
            .as_ref()
            .ok_or_else(|| setup("contact damping needs the model's contact grid".into()))?;
        let areas = grid.tributary_areas();
        let n = model.k.nrows();
        let mut trip = Vec::new();
        for i in (0..set.len()).filter(|&i| active[i]) {
            let ci = ct * areas[set.grid_index[i]];
            for a in 0..2 {
                let (p, d) = (set.pin_dofs[i][a], set.disc_dofs[i][a]);
                trip.extend([
                    Triplet::new(p, p, ci),
                    Triplet::new(d, d, ci),
                    Triplet::new(p, d, -ci),
                    Triplet::new(d, p, -ci),
                ]);
            }
        }
        let dash = SparseMat::try_new_from_triplets(n, n, &trip)
            .map_err(|e| setup(format!("contact dashpots: {e:?}")))?;
        c = add_scaled(c.as_ref(), 1.0, dash.as_ref(), 1.0)?;
    }
    Ok(Some(c))
}
