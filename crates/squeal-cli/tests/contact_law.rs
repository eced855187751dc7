//! A contact law's parameters on the command line (`--law penalty --law-opt
//! kn_n_per_m=...`): a mu sweep uses them for its equilibria, writes them into its
//! summary, and refuses to resume a sweep run with other ones.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn temp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("squeal-contact-law-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn sweep(out: &Path, law: &[&str], resume: bool) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_squeal"));
    c.args([
        "sweep",
        "mu",
        "pin-on-disc-coarse",
        "--from",
        "0.3",
        "--to",
        "0.3",
    ])
    .args(["--basis", "modes"])
    .args(law)
    .arg("--out")
    .arg(out);
    if resume {
        c.arg("--resume");
    }
    c.output().unwrap()
}

fn summary(out: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

#[test]
fn penalty_stiffness_reaches_the_sweep_and_its_checkpoint() {
    let soft = temp("soft");
    let o = sweep(
        &soft,
        &["--law", "penalty", "--law-opt", "kn_n_per_m=1e5"],
        false,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s = summary(&soft);
    assert_eq!(s["law"], "penalty");
    assert_eq!(s["law_params"], "kn_n_per_m=100000");

    // the exact law: no parameters recorded
    let exact = temp("exact");
    let o = sweep(&exact, &[], false);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s = summary(&exact);
    assert_eq!(s["law"], "lagrange");
    assert!(s.get("law_params").is_none(), "{s}");

    // the same directory with another stiffness is another sweep
    let o = sweep(
        &soft,
        &["--law", "penalty", "--law-opt", "kn_n_per_m=1e6"],
        true,
    );
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--out"), "{err}");
    // with its own stiffness it resumes
    let o = sweep(
        &soft,
        &["--law", "penalty", "--law-opt", "kn_n_per_m=1e5"],
        true,
    );
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    for d in [soft, exact] {
        let _ = std::fs::remove_dir_all(d);
    }
}
