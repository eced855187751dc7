//! Model stages of the bases (the free-interface synthesis of `cms`): which a run needs
//! and how each is built on the free model.

use super::*;

/// The model-stage keys ([`ReductionBasis::stage_key`]) of the bases named in `bases`
/// (`none` for full order, default parameters) at the band top `band_top_hz`, without
/// repeats: what a run that goes on with those bases still needs of the free model.
pub fn stage_keys<'a>(
    registry: &Registry,
    bases: impl IntoIterator<Item = &'a str>,
    band_top_hz: f64,
) -> Result<Vec<String>> {
    let mut keys = Vec::new();
    for b in bases.into_iter().filter(|b| *b != "none") {
        let plugin = registry
            .bases
            .create(b, &Params::new())
            .map_err(core(&format!("basis `{b}`")))?;
        if let Some(k) = plugin.stage_key(band_top_hz) {
            if !keys.contains(&k) {
                keys.push(k);
            }
        }
    }
    Ok(keys)
}

/// The model stage of `basis` ([`ReductionBasis::prepare`]) on `model` and the candidate
/// pairs of `set`, with `k_factor` (a Cholesky factor of the model's `K`, when the caller
/// has one) and `normal_modes` (the free model's modes up to a frequency); `modal` and
/// `params` as the stage's solver and tolerances, `params.fmax_hz` the band top;
/// `contact_sets` the number of contact sets the caller will build on it, when known
/// ([`FreeModel::contact_sets`]). `None` when the basis has no model stage.
#[allow(clippy::too_many_arguments)]
pub fn prepare_stage(
    basis: &dyn ReductionBasis,
    model: &Model,
    set: &ContactSet,
    k_factor: Option<Arc<Cholesky>>,
    normal_modes: &NormalModes<'_>,
    modal: &dyn EigenSolver,
    params: &EigenParams,
    contact_sets: Option<usize>,
) -> Result<Option<ModelStage>> {
    if basis.stage_key(params.fmax_hz).is_none() {
        return Ok(None);
    }
    let pairs = pair_dofs(set);
    let free = FreeModel {
        k: model.k.as_ref(),
        m: model.m.as_ref(),
        pairs: &pairs,
        k_factor,
        normal_modes,
        modal,
        band_hz: (params.fmin_hz, params.fmax_hz),
        params,
        contact_sets,
    };
    basis
        .prepare(&free)
        .map_err(core(&format!("model stage of basis `{}`", basis.name())))
}

/// [`prepare_stage`] without a factor of `K` or kept modes: the normal modes of the free
/// model are solved by `modal` at the tolerances of `params`.
pub fn prepare_stage_alone(
    basis: &dyn ReductionBasis,
    model: &Model,
    set: &ContactSet,
    modal: &dyn EigenSolver,
    params: &EigenParams,
    contact_sets: Option<usize>,
) -> Result<Option<ModelStage>> {
    let modes = |fmax_hz: f64| {
        modal.solve_symmetric(
            &SymmetricProblem {
                k: model.k.as_ref(),
                m: model.m.as_ref(),
            },
            &EigenParams {
                fmin_hz: 0.0,
                fmax_hz,
                nev_hint: None,
                ..params.clone()
            },
        )
    };
    prepare_stage(basis, model, set, None, &modes, modal, params, contact_sets)
}

/// The DOFs of the candidate pairs of `set`, in the synthesis's terms.
fn pair_dofs(set: &ContactSet) -> Vec<PairDofs> {
    (0..set.len())
        .map(|i| PairDofs {
            pin: set.pin_dofs[i],
            disc: set.disc_dofs[i],
            direction: set.direction[i],
        })
        .collect()
}
