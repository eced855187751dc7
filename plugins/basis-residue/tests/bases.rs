//! The three built-in bases against a full-order reference on a coarse build of the
//! default pin-on-disc scene (band 0-3500 Hz), at mu = 0.3 (no flutter on this mesh) and
//! 0.7 (the a,0,3 + pin-pitch flutter pair near 2200 Hz):
//!
//! - `enriched` and `residue` reproduce every reference mode in the band (frequency error
//!   <= 0.1 %, |DvR error| <= 1e-4), find every unstable mode and no false one;
//! - `modes` cut at the band top is reported with its (larger) errors, and its backward
//!   errors on the full operator flag it;
//! - `enriched` is fixed in mu, `residue` is not, and a residue basis refuses another mu.
//!
//! Each run prints a table (size, times, errors, backward errors) with `--nocapture`.

use squeal_analysis::pipeline::Prepared;
use squeal_core::operator::ComplexModes;
use squeal_core::{
    BasisRequest, EigenParams, EigenSolver, FrictionalOperator, Params, ReducedOperator, Registry,
};
use squeal_scene::Scene;
use std::time::Instant;

const FMAX: f64 = 3500.0;

fn registry() -> Registry {
    let mut reg = Registry::new();
    squeal_materials::register(&mut reg);
    squeal_contact_laws::register(&mut reg);
    squeal_equilibrium_lcp::register(&mut reg);
    squeal_eigen_dense::register(&mut reg);
    squeal_eigen_arpack::register(&mut reg);
    squeal_basis_modes::register(&mut reg);
    squeal_basis_enriched::register(&mut reg);
    squeal_basis_residue::register(&mut reg);
    reg
}

/// The default rig, coarsened (4 kHz mesh rule, 6 x 6 pin face elements): it keeps the
/// coupling of a,0,3 with the pin's pitch at high mu.
fn coarse() -> Scene {
    let mut s = Scene::builtin("pin-on-disc").unwrap();
    s.mesh.max_freq_hz = 4000.0;
    s.mesh.pin_face_elements = 6;
    s
}

fn params(fmax: f64) -> EigenParams {
    EigenParams {
        fmin_hz: 0.0,
        fmax_hz: fmax,
        tol: 1e-12,
        ..EigenParams::default()
    }
}

/// Errors of a reduced solve against the reference.
#[derive(Debug, Default)]
struct Errors {
    /// Reference modes without a partner.
    missing: usize,
    /// Reduced modes in the band without a reference partner.
    extra: usize,
    freq: f64,
    dvr: f64,
    worst_backward: f64,
    unstable_ref: usize,
    unstable_found: usize,
    false_unstable: usize,
}

fn unstable(m: &ComplexModes, i: usize) -> bool {
    // what the basis computes (its DvR), not what its error bound certifies: a reduced
    // mode's bound may leave it neutral (`ComplexModes::stability`)
    m.dvr[i] > 1e-8
}

/// Matches every reference mode in the band to its nearest unused reduced mode (the
/// reduced solve covers a slightly wider band so that edge modes are not lost).
fn compare(reference: &ComplexModes, reduced: &ComplexModes) -> Errors {
    let mut e = Errors::default();
    let mut used = vec![false; reduced.len()];
    for i in 0..reference.len() {
        let best = (0..reduced.len())
            .filter(|&j| !used[j])
            .map(|j| (j, (reference.lambda[i] - reduced.lambda[j]).norm()))
            .min_by(|a, b| a.1.total_cmp(&b.1));
        let Some((j, _)) = best else {
            e.missing += 1;
            continue;
        };
        let df = (reduced.freq_hz[j] - reference.freq_hz[i]).abs() / reference.freq_hz[i];
        if df > 0.01 {
            e.missing += 1;
            continue;
        }
        used[j] = true;
        e.freq = e.freq.max(df);
        e.dvr = e.dvr.max((reduced.dvr[j] - reference.dvr[i]).abs());
        e.worst_backward = e.worst_backward.max(reduced.backward_error[j]);
        if unstable(reference, i) {
            e.unstable_ref += 1;
            if unstable(reduced, j) {
                e.unstable_found += 1;
            }
        } else if unstable(reduced, j) {
            e.false_unstable += 1;
        }
    }
    for j in 0..reduced.len() {
        if !used[j] && reduced.freq_hz[j] <= FMAX {
            e.extra += 1;
            if unstable(reduced, j) {
                e.false_unstable += 1;
            }
        }
    }
    e
}

struct Run {
    name: String,
    size: usize,
    basis_s: f64,
    per_mu_s: f64,
    errors: Errors,
    iterations: usize,
}

fn run_basis(
    reg: &Registry,
    name: &str,
    opts: &[(&str, f64)],
    op: &FrictionalOperator,
    mu: f64,
    modal: &dyn EigenSolver,
    reference: &ComplexModes,
) -> Run {
    let mut p = Params::new();
    for (k, v) in opts {
        p = p.with_num(k, *v);
    }
    let basis = reg.bases.create(name, &p).unwrap();
    let dense = reg.eigen.create("dense", &Params::new()).unwrap();
    let ep = params(FMAX);
    let b = squeal_core::build_basis(
        basis.as_ref(),
        &BasisRequest {
            op,
            mu,
            band_hz: (0.0, FMAX),
            modal,
            reduced: dense.as_ref(),
            params: &ep,
            stage: None,
            seed: None,
        },
    )
    .unwrap();
    assert!(
        squeal_core::reduction::m_orthonormality_error(op.mc.as_ref(), b.v.as_ref()) < 1e-8,
        "{name}: basis not M-orthonormal"
    );
    let iterations = b.iterations;
    let red = ReducedOperator::new(op, b).unwrap();
    let solved = red
        .solve(op, mu, dense.as_ref(), &params(FMAX * 1.01))
        .unwrap();
    let errors = compare(reference, &solved.modes);
    Run {
        name: format!("{name}{opts:?}"),
        size: solved.basis_size,
        basis_s: solved.basis_time_s,
        per_mu_s: solved.projection_time_s + solved.solve_time_s + solved.expansion_time_s,
        errors,
        iterations,
    }
}

#[test]
fn bases_against_the_full_reference_on_a_coarse_scene() {
    let reg = registry();
    let prep = Prepared::new(&reg, coarse(), "coarse").unwrap();
    let arpack = reg.eigen.create("arpack", &Params::new()).unwrap();
    let mut unstable_seen = 0;
    for mu in [0.3, 0.7] {
        let eq = prep.equilibrium(&reg, "lcp", "lagrange", mu).unwrap();
        let op = prep.operator(&eq.eq.active).unwrap();
        let t = Instant::now();
        let reference = arpack.solve_frictional(&op, mu, &params(FMAX)).unwrap();
        let ref_s = t.elapsed().as_secs_f64();
        let n_unstable = (0..reference.len())
            .filter(|&i| unstable(&reference, i))
            .count();
        unstable_seen += n_unstable;
        println!(
            "mu = {mu}: n_c = {}, {} active pairs, reference `arpack`: {} modes in 0-{FMAX} Hz, \
             {n_unstable} unstable, {ref_s:.2} s",
            op.dim(),
            eq.eq.active.iter().filter(|&&a| a).count(),
            reference.len()
        );
        assert!(reference.len() >= 10);
        println!(
            "  {:<34} {:>5} {:>8} {:>8} {:>9} {:>9} {:>9} {:>4} {:>8} {:>5} {:>4}",
            "basis",
            "size",
            "build s",
            "per-mu s",
            "max df/f",
            "max dDvR",
            "max eta",
            "miss",
            "unst r/f",
            "false",
            "it"
        );
        let runs: Vec<Run> = [
            ("modes", vec![("cutoff_factor", 1.0)]),
            ("modes", vec![]),
            ("enriched", vec![]),
            ("enriched", vec![("svd_tol", 1e-3)]),
            ("enriched", vec![("cutoff_factor", 3.0)]),
            ("residue", vec![]),
        ]
        .iter()
        .map(|(name, opts)| run_basis(&reg, name, opts, &op, mu, arpack.as_ref(), &reference))
        .collect();
        for r in &runs {
            let e = &r.errors;
            println!(
                "  {:<34} {:>5} {:>8.3} {:>8.3} {:>9.2e} {:>9.2e} {:>9.2e} {:>4} {:>4}/{:<3} {:>5} {:>4}",
                r.name, r.size, r.basis_s, r.per_mu_s, e.freq, e.dvr, e.worst_backward,
                e.missing + e.extra, e.unstable_ref, e.unstable_found, e.false_unstable,
                r.iterations
            );
        }
        // the accuracy contract: residue (defaults) and enriched with modes up to 3x the
        // band top
        for r in [&runs[4], &runs[5]] {
            let e = &r.errors;
            assert_eq!((e.missing, e.extra), (0, 0), "mu {mu} {}: {e:?}", r.name);
            assert!(e.freq <= 1e-3, "mu {mu} {}: {e:?}", r.name);
            assert!(e.dvr <= 1e-4, "mu {mu} {}: {e:?}", r.name);
            assert_eq!(e.unstable_found, n_unstable, "mu {mu} {}: {e:?}", r.name);
            assert_eq!(e.false_unstable, 0, "mu {mu} {}: {e:?}", r.name);
        }
        // every enriched variant finds the unstable modes and no false one here
        for r in &runs[2..5] {
            let e = &r.errors;
            assert_eq!(
                (e.missing, e.extra, e.false_unstable),
                (0, 0, 0),
                "mu {mu} {}",
                r.name
            );
            assert_eq!(e.unstable_found, n_unstable, "mu {mu} {}: {e:?}", r.name);
        }
        // the residue method converged (its own criterion) and beats the enriched basis
        assert!(runs[5].iterations >= 1 && runs[5].iterations < 10);
        assert!(runs[5].errors.freq < runs[2].errors.freq);
        // modes cut at the band top: its backward errors on the full operator flag it
        // (measured 2.6e-7 and 2.9e-6 vs 3.9e-9 and 4.9e-8 for enriched)
        let (cut, enr) = (&runs[0].errors, &runs[2].errors);
        assert!(
            cut.worst_backward > 5.0 * enr.worst_backward,
            "mu {mu}: modes {cut:?} vs enriched {enr:?}"
        );
        if n_unstable > 0 {
            // and where there is flutter it gets the picture wrong (measured at mu = 0.7:
            // two reference modes without a partner within 1 %, df/f 9.4e-3)
            assert!(
                cut.missing + cut.extra + cut.false_unstable > 0
                    || cut.unstable_found < n_unstable
                    || cut.dvr > 1e-4,
                "mu {mu}: modes {cut:?}"
            );
        }
    }
    assert!(
        unstable_seen > 0,
        "no unstable mode at any mu: the test proves nothing"
    );
}

#[test]
fn residue_depends_on_mu_and_refuses_another_mu() {
    let reg = registry();
    let names = reg.bases.names();
    for n in ["enriched", "modes", "residue"] {
        assert!(names.contains(&n.to_string()), "{names:?}");
    }
    let fixed = |n: &str| !reg.bases.create(n, &Params::new()).unwrap().depends_on_mu();
    assert!(fixed("modes") && fixed("enriched") && !fixed("residue"));
    assert!(reg
        .bases
        .create("residue", &Params::new().with_num("tolerance", 1e-6))
        .is_err());
    assert!(reg
        .bases
        .create("enriched", &Params::new().with_num("svd_tol", 2.0))
        .is_err());
    let prep = Prepared::new(&reg, coarse(), "coarse").unwrap();
    let eq = prep.equilibrium(&reg, "lcp", "lagrange", 0.7).unwrap();
    let op = prep.operator(&eq.eq.active).unwrap();
    // the stored friction load directions U span the range of F_K (= U V_K^T)
    let u = squeal_core::reduction::friction_load_directions(&op).unwrap();
    assert_eq!(u.ncols(), eq.eq.active.iter().filter(|&&a| a).count());
    let mut bare = op.clone();
    bare.friction_loads = None;
    let from_fk = squeal_core::reduction::friction_load_directions(&bare).unwrap();
    let mc = op.mc.as_ref();
    let (q, _) = squeal_core::reduction::m_orthonormalize(mc, u.as_ref(), 1e-10).unwrap();
    let (all, dropped) =
        squeal_core::reduction::m_orthonormal_extend(mc, q.as_ref(), from_fk.as_ref(), 1e-8)
            .unwrap();
    assert_eq!((all.ncols(), dropped), (u.ncols(), from_fk.ncols()));
    let arpack = reg.eigen.create("arpack", &Params::new()).unwrap();
    let dense = reg.eigen.create("dense", &Params::new()).unwrap();
    let ep = params(FMAX);
    let req = BasisRequest {
        op: &op,
        mu: 0.7,
        band_hz: (0.0, FMAX),
        modal: arpack.as_ref(),
        reduced: dense.as_ref(),
        params: &ep,
        stage: None,
        seed: None,
    };
    // a residue basis with one iteration allowed and a tight tolerance reports that it
    // stopped on the cap
    let residue = reg
        .bases
        .create(
            "residue",
            &Params::new()
                .with_num("max_iterations", 1.0)
                .with_num("tol", 1e-12),
        )
        .unwrap();
    // the driver records the mu a mu-dependent basis belongs to
    let capped = squeal_core::build_basis(residue.as_ref(), &req).unwrap();
    assert_eq!(capped.mu, Some(0.7));
    assert_eq!(capped.iterations, 1);
    assert!(capped.residual.unwrap() > 1e-12);
    assert!(
        capped.notes.iter().any(|n| n.contains("NOT converged")),
        "{:?}",
        capped.notes
    );
    let red = ReducedOperator::new(&op, capped).unwrap();
    assert!(red.solve(&op, 0.7, dense.as_ref(), &ep).is_ok());
    assert!(red.solve(&op, 0.3, dense.as_ref(), &ep).is_err());
}

/// A residue basis started from the previous sweep point's target modes (the seed it
/// leaves, carried on the free model's DOFs to the next contact set) meets the same
/// energy tolerance in fewer enrichments than one built alone, and gives the same modes.
#[test]
fn residue_seeded_by_the_previous_point_needs_fewer_enrichments() {
    let reg = registry();
    let prep = Prepared::new(&reg, coarse(), "coarse").unwrap();
    let arpack = reg.eigen.create("arpack", &Params::new()).unwrap();
    let dense = reg.eigen.create("dense", &Params::new()).unwrap();
    let residue = reg.bases.create("residue", &Params::new()).unwrap();
    let ep = params(FMAX);
    let build = |op: &FrictionalOperator, mu: f64, seed: Option<&squeal_core::Seed>| {
        squeal_core::build_basis(
            residue.as_ref(),
            &BasisRequest {
                op,
                mu,
                band_hz: (0.0, FMAX),
                modal: arpack.as_ref(),
                reduced: dense.as_ref(),
                params: &ep,
                stage: None,
                seed,
            },
        )
        .unwrap()
    };
    let (mu0, mu1) = (0.6, 0.7);
    let eq0 = prep.equilibrium(&reg, "lcp", "lagrange", mu0).unwrap();
    let op0 = prep.operator(&eq0.eq.active).unwrap();
    let first = build(&op0, mu0, None);
    let seed = first.seed.clone();
    let free_dofs = op0.t.as_ref().unwrap().len();
    let directions = seed
        .directions
        .as_ref()
        .expect("a converged residue basis leaves its target modes");
    assert_eq!(directions.nrows(), free_dofs);
    let modes = seed
        .real_modes
        .as_ref()
        .expect("a residue basis leaves its real modes");
    assert_eq!(modes.nrows(), free_dofs);
    let eq1 = prep.equilibrium(&reg, "lcp", "lagrange", mu1).unwrap();
    let op1 = prep.operator(&eq1.eq.active).unwrap();
    println!(
        "contact sets: {} and {} active pairs, {} constrained DOFs at mu = {mu1}",
        eq0.eq.active.iter().filter(|&&a| a).count(),
        eq1.eq.active.iter().filter(|&&a| a).count(),
        op1.dim()
    );
    let alone = build(&op1, mu1, None);
    let seeded = build(&op1, mu1, Some(&seed));
    println!(
        "alone: {} columns, {} enrichments, residual {:.2e}; seeded: {} columns, {} \
         enrichments, residual {:.2e}",
        alone.len(),
        alone.iterations,
        alone.residual.unwrap(),
        seeded.len(),
        seeded.iterations,
        seeded.residual.unwrap()
    );
    assert!(
        seeded.notes[0].contains("previous point"),
        "{:?}",
        seeded.notes
    );
    for b in [&alone, &seeded] {
        assert!(b.residual.unwrap() <= 1e-6, "{:?}", b.notes);
    }
    assert!(seeded.iterations < alone.iterations);
    let reference = arpack.solve_frictional(&op1, mu1, &ep).unwrap();
    for b in [alone, seeded] {
        let red = ReducedOperator::new(&op1, b).unwrap();
        let solved = red
            .solve(&op1, mu1, dense.as_ref(), &params(FMAX * 1.01))
            .unwrap();
        let e = compare(&reference, &solved.modes);
        assert_eq!((e.missing, e.extra, e.false_unstable), (0, 0, 0), "{e:?}");
        assert_eq!(e.unstable_found, e.unstable_ref);
        assert!(e.freq < 1e-6 && e.dvr < 1e-6, "{e:?}");
    }
}
