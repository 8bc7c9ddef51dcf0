//! `run`, `plot`, `reproduce` and `bench`: experiment specs to CSV to SVG, and speed vs meshopt.

use std::path::Path;

use triorder::experiment::shard::Shard;
use triorder::experiment::{self, Failure, RunOptions, provenance};
use triorder::figure::PlotOptions;
use triorder::mesh::{Source, source};
use triorder::reproduce;
use triorder::{Error, Result};
use triorder::{measure, raster};

use crate::{BenchPart, Common};

/// Options for `run`, `merge` and `reproduce`; an unknown backend fails here, before any spec runs.
fn run_options(quick: bool, backend: Option<String>, common: &Common) -> Result<RunOptions> {
    if let Some(name) = &backend {
        measure::check_backend_name(name)?;
    }
    Ok(RunOptions { quick, data: common.data.clone(), progress: true, backend, ..Default::default() })
}

pub fn run(spec: &Path, quick: bool, backend: Option<String>, shard: Option<&str>, common: &Common) -> Result<()> {
    let shard = shard.map(str::parse::<Shard>).transpose()?;
    let outcome = experiment::run(spec, &RunOptions { shard, ..run_options(quick, backend, common)? })?;
    let share = match shard {
        Some(shard) => format!(" (shard {shard}: {} of {} units)", outcome.units, outcome.total_units),
        None => String::new(),
    };
    if outcome.skipped {
        println!("{} is complete for this spec and version: skipped{share}", outcome.csv.display());
        return Ok(());
    }
    println!("wrote {}{share}", outcome.csv.display());
    print!("{}", failures(outcome.failures.iter().map(|f| ("", f)), &outcome.csv));
    Ok(())
}

pub fn merge(spec: &Path, quick: bool, shards: Option<usize>, common: &Common) -> Result<()> {
    let merged = experiment::merge(spec, &run_options(quick, None, common)?, shards)?;
    println!("wrote {} ({} rows from {} shards)", merged.csv.display(), merged.rows, merged.shards);
    Ok(())
}

/// What failed in a run and went on without, a line each (at most 20, then a count); empty when
/// nothing failed. `spec` prefixes each line in a reproduction (the spec's id).
fn failures<'a>(failed: impl Iterator<Item = (&'a str, &'a Failure)>, csv: &Path) -> String {
    let failed: Vec<_> = failed.collect();
    if failed.is_empty() {
        return String::new();
    }
    let models: std::collections::BTreeSet<&str> = failed.iter().map(|(_, f)| f.model.as_str()).collect();
    let mut out = format!(
        "{} failure(s) in {} model(s), recorded as `error` rows in {} (the run went on without them):\n",
        failed.len(),
        models.len(),
        csv.display()
    );
    const SHOWN: usize = 20;
    for (spec, f) in failed.iter().take(SHOWN) {
        let spec = if spec.is_empty() { String::new() } else { format!("{spec}: ") };
        let method = f.method.as_ref().map_or(String::new(), |m| format!("with {m}: "));
        let reason = f.reason.lines().next().unwrap_or_default();
        // Most reasons start with the file's path already.
        let model = if reason.contains(&f.model) { String::new() } else { format!("{}: ", f.model) };
        out += &format!("  {spec}{model}{method}{reason}\n");
    }
    if failed.len() > SHOWN {
        out += &format!("  … and {} more\n", failed.len() - SHOWN);
    }
    out
}

pub fn plot(spec: &Path, quick: bool, common: &Common) -> Result<()> {
    let svg = reproduce::plot(spec, &PlotOptions { quick, data: common.data.clone(), ..Default::default() })?;
    println!("wrote {}", svg.display());
    Ok(())
}

pub fn gallery(file: &Path, check: bool) -> Result<()> {
    let text = std::fs::read_to_string(file).map_err(|e| Error::input(file.display(), e))?;
    // Its CSVs are named from the project root: the folder above paper-figures/.
    let root = file.parent().and_then(Path::parent).filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let (fresh, sources) = triorder::figure::gallery::refresh(&text, root, file)?;
    if fresh == text {
        println!("{}: {} generated tables, all as their CSVs give them", file.display(), sources.len());
        return Ok(());
    }
    if check {
        return Err(Error::input(
            file.display(),
            "a generated table differs from its CSV; run `triorder gallery` to rewrite it",
        ));
    }
    triorder::atomic::write(file, fresh.as_bytes())?;
    println!("{}: rewrote {} generated tables from their CSVs", file.display(), sources.len());
    Ok(())
}

pub fn reproduce(
    quick: bool,
    only: Option<&str>,
    backend: Option<String>,
    cpu_only: bool,
    common: &Common,
) -> Result<()> {
    let outcome = reproduce::reproduce(&run_options(quick, backend, common)?, only, cpu_only)?;
    for ran in &outcome.ran {
        println!("wrote {} and {} ({:.1} s)", ran.csv.display(), ran.svg.display(), ran.seconds);
    }
    if let Some(gallery) = &outcome.gallery {
        println!("rewrote the generated tables of {} from the CSVs", gallery.display());
    }
    print!("{}", summary(&outcome, quick));
    Ok(())
}

/// What `reproduce` did, in a few lines: how many specs ran and which were skipped and why, the
/// GPU the GPU specs used, the time it took, and where the results are.
fn summary(outcome: &reproduce::Outcome, quick: bool) -> String {
    let total = outcome.ran.len() + outcome.skipped.len();
    let (minutes, seconds) = ((outcome.seconds / 60.0).floor(), outcome.seconds % 60.0);
    let mut out = format!(
        "\nreproduced {} of {total} specs in {minutes:.0} min {seconds:.0} s{}\n",
        outcome.ran.len(),
        if quick { " (quick: procedural models and assets/ only, small view sets)" } else { "" }
    );
    let mut slowest: Vec<&reproduce::Ran> = outcome.ran.iter().collect();
    slowest.sort_by(|a, b| b.seconds.total_cmp(&a.seconds));
    if slowest.len() > 1 {
        let five: Vec<String> = slowest.iter().take(5).map(|r| format!("{} {:.0} s", r.id, r.seconds)).collect();
        out += &format!("  slowest: {}\n", five.join(", "));
    }
    for (id, why) in &outcome.skipped {
        out += &format!("  skipped {id}: {why}\n");
    }
    out += &failures(
        outcome.failures.iter().map(|(id, f)| (id.as_str(), f)),
        Path::new(&format!("results{}/", if quick { "/quick" } else { "" })),
    );
    if let Some(device) = &outcome.device {
        out += &format!("  GPU specs ran on {device}\n");
    }
    let sub = if quick { "/quick" } else { "" };
    out += &format!(
        "  results in results{sub}/ (CSV), figures in paper-figures{sub}/ (SVG); paper-figures/README.md reads them\n"
    );
    out
}

/// The meshes `bench` times: the large shared models when a data directory exists, else a
/// procedural sphere of similar size and the bundled cow.
const BENCH_MODELS: [&str; 3] =
    ["models/bun_zipper.ply", "models/happy_buddha_100k.obj", "models/dragon_vrip_res2.ply"];
/// A row's spread as `low–high` (the quartiles of its per-round speedups), `-` without a peer.
fn spread(row: &triorder::experiment::bench::BenchRow) -> String {
    row.spread.map_or("-".to_string(), |(low, high)| format!("{low:.2}–{high:.2}"))
}

const BENCH_FALLBACK: [&str; 2] = ["sphere:100000", "assets/spot.obj"];

pub fn bench(reps: usize, meshes: &[String], only: Option<BenchPart>, common: &Common) -> Result<()> {
    let data = source::data_dir(common.data.as_deref());
    let defaults: &[&str] = if data.is_some() { &BENCH_MODELS } else { &BENCH_FALLBACK };
    let models: Vec<&str> =
        if meshes.is_empty() { defaults.to_vec() } else { meshes.iter().map(String::as_str).collect() };
    let scenes = models
        .iter()
        .map(|model| Source::parse(model)?.open(data.as_deref(), common.seed).map(|scene| (*model, scene)))
        .collect::<Result<Vec<_>>>()?;
    println!("machine: {}", provenance::machine());
    println!(
        "median of {reps} runs; speedup = meshopt time / our time (> 1: we are faster); spread = quartiles of the per-round speedups (ours and meshopt's take turns in each round)"
    );
    if only == Some(BenchPart::Backends) {
        let gpu = measure::backend("gpu")?;
        println!("\noverdraw counting, GPU backend vs CPU (ratio = GPU time / CPU time; < 1: the GPU is faster)");
        println!(
            "{:<28} {:>9}  {:<14} {:>10} {:>10} {:>8}  device",
            "mesh", "triangles", "views", "cpu ms", "gpu ms", "ratio"
        );
        for (model, scene) in &scenes {
            let r = triorder::experiment::bench::compare_backends(
                &scene.mesh,
                gpu.as_ref(),
                raster::ViewSet::Ico(162),
                512,
                reps,
            )?;
            println!(
                "{:<28} {:>9}  {:<14} {:>10.1} {:>10.1} {:>7.2}x  {}",
                model,
                r.triangles,
                format!("{}@{}", r.views, r.res),
                r.cpu_seconds * 1e3,
                r.gpu_seconds * 1e3,
                r.gpu_seconds / r.cpu_seconds,
                r.device
            );
        }
        return Ok(());
    }
    if only == Some(BenchPart::Progressive) {
        println!("\nprogressive meshes down to 1% of the triangles (speedup = meshopt time / ours)");
        println!(
            "{:<28} {:>9}  {:<36} {:>9} {:>10} {:>10} {:>8} {:>11}",
            "mesh", "triangles", "task", "removals", "ours ms", "meshopt ms", "speedup", "µs/removal"
        );
        for (model, scene) in &scenes {
            for r in triorder::experiment::bench::compare_progressive(scene, reps) {
                let theirs = r.meshopt_seconds.map_or("-".to_string(), |s| format!("{:.1}", s * 1e3));
                let speedup = r.meshopt_seconds.map_or("-".to_string(), |s| format!("{:.2}x", s / r.ours_seconds));
                println!(
                    "{:<28} {:>9}  {:<36} {:>9} {:>10.1} {:>10} {:>8} {:>11.3}",
                    model,
                    r.triangles,
                    r.task,
                    r.removals,
                    r.ours_seconds * 1e3,
                    theirs,
                    speedup,
                    r.ours_seconds * 1e6 / r.removals.max(1) as f64
                );
            }
        }
        return Ok(());
    }
    if only != Some(BenchPart::Orderings) {
        println!(
            "\n{:<28} {:>9}  {:<46} {:>10} {:>10} {:>8} {:>11}",
            "mesh", "triangles", "task", "ours ms", "meshopt ms", "speedup", "spread"
        );
        for (model, scene) in &scenes {
            for r in triorder::experiment::bench::compare(&scene.mesh, reps) {
                let theirs = r.meshopt_seconds.map_or("-".to_string(), |s| format!("{:.3}", s * 1e3));
                let speedup = r.speedup().map_or("-".to_string(), |s| format!("{s:.2}x"));
                println!(
                    "{:<28} {:>9}  {:<46} {:>10.3} {:>10} {:>8} {:>11}",
                    model,
                    r.triangles,
                    r.task,
                    r.ours_seconds * 1e3,
                    theirs,
                    speedup,
                    spread(&r)
                );
            }
        }
    }
    if only != Some(BenchPart::Metrics) {
        println!("\norderings on the input order as loaded; ACMR at fifo:16 (ratio = ours / meshopt)");
        println!(
            "{:<28} {:>9}  {:<46} {:>10} {:>10} {:>8} {:>11} {:>8} {:>8} {:>7}",
            "mesh", "triangles", "task", "ours ms", "meshopt ms", "speedup", "spread", "ACMR", "meshopt", "ratio"
        );
        for (model, scene) in &scenes {
            for r in triorder::experiment::bench::compare_orderings(scene, reps) {
                let (ours, theirs) = r.acmr.unwrap_or((f64::NAN, f64::NAN));
                println!(
                    "{:<28} {:>9}  {:<46} {:>10.3} {:>10.3} {:>7.2}x {:>11} {:>8.4} {:>8.4} {:>7.4}",
                    model,
                    r.triangles,
                    r.task,
                    r.ours_seconds * 1e3,
                    r.meshopt_seconds.unwrap_or(f64::NAN) * 1e3,
                    r.speedup().unwrap_or(f64::NAN),
                    spread(&r),
                    ours,
                    theirs,
                    ours / theirs
                );
            }
        }
    }
    Ok(())
}
