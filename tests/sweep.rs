//! mu sweeps: a run killed mid-way and resumed from its checkpoint, and shards over parts
//! of the mu list merged by mu, give exactly the points of one uninterrupted run.

use squeal::analysis::pipeline::{run_mu_sweep, Method, Prepared};
use squeal::analysis::sweep::{Checkpoint, SweepPoint};
use squeal::core::{EigenParams, Params};
use squeal::scene::Scene;

/// The embedded coarse rig (about 1600 DOFs).
fn coarse() -> Scene {
    Scene::builtin("pin-on-disc-coarse").unwrap()
}

/// Everything but the wall times.
fn key(p: &SweepPoint) -> String {
    let mut q = p.clone();
    q.times_s = [0.0; 3];
    serde_json::to_string(&q).unwrap()
}

/// Names the first point and field that differ.
fn same(x: &[SweepPoint], y: &[SweepPoint], what: &str) {
    assert_eq!(x.len(), y.len(), "{what}: point count");
    for (p, q) in x.iter().zip(y) {
        assert_eq!(
            (p.mu, p.active_hash, p.rebuilt, p.basis_size),
            (q.mu, q.active_hash, q.rebuilt, q.basis_size),
            "{what}: at mu {}",
            p.mu
        );
        assert_eq!(p.modes.len(), q.modes.len(), "{what}: modes at mu {}", p.mu);
        for (m, n) in p.modes.iter().zip(&q.modes) {
            assert!(
                m == n,
                "{what}: mu {}: {} Hz vs {} Hz, dvr {:e} vs {:e}",
                p.mu,
                m.freq_hz,
                n.freq_hz,
                m.dvr,
                n.dvr
            );
        }
    }
}

#[test]
fn resumed_and_sharded_sweeps_equal_the_whole() {
    let reg = squeal::registry();
    let prep = Prepared::new(&reg, coarse(), "coarse").unwrap();
    let free = prep.free_interface_modes(&reg, "arpack", 3750.0).unwrap();
    let params = EigenParams {
        fmax_hz: 2500.0,
        tol: 1e-10,
        ..EigenParams::default()
    };
    let mus: Vec<f64> = (0..9).map(|k| 0.1 * k as f64).collect();
    let dir = std::env::temp_dir().join(format!("squeal-sweep-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let run = |mus: &[f64], ck: Option<&Checkpoint>| -> Vec<SweepPoint> {
        let mut m = Method::new(
            &reg,
            "enriched",
            &Params::new(),
            "dense",
            "arpack",
            params.clone(),
        )
        .unwrap();
        run_mu_sweep(
            &prep,
            &reg,
            mus,
            "lcp",
            "lagrange",
            &free,
            ck,
            |op, mu, ch| m.solve(op, mu, ch),
            |_| {},
        )
        .unwrap()
    };
    let whole = run(&mus, None);
    assert_eq!(whole.len(), mus.len());
    assert!(
        whole.iter().filter(|p| p.rebuilt).count() >= 2,
        "the contact set changes along the sweep"
    );
    // killed after 4 points: the checkpoint holds them (plus a torn line), the rerun resumes
    let ck = Checkpoint::new(dir.join("resume.jsonl"));
    let _ = run(&mus[..4], Some(&ck));
    use std::io::Write;
    let mut f = std::fs::OpenOptions::new()
        .append(true)
        .open(dir.join("resume.jsonl"))
        .unwrap();
    write!(f, "{{\"mu\":0.4,\"act").unwrap();
    drop(f);
    let mut computed = 0;
    let mut m = Method::new(
        &reg,
        "enriched",
        &Params::new(),
        "dense",
        "arpack",
        params.clone(),
    )
    .unwrap();
    let resumed = run_mu_sweep(
        &prep,
        &reg,
        &mus,
        "lcp",
        "lagrange",
        &free,
        Some(&ck),
        |op, mu, ch| {
            computed += 1;
            m.solve(op, mu, ch)
        },
        |_| {},
    )
    .unwrap();
    assert_eq!(
        computed,
        mus.len() - 4,
        "finished points are not recomputed"
    );
    let (a, b): (Vec<String>, Vec<String>) = (
        whole.iter().map(key).collect(),
        resumed.iter().map(key).collect(),
    );
    same(&whole, &resumed, "resumed run");
    // shards: even and odd mu in separate runs, merged by mu
    let (even, odd): (Vec<f64>, Vec<f64>) =
        mus.iter()
            .enumerate()
            .fold((vec![], vec![]), |(mut e, mut o), (i, &m)| {
                if i % 2 == 0 {
                    e.push(m)
                } else {
                    o.push(m)
                }
                (e, o)
            });
    let mut merged: Vec<SweepPoint> = run(&even, None)
        .into_iter()
        .chain(run(&odd, None))
        .collect();
    merged.sort_by(|x, y| x.mu.total_cmp(&y.mu));
    // the `rebuilt` flag is relative to the previous point of the run: recompute it on
    // the merged list from the contact-set fingerprints
    for i in 0..merged.len() {
        merged[i].rebuilt = i == 0 || merged[i].active_hash != merged[i - 1].active_hash;
    }
    same(&whole, &merged, "merged shards");
    let c: Vec<String> = merged.iter().map(key).collect();
    assert_eq!(a, c, "merged shards differ from the whole");
    assert_eq!(a, b);
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_sweep_reports_where_its_time_went() {
    use squeal::analysis::mu_sweep::{run_sweep, MuSweepSettings};
    let reg = squeal::registry();
    let prep = Prepared::new(&reg, coarse(), "coarse").unwrap();
    let mus = vec![0.0, 0.3, 0.6];
    let s = run_sweep(
        &reg,
        &prep,
        &MuSweepSettings::new(mus.clone(), "cms", [0.0, 2500.0]),
        None,
        |_| {},
    )
    .unwrap();
    let count = |name: &str| {
        s.profile
            .stages
            .iter()
            .find(|st| st.stage == name)
            .map(|st| st.count)
    };
    assert_eq!(count("model stage of `cms`"), Some(1), "{:?}", s.profile);
    assert_eq!(count("free modes of tracking"), Some(1));
    assert_eq!(count("equilibrium"), Some(mus.len()));
    // `cms` depends on mu: a basis at every point
    assert_eq!(count("basis"), Some(mus.len()));
    assert_eq!(count("eigen solve"), Some(mus.len()));
    let rebuilt = s.points.iter().filter(|p| p.rebuilt).count();
    assert_eq!(count("operator assembly"), Some(rebuilt));
    assert!(s.profile.total_s() <= s.time_s + 1e-9);
}
