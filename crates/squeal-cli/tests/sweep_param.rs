//! `squeal sweep param` on the committed parametric lattice operator (84 DOFs, parameter
//! `W`, friction part `FK`): it finds the unstable mode of the dense SciPy reference at
//! W = 5, mu = 0.6, its points equal `squeal stability --operator DIR --param W=...` at
//! the same values, every mode carries `cond` and `error_bound` (in `stability --json`
//! and in `sweep.csv`), and a finished sweep resumes without recomputing.

use std::path::{Path, PathBuf};
use std::process::Command;

const LATTICE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../squeal-io/tests/data/parametric-lattice"
);

fn squeal() -> Command {
    Command::new(env!("CARGO_BIN_EXE_squeal"))
}

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("squeal-sweep-param-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn run(args: &[&str], out: &Path) -> (String, String) {
    let o = squeal().args(args).arg("--out").arg(out).output().unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&o.stdout).to_string(),
        String::from_utf8_lossy(&o.stderr).to_string(),
    );
    assert!(o.status.success(), "squeal {args:?}:\n{stdout}\n{stderr}");
    (stdout, stderr)
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// `(re, im)` of every reference eigenvalue of the case `(w, mu)` of `reference.json`.
fn reference(w: f64, mu: f64) -> Vec<(f64, f64)> {
    let r = json(&Path::new(LATTICE).join("reference.json"));
    let case = r["cases"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["W"].as_f64() == Some(w) && c["mu"].as_f64() == Some(mu))
        .expect("reference case");
    assert_eq!(case["fmax_hz"].as_f64(), Some(1500.0));
    case["eigenvalues"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| (l[0].as_f64().unwrap(), l[1].as_f64().unwrap()))
        .collect()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs().max(1e-300)
}

const SWEEP: [&str; 16] = [
    "sweep",
    "param",
    "--operator",
    LATTICE,
    "--param",
    "W",
    "--from",
    "5",
    "--to",
    "20",
    "--step",
    "5",
    "--mu",
    "0.6",
    "--band",
    "0:1500",
];

#[test]
fn sweep_param_finds_the_unstable_modes_and_matches_stability() {
    let d = temp("sweep");
    let out = d.join("sweep");
    let (stdout, stderr) = run(&SWEEP, &out);
    assert!(stderr.contains("[4/4]"), "progress:\n{stderr}");
    for f in [
        "sweep.csv",
        "summary.json",
        "frequency_vs_W.svg",
        "dvr_vs_W.svg",
        "sweep.partial.jsonl",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["parameter"], "W");
    assert_eq!(summary["points"], 4);
    assert_eq!(summary["dofs"], 84);
    // the flutter mode near 418 Hz at W = 5 (reference: Re 1.68 1/s) stays unstable to
    // W = 20: one coupling over the whole range
    let couplings = summary["couplings"].as_array().unwrap();
    assert_eq!(couplings.len(), 1, "{stdout}");
    assert_eq!(couplings[0]["from"].as_f64(), Some(5.0));
    assert_eq!(couplings[0]["to"].as_f64(), Some(20.0));
    assert!(summary["max_error_bound"].as_f64().unwrap() < 1e-10);

    // the points, at full precision
    let points: Vec<serde_json::Value> = std::fs::read_to_string(out.join("sweep.partial.jsonl"))
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(points.len(), 4);
    let tau = 2.0 * std::f64::consts::PI;

    // W = 5: every reference eigenvalue of the band, the unstable one included
    let p5 = &points[0];
    assert_eq!(p5["value"].as_f64(), Some(5.0));
    assert_eq!(p5["mu"].as_f64(), Some(0.6));
    let modes = p5["modes"].as_array().unwrap();
    let refs = reference(5.0, 0.6);
    assert_eq!(modes.len(), refs.len());
    for (m, (re, im)) in modes.iter().zip(&refs) {
        let f = m["freq_hz"].as_f64().unwrap();
        assert!(rel(f, im / tau) < 1e-9, "{f} Hz vs {} Hz", im / tau);
        assert!((m["re"].as_f64().unwrap() - re).abs() < 1e-8 * im, "{m}");
    }
    let unstable: Vec<f64> = modes
        .iter()
        .filter(|m| m["dvr"].as_f64().unwrap() > 1e-6)
        .map(|m| m["freq_hz"].as_f64().unwrap())
        .collect();
    assert_eq!(unstable.len(), 1, "{unstable:?}");
    assert!((unstable[0] - 417.899).abs() < 1e-2, "{unstable:?}");

    // every point equals `stability --operator DIR --param W=...` at its value
    for p in &points {
        let w = p["value"].as_f64().unwrap();
        let js = d.join(format!("stability-{w}.json"));
        let o = squeal()
            .args(["stability", "--operator", LATTICE, "--param"])
            .arg(format!("W={w}"))
            .args(["--mu", "0.6", "--band", "0:1500", "--json"])
            .arg(&js)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let table = String::from_utf8_lossy(&o.stdout);
        assert!(
            table.contains("cond") && table.contains("err bound"),
            "{table}"
        );
        let st = json(&js);
        assert_eq!(st["param"].as_str(), Some(format!("W={w}").as_str()));
        let (a, b) = (
            p["modes"].as_array().unwrap(),
            st["modes"].as_array().unwrap(),
        );
        assert_eq!(a.len(), b.len(), "W = {w}");
        for (x, y) in a.iter().zip(b) {
            for key in ["freq_hz", "re", "dvr", "cond", "error_bound"] {
                let (u, v) = (x[key].as_f64().unwrap(), y[key].as_f64().unwrap());
                assert!(
                    rel(u, v) < 1e-9,
                    "W = {w}, {key}: sweep {u} vs stability {v}"
                );
            }
            assert_eq!(
                x["dvr"].as_f64().unwrap() > 1e-6,
                y["unstable"].as_bool().unwrap()
            );
        }
    }

    // a finished sweep is refused without --resume and read back with it
    let again = squeal()
        .args(SWEEP)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(!again.status.success());
    assert!(String::from_utf8_lossy(&again.stderr).contains("--resume"));
    let mut resumed: Vec<&str> = SWEEP.to_vec();
    resumed.push("--resume");
    let (_, stderr) = run(&resumed, &out);
    assert!(stderr.contains("resuming: 4 points"), "{stderr}");
    let back = json(&out.join("summary.json"));
    assert_eq!(back["couplings"], summary["couplings"]);
    std::fs::remove_dir_all(&d).ok();
}

/// `stability --json` of a small problem has every mode's condition number and forward
/// error estimate, with `error_bound = cond * backward_error`.
#[test]
fn stability_json_has_cond_and_error_bound() {
    let d = temp("stability");
    let js = d.join("s.json");
    let o = squeal()
        .args([
            "stability",
            "--operator",
            LATTICE,
            "--param",
            "W=20",
            "--mu",
            "0.8",
            "--band",
            "0:1500",
            "--json",
        ])
        .arg(&js)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let st = json(&js);
    let modes = st["modes"].as_array().unwrap();
    assert_eq!(modes.len(), reference(20.0, 0.8).len());
    let mut worst = 0.0f64;
    for m in modes {
        let (c, b, e) = (
            m["cond"].as_f64().expect("cond is a number"),
            m["error_bound"].as_f64().expect("error_bound is a number"),
            m["backward_error"].as_f64().unwrap(),
        );
        assert!(c >= 1.0 && c.is_finite(), "{m}");
        assert!(rel(b, c * e) < 1e-12, "{m}");
        worst = worst.max(b);
    }
    assert_eq!(st["max_error_bound"].as_f64(), Some(worst));
    // the estimate holds against the dense reference: every error within its bound
    for (re, im) in reference(20.0, 0.8) {
        let m = modes
            .iter()
            .min_by(|a, b| {
                let d = |m: &&serde_json::Value| {
                    (m["re"].as_f64().unwrap() - re)
                        .hypot(m["freq_hz"].as_f64().unwrap() * 2.0 * std::f64::consts::PI - im)
                };
                d(a).total_cmp(&d(b))
            })
            .unwrap();
        let lambda = (m["re"].as_f64().unwrap(), m["im"].as_f64().unwrap());
        let err = (lambda.0 - re).hypot(lambda.1 - im) / re.hypot(im);
        assert!(
            err <= m["error_bound"].as_f64().unwrap() + 1e-12,
            "error {err:e} above the bound of {m}"
        );
    }
    std::fs::remove_dir_all(&d).ok();
}
