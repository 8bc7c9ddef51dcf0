//! Running a spec: models × methods, each ordered once and measured with every cache model and
//! the view set, one CSV row per number.
//!
//! Models are handled one at a time (load, topology, then every method) so memory stays that of
//! the largest model. An animation (`PATH#clip=…`) is read and posed once and every method is
//! measured over its keyframes with the index buffers it picks per (keyframe, view) (Han & Sander
//! 2017, §4); so is a static model, as one frame, when a method of the spec gives several buffers,
//! so that all methods on it are measured the same way. Orderings run one after another so their
//! wall times are honest; only the rasterizer runs in parallel, inside one measurement. The CSV is
//! written atomically at the end: an interrupted run leaves the previous results untouched.

use std::path::{Path, PathBuf};

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::provenance;
use super::row::{Context, OrderRow, Row};
use super::spec::Spec;
use crate::error::{Error, Result};
use crate::eval::{MeasureOptions, evaluate, evaluate_nodes};
use crate::mesh::keyframes::Keyframes;
use crate::mesh::report::MeshReport;
use crate::mesh::source::{self, AnimationSource};
use crate::order;
use crate::topology::Topology;
use crate::{atomic, figure, raster};

/// How to run (and, for [`reproduce`], plot) experiments.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RunOptions {
    /// Run the spec's `[quick]` table: writes `results/quick/` and `paper-figures/quick/`.
    pub quick: bool,
    /// The data directory models are looked up in (else `TRIORDER_DATA`, else `../shared/data`).
    pub data: Option<PathBuf>,
    /// Progress bars on stderr (drawn only when stderr is a terminal).
    pub progress: bool,
    /// The project root: [`reproduce`] reads `experiments/` in it, and `results/` and
    /// `paper-figures/` are written under it.
    pub out_dir: PathBuf,
    /// Raster backend for every spec, overriding each spec's `backend` (`cpu` or `gpu`).
    pub backend: Option<String>,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions { quick: false, data: None, progress: false, out_dir: PathBuf::from("."), backend: None }
    }
}

/// Runs the spec at `spec` and writes its CSV; returns the CSV's path.
pub fn run(spec: &Path, opts: &RunOptions) -> Result<PathBuf> {
    let spec = Spec::load(spec)?;
    run_spec(&spec, opts, &bars(opts.progress))
}

/// Runs and plots every `experiments/*.toml` under `opts.out_dir` whose id contains `filter`, in
/// file-name order; returns each `(csv, svg)`. Every spec is loaded and checked before the first
/// one runs, so a typo in the last spec does not surface after an hour of work.
pub fn reproduce(opts: &RunOptions, filter: Option<&str>) -> Result<Vec<(PathBuf, PathBuf)>> {
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
    let mut gpu_specs = Vec::new();
    for spec in &specs {
        let work = spec.workload(opts.quick)?;
        if opts.backend.is_none() && (spec.backend == "gpu" || work.gpu_vertices || !spec.render.is_empty()) {
            gpu_specs.push(spec.id.clone());
        }
    }
    // Specs that ask for the GPU themselves are skipped, with a notice, where there is none, so
    // that every CPU experiment still runs on any machine (an explicit --backend gpu must work).
    let no_gpu = if gpu_specs.is_empty() { None } else { crate::gpu::shared().err() };
    let bars = bars(opts.progress);
    let overall = bars.add(ProgressBar::new(specs.len() as u64));
    overall.set_style(style("experiments {pos}/{len} {bar:30} {msg}"));
    let plot = figure::PlotOptions { quick: opts.quick, out_dir: opts.out_dir.clone(), data: opts.data.clone() };
    let mut outputs = Vec::new();
    for spec in &specs {
        overall.set_message(spec.id.clone());
        if let Some(why) = no_gpu.as_ref().filter(|_| gpu_specs.contains(&spec.id)) {
            overall.suspend(|| eprintln!("skipping {}: it needs a GPU ({why})", spec.id));
            overall.inc(1);
            continue;
        }
        let csv = run_spec(spec, opts, &bars)?;
        let svg = figure::plot_spec(spec, &plot)?;
        outputs.push((csv, svg));
        overall.inc(1);
    }
    overall.finish_and_clear();
    Ok(outputs)
}

/// Runs a loaded spec, showing its progress bar among `bars`.
fn run_spec(spec: &Spec, opts: &RunOptions, bars: &MultiProgress) -> Result<PathBuf> {
    let work = spec.workload(opts.quick)?;
    let data = source::data_dir(opts.data.as_deref());
    let models_key = if opts.quick { "quick.models" } else { "models" };
    for (i, model) in work.models.iter().enumerate() {
        check_model(spec, &format!("{models_key}[{i}]"), model, data.as_deref())?;
    }
    let methods = spec.methods.iter().map(|m| order::resolve(m, spec.seed)).collect::<Result<Vec<_>>>()?;
    let raster = raster::backend(opts.backend.as_deref().unwrap_or(&spec.backend))?;
    let measure = MeasureOptions {
        caches: work.caches.clone(),
        gpu_vertices: work.gpu_vertices,
        views: work.views,
        res: work.res,
        seed: spec.seed,
        render: spec.render.clone(),
        render_frames: spec.render_frames,
    };
    let context = Context {
        experiment: spec.id.clone(),
        seed: spec.seed,
        backend: raster.describe(),
        machine: provenance::machine(),
        commit: provenance::commit(),
        per_view: spec.figure.metrics.iter().any(|m| m == "ovr" || m.ends_with("_view")),
    };

    let bar = bars.add(ProgressBar::new((work.models.len() * methods.len()) as u64));
    bar.set_style(style("{prefix} {pos}/{len} {bar:30} {elapsed} {wide_msg}"));
    bar.set_prefix(spec.id.clone());
    let mut rows: Vec<Row> = Vec::new();
    let mut orders: Vec<OrderRow> = Vec::new();
    let save_orders = spec.figure.kind.draws_meshes();
    let per_node = methods.iter().any(|m| m.method.per_node);
    for model in &work.models {
        bar.set_message(format!("{model}: loading"));
        let animation = AnimationSource::parse(model).transpose()?;
        let (mesh, keyframes) = match &animation {
            Some(animation) => {
                let (mesh, keyframes) = animation.open(data.as_deref())?;
                (mesh, Some(keyframes))
            }
            None => {
                let mesh = source::open(model, data.as_deref(), spec.seed)?;
                let still = per_node.then(|| Keyframes::still(&mesh));
                (mesh, still)
            }
        };
        let topology = Topology::new(&mesh);
        for warning in MeshReport::new(&mesh, &topology).warnings() {
            bars.suspend(|| eprintln!("{model}: note: {warning}"));
        }
        for method in &methods {
            bar.set_message(format!("{model} · {}", method.canonical()));
            let name = method.method.name;
            if let Some(keyframes) = &keyframes {
                let evaluation = evaluate_nodes(&mesh, &topology, keyframes, method, &measure, raster.as_ref())?;
                rows.extend(context.node_rows(model, &mesh, name, &evaluation, animation.is_some()));
            } else {
                let evaluation = evaluate(&mesh, &topology, method, &measure, raster.as_ref())?;
                rows.extend(context.rows(model, &mesh, name, &evaluation));
                if save_orders {
                    let words = |values: &mut dyn Iterator<Item = String>| values.collect::<Vec<_>>().join(" ");
                    orders.push(OrderRow {
                        model: model.clone(),
                        method: evaluation.method.clone(),
                        order: words(&mut evaluation.order.iter().map(u32::to_string)),
                        clusters: words(&mut evaluation.cluster_starts.iter().map(usize::to_string)),
                    });
                }
            }
            bar.inc(1);
        }
    }
    bar.finish_and_clear();
    bars.remove(&bar);

    if save_orders {
        write_csv(&spec.orders_path(&opts.out_dir, opts.quick), &orders)?;
    }
    let path = spec.csv_path(&opts.out_dir, opts.quick);
    write_csv(&path, &rows)?;
    Ok(path)
}

/// Fails before any work if `model` cannot be opened, naming the spec key.
fn check_model(spec: &Spec, key: &str, model: &str, data: Option<&Path>) -> Result<()> {
    source::check(model, data).map_err(|e| Error::spec(&spec.path, format!("{key}: {e}")))
}

/// Writes `rows` as CSV to `path` atomically, creating its directory.
fn write_csv<T: serde::Serialize>(path: &Path, rows: &[T]) -> Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| Error::output(path, e))?;
    }
    atomic::write_with(path, |out| {
        let mut writer = csv::Writer::from_writer(out);
        for row in rows {
            writer.serialize(row).map_err(std::io::Error::other)?;
        }
        writer.flush()
    })
}

/// A progress-bar group on stderr, or a hidden one.
fn bars(progress: bool) -> MultiProgress {
    MultiProgress::with_draw_target(if progress { ProgressDrawTarget::stderr() } else { ProgressDrawTarget::hidden() })
}

fn style(template: &str) -> ProgressStyle {
    ProgressStyle::with_template(template).expect("progress templates are valid")
}
