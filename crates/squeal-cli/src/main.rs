//! The `squeal` command line: each subcommand is a `clap::Args` struct in its own module
//! whose `run` calls the library and prints; options every command shares live in
//! [`opts`].

mod bench;
mod bench_charts;
mod calibrate;
mod equilibrium;
mod modes;
mod opts;
mod scene_cmd;
mod stability;
mod study;
mod study_charts;
mod study_flags;
mod study_progress;
mod sweep;
mod sweep_charts;
mod validate;

use anyhow::Result;
use clap::{Parser, Subcommand};

/// Counts heap allocations so `squeal bench` can report each run's peak memory.
#[global_allocator]
static HEAP: peak_alloc::PeakAlloc = peak_alloc::PeakAlloc;

/// Brake-squeal stability analysis.
#[derive(Parser)]
#[command(name = "squeal", version, about, allow_negative_numbers = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Normal modes of the scene's bodies (free contact face), labelled.
    #[command(allow_negative_numbers = true)]
    Modes(modes::ModesArgs),
    /// The main job: the uniform-contact validation on the embedded default scene: disc
    /// modes vs Table 2, sliding equilibria, the mu sweep through two bases, full-order
    /// reference points, report.md/report.json and a paper-vs-squeal table.
    #[command(allow_negative_numbers = true)]
    Validate(validate::ValidateArgs),
    /// The steady sliding equilibrium (unilateral contact, Coulomb friction) for one or
    /// several mu: equilibrium.json (one object, or a list for several mu), per-pair CSV
    /// and a contact force map.
    #[command(allow_negative_numbers = true)]
    Equilibrium(equilibrium::EquilibriumArgs),
    /// Complex modes of the frictional operator: of a scene at its sliding equilibrium,
    /// or of an operator directory (`--operator DIR`).
    #[command(allow_negative_numbers = true)]
    Stability(stability::StabilityArgs),
    /// Writes the frictional operator of a scene at its equilibrium for MU, in both forms:
    /// constrained parts (Mc, Kc, FM, FK, T) and full form (M, K, pairs.csv), + README.txt.
    #[command(allow_negative_numbers = true)]
    Export(stability::ExportArgs),
    /// The solver benchmark: every registered basis x eigen solver (and full order) on
    /// the same frictional operator against full-order `arpack` at a tight tolerance:
    /// time (setup, solve), peak memory, basis size, errors, missed and false unstable
    /// modes, backward errors. Writes bench.json, bench-summary.json and error-vs-time /
    /// error-vs-size charts; `--stress` runs the stress set instead (stress.json,
    /// stress-table.json).
    #[command(allow_negative_numbers = true)]
    Bench(bench::BenchArgs),
    /// Parameter sweeps.
    #[command(subcommand)]
    Sweep(sweep::SweepCmd),
    /// Joins the directories of a study's shards (`--shard K/N` runs) into one: the same
    /// results.jsonl and summary.json as one run over the whole study, plus its charts.
    #[command(allow_negative_numbers = true)]
    Merge(study::MergeArgs),
    /// Model updating: fits scene parameters (any numeric scene field, within bounds) to
    /// targets (labelled mode frequencies, mode counts, the axial stiffness, tied-system
    /// modes picked by make-up, couplings of the stability sweep): fit.json, fitted.toml
    /// and a convergence chart.
    #[command(allow_negative_numbers = true)]
    Calibrate(calibrate::CalibrateArgs),
    /// Lists the registered plugins.
    Plugins,
    /// Scene inspection: the embedded scenes, what the builder makes of a scene, the scene
    /// with every default filled in.
    #[command(subcommand)]
    Scene(scene_cmd::SceneCmd),
}

fn main() {
    // A closed pipe (`squeal ... | head`) ends the process quietly, as for other Unix
    // tools, instead of a panic in `println!`.
    #[cfg(unix)]
    // SAFETY: restoring the default action of one signal before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    if let Err(e) = run() {
        eprintln!("error: {}", message(&e));
        std::process::exit(1);
    }
}

/// The error and its causes on one line, each message once: a cause whose text the
/// line already holds (a library error that quotes its source) is not repeated.
fn message(e: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if out.contains(&text) {
            continue;
        }
        if !out.is_empty() {
            out.push_str(": ");
        }
        out.push_str(&text);
    }
    out.replace('\n', " ")
}

/// Allocator settings for the zone studies (`sweep macro`, `sweep meso`), whose workers
/// allocate and free blocks of tens to hundreds of MB per case: one arena that keeps the
/// memory it frees and serves every block from its heap (no trimming, a 256 MB pad on every
/// heap growth, no `mmap` of large blocks) instead of glibc's defaults, which map each
/// large block afresh and return it to the system when freed, so every case faults its
/// memory in again. One arena, not one per worker: a thread's own arena grows by heaps of
/// at most 64 MiB and maps any larger block afresh whatever `M_MMAP_MAX` says (the contact
/// set's operator, a few hundred MB on the meso scenes, would be faulted in at every case).
/// On 24 layouts of the coupling-2 meso scene (2 workers, 2 cores) this takes a case from
/// 3.56 to 3.29 s, the page faults from 5.7 to 1.1 million and the peak RSS from 5,054 to
/// 4,401 MB against two arenas, with the same results to the bit; the other commands keep
/// glibc's defaults.
fn tune_allocator_for_studies() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only changes glibc's tunables; called before any worker starts.
    unsafe {
        libc::mallopt(libc::M_ARENA_MAX, 1);
        libc::mallopt(libc::M_TRIM_THRESHOLD, i32::MAX);
        libc::mallopt(libc::M_TOP_PAD, 256 << 20);
        libc::mallopt(libc::M_MMAP_MAX, 0);
    }
}

fn run() -> Result<()> {
    let cli = Cli::parse();
    if let Command::Sweep(sweep::SweepCmd::Macro(_) | sweep::SweepCmd::Meso(_)) = &cli.command {
        tune_allocator_for_studies();
    }
    opts::install_interrupt_handler();
    let registry = squeal::registry();
    match cli.command {
        Command::Modes(a) => a.run(&registry),
        Command::Validate(a) => a.run(&registry),
        Command::Equilibrium(a) => a.run(&registry),
        Command::Stability(a) => a.run(&registry),
        Command::Export(a) => a.run(&registry),
        Command::Bench(a) => a.run(&registry, &HEAP),
        Command::Sweep(s) => s.run(&registry),
        Command::Merge(a) => a.run(),
        Command::Calibrate(a) => a.run(&registry),
        Command::Plugins => {
            for (kind, list) in [
                ("material", registry.materials.describe()),
                ("contact law", registry.contact_laws.describe()),
                ("equilibrium", registry.equilibrium.describe()),
                ("basis", registry.bases.describe()),
                ("eigen", registry.eigen.describe()),
            ] {
                for (name, desc) in list {
                    println!("{kind:<12} {name:<24} {desc}");
                }
            }
            Ok(())
        }
        Command::Scene(s) => s.run(&registry),
    }
}
