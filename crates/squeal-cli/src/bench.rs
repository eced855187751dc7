//! `squeal bench`: every registered basis x eigen solver on the same frictional operator
//! against the full-order reference, and the stress set (`--stress`).

use anyhow::{Context, Result};
use serde::Serialize;
use squeal_analysis::bench::{
    bench_case, speed_ratios, BenchOptions, BenchRun, MemoryProbe, ReferenceSolve, SpeedRatio,
};
use squeal_analysis::pipeline::Prepared;
use squeal_core::{FrictionalOperator, Registry};
use squeal_plot::{line_chart, pareto_chart, ChartOptions, Series, SeriesStyle};
use squeal_scene::Zone;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The counting allocator of the binary, as a [`MemoryProbe`].
pub struct HeapProbe(pub &'static peak_alloc::PeakAlloc);

impl MemoryProbe for HeapProbe {
    fn reset(&self) -> usize {
        self.0.reset_peak_usage();
        self.0.current_usage()
    }
    fn peak(&self) -> usize {
        self.0.peak_usage()
    }
}

/// Inputs of `squeal bench`.
pub struct Args<'a> {
    pub scene: Option<&'a str>,
    pub operator: Option<&'a Path>,
    pub mus: &'a [f64],
    pub out: &'a Path,
    pub opts: BenchOptions,
    pub equilibrium: &'a str,
    pub law: &'a str,
    pub stress: bool,
}

/// `bench-summary.json`: what produced `bench.json`.
#[derive(Serialize)]
struct Summary<'a> {
    source: String,
    version: &'static str,
    units: &'static str,
    band_hz: [f64; 2],
    tol: f64,
    reference_eigen: &'a str,
    reference_tol: f64,
    unstable_tol: f64,
    accuracy: squeal_analysis::bench::Accuracy,
    bases: &'a [String],
    eigens: &'a [String],
    vary: Vec<String>,
    references: Vec<ReferenceSolve>,
    speed_ratios: Vec<SpeedRatio>,
    cases: Vec<CaseInfo>,
    time_s: f64,
    charts: Vec<String>,
}

/// One case: where its operator came from.
#[derive(Serialize, Clone)]
struct CaseInfo {
    case: String,
    mu: f64,
    what: String,
    active_pairs: Option<usize>,
    dofs: usize,
    operator_time_s: f64,
}

/// One stress case: a scene change, a mu and basis parameters chosen to break methods.
struct StressCase {
    name: &'static str,
    what: &'static str,
    mu: f64,
    zone: Option<Zone>,
    vary: Option<(&'static str, f64)>,
}

fn stress_cases() -> Vec<StressCase> {
    vec![
        StressCase {
            name: "baseline",
            what: "uniform contact, mu = 0.3: the reference point of each method's error estimate",
            mu: 0.3,
            zone: None,
            vary: None,
        },
        StressCase {
            name: "threshold",
            what: "mu = 0.6, just past the onset of the 2150 Hz coupling of the default scene \
                   (between 0.55 and 0.6): a small positive real part",
            mu: 0.6,
            zone: None,
            vary: None,
        },
        StressCase {
            name: "localized",
            what: "contact zone 4 x 4 mm at the leading edge (x0 = 16 mm, y0 = 8 mm), mu = 0.43",
            mu: 0.43,
            zone: Some(Zone::Rectangle {
                x0_m: 0.016,
                y0_m: 0.008,
                a_m: 0.004,
                b_m: 0.004,
            }),
            vary: None,
        },
        StressCase {
            name: "high-mu",
            what: "mu = 1.2, far beyond the paper's range: strong friction coupling",
            mu: 1.2,
            zone: None,
            vary: None,
        },
        StressCase {
            name: "truncated",
            what: "mu = 0.7 with every basis cut at the band top (cutoff_factor = 1)",
            mu: 0.7,
            zone: None,
            vary: Some(("cutoff_factor", 1.0)),
        },
        StressCase {
            name: "doublet",
            what: "mu = 0.02: the disc's doublets split by the pin and barely coupled by \
                   friction (near-degenerate pairs, DvR near 0 on both sides)",
            mu: 0.02,
            zone: None,
            vary: None,
        },
    ]
}

/// Appends one run to `bench.partial.jsonl` at once (a killed bench keeps what finished).
fn append(path: &Path, run: &BenchRun) -> Result<()> {
    let mut f = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(path)
        .with_context(|| format!("opening {}", path.display()))?;
    writeln!(f, "{}", serde_json::to_string(run)?)?;
    f.flush()?;
    Ok(())
}

fn print_run(r: &BenchRun) {
    let opts = if r.basis_opts.is_empty() {
        String::new()
    } else {
        format!(" [{}]", r.basis_opts)
    };
    if r.status != "ok" {
        println!(
            "  {:<26} {}",
            format!("{}/{}{opts}", r.basis, r.eigen),
            r.status
        );
        return;
    }
    let split = match (r.reduced_solve_s, r.expansion_s) {
        (Some(a), Some(b)) => format!(" (reduced {a:.2} + expansion {b:.2})"),
        _ => String::new(),
    };
    println!(
        "  {:<26} n={:<6} setup {:>7.2} s  solve {:>7.2} s{split}  df/f {:>8.1e}  \
         dDvR {:>8.1e}  missed {} modes, {} unstable; false unstable {}  bwd {:>8.1e}  \
         x{:.1}{}",
        format!("{}/{}{opts}", r.basis, r.eigen),
        if r.basis_size == 0 {
            r.dofs
        } else {
            r.basis_size
        },
        r.setup_s,
        r.solve_s,
        r.errors.max_rel_freq_err,
        r.errors.max_abs_dvr_err,
        r.errors.missed_modes,
        r.errors.missed_unstable,
        r.errors.false_unstable,
        r.errors.max_backward_error,
        r.solve_speedup,
        if r.accurate { "" } else { "  (not accurate)" }
    );
}

struct Source {
    name: String,
    prep: Option<Prepared>,
    op: Option<FrictionalOperator>,
}

/// The operator of a case: the scene's at its equilibrium for `mu` (or with a changed
/// zone), or the operator directory's.
fn case_operator(
    registry: &Registry,
    src: &mut Source,
    a: &Args<'_>,
    mu: f64,
    zone: Option<&Zone>,
) -> Result<(FrictionalOperator, Option<usize>, f64)> {
    let t = Instant::now();
    if let Some(op) = &src.op {
        if zone.is_some() {
            anyhow::bail!("a zone change needs a scene, not --operator");
        }
        return Ok((op.clone(), None, 0.0));
    }
    let base = src.prep.as_ref().expect("scene source");
    let zoned;
    let prep = match zone {
        None => base,
        Some(z) => {
            let mut scene = base.scene.clone();
            scene.contact.zone = z.clone();
            zoned = Prepared::new(registry, scene, &src.name)?;
            &zoned
        }
    };
    let eq = prep.equilibrium(registry, a.equilibrium, a.law, mu)?;
    let op = prep.operator(&eq.eq.active)?;
    Ok((
        op,
        Some(eq.eq.active.iter().filter(|&&x| x).count()),
        t.elapsed().as_secs_f64(),
    ))
}

/// Redraws the charts (or the stress table) of a finished run from its `bench.json`
/// (`stress.json`) in `out`.
pub fn replot(out: &Path, stress: bool) -> Result<()> {
    let json = out.join(if stress { "stress.json" } else { "bench.json" });
    let text = std::fs::read_to_string(&json)
        .with_context(|| format!("--replot: reading {} (run the bench first)", json.display()))?;
    let runs: Vec<BenchRun> = serde_json::from_str(&text)
        .with_context(|| format!("--replot: {} is not a list of bench runs", json.display()))?;
    let files = if stress {
        stress_report(out, &runs)?
    } else {
        charts(out, &runs)?
    };
    println!("redrew {} files in {}", files.len(), out.display());
    Ok(())
}

/// Runs the bench (or the stress set) and writes its outputs.
/// A benchmark case: name, description, mu, zone, one varied basis parameter.
type BenchCase<'a> = (String, String, f64, Option<Zone>, Option<(&'a str, f64)>);

pub fn run(registry: &Registry, a: &Args<'_>, probe: Option<&dyn MemoryProbe>) -> Result<()> {
    let start = Instant::now();
    std::fs::create_dir_all(a.out).with_context(|| format!("creating {}", a.out.display()))?;
    let partial = a.out.join("bench.partial.jsonl");
    let _ = std::fs::remove_file(&partial);
    let mut src = if let Some(dir) = a.operator {
        if a.scene.is_some() {
            anyhow::bail!("give either a scene or --operator DIR, not both");
        }
        if a.stress {
            anyhow::bail!(
                "--stress changes the contact zone and mu: it needs a scene, not --operator"
            );
        }
        Source {
            name: dir.display().to_string(),
            prep: None,
            op: Some(crate::stability::read_operator_any(dir)?),
        }
    } else {
        let (scene, file) = crate::load_scene(a.scene)?;
        let prep = Prepared::new(registry, scene, &file)?;
        Source {
            name: file,
            prep: Some(prep),
            op: None,
        }
    };
    for &mu in a.mus {
        squeal_contact::check_user_mu(mu)?;
    }
    let cases: Vec<BenchCase<'_>> = if a.stress {
        stress_cases()
            .into_iter()
            .map(|c| (c.name.to_string(), c.what.to_string(), c.mu, c.zone, c.vary))
            .collect()
    } else {
        a.mus
            .iter()
            .map(|&mu| (format!("mu={mu}"), format!("mu = {mu}"), mu, None, None))
            .collect()
    };
    // the free-interface synthesis of the scene's model, for a basis that asks for one
    // (every pair of the face: a stress zone is a subset)
    let free = match &src.prep {
        Some(prep) => {
            let all = squeal_contact::ContactSet::new(
                &prep.model,
                &Zone::Uniform,
                prep.scene.study.rotation,
            )?;
            squeal_analysis::bench::free_interface_for(registry, &a.opts, &prep.model, &all)?
        }
        None => None,
    };
    let mut all_runs = Vec::new();
    let mut refs = Vec::new();
    let mut infos = Vec::new();
    for (case, what, mu, zone, vary) in &cases {
        println!("case {case}: {what}");
        let (op, active, op_time) = case_operator(registry, &mut src, a, *mu, zone.as_ref())?;
        infos.push(CaseInfo {
            case: case.clone(),
            mu: *mu,
            what: what.clone(),
            active_pairs: active,
            dofs: op.dim(),
            operator_time_s: op_time,
        });
        let mut opts = a.opts.clone();
        if let Some((k, v)) = vary {
            opts.vary = vec![(k.to_string(), vec![*v])];
            opts.defaults = false;
        }
        let mut append_err = None;
        let (reference, runs) =
            bench_case(registry, case, &op, free.as_ref(), *mu, &opts, probe, |r| {
                print_run(r);
                if let Err(e) = append(&partial, r) {
                    append_err.get_or_insert(e);
                }
            })?;
        if let Some(e) = append_err {
            return Err(e);
        }
        println!(
            "  reference `{}`: {} modes in band, {} unstable, {:.1} s",
            reference.eigen,
            reference.modes,
            reference.unstable.len(),
            reference.time_s
        );
        refs.push(reference);
        all_runs.extend(runs);
    }
    let stem = if a.stress { "stress" } else { "bench" };
    let json = a.out.join(format!("{stem}.json"));
    std::fs::write(&json, serde_json::to_string_pretty(&all_runs)?)
        .with_context(|| format!("writing {}", json.display()))?;
    let charts = if a.stress {
        stress_report(a.out, &all_runs)?
    } else {
        charts(a.out, &all_runs)?
    };
    let ratios = speed_ratios(&all_runs);
    let summary = Summary {
        source: src.name.clone(),
        version: env!("CARGO_PKG_VERSION"),
        units: "times in s, memory in MB (heap above the run's start), frequencies in Hz; \
                errors relative (frequency) or absolute (DvR = Re/Im)",
        band_hz: a.opts.band_hz,
        tol: a.opts.tol,
        reference_eigen: &a.opts.reference_eigen,
        reference_tol: a.opts.reference_tol,
        unstable_tol: a.opts.unstable_tol,
        accuracy: a.opts.accuracy,
        bases: &a.opts.bases,
        eigens: &a.opts.eigens,
        vary: a
            .opts
            .vary
            .iter()
            .map(|(k, v)| format!("{k}={v:?}"))
            .collect(),
        references: refs,
        speed_ratios: ratios.clone(),
        cases: infos,
        time_s: start.elapsed().as_secs_f64(),
        charts: charts.iter().map(|p| p.display().to_string()).collect(),
    };
    let sj = a.out.join(format!("{stem}-summary.json"));
    std::fs::write(&sj, serde_json::to_string_pretty(&summary)?)
        .with_context(|| format!("writing {}", sj.display()))?;
    let _ = std::fs::remove_file(&partial);
    if !a.stress {
        println!("\nspeed-up over the reference at equal accuracy (fastest accurate run):");
        for r in &ratios {
            println!(
                "  {:<8} {:<22} {:<20} total x{:<8.1} per mu x{:.1}",
                r.case, r.method, r.basis_opts, r.speedup, r.solve_speedup
            );
        }
    }
    println!(
        "wrote {}, {} and {} charts in {:.1} s",
        json.display(),
        sj.display(),
        charts.len(),
        summary.time_s
    );
    Ok(())
}

fn label(r: &BenchRun) -> String {
    if r.basis_opts.is_empty() {
        format!("{}/{}", r.basis, r.eigen)
    } else {
        format!("{} [{}]/{}", r.basis, r.basis_opts, r.eigen)
    }
}

/// Chart points `(label, time, error)`: the runs of one basis variant whose errors agree
/// to 1 % (the eigen solvers of one reduced problem do, to a few digits) become one point
/// at the fastest time, labelled `basis [opts]/fastest (~ others)`, so labels do not
/// overlap on the log axes.
fn merged_points(
    runs: &[&BenchRun],
    err: fn(&BenchRun) -> f64,
    time: fn(&BenchRun) -> f64,
) -> Vec<(String, f64, f64)> {
    let mut groups: Vec<Vec<&BenchRun>> = Vec::new();
    for r in runs.iter().filter(|r| err(r).is_finite()) {
        let same = |g: &Vec<&BenchRun>| {
            let h = g[0];
            h.basis == r.basis
                && h.basis_opts == r.basis_opts
                && (err(h) - err(r)).abs() <= 1e-2 * err(h).abs().max(err(r).abs())
        };
        match groups.iter_mut().find(|g| same(g)) {
            Some(g) => g.push(r),
            None => groups.push(vec![r]),
        }
    }
    groups
        .into_iter()
        .map(|mut g| {
            g.sort_by(|a, b| time(a).total_cmp(&time(b)));
            let mut name = label(g[0]);
            if g.len() > 1 {
                let others: Vec<&str> = g[1..].iter().map(|r| r.eigen.as_str()).collect();
                name.push_str(&format!(" (~ {})", others.join(", ")));
            }
            (name, time(g[0]), err(g[0]))
        })
        .collect()
}

/// Error vs time (total, and per mu with the basis reused; Pareto front marked) and
/// error vs basis size, per case.
fn charts(out: &Path, runs: &[BenchRun]) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    let mut cases: Vec<&str> = runs.iter().map(|r| r.case.as_str()).collect();
    cases.dedup();
    for case in cases {
        let ok: Vec<&BenchRun> = runs
            .iter()
            .filter(|r| r.case == case && r.status == "ok" && !r.reference)
            .collect();
        let tag = case.replace('=', "");
        let ref_time = runs
            .iter()
            .find(|r| r.case == case && r.reference)
            .map_or(f64::NAN, |r| r.solve_s);
        for (what, key, err) in [
            (
                "max relative frequency error",
                "freq",
                (|r: &BenchRun| r.errors.max_rel_freq_err) as fn(&BenchRun) -> f64,
            ),
            ("max |DvR error|", "dvr", |r: &BenchRun| {
                r.errors.max_abs_dvr_err
            }),
        ] {
            for (stem, stem_title, axis, time) in [
                (
                    "time",
                    "total time",
                    "time (setup + solve)",
                    (|r: &BenchRun| r.time_s) as fn(&BenchRun) -> f64,
                ),
                (
                    "solve_time",
                    "per-mu time",
                    "per-mu solve time, basis reused",
                    |r: &BenchRun| r.solve_s,
                ),
            ] {
                let pts = merged_points(&ok, err, time);
                if pts.iter().any(|p| p.1 > 0.0 && p.2 > 0.0) {
                    files.extend(pareto_chart(
                        &out.join(format!("{key}_error_vs_{stem}_{tag}")),
                        &format!("{case}: {what} vs {stem_title} (reference {ref_time:.1} s)"),
                        &format!("{axis} (s)"),
                        what,
                        &pts,
                    )?);
                }
            }
        }
        // error vs basis size, one series per basis/eigen
        let mut series: Vec<Series> = Vec::new();
        for r in ok.iter().filter(|r| r.basis != "none") {
            let name = format!("{}/{}", r.basis, r.eigen);
            let p = (r.basis_size as f64, r.errors.max_rel_freq_err);
            if !p.1.is_finite() {
                continue;
            }
            match series.iter_mut().find(|s| s.name == name) {
                Some(s) => s.points.push(p),
                None => series.push(Series {
                    name,
                    points: vec![p],
                    style: SeriesStyle::LineMarkers,
                    highlight: Vec::new(),
                }),
            }
        }
        for s in &mut series {
            s.points.sort_by(|a, b| a.0.total_cmp(&b.0));
        }
        if series
            .iter()
            .any(|s| s.points.iter().any(|p| p.0 > 0.0 && p.1 > 0.0))
        {
            files.extend(line_chart(
                &out.join(format!("error_vs_size_{tag}")),
                &format!("{case}: max relative frequency error vs basis size"),
                "basis size (vectors)",
                "max relative frequency error",
                &series,
                &ChartOptions {
                    log_y: true,
                    ..ChartOptions::default()
                },
            )?);
        }
    }
    Ok(files)
}

/// The stress table: per case and method, whether it is wrong and how its own error
/// estimate (the worst backward error) moved against the baseline case.
fn stress_report(out: &Path, runs: &[BenchRun]) -> Result<Vec<PathBuf>> {
    #[derive(Serialize)]
    struct Row {
        case: String,
        method: String,
        basis_opts: String,
        wrong: bool,
        why: Vec<String>,
        max_backward_error: f64,
        baseline_backward_error: f64,
        estimate_ratio: f64,
        flagged: bool,
        /// The method stopped with an error (e.g. `dense` refusing a full-order problem
        /// above its `max_dim`): no answer, so neither right nor wrong.
        failed: bool,
    }
    let base = |r: &BenchRun| -> f64 {
        runs.iter()
            .find(|b| b.case == "baseline" && b.basis == r.basis && b.eigen == r.eigen)
            .map_or(f64::NAN, |b| b.errors.max_backward_error)
    };
    let mut rows = Vec::new();
    for r in runs.iter().filter(|r| !r.reference) {
        let acc = squeal_analysis::bench::Accuracy::default();
        let mut why = Vec::new();
        if r.status != "ok" {
            why.push(r.status.clone());
        } else {
            let e = &r.errors;
            if e.missed_modes > 0 {
                why.push(format!("{} modes missed", e.missed_modes));
            }
            if e.missed_unstable > 0 {
                why.push(format!("{} unstable modes missed", e.missed_unstable));
            }
            if e.false_unstable > 0 {
                why.push(format!("{} false unstable", e.false_unstable));
            }
            if e.max_rel_freq_err > acc.freq_rel {
                why.push(format!("df/f {:.1e}", e.max_rel_freq_err));
            }
            if e.max_abs_dvr_err > acc.dvr_abs {
                why.push(format!("dDvR {:.1e}", e.max_abs_dvr_err));
            }
        }
        let b = base(r);
        let ratio = r.errors.max_backward_error / b;
        rows.push(Row {
            case: r.case.clone(),
            method: format!("{}/{}", r.basis, r.eigen),
            basis_opts: r.basis_opts.clone(),
            wrong: r.status == "ok" && !why.is_empty(),
            failed: r.status != "ok",
            why,
            max_backward_error: r.errors.max_backward_error,
            baseline_backward_error: b,
            estimate_ratio: ratio,
            flagged: ratio >= 10.0,
        });
    }
    println!("\nstress set: where each method is wrong, and whether its backward error rose >= 10x over the baseline case");
    println!(
        "  {:<10} {:<28} {:<6} {:>10} {:>9} {:<7} why",
        "case", "method", "wrong", "bwd err", "x base", "flagged"
    );
    for r in &rows {
        println!(
            "  {:<10} {:<28} {:<6} {:>10.1e} {:>9.1} {:<7} {}",
            r.case,
            format!(
                "{}{}",
                r.method,
                if r.basis_opts.is_empty() {
                    String::new()
                } else {
                    format!(" [{}]", r.basis_opts)
                }
            ),
            if r.failed {
                "failed"
            } else if r.wrong {
                "WRONG"
            } else {
                "ok"
            },
            r.max_backward_error,
            r.estimate_ratio,
            if r.flagged { "yes" } else { "no" },
            r.why.join("; ")
        );
    }
    let path = out.join("stress-table.json");
    std::fs::write(&path, serde_json::to_string_pretty(&rows)?)
        .with_context(|| format!("writing {}", path.display()))?;
    Ok(vec![path])
}

/// Parses `--vary key=v1,v2` options (`none` for no variant).
pub fn parse_vary(items: &[String]) -> Result<Vec<(String, Vec<f64>)>> {
    let mut out = Vec::new();
    for item in items.iter().filter(|i| i.as_str() != "none") {
        let (k, vs) = item.split_once('=').with_context(|| {
            format!("--vary `{item}`: expected key=v1,v2 (e.g. cutoff_factor=2,3)")
        })?;
        let values = vs
            .split(',')
            .map(|v| {
                v.trim()
                    .parse::<f64>()
                    .with_context(|| format!("--vary `{item}`: `{v}` is not a number"))
            })
            .collect::<Result<Vec<f64>>>()?;
        out.push((k.trim().to_string(), values));
    }
    Ok(out)
}
