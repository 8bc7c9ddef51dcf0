//! Running a spec: models × methods, each ordered once and measured with every cache model and
//! the view set, one CSV row per number.
//!
//! Models are handled one at a time (open, then every method) so memory stays that of the largest
//! model. Every model goes through the same path: a static mesh is one frame, an animation
//! (`PATH#clip=…`) its keyframes, and every method is measured over the frames with the index
//! buffers it picks per (frame, view) (Han & Sander 2017, §4). Orderings run one after another so
//! their wall times are honest; only measurements run in parallel (views, cache models, orders). The
//! CSV is written atomically at the end: an interrupted run leaves the previous results untouched.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use base64::Engine;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::corpus;
use super::provenance;
use super::shard::{self, Shard, Unit};
use super::spec::{Model, Spec};
use crate::atomic;
use crate::error::{Error, Result};
use crate::figure::spec::FigureKind;
use crate::measure::{self, Evaluation, cache};
use crate::mesh::progressive::Update;
use crate::mesh::scene::SharedWork;
use crate::mesh::{Mesh, Scene, source};
use crate::order::{self, Clustered, Orders, Resolved};
use crate::raster::kept::{KeptLayers, LayerMemo};
use crate::raster::{RasterBackend, cpu, views};
use crate::results::{COLUMNS, Context, ORDER_COLUMNS, OrderRow, Row};

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
    /// Run only this shard of the spec's units, into its own file ([`shard`]).
    pub shard: Option<Shard>,
}

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            quick: false,
            data: None,
            progress: false,
            out_dir: PathBuf::from("."),
            backend: None,
            shard: None,
        }
    }
}

/// What a run did.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// The file written: the results CSV, or the shard's file.
    pub csv: PathBuf,
    /// The units this run did, and how many the spec has.
    pub units: usize,
    pub total_units: usize,
    /// Each model that could not be loaded, or (model, method) that could not be ordered or
    /// measured; the CSV has an `error` row for each.
    pub failures: Vec<Failure>,
    /// The shard's file was already complete for this spec and version: nothing ran.
    pub skipped: bool,
}

/// A model, or a model and method, that failed; the run went on without it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Failure {
    pub model: String,
    /// `None` when the model itself could not be loaded.
    pub method: Option<String>,
    pub reason: String,
}

/// Runs the spec at `spec` and writes its CSV (or the shard's file).
pub fn run(spec: &Path, opts: &RunOptions) -> Result<Outcome> {
    let spec = Spec::load(spec)?;
    run_spec(&spec, opts, &bars(opts.progress), &mut RunMemo::default())
}

/// What one spec of a run computes and a later spec asks for again, kept between them:
/// - orders: the same model opened the same way (source, seed, levels, update), the same method
///   with the same parameters, under the same draw-call rule, which make the same orders. Several
///   specs order "all" methods on the same shared models; each order is computed once. A reused
///   order keeps the seconds it took when it was computed, its own time, as
///   [`crate::mesh::scene::SharedWork`] charges a reuse.
/// - views' depth layers ([`LayerMemo`]): the same model opened the same way, measured on the
///   CPU from the same view set at the same size. Six specs measure Soldier's keyframes from the
///   same 300 views, each with orders of its own; each view is rasterized once.
/// - a scene's shared work ([`crate::mesh::scene::SharedWork`]): the same model opened the same
///   way. hs17's rasterized (keyframe, viewpoint) nodes are named by frame, viewpoints and size,
///   and six specs run hs17 on Soldier's 91 keyframes from the same 162 viewpoints (two from 642):
///   each node is rasterized once instead of once a spec, and each reuse charged at what it cost.
///
/// `reproduce` runs every spec with one. Only what a later spec asks for is kept, each until the
/// last spec that asks for it has run.
#[derive(Default)]
pub struct RunMemo {
    orders: Claims,
    kept: HashMap<String, Evaluation>,
    views: Claims,
    layers: LayerMemo,
    scenes: Claims,
    work: HashMap<String, SharedWork>,
}

/// Per key, the specs still to run that ask for it; only keys two or more specs ask for.
#[derive(Default)]
struct Claims(HashMap<String, HashSet<String>>);

impl Claims {
    fn of(keys: impl IntoIterator<Item = (String, String)>) -> Claims {
        let mut claims: HashMap<String, HashSet<String>> = HashMap::new();
        for (key, spec) in keys {
            claims.entry(key).or_default().insert(spec);
        }
        claims.retain(|_, specs| specs.len() > 1);
        Claims(claims)
    }

    /// Whether a spec other than `spec` still to run asks for `key`.
    fn by_another(&self, key: &str, spec: &str) -> bool {
        self.0.get(key).is_some_and(|specs| specs.iter().any(|s| s != spec))
    }

    fn contains(&self, key: &str) -> bool {
        self.0.contains_key(key)
    }

    /// Forgets `spec`'s claims once it has run.
    fn finished(&mut self, spec: &str) {
        self.0.retain(|_, specs| {
            specs.remove(spec);
            !specs.is_empty()
        });
    }
}

impl RunMemo {
    /// A memo for running `specs` in turn under `opts`.
    pub fn for_specs<'s>(specs: impl IntoIterator<Item = &'s Spec>, opts: &RunOptions) -> Result<RunMemo> {
        let (mut orders, mut views, mut scenes) = (Vec::new(), Vec::new(), Vec::new());
        for spec in specs {
            let plan = Plan::new(spec, opts)?;
            for u in 0..plan.units.len() {
                orders.push((plan.key(spec, opts, u)?, spec.id.clone()));
            }
            for m in 0..plan.models.len() {
                views.extend(plan.view_key(spec, opts, m)?.map(|key| (key, spec.id.clone())));
                scenes.push((plan.scene_key(spec, opts, m)?, spec.id.clone()));
            }
        }
        Ok(RunMemo {
            orders: Claims::of(orders),
            views: Claims::of(views),
            scenes: Claims::of(scenes),
            ..RunMemo::default()
        })
    }

    /// The evaluation for `key` asked for by `spec`: the one kept, or what `order` gives, kept
    /// when a later spec asks for it too.
    fn order(&mut self, spec: &str, key: String, order: impl FnOnce() -> Result<Evaluation>) -> Result<Evaluation> {
        if let Some(kept) = self.kept.get(&key) {
            return Ok(kept.clone());
        }
        let evaluation = order()?;
        if self.orders.by_another(&key, spec) {
            self.kept.insert(key, evaluation.clone());
        }
        Ok(evaluation)
    }

    /// The CPU backend keeping views' layers under `key` (a [`Plan::view_key`]) when another spec
    /// asks for them; `None` when none does.
    fn kept_layers(&self, spec: &str, key: Option<String>) -> Option<KeptLayers<'_>> {
        let key = key.filter(|k| self.views.contains(k))?;
        Some(KeptLayers { memo: &self.layers, keep: self.views.by_another(&key, spec), tag: key })
    }

    /// Drops the layers kept under `key` once `spec` has measured its model with them and no
    /// later spec asks for them: the specs after it need not hold them (Soldier's take 1.8 GB).
    fn measured(&self, spec: &str, key: &str) {
        if !self.views.by_another(key, spec) {
            self.layers.retain(|k| k != key);
        }
    }

    /// The shared work an earlier spec kept for the scene `key` names (a [`Plan::scene_key`]), or
    /// none yet.
    fn scene_work(&mut self, key: &str) -> SharedWork {
        self.work.remove(key).unwrap_or_default()
    }

    /// Keeps `work`, done on the scene `key` names, when a later spec opens that scene too.
    fn keep_scene_work(&mut self, spec: &str, key: String, work: SharedWork) {
        if self.scenes.by_another(&key, spec) {
            self.work.insert(key, work);
        }
    }

    /// Forgets `spec`'s claims once it has run, dropping what no spec still to run asks for.
    fn finished(&mut self, spec: &str) {
        self.orders.finished(spec);
        self.views.finished(spec);
        self.scenes.finished(spec);
        self.kept.retain(|key, _| self.orders.contains(key));
        self.layers.retain(|key| self.views.contains(key));
        self.work.retain(|key, _| self.scenes.contains(key));
    }
}

/// What a run of a spec works through: its models (corpora expanded), methods and updates, the
/// units they make, and the fingerprint a shard records.
pub(crate) struct Plan<'a> {
    pub models: Vec<Model>,
    pub methods: Vec<Resolved>,
    pub updates: &'a [Update],
    pub units: Vec<Unit>,
    pub fingerprint: String,
}

impl<'a> Plan<'a> {
    /// The plan of `spec` under `opts`; every model the spec names itself must exist.
    pub fn new(spec: &'a Spec, opts: &RunOptions) -> Result<Plan<'a>> {
        let work = spec.workload(opts.quick)?;
        let data = source::data_dir(opts.data.as_deref());
        let key = if opts.quick { "quick.models" } else { "models" };
        let models = corpus::expand(&work.models, data.as_deref(), key).map_err(|e| Error::spec(&spec.path, e))?;
        let methods = spec.methods.iter().map(|m| order::resolve(m, spec.seed)).collect::<Result<Vec<_>>>()?;
        // Without levels the one update is never used.
        let updates = if work.levels.is_empty() { &spec.updates[..1] } else { &spec.updates[..] };
        let units = shard::units(models.len(), updates.len(), methods.len());
        let names: Vec<String> = models.iter().map(|m| m.name.clone()).collect();
        let fingerprint = shard::fingerprint(&spec.text, opts.quick, opts.backend.as_deref(), &names);
        Ok(Plan { models, methods, updates, units, fingerprint })
    }

    /// What makes unit `u`'s order ([`RunMemo`]): how its scene is opened and its method.
    fn key(&self, spec: &Spec, opts: &RunOptions, u: usize) -> Result<String> {
        let work = spec.workload(opts.quick)?;
        let unit = &self.units[u];
        Ok(format!(
            "{:?} seed {} levels {:?} update {:?} per draw call {} · {}",
            self.models[unit.model].source,
            spec.seed,
            work.levels,
            self.updates[unit.update],
            spec.measure_options(work).per_draw_call,
            self.methods[unit.method].canonical()
        ))
    }

    /// What names model `m`'s scene ([`RunMemo`]): how it is opened. Its shared work is named by
    /// what it depends on besides the scene.
    fn scene_key(&self, spec: &Spec, opts: &RunOptions, m: usize) -> Result<String> {
        let work = spec.workload(opts.quick)?;
        Ok(format!(
            "{:?} seed {} levels {:?} per draw call {}",
            self.models[m].source,
            spec.seed,
            work.levels,
            spec.measure_options(work).per_draw_call
        ))
    }

    /// What names model `m`'s views' layers when they are drawn on the CPU ([`RunMemo`]): how its
    /// scene is opened, and the view set, its seed and the image size; `None` without views or
    /// on another backend.
    fn view_key(&self, spec: &Spec, opts: &RunOptions, m: usize) -> Result<Option<String>> {
        let work = spec.workload(opts.quick)?;
        let options = spec.measure_options(work);
        let backend = opts.backend.as_deref().unwrap_or(&spec.backend);
        Ok(options.views.filter(|_| backend == "cpu").map(|views| {
            format!(
                "{:?} seed {} levels {:?} per draw call {} · {views:?} seed {} at {}²",
                self.models[m].source, spec.seed, work.levels, options.per_draw_call, options.seed, options.res
            )
        }))
    }

    /// The units `shard` does: those [`shard::assign`] gives it by estimated cost.
    fn share(&self, spec: &Spec, opts: &RunOptions, shard: Shard) -> Result<Vec<usize>> {
        let work = spec.workload(opts.quick)?;
        let data = source::data_dir(opts.data.as_deref());
        let options = spec.measure_options(work);
        let triangles: Vec<f64> =
            self.models.iter().map(|m| shard::estimated_triangles(&m.source, data.as_deref())).collect();
        let costs: Vec<f64> = self
            .units
            .iter()
            .map(|u| {
                shard::unit_cost(triangles[u.model], self.methods[u.method].method.cost, &options, work.levels.len())
            })
            .collect();
        let setup: Vec<f64> = triangles.iter().map(|&t| shard::setup_cost(t, work.levels.len())).collect();
        let shard_of = shard::assign(&self.units, &costs, &setup, shard.count);
        Ok((0..self.units.len()).filter(|&u| shard_of[u] == shard.index - 1).collect())
    }
}

/// Whether a failure is the model's or method's own, to be recorded while the run goes on,
/// rather than the machine's (no GPU, an unwritable output), which stops it.
fn recorded(e: &Error) -> bool {
    !matches!(e, Error::Gpu(_) | Error::Output { .. })
}

/// Runs a loaded spec, showing its progress bar among `bars`.
pub fn run_spec(spec: &Spec, opts: &RunOptions, bars: &MultiProgress, memo: &mut RunMemo) -> Result<Outcome> {
    let work = spec.workload(opts.quick)?;
    let data = source::data_dir(opts.data.as_deref());
    let plan = Plan::new(spec, opts)?;
    let csv = spec.csv_path(&opts.out_dir, opts.quick);
    let orders_csv = spec.orders_path(&opts.out_dir, opts.quick);
    let draws = spec.figure.kind.draws_meshes();
    let mine = match opts.shard {
        None => (0..plan.units.len()).collect(),
        Some(shard) => plan.share(spec, opts, shard)?,
    };
    let header = opts.shard.map(|shard| shard::Header {
        shard,
        spec: spec.id.clone(),
        fingerprint: plan.fingerprint.clone(),
        version: env!("CARGO_PKG_VERSION").to_string(),
        units: plan.units.len(),
        mine: mine.clone(),
    });
    let outcome = |csv: PathBuf, failures: Vec<Failure>, skipped: bool| Outcome {
        csv,
        units: mine.len(),
        total_units: plan.units.len(),
        failures,
        skipped,
    };
    if let (Some(header), Some(shard)) = (&header, opts.shard) {
        let done = |path: &Path| Ok::<_, Error>(shard::Header::read(path).ok().flatten().as_ref() == Some(header));
        if done(&shard::path(&csv, shard))? && (!draws || done(&shard::path(&orders_csv, shard))?) {
            return Ok(outcome(shard::path(&csv, shard), Vec::new(), true));
        }
    }
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
    let per_node = plan.methods.iter().any(|m| m.method.per_node);

    let bar = bars.add(ProgressBar::new(mine.len() as u64));
    bar.set_style(style("{prefix} {pos}/{len} {bar:30} {elapsed} {wide_msg}"));
    bar.set_prefix(match opts.shard {
        Some(shard) => format!("{} shard {shard}", spec.id),
        None => spec.id.clone(),
    });
    let mut rows: Vec<(usize, Row)> = Vec::new();
    let mut orders_rows: Vec<(usize, OrderRow)> = Vec::new();
    let mut failures: Vec<Failure> = Vec::new();
    let per_model = plan.updates.len() * plan.methods.len();
    for (m, model) in plan.models.iter().enumerate() {
        let todo: Vec<usize> = mine.iter().copied().filter(|&u| plan.units[u].model == m).collect();
        let Some(&first) = todo.first() else { continue };
        let failed = failures.len();
        bar.set_message(format!("{}: loading", model.name));
        let scene = match open(spec, model, &work.levels, data.as_deref(), bars) {
            Ok(scene) => scene,
            Err(e) if recorded(&e) => {
                let reason = e.to_string();
                // One row per model, written by the run that has its first unit, so that the
                // shards of a run together hold what the unsharded run holds.
                if first == m * per_model {
                    rows.push((first, context.error_row(&model.name, &model.source, None, &reason)));
                }
                failures.push(Failure { model: model.name.clone(), method: None, reason });
                bar.inc(todo.len() as u64);
                continue;
            }
            Err(e) => return Err(e),
        };
        let mut scene = scene;
        let scene_key = plan.scene_key(spec, opts, m)?;
        scene.shared = memo.scene_work(&scene_key);
        // The methods of one update are ordered one by one, then measured together, so that the
        // work every order shares (each view rasterized once for overdraw) is done once.
        let view_key = plan.view_key(spec, opts, m)?;
        for batch in todo.chunk_by(|&a, &b| plan.units[a].update == plan.units[b].update) {
            scene.set_update(plan.updates[plan.units[batch[0]].update]);
            let mut ordered: Vec<(usize, Evaluation)> = Vec::new();
            for &u in batch {
                let method = &plan.methods[plan.units[u].method];
                bar.set_message(format!("{} · {}", model.name, method.canonical()));
                let key = plan.key(spec, opts, u)?;
                match memo.order(&spec.id, key, || measure::order_timed(&scene, method, &options)) {
                    Ok(evaluation) => ordered.push((u, evaluation)),
                    Err(e) => {
                        failed_unit(e, model, method, &context, (u, &mut rows), &mut failures)?;
                        bar.inc(1);
                    }
                }
            }
            bar.set_message(format!("{}: measuring {} orders", model.name, ordered.len()));
            let orders: Vec<&Orders> = ordered.iter().map(|(_, e)| &e.orders).collect();
            // Measured together, or where that fails, one by one, so a failure is the method's.
            let kept = memo.kept_layers(&spec.id, view_key.clone());
            let raster: &dyn RasterBackend = match &kept {
                Some(kept) if raster.name() == "cpu" => kept,
                _ => raster.as_ref(),
            };
            let together = measure::measure_many(&scene, &orders, &options, raster);
            let together: Vec<Result<_>> = together
                .map(|m| m.into_iter().map(Ok).collect())
                .unwrap_or_else(|_| orders.iter().map(|o| measure::measure(&scene, o, &options, raster)).collect());
            for ((u, mut evaluation), measured) in ordered.into_iter().zip(together) {
                let method = &plan.methods[plan.units[u].method];
                let result = measured.and_then(|measured| {
                    evaluation.measured = measured;
                    let buffers = per_node || scene.frames.is_animation();
                    let drawn = if draws {
                        drawn(spec, &model.name, &scene, &evaluation, &options.caches)?
                    } else {
                        Vec::new()
                    };
                    Ok((context.rows(&model.name, &model.source, &scene, &evaluation, buffers), drawn))
                });
                match result {
                    Ok((new_rows, drawn)) => {
                        rows.extend(new_rows.into_iter().map(|r| (u, r)));
                        orders_rows.extend(drawn.into_iter().map(|o| (u, o)));
                    }
                    Err(e) => failed_unit(e, model, method, &context, (u, &mut rows), &mut failures)?,
                }
                bar.inc(1);
            }
        }
        if let Some(key) = &view_key {
            memo.measured(&spec.id, key);
        }
        memo.keep_scene_work(&spec.id, scene_key, std::mem::take(&mut scene.shared));
        if failures.len() > failed {
            bar.set_prefix(format!(
                "{} ({} failed)",
                bar.prefix().split(" (").next().unwrap_or_default(),
                failures.len()
            ));
        }
    }
    bar.finish_and_clear();
    bars.remove(&bar);
    memo.finished(&spec.id);
    // In unit order (a batch's ordering failures were recorded before its measured rows).
    rows.sort_by_key(|(u, _)| *u);
    orders_rows.sort_by_key(|(u, _)| *u);

    let written = match (&header, opts.shard) {
        (Some(header), Some(shard)) => {
            if draws {
                shard::write(&shard::path(&orders_csv, shard), header, ORDER_COLUMNS, &orders_rows)?;
            }
            let path = shard::path(&csv, shard);
            shard::write(&path, header, COLUMNS, &rows)?;
            path
        }
        _ => {
            if draws {
                write_csv(&orders_csv, orders_rows.iter().map(|(_, o)| o))?;
            }
            write_csv(&csv, rows.iter().map(|(_, r)| r))?;
            csv
        }
    };
    Ok(outcome(written, failures, false))
}

/// `error`, met ordering or measuring `method` on `model` (unit `u`): written as the unit's error
/// row and listed among the failures when a run records it (a problem of that input), passed on
/// otherwise.
fn failed_unit(
    error: Error,
    model: &Model,
    method: &Resolved,
    context: &Context,
    (u, rows): (usize, &mut Vec<(usize, Row)>),
    failures: &mut Vec<Failure>,
) -> Result<()> {
    if !recorded(&error) {
        return Err(error);
    }
    let reason = error.to_string();
    rows.push((u, context.error_row(&model.name, &model.source, Some(method), &reason)));
    failures.push(Failure { model: model.name.clone(), method: Some(method.canonical()), reason });
    Ok(())
}

/// Opens `model` for a run: loads or builds it, says what its report warns of, and simplifies it
/// into `levels` when the spec measures progressive levels.
fn open(spec: &Spec, model: &Model, levels: &[f64], data: Option<&Path>, bars: &MultiProgress) -> Result<Scene> {
    let mut scene = model.source.open(data, spec.seed)?;
    for warning in scene.report().warnings() {
        bars.suspend(|| eprintln!("{}: note: {warning}", model.name));
    }
    if !levels.is_empty() {
        scene = scene.with_levels(levels, spec.updates[0])?;
        if let Some(note) = scene.frames.levels().and_then(|l| l.note.as_ref()) {
            bars.suspend(|| eprintln!("{}: note: {note}", model.name));
        }
    }
    Ok(scene)
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
            let camera = views::drawing_camera(&mesh.positions, spec.figure.view, spec.figure.up);
            let shaded = cpu::shaded_per_pixel(&mesh.positions, &triangles, &camera, views::DRAWING_RES)?;
            base64::engine::general_purpose::STANDARD.encode(OrderRow::encode_counts(&shaded, views::DRAWING_RES)?)
        }
        _ => String::new(),
    };
    let translucency = match spec.figure.kind {
        FigureKind::Translucency => {
            let camera = views::drawing_camera(&mesh.positions, spec.figure.view, spec.figure.up);
            let mut fragments = Vec::new();
            cpu::fragments(&mesh.positions, &triangles, &camera, views::DRAWING_RES, &mut fragments)?;
            let picture = measure::translucency::error_picture(&fragments, &buffer.order, views::DRAWING_RES);
            base64::engine::general_purpose::STANDARD.encode(OrderRow::encode_counts(&picture, views::DRAWING_RES)?)
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
        translucency,
        level: String::new(),
        update: String::new(),
    })
}

/// Writes `rows` as CSV to `path` atomically, creating its directory.
fn write_csv<'r, T: serde::Serialize + 'r>(path: &Path, rows: impl IntoIterator<Item = &'r T>) -> Result<()> {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn evaluation(seconds: f64) -> Evaluation {
        Evaluation {
            method: "input".into(),
            method_name: "input",
            peer: false,
            seconds,
            orders: Orders::from(vec![0u32, 1]),
            measured: Vec::new(),
        }
    }

    /// An order is kept for the later specs that ask for it, with its first seconds, and for
    /// nothing else; once they have run it is gone.
    #[test]
    fn a_memo_keeps_an_order_only_for_the_later_specs_that_ask_for_it() {
        let claims = [("k", "a"), ("k", "b"), ("alone", "a")].map(|(k, s)| (k.to_string(), s.to_string()));
        let mut memo = RunMemo { orders: Claims::of(claims), ..RunMemo::default() };
        let mut computed = 0;
        let mut order = |memo: &mut RunMemo, spec: &str, key: &str, seconds: f64| {
            memo.order(spec, key.to_string(), || {
                computed += 1;
                Ok(evaluation(seconds))
            })
            .unwrap()
            .seconds
        };
        assert_eq!(order(&mut memo, "a", "k", 1.0), 1.0);
        assert_eq!(order(&mut memo, "a", "alone", 2.0), 2.0);
        assert_eq!(memo.kept.len(), 1);
        memo.finished("a");
        assert_eq!(order(&mut memo, "b", "k", 3.0), 1.0);
        memo.finished("b");
        assert!(memo.kept.is_empty() && !memo.orders.contains("k"));
        assert_eq!(computed, 2);
    }

    /// A scene's shared work goes to the later spec that opens the same scene, with what computing
    /// it cost, and to no other; once the last spec that opens it has run it is gone.
    #[test]
    fn a_memo_hands_a_scenes_work_to_the_later_specs_that_open_it() {
        let claims = [("s", "a"), ("s", "b"), ("t", "a")].map(|(k, s)| (k.to_string(), s.to_string()));
        let mut memo = RunMemo { scenes: Claims::of(claims), ..RunMemo::default() };
        for (scene, value) in [("s", 7), ("t", 8)] {
            let work = memo.scene_work(scene);
            assert!(work.get_or_compute::<u32, ()>("nodes", || Ok(value)).unwrap().1.is_none());
            memo.keep_scene_work("a", scene.to_string(), work);
        }
        assert_eq!(memo.work.len(), 1, "kept for the scene b opens only");
        memo.finished("a");
        let work = memo.scene_work("s");
        let (value, reused) = work.get_or_compute::<u32, ()>("nodes", || panic!("computed again")).unwrap();
        assert_eq!((*value, reused.is_some()), (7, true));
        memo.keep_scene_work("b", "s".to_string(), work);
        assert!(memo.work.is_empty(), "b is the last spec that opens it");
        memo.finished("b");
        assert!(memo.scene_work("s").get_or_compute::<u32, ()>("nodes", || Ok(9)).unwrap().1.is_none());
    }

    /// Views' layers are kept under a key while a later spec asks for it: the first spec's
    /// measurement keeps them, the last one's reads them without keeping more, a key one spec
    /// alone asks for gets the plain backend.
    #[test]
    fn a_memo_keeps_layers_only_while_a_later_spec_asks_for_them() {
        let claims = [("v", "a"), ("v", "b"), ("w", "a")].map(|(k, s)| (k.to_string(), s.to_string()));
        let mut memo = RunMemo { views: Claims::of(claims), ..RunMemo::default() };
        assert!(memo.kept_layers("a", Some("w".into())).is_none());
        assert!(memo.kept_layers("a", None).is_none());
        let mesh = crate::mesh::procedural::generate("sphere:500", 0).unwrap().unwrap();
        let cameras = views::ViewSet::Ico(12).cameras(crate::mesh::Framing::of(&mesh.positions), 0);
        let order: Vec<u32> = (0..mesh.triangles.len() as u32).collect();
        let (orders, picks) = (vec![&order[..]], vec![vec![0]; cameras.len()]);
        let draws = crate::raster::OrderPicks { triangles: &mesh.triangles, orders: &orders, picks: &picks };
        let measure = |kept: KeptLayers| kept.count_orders(&mesh.positions, &cameras, &draws, 32).unwrap();
        let kept = memo.kept_layers("a", Some("v".into())).unwrap();
        assert!(kept.keep && kept.tag == "v");
        measure(kept);
        memo.measured("a", "v");
        let held = memo.layers.bytes();
        assert!(held > 0, "kept for b");
        memo.finished("a");
        let kept = memo.kept_layers("b", Some("v".into())).unwrap();
        assert!(!kept.keep);
        measure(kept);
        assert_eq!(memo.layers.bytes(), held, "b reads what a kept");
        memo.measured("b", "v");
        assert_eq!(memo.layers.bytes(), 0, "dropped once the last spec that asks has measured");
        memo.finished("b");
        assert!(memo.kept_layers("b", Some("v".into())).is_none());
    }
}
