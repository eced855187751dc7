//! Long studies on the coarse scene (3 x 3 contact pairs, about 1 600 DOFs) with the
//! cheapest method (real modes + dense reduced solve): an interrupted and resumed run, and
//! shards merged, give byte for byte the results of one uninterrupted run; bad inputs are
//! errors naming their option.

use squeal::analysis::study::{
    self, merge, Axis, MacroSpec, MesoSpec, Progress, RunOptions, Shard, SolveSpec, StudyDef,
    StudyDir, StudySpec,
};
use squeal::scene::{build, BodyKind, Model, Scene};
use std::path::{Path, PathBuf};

struct Fixture {
    reg: squeal::Registry,
    scene: Scene,
    model: Model,
}

fn fixture() -> Fixture {
    let reg = squeal::registry();
    let scene = Scene::builtin("pin-on-disc-coarse").unwrap();
    let model = build(&scene, BodyKind::All, &reg, "coarse").unwrap();
    Fixture { reg, scene, model }
}

fn solve() -> SolveSpec {
    SolveSpec {
        basis: "cms".into(),
        basis_params: Vec::new(),
        eigen: "dense".into(),
        modal: "arpack".into(),
        band_hz: [0.0, 5000.0],
        tol: 1e-10,
        dvr_margin: 0.0,
        classes_hz: vec![2100.0, 3500.0],
        class_width: 0.2,
    }
}

/// 12 zones: a, b in {10, 20} mm, x0 in {0, 10} mm (4 combinations leave the face), two mu.
fn macro_def(f: &Fixture) -> StudyDef {
    let spec = StudySpec::Macro(MacroSpec {
        mu: vec![0.36, 0.43],
        x0: Axis::Values(vec![0.0, 0.01]),
        y0: Axis::Values(vec![0.0]),
        a_m: vec![0.01, 0.02],
        b_m: vec![0.01, 0.02],
    });
    StudyDef::new("coarse", &f.scene, &f.model, spec, solve()).unwrap()
}

/// 2 patch sizes x 3 layouts on the whole face.
fn meso_def(f: &Fixture) -> StudyDef {
    let spec = StudySpec::Meso(MesoSpec {
        mu: vec![0.36],
        region_m: [0.0, 0.0, 0.02, 0.02],
        patch_m: vec![0.01, 0.02],
        layouts: 3,
        fraction: 0.5,
        seed: 11,
    });
    StudyDef::new("coarse", &f.scene, &f.model, spec, solve()).unwrap()
}

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("squeal-studies-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn run(f: &Fixture, def: &StudyDef, dir: &Path, opts: RunOptions) -> study::RunReport {
    study::run(&f.reg, &f.model, def, &StudyDir::new(dir), &opts, &|_| {}).unwrap()
}

fn bytes(dir: &Path, file: &str) -> Vec<u8> {
    std::fs::read(dir.join(file)).unwrap_or_else(|e| panic!("{}: {e}", dir.join(file).display()))
}

fn assert_same(a: &Path, b: &Path) {
    for f in ["study.json", "results.jsonl", "summary.json"] {
        let (x, y) = (bytes(a, f), bytes(b, f));
        assert!(
            x == y,
            "{f} differs between {} and {}:\n{}\n---\n{}",
            a.display(),
            b.display(),
            String::from_utf8_lossy(&x),
            String::from_utf8_lossy(&y)
        );
    }
}

#[test]
fn an_interrupted_study_resumes_to_the_same_bytes() {
    let f = fixture();
    let def = macro_def(&f);
    let whole = tmp("whole");
    let r = run(&f, &def, &whole, RunOptions::default());
    assert_eq!((r.cases, r.computed, r.remaining), (12, 12, 0));
    assert!(r.summary.complete);
    assert!(
        r.summary.unstable_cases > 0,
        "the coarse rig has unstable zones"
    );
    assert!(r.summary.unstable_cases < 12);
    let records = StudyDir::new(&whole).records().unwrap();
    assert_eq!(records.len(), 12);
    assert!(records
        .iter()
        .all(|r| r.error.is_none() && !r.modes.is_empty()));

    // 1. stopped after 5 cases (a batch slot), the last line then torn by a crash
    let part = tmp("part");
    let seen = std::sync::Mutex::new(Vec::new());
    let r = study::run(
        &f.reg,
        &f.model,
        &def,
        &StudyDir::new(&part),
        &RunOptions {
            max_cases: Some(5),
            ..RunOptions::default()
        },
        &|p| {
            if let Progress::Case { done, .. } = p {
                seen.lock().unwrap().push(done);
            }
        },
    )
    .unwrap();
    assert_eq!((r.computed, r.remaining), (5, 7));
    assert_eq!(*seen.lock().unwrap(), [1, 2, 3, 4, 5]);
    // the run's profile counts the cases computed now, each stage once per case
    let eigen = r.profile.stages.iter().find(|s| s.stage == "eigen solve");
    assert_eq!(eigen.map(|s| s.count), Some(5), "{:?}", r.profile);
    assert!(r.profile.total_s() > 0.0);
    assert!(!r.summary.complete);
    assert_ne!(
        bytes(&part, "results.jsonl"),
        bytes(&whole, "results.jsonl")
    );
    let results = part.join("results.jsonl");
    let text = std::fs::read_to_string(&results).unwrap();
    let last = text.lines().last().unwrap();
    let torn = &text[..text.len() - last.len() / 2 - 1];
    std::fs::write(&results, torn).unwrap();
    // a plain rerun must not overwrite results
    let e = study::run(
        &f.reg,
        &f.model,
        &def,
        &StudyDir::new(&part),
        &RunOptions::default(),
        &|_| {},
    )
    .unwrap_err()
    .to_string();
    assert!(e.starts_with("dir:") && e.contains("options.resume"), "{e}");
    let r = run(
        &f,
        &def,
        &part,
        RunOptions {
            resume: true,
            ..RunOptions::default()
        },
    );
    assert_eq!((r.resumed, r.computed, r.remaining), (4, 8, 0));
    assert_same(&whole, &part);

    // 2. killed mid-way: records in completion order, no summary, a torn last line
    let killed = tmp("killed");
    std::fs::create_dir_all(&killed).unwrap();
    std::fs::copy(whole.join("study.json"), killed.join("study.json")).unwrap();
    let whole_text = String::from_utf8(bytes(&whole, "results.jsonl")).unwrap();
    let lines: Vec<&str> = whole_text.lines().collect();
    let mut text: String = [lines[7], lines[2], lines[9]]
        .map(|l| format!("{l}\n"))
        .concat();
    text.push_str(&lines[0][..40]);
    std::fs::write(killed.join("results.jsonl"), text).unwrap();
    let r = run(
        &f,
        &def,
        &killed,
        RunOptions {
            resume: true,
            jobs: 2,
            ..RunOptions::default()
        },
    );
    assert_eq!((r.resumed, r.computed), (3, 9));
    assert_same(&whole, &killed);
    for d in [whole, part, killed] {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn shards_merged_equal_the_whole_run() {
    let f = fixture();
    for (name, def) in [("macro", macro_def(&f)), ("meso", meso_def(&f))] {
        let whole = tmp(&format!("{name}-whole"));
        let r = run(&f, &def, &whole, RunOptions::default());
        assert!(
            r.summary.complete && r.cases >= 6,
            "{name}: {} cases",
            r.cases
        );
        let shards: Vec<PathBuf> = (1..=2)
            .map(|k| {
                let d = tmp(&format!("{name}-shard{k}"));
                let r = run(
                    &f,
                    &def,
                    &d,
                    RunOptions {
                        shard: Some(Shard::parse(&format!("{k}/2")).unwrap()),
                        jobs: k,
                        ..RunOptions::default()
                    },
                );
                assert!(
                    !r.summary.complete,
                    "{name}: a shard is not the whole study"
                );
                assert!(r.shard_cases > 0 && r.shard_cases < r.cases);
                d
            })
            .collect();
        // one shard alone is not the whole run
        let alone = tmp(&format!("{name}-alone"));
        let (_, s, _) = merge(&shards[..1], &alone).unwrap();
        assert!(!s.complete);
        assert_ne!(
            bytes(&alone, "results.jsonl"),
            bytes(&whole, "results.jsonl")
        );
        // a merged part resumes into the whole run (one set-up for the remaining cases)
        let r = run(
            &f,
            &def,
            &alone,
            RunOptions {
                resume: true,
                ..RunOptions::default()
            },
        );
        assert!(r.summary.complete, "{name}: the resumed merge is complete");
        assert_same(&whole, &alone);
        let merged = tmp(&format!("{name}-merged"));
        let (_, s, _) = merge(&[shards[1].clone(), shards[0].clone()], &merged).unwrap();
        assert!(s.complete);
        assert_same(&whole, &merged);
        if name == "meso" {
            assert_eq!(s.by_patch.len(), 2);
            assert!(s.by_patch.iter().all(|p| p.done == 3));
        }
        for d in shards.into_iter().chain([whole, alone, merged]) {
            let _ = std::fs::remove_dir_all(d);
        }
    }
}

#[test]
fn bad_inputs_are_errors_naming_the_option() {
    let f = fixture();
    let msg = |d: &StudyDef| d.cases().unwrap_err().to_string();
    // patch below the contact grid spacing (10 mm on the coarse scene)
    let mut d = meso_def(&f);
    if let StudySpec::Meso(s) = &mut d.study {
        s.patch_m = vec![0.004];
    }
    let e = msg(&d);
    assert!(
        e.starts_with("study.patch_m:") && e.contains("grid spacing") && e.contains(">= 10.000 mm"),
        "{e}"
    );
    // patch not fitting in the region
    if let StudySpec::Meso(s) = &mut d.study {
        s.patch_m = vec![0.01];
        s.region_m = [0.0, 0.0, 0.02, 0.008];
    }
    let e = msg(&d);
    assert!(
        e.starts_with("study.patch_m:") && e.contains("<= 0.008 m"),
        "{e}"
    );
    // region outside the face
    if let StudySpec::Meso(s) = &mut d.study {
        s.region_m = [0.005, 0.0, 0.02, 0.02];
    }
    assert!(msg(&d).starts_with("study.region_m:"), "{}", msg(&d));
    // zones outside the pin face
    let mut d = macro_def(&f);
    if let StudySpec::Macro(s) = &mut d.study {
        s.a_m = vec![0.03];
    }
    let e = msg(&d);
    assert!(
        e.starts_with("study.a_m:") && e.contains("(0, 0.02]"),
        "{e}"
    );
    if let StudySpec::Macro(s) = &mut d.study {
        s.a_m = vec![0.01];
        s.x0 = Axis::Values(vec![0.0, 0.015]);
    }
    let e = msg(&d);
    assert!(e.starts_with("study.x0:") && e.contains("[0, 0.01]"), "{e}");
    // bad shard specs
    for bad in ["0/2", "3/2", "2", "1/0", "x/y"] {
        let e = Shard::parse(bad).unwrap_err().to_string();
        assert!(
            e.starts_with("options.shard:") && e.contains("K/N"),
            "{bad}: {e}"
        );
    }
    // a directory of another study is refused on resume and in a merge
    let a = tmp("bad-a");
    let b = tmp("bad-b");
    let small = |f: &Fixture, mu: f64| {
        let mut d = macro_def(f);
        if let StudySpec::Macro(s) = &mut d.study {
            s.mu = vec![mu];
            s.a_m = vec![0.02];
            s.b_m = vec![0.02];
            s.x0 = Axis::Values(vec![0.0]);
        }
        d
    };
    run(&f, &small(&f, 0.36), &a, RunOptions::default());
    run(&f, &small(&f, 0.43), &b, RunOptions::default());
    let e = study::run(
        &f.reg,
        &f.model,
        &small(&f, 0.43),
        &StudyDir::new(&a),
        &RunOptions {
            resume: true,
            ..RunOptions::default()
        },
        &|_| {},
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("another study") && e.contains("study.mu"), "{e}");
    let out = tmp("bad-out");
    let e = merge(&[a.clone(), b.clone()], &out)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("bad-b") && e.contains("another study") && e.contains("study.mu"),
        "{e}"
    );
    let e = merge(&[a.clone(), std::env::temp_dir()], &out)
        .unwrap_err()
        .to_string();
    assert!(e.contains("not a study directory"), "{e}");
    let e = merge(std::slice::from_ref(&a), &a).unwrap_err().to_string();
    assert!(e.starts_with("dir:"), "{e}");
    for d in [a, b, out] {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn a_meso_study_resumed_with_more_layouts_equals_one_run_with_them() {
    let f = fixture();
    let three = meso_def(&f);
    let mut five = three.clone();
    if let StudySpec::Meso(m) = &mut five.study {
        m.layouts = 5;
    }
    let grown = tmp("grown");
    let r = run(&f, &three, &grown, RunOptions::default());
    assert_eq!(r.computed, r.cases);
    let resume = RunOptions {
        resume: true,
        ..RunOptions::default()
    };
    let r = run(&f, &five, &grown, resume.clone());
    assert_eq!(
        r.resumed,
        2 * 3,
        "the three layouts of each patch size are kept"
    );
    assert_eq!(r.computed, 2 * 2);
    let fresh = tmp("fresh5");
    run(&f, &five, &fresh, RunOptions::default());
    assert_same(&fresh, &grown);
    // fewer layouts, or another change, is still another study
    let refused = |def: &StudyDef| {
        study::run(
            &f.reg,
            &f.model,
            def,
            &StudyDir::new(&grown),
            &resume,
            &|_| {},
        )
        .unwrap_err()
        .to_string()
    };
    let e = refused(&three);
    assert!(e.contains("written for another study"), "{e}");
    let mut other = five.clone();
    if let StudySpec::Meso(m) = &mut other.study {
        m.layouts = 7;
        m.seed = 12;
    }
    let e = refused(&other);
    assert!(e.contains("written for another study"), "{e}");
    for d in [grown, fresh] {
        let _ = std::fs::remove_dir_all(d);
    }
}

#[test]
fn a_study_lists_the_timed_steps_of_its_basis() {
    let f = fixture();
    for (basis, steps) in [
        ("cms", vec!["expansion", "orthonormalization", "synthesis"]),
        (
            "enriched",
            vec![
                "real modes",
                "set-up",
                "statics, orthonormalization and projection",
            ],
        ),
        ("residue", vec!["iterations", "real modes", "set-up"]),
    ] {
        steps_of(&f, basis, &steps);
    }
    // a basis that does not time its steps writes none
    let plain = tmp("steps-plain");
    let mut def = meso_def(&f);
    def.solve.basis = "modes".into();
    run(&f, &def, &plain, RunOptions::default());
    let timings = StudyDir::new(&plain).timing_records().unwrap();
    assert!(timings.iter().all(|t| t.basis_steps.is_empty()));
    let written = String::from_utf8(bytes(&plain, "timings.jsonl")).unwrap();
    assert!(!written.contains("basis_steps"));
    let _ = std::fs::remove_dir_all(plain);
}

/// A meso study through `basis`: every case times the basis's `steps` (names in order),
/// within the basis's time, and the run's profile and mean list their sums.
fn steps_of(f: &Fixture, basis: &str, steps: &[&str]) {
    let mut def = meso_def(f);
    def.solve.basis = basis.into();
    let dir = tmp(&format!("steps-{basis}"));
    let r = run(f, &def, &dir, RunOptions::default());
    assert_eq!((r.computed, r.summary.failed), (6, 0), "{basis}");
    let timings = StudyDir::new(&dir).timing_records().unwrap();
    assert_eq!(timings.len(), 6);
    for t in &timings {
        let keys: Vec<&str> = t.basis_steps.keys().map(String::as_str).collect();
        assert_eq!(keys, steps, "{basis}, case {}", t.id);
        let sum: f64 = t.basis_steps.values().sum();
        assert!(t.basis_steps.values().all(|s| s.is_finite() && *s >= 0.0));
        // the steps are parts of the basis's time
        assert!(sum <= t.basis_s * (1.0 + 1e-9), "case {}: {t:?}", t.id);
    }
    for &step in steps {
        let total: f64 = timings.iter().map(|t| t.basis_steps[step]).sum();
        let row = r
            .profile
            .stages
            .iter()
            .find(|s| s.stage == format!("basis: {step}"))
            .unwrap_or_else(|| panic!("{basis}: no profile row for {step}"));
        assert!((row.time_s - total).abs() <= 1e-9 * total.max(1.0));
        assert_eq!(row.count, 6);
        assert!((r.timings.mean.basis_steps[step] - total / 6.0).abs() <= 1e-9 * total.max(1.0));
    }
    let _ = std::fs::remove_dir_all(dir);
}
