//! The validation through the library (`squeal_analysis::validate`), on the embedded
//! coarse rig: every stage runs in order, each sweep reaches the caller's hooks, the
//! report's paper table and reference rows come from the sweeps it ran, a resumed run
//! gives the same report, and settings that cannot run are refused by field.

use squeal::analysis::mu_sweep::{MuSweep, SweepEvent, SweepSummary};
use squeal::analysis::outdir::RunError;
use squeal::analysis::pipeline::Prepared;
use squeal::analysis::validate::{check, run, ValidateHooks, ValidateSettings};
use squeal::contact::LoadedEquilibrium;
use squeal::scene::Scene;
use std::path::{Path, PathBuf};

/// Records what the validation tells its caller.
#[derive(Default)]
struct Record {
    stages: Vec<usize>,
    equilibria: usize,
    points: usize,
    sweeps: Vec<(PathBuf, usize)>,
}

impl ValidateHooks for Record {
    fn stage(&mut self, k: usize, _n: usize, _what: &str) {
        self.stages.push(k);
    }
    fn equilibria(
        &mut self,
        _: &Path,
        _: &Prepared,
        eqs: &[LoadedEquilibrium],
    ) -> Result<(), RunError> {
        self.equilibria = eqs.len();
        Ok(())
    }
    fn sweep_event(&mut self, _: &Path, _: &Prepared, event: SweepEvent<'_>) {
        if let SweepEvent::Point(_) = event {
            self.points += 1;
        }
    }
    fn sweep_done(
        &mut self,
        out: &Path,
        s: &SweepSummary,
        sweep: &MuSweep,
    ) -> Result<(), RunError> {
        assert_eq!(s.points, sweep.points.len());
        self.sweeps.push((out.to_path_buf(), s.points));
        Ok(())
    }
}

fn settings() -> ValidateSettings {
    ValidateSettings {
        sweeps: vec![("cms".into(), 0.1), ("residue".into(), 0.2)],
        band_hz: None,
        reference_mu: vec![0.4],
        eigen: "arpack".into(),
        resume: false,
    }
}

#[test]
fn every_stage_runs_and_the_report_holds_what_the_sweeps_found() {
    let registry = squeal::registry();
    let scene = Scene::builtin("pin-on-disc-coarse").unwrap();
    let out = std::env::temp_dir().join(format!("squeal-validate-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&out);
    let s = settings();
    check(&registry, &s).unwrap();
    let mut rec = Record::default();
    let v = run(&registry, &scene, "coarse", &s, &out, &mut rec).unwrap();
    assert_eq!(rec.stages, [1, 2, 3, 4, 4, 5]);
    assert_eq!(rec.equilibria, 5);
    assert_eq!(
        rec.points,
        9 + 5,
        "every point of both sweeps reached the hooks"
    );
    assert_eq!(
        rec.sweeps,
        [(out.join("sweep-cms"), 9), (out.join("sweep-residue"), 5)]
    );
    // the paper table: each paper coupling against each sweep, from that sweep's couplings
    assert_eq!(v.paper_rows.len(), 2 * 2);
    for r in &v.paper_rows {
        let (_, _, sweep) = v.sweeps.iter().find(|(b, _, _)| *b == r.basis).unwrap();
        if let Some(f) = r.squeal_freq_hz {
            assert!(sweep.couplings.iter().any(|c| c.freq_hz == f), "{f} Hz");
        }
    }
    // one reference row per basis and reference mu, every mode of the band matched
    assert_eq!(v.references.len(), 2);
    for r in &v.references {
        assert!(r.errors.reference_modes > 5, "{}", r.basis);
        assert_eq!(r.errors.missed_modes, 0, "{}", r.basis);
        assert!(r.errors.max_rel_freq_err < 1e-4, "{}", r.basis);
    }
    assert_eq!(v.table2.len(), 16);
    assert!(v.stiffness_n_per_m > 1e5 && v.force_at_datum_n > 0.0);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("report.json")).unwrap()).unwrap();
    assert_eq!(json["sweeps"].as_array().unwrap().len(), 2);
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains(&v.paper_table()));

    // resumed: every point is read back, the report is the same but for times
    let mut again = Record::default();
    let resumed = ValidateSettings {
        resume: true,
        ..settings()
    };
    let w = run(&registry, &scene, "coarse", &resumed, &out, &mut again).unwrap();
    assert_eq!(w.paper_table(), v.paper_table());
    for (a, b) in v.references.iter().zip(&w.references) {
        let (ea, eb) = (a.errors.max_rel_freq_err, b.errors.max_rel_freq_err);
        if a.basis == "residue" {
            // a sweep's residue point starts from the one before it; the resumed run
            // solves the reference point again without that start: the same tolerance,
            // not the same bits
            assert!(ea < 1e-6 && eb < 1e-6 && ea != eb, "{ea:e} {eb:e}");
        } else {
            assert_eq!(ea, eb, "{}", a.basis);
        }
    }
    std::fs::remove_dir_all(&out).unwrap();
}

#[test]
fn settings_that_cannot_run_are_refused_by_field() {
    let registry = squeal::registry();
    let refused = |s: ValidateSettings| check(&registry, &s).unwrap_err().to_string();
    let e = refused(ValidateSettings {
        reference_mu: vec![0.35],
        ..settings()
    });
    assert!(
        e.starts_with("reference_mu: 0.35: expected a point of every sweep"),
        "{e}"
    );
    let e = refused(ValidateSettings {
        sweeps: vec![("cms".into(), 0.1), ("nonesuch".into(), 0.1)],
        ..settings()
    });
    assert!(e.starts_with("sweeps[1].basis: nonesuch"), "{e}");
    let e = refused(ValidateSettings {
        sweeps: vec![("cms".into(), -0.1)],
        ..settings()
    });
    assert!(e.starts_with("sweeps[0].step: -0.1"), "{e}");
    let e = refused(ValidateSettings {
        eigen: "nonesuch".into(),
        ..settings()
    });
    assert!(e.starts_with("eigen: `nonesuch`"), "{e}");
}
