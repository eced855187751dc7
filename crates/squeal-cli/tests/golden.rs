//! Golden outputs: four commands on the coarse scene give the numbers committed in
//! `tests/golden/` to 1e-12 (frequencies relative, DvR and MAC absolute), so a change of
//! layout or machinery that should not change results is checked to do so:
//!
//! - `validate --disc-only` (the disc's labelled modes),
//! - `stability --mu 0.7` (full order, every mode of the band),
//! - `sweep mu` 0 to 0.8 by 0.1 (every tracked mode of every point, and the couplings),
//! - `sweep macro` (two zones at two mu, every mode of every case).
//!
//! A change that is meant to move results regenerates the files with
//! `SQUEAL_BLESS=1 cargo test --release -p squeal-cli --test golden` and says why in its
//! commit.

use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;

const FREQ_REL: f64 = 1e-12;
const ABS: f64 = 1e-12;

fn squeal(dir: &Path, args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_squeal"))
        .args(args)
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "squeal {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn read(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn golden_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

/// Compares `got` with the committed `name.json` (or writes it with `SQUEAL_BLESS=1`).
/// Keys ending in `freq_hz` compare relatively, other numbers absolutely, everything else
/// exactly.
fn check(name: &str, got: Value) {
    let path = golden_dir().join(format!("{name}.json"));
    if std::env::var("SQUEAL_BLESS").is_ok_and(|v| v == "1") {
        std::fs::create_dir_all(golden_dir()).unwrap();
        std::fs::write(&path, serde_json::to_string_pretty(&got).unwrap() + "\n").unwrap();
        return;
    }
    let want = read(&path);
    let mut diffs = Vec::new();
    compare("", &want, &got, false, &mut diffs);
    assert!(
        diffs.is_empty(),
        "{name}: {} difference(s) from {}, first: {}",
        diffs.len(),
        path.display(),
        diffs[..diffs.len().min(5)].join("; ")
    );
}

fn compare(at: &str, want: &Value, got: &Value, rel: bool, diffs: &mut Vec<String>) {
    match (want, got) {
        (Value::Object(a), Value::Object(b)) => {
            if a.keys().ne(b.keys()) {
                diffs.push(format!("{at}: keys {:?} vs {:?}", a.keys(), b.keys()));
                return;
            }
            for (k, v) in a {
                compare(
                    &format!("{at}.{k}"),
                    v,
                    &b[k],
                    k.ends_with("freq_hz"),
                    diffs,
                );
            }
        }
        (Value::Array(a), Value::Array(b)) => {
            if a.len() != b.len() {
                diffs.push(format!("{at}: {} entries, expected {}", b.len(), a.len()));
                return;
            }
            for (i, (x, y)) in a.iter().zip(b).enumerate() {
                compare(&format!("{at}[{i}]"), x, y, rel, diffs);
            }
        }
        (Value::Number(a), Value::Number(b)) => {
            let (a, b) = (a.as_f64().unwrap(), b.as_f64().unwrap());
            let err = if rel {
                (a - b).abs() / a.abs().max(1e-300)
            } else {
                (a - b).abs()
            };
            if err > if rel { FREQ_REL } else { ABS } {
                diffs.push(format!("{at}: {b:e}, expected {a:e}"));
            }
        }
        (a, b) if a != b => diffs.push(format!("{at}: {b}, expected {a}")),
        _ => {}
    }
}

fn temp() -> PathBuf {
    let d = std::env::temp_dir().join(format!("squeal-golden-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// `{freq_hz, dvr}` of a list of mode objects, by frequency; the modes of one frequency (to
/// 1e-9 relative: the two modes of a flutter pair) in DvR order, which round-off of the
/// solver's BLAS does not decide.
fn modes(v: &Value) -> Value {
    let mut m: Vec<(f64, f64)> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|m| (m["freq_hz"].as_f64().unwrap(), m["dvr"].as_f64().unwrap()))
        .collect();
    m.sort_by(|a, b| a.0.total_cmp(&b.0));
    for i in 1..m.len() {
        let mut j = i;
        while j > 0 && m[j].0 - m[j - 1].0 <= 1e-9 * m[j].0.abs() && m[j].1 < m[j - 1].1 {
            m.swap(j, j - 1);
            j -= 1;
        }
    }
    Value::Array(
        m.into_iter()
            .map(|(f, d)| json!({"freq_hz": f, "dvr": d}))
            .collect(),
    )
}

#[test]
fn four_commands_give_the_committed_numbers() {
    let d = temp();
    let coarse = "pin-on-disc-coarse";

    squeal(
        &d,
        &["validate", coarse, "--disc-only", "--json", "disc.json"],
    );
    let disc = read(&d.join("disc.json"));
    let got: Vec<Value> = disc["modes"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| json!({"label": m["label"], "freq_hz": m["freq_hz"]}))
        .collect();
    check("validate-disc-only", Value::Array(got));

    squeal(
        &d,
        &[
            "stability",
            coarse,
            "--mu",
            "0.7",
            "--json",
            "stability.json",
        ],
    );
    let s = read(&d.join("stability.json"));
    check(
        "stability-mu0.7",
        json!({"active_pairs": s["active_pairs"], "modes": modes(&s["modes"])}),
    );

    let sw = d.join("sweep");
    let sw = sw.to_str().unwrap();
    squeal(
        &d,
        &[
            "sweep", "mu", coarse, "--from", "0", "--to", "0.8", "--step", "0.1", "--out", sw,
        ],
    );
    let text = std::fs::read_to_string(d.join("sweep/sweep.partial.jsonl")).unwrap();
    let points: Vec<Value> = text
        .lines()
        .map(|l| {
            let p: Value = serde_json::from_str(l).unwrap();
            json!({"mu": p["mu"], "active_pairs": p["active_pairs"], "modes": modes(&p["modes"])})
        })
        .collect();
    let summary = read(&d.join("sweep/summary.json"));
    let couplings: Vec<Value> = summary["couplings"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| {
            // the two partners as a set: which of two equal-frequency modes comes first
            // is round-off
            let mut partners: Vec<u64> = c["partners"]
                .as_array()
                .unwrap()
                .iter()
                .map(|p| p.as_u64().unwrap())
                .collect();
            partners.sort_unstable();
            json!({"freq_hz": c["freq_hz"], "mu_from": c["mu_from"], "mu_to": c["mu_to"],
                   "max_dvr": c["max_dvr"], "partners": partners})
        })
        .collect();
    check(
        "sweep-mu",
        json!({"points": points, "couplings": couplings}),
    );

    let mac = d.join("macro");
    let mac = mac.to_str().unwrap();
    squeal(
        &d,
        &[
            "sweep",
            "macro",
            coarse,
            "--a",
            "0.01,0.02",
            "--b",
            "0.02",
            "--mu",
            "0.36,0.7",
            "--out",
            mac,
        ],
    );
    let text = std::fs::read_to_string(d.join("macro/results.jsonl")).unwrap();
    let cases: Vec<Value> = text
        .lines()
        .map(|l| {
            let r: Value = serde_json::from_str(l).unwrap();
            let modes: Vec<Value> = r["modes"]
                .as_array()
                .unwrap()
                .iter()
                .map(|m| json!({"freq_hz": m[0], "dvr": m[1]}))
                .collect();
            json!({"id": r["id"], "pairs": r["pairs"], "unstable": r["unstable"].as_array().unwrap().len(), "modes": modes})
        })
        .collect();
    check("sweep-macro", Value::Array(cases));
    let _ = std::fs::remove_dir_all(&d);
}
