//! Bad input, table-driven: every case ends with exit code 1 or 2, one error line on
//! stderr that names the option or field, and no output directory.

use std::path::Path;
use std::process::Command;

/// The committed parametric operator (parameter `W` in [1, 100], friction part `FK`).
const LATTICE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../squeal-io/tests/data/parametric-lattice"
);

/// A committed fixed operator directory (no parameter).
const HOFFMANN: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../squeal-io/tests/data/hoffmann"
);

fn squeal() -> Command {
    Command::new(env!("CARGO_BIN_EXE_squeal"))
}

/// A fresh directory under the system temp dir, removed when the guard drops.
fn temp(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("squeal-bad-input-{name}-"))
        .tempdir()
        .unwrap()
}

/// A copy of the coarse scene with `from` replaced by `to`.
fn scene_with(dir: &Path, name: &str, from: &str, to: &str) -> String {
    let text = squeal_scene::Scene::builtin("pin-on-disc-coarse")
        .unwrap()
        .to_toml();
    assert!(text.contains(from), "the scene has no `{from}`");
    let path = dir.join(name);
    std::fs::write(&path, text.replacen(from, to, 1)).unwrap();
    path.display().to_string()
}

/// Runs `args` in `dir`; checks the exit code, that stderr's last line is one error
/// holding every `needles`, and that `out` was not created.
fn refused(dir: &Path, args: &[&str], needles: &[&str]) {
    let out = dir.join("out-should-not-exist");
    let mut cmd = squeal();
    cmd.current_dir(dir).args(args);
    if args.contains(&"--out") {
        // the case names its own --out
    } else if [
        "sweep",
        "equilibrium",
        "bench",
        "validate",
        "calibrate",
        "export",
    ]
    .contains(&args[0])
    {
        cmd.arg("--out").arg(&out);
    }
    let o = cmd.output().unwrap();
    let code = o.status.code().unwrap_or(-1);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        code == 1 || code == 2,
        "squeal {args:?}: exit code {code}, stderr:\n{err}"
    );
    let last = err.trim_end().lines().last().unwrap_or("");
    for n in needles {
        assert!(last.contains(n), "squeal {args:?}: `{n}` not in: {last}");
    }
    assert!(
        !last.contains("Some(") && !last.contains("Str(") && !last.contains("Custom {"),
        "squeal {args:?}: Debug text in: {last}"
    );
    // each message once
    let parts: Vec<&str> = last.split(": ").collect();
    for w in parts.windows(2) {
        assert_ne!(w[0], w[1], "squeal {args:?}: repeated message in: {last}");
    }
    assert!(!out.exists(), "squeal {args:?} wrote {}", out.display());
}

#[test]
fn options_are_checked_before_any_work() {
    let tmp = temp("options");
    let d = tmp.path();
    let cases: &[(&[&str], &[&str])] = &[
        (
            &["stability", "pin-on-disc-coarse", "--mu", "-1"],
            &["--mu -1", ">= 0"],
        ),
        (
            &["stability", "pin-on-disc-coarse", "--eigen", "foo"],
            &["--eigen foo", "registered"],
        ),
        (
            &["stability", "pin-on-disc-coarse", "--basis", "foo"],
            &["--basis foo", "registered"],
        ),
        (
            &["stability", "pin-on-disc-coarse", "--tol", "0"],
            &["--tol 0", "(0, 1)"],
        ),
        (
            &["stability", "pin-on-disc-coarse", "--band", "0:1e12"],
            &["--band", "mesh.max_freq_hz"],
        ),
        (
            &["stability", "pin-on-disc-coarse", "--band", "abc"],
            &["--band", "FMIN:FMAX"],
        ),
        (
            &["stability", "pin-on-disc-coarse", "--basis-opt", "a=1"],
            &["--basis-opt", "--basis"],
        ),
        (
            &[
                "stability",
                "pin-on-disc-coarse",
                "--basis",
                "residue",
                "--basis-opt",
                "tol=abc",
            ],
            &["--basis residue", "tol", "`abc`"],
        ),
        (
            &["sweep", "mu", "pin-on-disc-coarse", "--step", "0"],
            &["--step", "step > 0"],
        ),
        (
            &["sweep", "mu", "pin-on-disc-coarse", "--step", "1e-9"],
            &["points", "at most"],
        ),
        // contact law parameters, shared by every command that solves an equilibrium
        (
            &[
                "sweep",
                "mu",
                "pin-on-disc-coarse",
                "--law",
                "penalty",
                "--law-opt",
                "kn_n_per_m=-1",
            ],
            &["--law penalty --law-opt", "kn_n_per_m", "positive"],
        ),
        (
            &[
                "stability",
                "pin-on-disc-coarse",
                "--law-opt",
                "kn_n_per_m=1e8",
            ],
            &["--law lagrange --law-opt", "kn_n_per_m"],
        ),
        (
            &["equilibrium", "pin-on-disc-coarse", "--law-opt", "kn"],
            &["--law-opt", "key=value"],
        ),
        (
            &["sweep", "macro", "pin-on-disc-coarse", "--jobs", "0"],
            &["--jobs 0"],
        ),
        (
            &["sweep", "meso", "pin-on-disc-coarse", "--coupling", "3"],
            &["--coupling 3"],
        ),
        (
            &["validate", "pin-on-disc-coarse", "--step", "0"],
            &["--step 0"],
        ),
        (
            &["validate", "pin-on-disc-coarse", "--json", "x.json"],
            &["--json", "--disc-only"],
        ),
        (
            &["modes", "nothere.toml"],
            &["SCENE nothere.toml", "no such scene file"],
        ),
        (&["modes", "no-such-scene"], &["no-such-scene"]),
        (
            &["bench", "pin-on-disc-coarse", "--bases", "foo"],
            &["--bases foo"],
        ),
        (
            &["bench", "pin-on-disc-coarse", "--reference-tol", "2"],
            &["--reference-tol 2"],
        ),
        (
            &["equilibrium", "pin-on-disc-coarse", "--mu=-0.5"],
            &["--mu -0.5"],
        ),
        // parametric operators: --param NAME=VALUE, the name the operator declares
        (
            &[
                "stability",
                "--operator",
                LATTICE,
                "--mu",
                "0.3",
                "--param",
                "X=5",
            ],
            &["--param X=5", "`W`, not `X`"],
        ),
        (
            &[
                "stability",
                "--operator",
                LATTICE,
                "--mu",
                "0.3",
                "--param",
                "W",
            ],
            &["--param W", "NAME=VALUE"],
        ),
        (
            &[
                "stability",
                "--operator",
                LATTICE,
                "--mu",
                "0.3",
                "--param",
                "W=abc",
            ],
            &["--param W=abc", "`abc`"],
        ),
        (
            &[
                "stability",
                "--operator",
                LATTICE,
                "--mu",
                "0.3",
                "--param",
                "W=500",
            ],
            &["--param W=500", "1 <= W <= 100"],
        ),
        (
            &["stability", "--operator", LATTICE, "--mu", "0.3"],
            &["--operator", "parametric", "--param W=VALUE"],
        ),
        (
            &["stability", "pin-on-disc-coarse", "--param", "W=5"],
            &["--param W=5", "--operator DIR"],
        ),
        (
            &[
                "stability",
                "--operator",
                HOFFMANN,
                "--mu",
                "0.3",
                "--param",
                "W=5",
            ],
            &["--param W=5", "not a parametric operator"],
        ),
        (
            &[
                "bench",
                "--operator",
                LATTICE,
                "--mu",
                "0.3",
                "--param",
                "X=5",
            ],
            &["--param X=5", "`W`, not `X`"],
        ),
        (
            &["bench", "pin-on-disc-coarse", "--param", "W=5"],
            &["--param W=5", "--operator DIR"],
        ),
        (
            &[
                "sweep",
                "param",
                "--operator",
                LATTICE,
                "--param",
                "X",
                "--from",
                "5",
                "--to",
                "6",
                "--step",
                "1",
                "--mu",
                "0.3",
            ],
            &["--param X", "`W`, not `X`"],
        ),
        (
            &[
                "sweep",
                "param",
                "--operator",
                HOFFMANN,
                "--param",
                "W",
                "--from",
                "5",
                "--to",
                "6",
                "--step",
                "1",
                "--mu",
                "0.3",
            ],
            &["--param W", "not a parametric operator"],
        ),
        (
            &[
                "sweep",
                "param",
                "--operator",
                LATTICE,
                "--param",
                "W",
                "--from",
                "0",
                "--to",
                "6",
                "--step",
                "1",
                "--mu",
                "0.3",
            ],
            &["--from/--to", "[1, 100]"],
        ),
        (
            &[
                "sweep",
                "param",
                "--operator",
                LATTICE,
                "--param",
                "W",
                "--from",
                "6",
                "--to",
                "5",
                "--step",
                "1",
                "--mu",
                "0.3",
            ],
            &["--from/--to/--step", "from <= to"],
        ),
        (
            &[
                "sweep",
                "param",
                "--operator",
                LATTICE,
                "--param",
                "W",
                "--from",
                "5",
                "--to",
                "6",
                "--step",
                "1",
            ],
            &["--mu", "friction parts"],
        ),
    ];
    for (args, needles) in cases {
        refused(d, args, needles);
    }
}

#[test]
fn scene_fields_are_named() {
    let tmp = temp("scenes");
    let d = tmp.path();
    let cases = [
        (
            "nu.toml",
            "poisson_ratio = 0.3",
            "poisson_ratio = 0.5",
            &["nu.toml", "disc.material", "poisson_ratio = 0.5"][..],
        ),
        (
            "face.toml",
            "pin_face_elements = 2",
            "pin_face_elements = 0",
            &["face.toml", "mesh.pin_face_elements"][..],
        ),
        (
            "radii.toml",
            "inner_radius_m = 0.0677",
            "inner_radius_m = 0.2",
            &["radii.toml", "disc.inner_radius_m"][..],
        ),
        (
            "text.toml",
            "thickness_m = 0.0118",
            "thickness_m = \"abc\"",
            &["text.toml", "thickness_m"][..],
        ),
        (
            "huge.toml",
            "max_freq_hz = 1000.0",
            "max_freq_hz = 1e7",
            &["huge.toml", "mesh.max_dofs", "DOFs"][..],
        ),
    ];
    for (name, from, to, needles) in cases {
        let s = scene_with(d, name, from, to);
        refused(d, &["scene", "info", &s], needles);
    }
    // a shear modulus given as the scene names it
    let s = scene_with(
        d,
        "g.toml",
        "youngs_modulus_axial_pa = 5400000000.0",
        "youngs_modulus_axial_pa = 5400000000.0, shear_modulus_axial_pa = -1.0",
    );
    refused(d, &["scene", "info", &s], &["shear_modulus_axial_pa"]);
}

#[test]
fn output_directories_belong_to_one_command() {
    let tmp = temp("out");
    let d = tmp.path();
    // --out naming a file
    std::fs::write(d.join("afile"), "x").unwrap();
    refused(
        d,
        &["equilibrium", "pin-on-disc-coarse", "--out", "afile"],
        &["--out afile", "is a file"],
    );
    // a sweep's directory refused to a study, and a finished sweep without --resume
    let sweep = d.join("sweep");
    let o = squeal()
        .current_dir(d)
        .args([
            "sweep",
            "mu",
            "pin-on-disc-coarse",
            "--to",
            "0.1",
            "--step",
            "0.1",
            "--out",
        ])
        .arg(&sweep)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s = sweep.display().to_string();
    refused(
        d,
        &["sweep", "macro", "pin-on-disc-coarse", "--out", &s],
        &["holds the output of `squeal sweep mu`"],
    );
    refused(
        d,
        &[
            "sweep",
            "mu",
            "pin-on-disc-coarse",
            "--to",
            "0.1",
            "--step",
            "0.1",
            "--out",
            &s,
        ],
        &["--resume"],
    );
    // with --resume it finishes
    let o = squeal()
        .current_dir(d)
        .args([
            "sweep",
            "mu",
            "pin-on-disc-coarse",
            "--to",
            "0.1",
            "--step",
            "0.1",
            "--resume",
            "--out",
        ])
        .arg(&sweep)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stderr).contains("resuming: 2 points"));
}

#[test]
fn operators_read_from_files_are_checked() {
    let tmp = temp("operator");
    let d = tmp.path();
    let dir = d.join("op");
    let o = squeal()
        .args(["export", "pin-on-disc-coarse", "--mu", "0.3", "--out"])
        .arg(&dir)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // negate the constrained mass: the diagonal check names it
    let mc = dir.join("Mc.mtx");
    let text = std::fs::read_to_string(&mc).unwrap();
    // every entry negated (the size line, the first after the comments, kept)
    let mut size_seen = false;
    let negated: String = text
        .lines()
        .map(|l| {
            if l.starts_with('%') {
                return l.to_string();
            }
            if !size_seen {
                size_seen = true;
                return l.to_string();
            }
            let f: Vec<&str> = l.split_whitespace().collect();
            format!("{} {} {:e}", f[0], f[1], -f[2].parse::<f64>().unwrap())
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&mc, negated + "\n").unwrap();
    let op = dir.display().to_string();
    refused(
        d,
        &["stability", "--operator", &op, "--mu", "0.3"],
        &["--operator", "M_c", "diagonal"],
    );
}

#[test]
fn scene_list_names_the_embedded_scenes() {
    let o = squeal().args(["scene", "list"]).output().unwrap();
    assert!(o.status.success());
    let text = String::from_utf8_lossy(&o.stdout);
    for name in squeal_scene::BUILTIN_SCENES {
        assert!(text.contains(name), "{name} missing from:\n{text}");
    }
}
