//! `reproduce` and `plot`: what drives both the runs ([`crate::experiment`]) and the figures
//! ([`crate::figure`]), so neither calls the other.

use std::path::{Path, PathBuf};
use std::time::Instant;

use indicatif::ProgressBar;

use crate::error::{Error, Result};
use crate::experiment::run::{RunMemo, bars, run_spec, style};
use crate::experiment::{RunOptions, Spec};
use crate::figure::{self, PlotOptions};

/// Draws the figure of the spec at `spec` from its results; returns the SVG's path.
pub fn plot(spec: &Path, opts: &PlotOptions) -> Result<PathBuf> {
    let spec = Spec::load(spec)?;
    figure::plot(&spec.chart(opts))
}

/// The device as the summary names it, saying when it is a software rasterizer.
fn describe(gpu: &crate::gpu::Gpu) -> String {
    let software = if gpu.is_software() { ", a software rasterizer: its times are the CPU's, not a GPU's" } else { "" };
    format!("{}{software}", gpu.describe())
}

/// One spec run and plotted: its id, CSV, SVG, and the wall time of both.
#[derive(Debug, Clone)]
pub struct Ran {
    pub id: String,
    pub csv: PathBuf,
    pub svg: PathBuf,
    pub seconds: f64,
}

/// What [`reproduce`] did.
#[derive(Debug, Clone, Default)]
pub struct Outcome {
    /// Each spec run and plotted, in the order run.
    pub ran: Vec<Ran>,
    /// Each spec skipped, and why.
    pub skipped: Vec<(String, String)>,
    /// The gallery whose generated tables were rewritten from the new CSVs, if there is one.
    pub gallery: Option<PathBuf>,
    /// Each model (and method) that failed in a spec, which went on without it: the spec's id and
    /// the failure.
    pub failures: Vec<(String, crate::experiment::Failure)>,
    /// The GPU the specs that needed one ran on, if any did.
    pub device: Option<String>,
    /// Wall time of the whole reproduction.
    pub seconds: f64,
}

/// Runs and plots every `experiments/*.toml` under `opts.out_dir` whose id contains `filter`, in
/// file-name order. Every spec is loaded and checked before the first one runs, so a typo in the
/// last spec does not surface after an hour of work. Specs that ask for the GPU themselves are
/// skipped, with the reason, where there is none, so every CPU experiment still runs on any
/// machine (an explicit `--backend gpu` must work); with `cpu_only` they are skipped wherever
/// they are, and no GPU is opened.
pub fn reproduce(opts: &RunOptions, filter: Option<&str>, cpu_only: bool) -> Result<Outcome> {
    let start = Instant::now();
    let dir = opts.out_dir.join("experiments");
    let entries =
        std::fs::read_dir(&dir).map_err(|e| Error::input(dir.display(), format!("cannot list experiments: {e}")))?;
    let mut paths = Vec::new();
    for entry in entries {
        let path = entry.map_err(|e| Error::input(dir.display(), e))?.path();
        if path.extension().is_some_and(|e| e == "toml") {
            paths.push(path);
        }
    }
    paths.sort();
    let all = paths.len();
    paths.retain(|p| filter.is_none_or(|f| p.file_stem().is_some_and(|s| s.to_string_lossy().contains(f))));
    if paths.is_empty() {
        let what = filter.map_or(String::new(), |f| format!(" matching `{f}` (of {all})"));
        return Err(Error::usage(format!("no experiment specs{what} in {}", dir.display())));
    }
    let specs = paths.iter().map(|p| Spec::load(p)).collect::<Result<Vec<_>>>()?;
    let gpu = |spec: &Spec| opts.backend.is_none() && spec.needs_gpu();
    let device = match specs.iter().any(gpu) {
        false => None,
        true if cpu_only => Some(Err("--cpu-only: none opened".to_string())),
        true => Some(crate::gpu::shared().map(describe).map_err(|e| e.to_string())),
    };
    let bars = bars(opts.progress);
    let overall = bars.add(ProgressBar::new(specs.len() as u64));
    overall.set_style(style("experiments {pos}/{len} {bar:30} {msg}"));
    // Orders and views' layers shared between specs, over the specs that will run.
    let mut memo =
        RunMemo::for_specs(specs.iter().filter(|s| !gpu(s) || device.as_ref().is_some_and(|d| d.is_ok())), opts)?;
    let plot = PlotOptions { quick: opts.quick, out_dir: opts.out_dir.clone(), data: opts.data.clone() };
    let mut outcome = Outcome::default();
    for spec in &specs {
        overall.set_message(spec.id.clone());
        if let Some(Err(why)) = device.as_ref().filter(|_| gpu(spec)) {
            overall.suspend(|| eprintln!("skipping {}: it needs a GPU ({why})", spec.id));
            outcome.skipped.push((spec.id.clone(), format!("it needs a GPU ({why})")));
            overall.inc(1);
            continue;
        }
        let spec_start = Instant::now();
        let run = run_spec(spec, opts, &bars, &mut memo)?;
        outcome.failures.extend(run.failures.into_iter().map(|f| (spec.id.clone(), f)));
        let svg = figure::plot(&spec.chart(&plot))?;
        outcome.ran.push(Ran { id: spec.id.clone(), csv: run.csv, svg, seconds: spec_start.elapsed().as_secs_f64() });
        overall.inc(1);
    }
    overall.finish_and_clear();
    // The gallery's generated tables follow the CSVs just written (a quick run writes elsewhere).
    let gallery = opts.out_dir.join("paper-figures/README.md");
    if !opts.quick && gallery.is_file() {
        let text = std::fs::read_to_string(&gallery).map_err(|e| Error::input(gallery.display(), e))?;
        let (fresh, _) = figure::gallery::refresh(&text, &opts.out_dir, &gallery)?;
        if fresh != text {
            crate::atomic::write(&gallery, fresh.as_bytes())?;
        }
        outcome.gallery = Some(gallery);
    }
    outcome.device = device.and_then(|d| d.ok());
    outcome.seconds = start.elapsed().as_secs_f64();
    Ok(outcome)
}
