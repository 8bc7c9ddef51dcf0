//! Running a spec: models × methods, each ordered once and measured with every cache model and
//! the view set, one CSV row per number.
//!
//! Models are handled one at a time (open, then every method) so memory stays that of the largest
//! model. Every model goes through the same path: a static mesh is one frame, an animation
//! (`PATH#clip=…`) its keyframes, and every method is measured over the frames with the index
//! buffers it picks per (frame, view) (Han & Sander 2017, §4). Orderings run one after another so
//! their wall times are honest; only the rasterizer runs in parallel, inside one measurement. The
//! CSV is written atomically at the end: an interrupted run leaves the previous results untouched.

use std::path::{Path, PathBuf};

use base64::Engine;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::provenance;
use super::spec::Spec;
use crate::atomic;
use crate::error::{Error, Result};
use crate::figure::spec::FigureKind;
use crate::measure::{self, Evaluation, cache};
use crate::mesh::{Mesh, Scene, source};
use crate::order::{self, Clustered};
use crate::raster::{cpu, views};
use crate::results::{Context, OrderRow, Row};

/// How to run experiments.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RunOptions {
    /// Run the spec's `[quick]` table: writes `results/quick/`.
    pub quick: bool,
    /// The data directory models are looked up in (else `TRIORDER_DATA`, else `../shared/data`).
    pub data: Option<PathBuf>,
    /// Progress bars on stderr (drawn only when stderr is a terminal).
    pub progress: bool,
    /// The project root: `results/` is written under it.
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

/// Runs a loaded spec, showing its progress bar among `bars`; returns the CSV's path.
pub fn run_spec(spec: &Spec, opts: &RunOptions, bars: &MultiProgress) -> Result<PathBuf> {
    let work = spec.workload(opts.quick)?;
    let data = source::data_dir(opts.data.as_deref());
    let models_key = if opts.quick { "quick.models" } else { "models" };
    for (i, model) in work.models.iter().enumerate() {
        model.source.check(data.as_deref()).map_err(|e| Error::spec(&spec.path, format!("{models_key}[{i}]: {e}")))?;
    }
    let methods = spec.methods.iter().map(|m| order::resolve(m, spec.seed)).collect::<Result<Vec<_>>>()?;
    let raster = measure::backend(opts.backend.as_deref().unwrap_or(&spec.backend))?;
    let options = spec.measure_options(work);
    let context = Context {
        experiment: spec.id.clone(),
        seed: spec.seed,
        backend: raster.describe(),
        machine: provenance::machine(),
        commit: provenance::commit(),
        per_view: spec.figure.metrics.iter().any(|m| m == "ovr" || m.ends_with("_view")),
    };
    // Buffer counts are reported where they can differ between the methods compared: for an
    // animation, and for every model when some method gives several buffers.
    let per_node = methods.iter().any(|m| m.method.per_node);

    let updates = if work.levels.is_empty() { 1 } else { spec.updates.len() };
    let bar = bars.add(ProgressBar::new((work.models.len() * methods.len() * updates) as u64));
    bar.set_style(style("{prefix} {pos}/{len} {bar:30} {elapsed} {wide_msg}"));
    bar.set_prefix(spec.id.clone());
    let mut rows: Vec<Row> = Vec::new();
    let mut orders: Vec<OrderRow> = Vec::new();
    for model in &work.models {
        bar.set_message(format!("{}: loading", model.name));
        let mut scene = model.source.open(data.as_deref(), spec.seed)?;
        for warning in scene.report().warnings() {
            bars.suspend(|| eprintln!("{}: note: {warning}", model.name));
        }
        if !work.levels.is_empty() {
            bar.set_message(format!("{}: simplifying", model.name));
            scene = scene.with_levels(&work.levels, spec.updates[0])?;
            if let Some(note) = scene.frames.levels().and_then(|l| l.note.as_ref()) {
                bars.suspend(|| eprintln!("{}: note: {note}", model.name));
            }
        }
        // Without levels the one update is never used.
        let updates = if work.levels.is_empty() { &spec.updates[..1] } else { &spec.updates[..] };
        for &update in updates {
            scene.set_update(update);
            for method in &methods {
                bar.set_message(format!("{} · {}", model.name, method.canonical()));
                let evaluation = measure::evaluate(&scene, method, &options, raster.as_ref())?;
                let buffers = per_node || scene.frames.is_animation();
                rows.extend(context.rows(&model.name, &model.source, &scene, &evaluation, buffers));
                if spec.figure.kind.draws_meshes() {
                    orders.extend(drawn(spec, &model.name, &scene, &evaluation, &options.caches)?);
                }
                bar.inc(1);
            }
        }
    }
    bar.finish_and_clear();
    bars.remove(&bar);

    if spec.figure.kind.draws_meshes() {
        write_csv(&spec.orders_path(&opts.out_dir, opts.quick), &orders)?;
    }
    let path = spec.csv_path(&opts.out_dir, opts.quick);
    write_csv(&path, &rows)?;
    Ok(path)
}

/// What a drawing of `evaluation` needs beyond the geometry: the order and its clusters, and for
/// the kinds that show a measurement, that measurement per drawn triangle or pixel, so figures
/// never replay the cache simulator or the rasterizer. One row, or one per level of a progressive
/// mesh (each level's order indexes that level's triangles).
fn drawn(
    spec: &Spec,
    model: &str,
    scene: &Scene,
    evaluation: &Evaluation,
    caches: &[measure::CacheModel],
) -> Result<Vec<OrderRow>> {
    let one_order =
        || order::needs_one_order(evaluation.method_name, "a drawing of the mesh in its order cannot show it");
    let Some(levels) = scene.frames.levels() else {
        let buffer = evaluation.orders.single().ok_or_else(one_order)?;
        return Ok(vec![drawn_one(spec, model, &scene.mesh, evaluation, buffer, caches)?]);
    };
    (0..levels.alive.len())
        .map(|f| {
            let mesh = Mesh { triangles: levels.triangles(f), ..scene.mesh.clone() };
            let buffer = evaluation.orders.buffers.get(f).ok_or_else(one_order)?;
            Ok(OrderRow {
                level: levels.fractions[f].to_string(),
                update: levels.update.name().to_string(),
                ..drawn_one(spec, model, &mesh, evaluation, buffer, caches)?
            })
        })
        .collect()
}

/// [`drawn`] for one buffer drawing `mesh`.
fn drawn_one(
    spec: &Spec,
    model: &str,
    mesh: &Mesh,
    evaluation: &Evaluation,
    buffer: &Clustered,
    caches: &[measure::CacheModel],
) -> Result<OrderRow> {
    let words = |values: &mut dyn Iterator<Item = String>| values.collect::<Vec<_>>().join(" ");
    let triangles = mesh.triangles_in_order(&buffer.order);
    let corners = match spec.figure.kind {
        FigureKind::Corners => caches
            .iter()
            .map(|&model| {
                let (_, classes) = cache::corners(model, &triangles, mesh.vertex_count());
                format!("{model}={}", OrderRow::encode_corners(&classes))
            })
            .collect::<Vec<_>>()
            .join(";"),
        _ => String::new(),
    };
    let overdraw = match spec.figure.kind {
        FigureKind::Overdraw => {
            let camera = views::drawing_camera(&mesh.positions, spec.figure.view);
            let shaded = cpu::shaded_per_pixel(&mesh.positions, &triangles, &camera, views::DRAWING_RES)?;
            base64::engine::general_purpose::STANDARD.encode(OrderRow::encode_counts(&shaded, views::DRAWING_RES)?)
        }
        _ => String::new(),
    };
    Ok(OrderRow {
        model: model.to_string(),
        method: evaluation.method.clone(),
        order: words(&mut buffer.order.iter().map(u32::to_string)),
        clusters: words(&mut buffer.starts.iter().map(usize::to_string)),
        corners,
        overdraw,
        level: String::new(),
        update: String::new(),
    })
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

/// A progress-bar group on stderr (drawn only when stderr is a terminal), or a hidden one.
pub fn bars(progress: bool) -> MultiProgress {
    MultiProgress::with_draw_target(if progress { ProgressDrawTarget::stderr() } else { ProgressDrawTarget::hidden() })
}

pub fn style(template: &str) -> ProgressStyle {
    ProgressStyle::with_template(template).expect("progress templates are valid")
}
