//! Measuring orders: order a scene with a method and measure what it draws. One path serves
//! `eval`, `order` and every experiment, for a static mesh (one frame, one buffer) as for an
//! animation drawn with buffers picked per keyframe and view, so every number triorder prints is
//! computed the same way: [`evaluate`] orders and measures one method; a run orders each of a
//! model's methods ([`order_timed`]) and measures them together ([`measure_many`]), which gives
//! each order the values [`measure`] gives it but does the work that does not depend on the
//! order once (each view rasterized once for overdraw and translucency on the CPU).
//!
//! What is measured is a list of [`Metric`]s ([`METRICS`]). Each draws on the same [`Draws`]:
//! the scene's frames, the view set's cameras, and the buffer the method's lookup picks for each
//! (frame, view). Each reports [`Value`]s: a metric name, what it was measured under (cache model,
//! view set, view, clip, device) and the number. The CSV rows, `eval`'s table and its `--json`
//! lines are written from those values alone, and figures plot them by name.
//!
//! # Adding a metric
//! 1. Write `src/measure/NAME.rs` with a type implementing [`Metric`] and a `pub static METRIC`:
//!    [`Metric::names`] lists the names it reports, with an axis label and what a spec or command
//!    line must ask for to get it; [`Metric::reported`] says which of them the options ask for;
//!    [`Metric::measure`] returns them as [`Value`]s from the [`Draws`].
//! 2. Add `NAME` to the `registry!` list, which declares the module and lists it in [`METRICS`].
//!
//! That is all: `triorder eval` shows it (table and `--json`), every run writes its rows, and a
//! spec's figure may name it (`metric = "NAME"`). A metric that needs an option the command line
//! and specs do not have yet (views, caches, render shadings and the GPU switch exist) adds it to
//! [`MeasureOptions`] too.

use std::ops::Range;
use std::time::Instant;

pub use cache::{CacheModel, CacheStats, Corner};
pub use overdraw::OverdrawSummary;

use crate::error::{Error, Result};
use crate::gpu::render_time::Shading;
use crate::mesh::Scene;
use crate::mesh::frames::Kind;
use crate::order::{self, Orders, Resolved};
use crate::raster::{Camera, RasterBackend, ViewSet};

/// The registry: each entry declares its module and lists its `METRIC` in [`METRICS`].
macro_rules! registry {
    ($($module:ident),* $(,)?) => {
        $(pub mod $module;)*

        /// Every metric, in the order their values are reported (and their rows written).
        pub static METRICS: &[&dyn Metric] = &[$(&$module::METRIC),*];
    };
}

registry![cache, gpu_vertices, overdraw, render, translucency, meshlets];

/// The GPU vendors' cache models, which the `cache` metric simulates.
pub mod vendor;

/// What the ordering itself reports, beside the metrics: every row of a run also carries the
/// ordering's time, and runs that compare methods with several buffers say how many each needs.
pub static ORDERING: &[Name] = &[
    Name { name: "seconds", label: "ordering time (s)", needs: "nothing", optimum: None },
    Name {
        name: "buffers",
        label: "index buffers",
        needs: "an animation or a method with several buffers",
        optimum: None,
    },
    Name { name: "iterations", label: "optimization iterations", needs: "a method that iterates", optimum: None },
    Name { name: "clusters", label: "clusters in the order", needs: "a method that clusters", optimum: None },
    Name {
        name: "converged",
        label: "converged before the iteration cap (1) or not (0)",
        needs: "a method that iterates",
        optimum: None,
    },
];

/// Every name a run can report: the ordering's, then each metric's.
pub fn names() -> impl Iterator<Item = &'static Name> {
    ORDERING.iter().chain(METRICS.iter().flat_map(|m| m.names()))
}

/// The axis label of a reported name (the name itself if unknown).
pub fn label(name: &str) -> &str {
    names().find(|n| n.name == name).map_or(name, |n| n.label)
}

/// The optimum of a reported name (see [`Name::optimum`]); `None` if it has none or is unknown.
pub fn optimum(name: &str) -> Option<f64> {
    names().find(|n| n.name == name).and_then(|n| n.optimum)
}

/// A name a metric reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Name {
    /// The CSV `metric` value and `--json` key.
    pub name: &'static str,
    /// How an axis or a column is titled.
    pub label: &'static str,
    /// What a spec or command line must ask for to get it, for error messages.
    pub needs: &'static str,
    /// The best value it can take, where there is one a reader measures against (an overdraw
    /// ratio of 1, no blending error): figures mark it, and bars grow from it.
    pub optimum: Option<f64>,
}

/// A measurement of one kind: a vertex-cache model, overdraw, a GPU count or timing.
pub trait Metric: Sync {
    /// Every name it can report.
    fn names(&self) -> &'static [Name];

    /// The names it reports under `options`; empty when they do not ask for it.
    fn reported(&self, options: &MeasureOptions) -> Vec<&'static str>;

    /// Whether measuring it needs a GPU (so `reproduce` can skip it where there is none).
    fn needs_gpu(&self) -> bool {
        false
    }

    /// Measures `draws` (called only when [`Metric::reported`] is not empty).
    fn measure(&self, draws: &Draws) -> Result<Vec<Value>>;

    /// Measures several orders of one scene, drawn over the same frames with the same options
    /// and backend (one [`Draws`] per order): one list of values per order, each what
    /// [`Metric::measure`] gives for it. A metric whose work does not depend on the order (the
    /// rasterization behind overdraw) overrides it to do that work once.
    fn measure_many(&self, many: &[Draws]) -> Result<Vec<Vec<Value>>> {
        many.iter().map(|draws| self.measure(draws)).collect()
    }

    /// How `eval`'s table and `order`'s summary show its summary values (those of all frames and
    /// no single view): `(column title, cell)` pairs. By default one column per value.
    fn columns(&self, values: &[&Value]) -> Vec<(String, String)> {
        values.iter().map(|v| (v.title(), format!("{:.4}", v.value))).collect()
    }
}

/// What to measure.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct MeasureOptions {
    pub caches: Vec<CacheModel>,
    /// Also count vertex-shader invocations on the GPU (the cache entry [`GPU_CACHE`]).
    pub gpu_vertices: bool,
    /// Overdraw is measured only when a view set is given (it costs far more than the caches).
    pub views: Option<ViewSet>,
    pub res: u32,
    /// Seeds `random:N` view sets.
    pub seed: u64,
    /// Also time rendering on the GPU from every view, with each of these shaders.
    pub render: Vec<Shading>,
    /// Timed frames per view for `render`.
    pub render_frames: usize,
    /// Order each of the scene's draw calls on its own and measure them in sequence, as an
    /// engine draws an asset ([`order::draw_calls`]); otherwise the whole mesh, as the papers do.
    pub per_draw_call: bool,
    /// Also measure how wrong each order is for translucent rendering over the view set
    /// ([`translucency`]).
    pub translucency: bool,
    /// Also measure the meshlets each order makes ([`meshlets`]).
    pub meshlets: bool,
}

impl MeasureOptions {
    /// Whether any metric these options ask for runs on the GPU.
    pub fn needs_gpu(&self) -> bool {
        METRICS.iter().any(|m| m.needs_gpu() && !m.reported(self).is_empty())
    }

    /// The names a measurement under these options reports, besides the ordering's.
    pub fn reported(&self) -> Vec<&'static str> {
        METRICS.iter().flat_map(|m| m.reported(self)).collect()
    }
}

/// The cache entry, in `--cache` and a spec's `caches`, that counts the GPU's own vertex reuse
/// instead of simulating a model.
pub const GPU_CACHE: &str = "gpu";

/// The cache a value was measured with, as the CSV's `cache`, `cache_kind` and `cache_size`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CacheColumn {
    pub name: String,
    pub kind: &'static str,
    pub size: Option<u32>,
}

impl From<CacheModel> for CacheColumn {
    fn from(model: CacheModel) -> CacheColumn {
        CacheColumn { name: model.to_string(), kind: model.kind(), size: Some(model.size()) }
    }
}

/// One number a metric reports, with what it was measured under.
#[derive(Debug, Clone, PartialEq)]
pub struct Value {
    pub metric: &'static str,
    pub cache: Option<CacheColumn>,
    /// The view set and image size.
    pub views: Option<(ViewSet, u32)>,
    /// The view's index in the set (frame-major over an animation's frames), for per-view values.
    pub view: Option<usize>,
    /// The clip of an animation the value is about; `None` for all frames.
    pub clip: Option<String>,
    /// The level of a progressive mesh the value is about (a frame index).
    pub level: Option<usize>,
    /// The GPU that counted or timed it.
    pub device: Option<String>,
    pub value: f64,
}

impl Value {
    pub fn new(metric: &'static str, value: f64) -> Value {
        Value { metric, cache: None, views: None, view: None, clip: None, level: None, device: None, value }
    }

    /// A value of all frames (or one whole level) and no single view: what tables and summaries
    /// show.
    pub fn is_summary(&self) -> bool {
        self.view.is_none() && self.clip.is_none()
    }

    /// `metric cache views@res`: the value's default column title.
    pub fn title(&self) -> String {
        let mut title = self.metric.to_string();
        if let Some(cache) = &self.cache {
            title = format!("{title} {}", cache.name);
        }
        if let Some((views, res)) = self.views {
            title = format!("{title} {views}@{res}");
        }
        title
    }
}

/// What one evaluation draws: every frame of `frames` (all of the scene's, or one level of a
/// progressive mesh) from every camera of the view set, each draw with the buffer the method's
/// lookup picks for its frame and direction.
pub struct Draws<'a> {
    pub scene: &'a Scene,
    pub orders: &'a Orders,
    pub options: &'a MeasureOptions,
    pub raster: &'a dyn RasterBackend,
    /// The frames drawn.
    pub frames: Range<usize>,
    /// The view set's cameras, framed for the scene; empty without a view set.
    pub cameras: Vec<Camera>,
    /// Per frame of `frames`, per camera (frame-major): the buffer drawn.
    picks: Vec<usize>,
    /// How many draws use each buffer. Without a view set there are no draws, and each buffer
    /// counts as often as lookup cells of `frames` pick it.
    pub uses: Vec<u64>,
    /// Per buffer, a frame that draws it: whose triangles it orders.
    frame_of: Vec<usize>,
}

impl<'a> Draws<'a> {
    pub fn new(
        scene: &'a Scene,
        orders: &'a Orders,
        options: &'a MeasureOptions,
        raster: &'a dyn RasterBackend,
        frames: Range<usize>,
    ) -> Draws<'a> {
        let framing = scene.frames.framing;
        let cameras = options.views.map_or_else(Vec::new, |views| views.cameras(framing, options.seed));
        let lookup = &orders.lookup;
        let mut uses = vec![0u64; orders.buffers.len()];
        let mut frame_of = vec![frames.start; orders.buffers.len()];
        let mut picks = Vec::with_capacity(frames.len() * cameras.len());
        let mut pick = |f: usize, b: usize, uses: &mut Vec<u64>| {
            if uses[b] == 0 {
                frame_of[b] = f;
            }
            uses[b] += 1;
        };
        for f in frames.clone() {
            if cameras.is_empty() {
                let cells = lookup.cells_per_frame();
                let row = f.min(lookup.frames() - 1) * cells;
                lookup.cells()[row..row + cells].iter().for_each(|&b| pick(f, usize::from(b), &mut uses));
            } else {
                for camera in &cameras {
                    let b = lookup.buffer(f, camera.direction());
                    pick(f, b, &mut uses);
                    picks.push(b);
                }
            }
        }
        Draws { scene, orders, options, raster, frames, cameras, picks, uses, frame_of }
    }

    /// The view set and image size, when there are views.
    pub fn views(&self) -> Option<(ViewSet, u32)> {
        self.options.views.map(|v| (v, self.options.res))
    }

    /// The triangles of buffer `b`, in its draw order.
    pub fn triangles(&self, b: usize) -> Vec<[u32; 3]> {
        let frame = self.scene.frames.triangles(self.frame_of[b], &self.scene.mesh);
        self.orders.buffers[b].order.iter().map(|&t| frame[t as usize]).collect()
    }

    /// The buffers some draw uses, with how many draws use each.
    pub fn used(&self) -> impl Iterator<Item = (usize, u64)> + '_ {
        self.uses.iter().enumerate().filter(|(_, n)| **n > 0).map(|(b, &n)| (b, n))
    }

    /// The buffer drawn at frame `f` from camera `v`.
    pub fn pick(&self, f: usize, v: usize) -> usize {
        self.picks[(f - self.frames.start) * self.cameras.len() + v]
    }

    /// The views of frame `f` grouped by the buffer that draws them, in buffer order.
    pub fn groups(&self, f: usize) -> Vec<(usize, Vec<usize>)> {
        let views = self.cameras.len();
        let row = (f - self.frames.start) * views;
        let mut by_buffer: Vec<Vec<usize>> = vec![Vec::new(); self.orders.buffers.len()];
        for (v, &b) in self.picks[row..row + views].iter().enumerate() {
            by_buffer[b].push(v);
        }
        by_buffer.into_iter().enumerate().filter(|(_, g)| !g.is_empty()).collect()
    }

    /// The positions of frame `f`.
    pub fn positions(&self, f: usize) -> &[glam::Vec3] {
        &self.scene.frames.frames[f]
    }

    /// The clips whose values are reported on their own: each clip when an animation has several.
    pub fn clips(&self) -> &[(String, Range<usize>)] {
        let clips = &self.scene.frames.clips;
        if self.scene.frames.is_animation() && clips.len() > 1 { clips } else { &[] }
    }
}

/// The values one metric reported.
#[derive(Clone)]
pub struct Measured {
    pub metric: &'static dyn Metric,
    pub values: Vec<Value>,
}

impl std::fmt::Debug for Measured {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(&self.values).finish()
    }
}

impl Measured {
    /// The values about one level of a progressive mesh (`None`: values not about a level).
    pub fn at_level(&self, level: Option<usize>) -> Measured {
        Measured { metric: self.metric, values: self.values.iter().filter(|v| v.level == level).cloned().collect() }
    }

    /// How `eval`'s table shows these values: the metric's columns for its summary values.
    pub fn columns(&self) -> Vec<(String, String)> {
        let summaries: Vec<&Value> = self.values.iter().filter(|v| v.is_summary()).collect();
        if summaries.is_empty() { Vec::new() } else { self.metric.columns(&summaries) }
    }
}

/// One method's result on one scene.
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// The method spec with every parameter (canonical form).
    pub method: String,
    pub method_name: &'static str,
    pub peer: bool,
    /// Wall time of the ordering alone (posing the keyframes is loading, not ordering).
    pub seconds: f64,
    pub orders: Orders,
    /// What each metric the options ask for reported, in [`METRICS`] order.
    pub measured: Vec<Measured>,
}

impl Evaluation {
    /// Every value, metric by metric.
    pub fn values(&self) -> impl Iterator<Item = &Value> {
        self.measured.iter().flat_map(|m| &m.values)
    }

    /// The first summary value (all frames, no single view) named `metric`: with several cache
    /// models, the first model's.
    pub fn summary(&self, metric: &str) -> Option<f64> {
        self.values().find(|v| v.metric == metric && v.is_summary()).map(|v| v.value)
    }
}

/// Orders `scene` with `method` (timed) and measures the orders.
pub fn evaluate(
    scene: &Scene,
    method: &Resolved,
    options: &MeasureOptions,
    raster: &dyn RasterBackend,
) -> Result<Evaluation> {
    let ordered = order_timed(scene, method, options)?;
    let measured = measure(scene, &ordered.orders, options, raster)?;
    Ok(Evaluation { measured, ..ordered })
}

/// Orders `scene` with `method`, timed, as [`evaluate`] does: an evaluation with nothing
/// measured yet ([`measure_many`] measures several together).
pub fn order_timed(scene: &Scene, method: &Resolved, options: &MeasureOptions) -> Result<Evaluation> {
    let start = Instant::now();
    let orders =
        if options.per_draw_call { order::draw_calls::run(method, scene)? } else { order::run(method, scene)? };
    let seconds = start.elapsed().as_secs_f64() + orders.reused;
    Ok(Evaluation {
        method: method.canonical(),
        method_name: method.method.name,
        peer: method.method.peer,
        seconds,
        orders,
        measured: Vec::new(),
    })
}

/// Measures `orders` of `scene` with every metric `options` ask for.
pub fn measure(
    scene: &Scene,
    orders: &Orders,
    options: &MeasureOptions,
    raster: &dyn RasterBackend,
) -> Result<Vec<Measured>> {
    Ok(measure_many(scene, &[orders], options, raster)?.pop().expect("one order, one list"))
}

/// Measures several orders of `scene` (one per method compared) with every metric `options` ask
/// for: per order, what [`measure`] gives for it, but with the work that does not depend on the
/// order (rasterizing each view, for overdraw on the CPU) done once for all of them.
pub fn measure_many(
    scene: &Scene,
    orders: &[&Orders],
    options: &MeasureOptions,
    raster: &dyn RasterBackend,
) -> Result<Vec<Vec<Measured>>> {
    // A progressive mesh is measured level by level, every value naming its level.
    let parts: Vec<(Range<usize>, Option<usize>)> = match &scene.frames.kind {
        Kind::Levels(_) => (0..scene.frames.len()).map(|f| (f..f + 1, Some(f))).collect(),
        _ => vec![(0..scene.frames.len(), None)],
    };
    let draws: Vec<(Vec<Draws>, Option<usize>)> = parts
        .into_iter()
        .map(|(frames, level)| {
            let many = orders.iter().map(|o| Draws::new(scene, o, options, raster, frames.clone())).collect();
            (many, level)
        })
        .collect();
    let mut measured: Vec<Vec<Measured>> = vec![Vec::new(); orders.len()];
    for &metric in METRICS.iter().filter(|m| !m.reported(options).is_empty()) {
        let mut values: Vec<Vec<Value>> = vec![Vec::new(); orders.len()];
        for (many, level) in &draws {
            for (values, new) in values.iter_mut().zip(metric.measure_many(many)?) {
                values.extend(new.into_iter().map(|v| Value { level: *level, ..v }));
            }
        }
        for (measured, values) in measured.iter_mut().zip(values) {
            measured.push(Measured { metric, values });
        }
    }
    Ok(measured)
}

/// The backend named `name`: `cpu` (the reference) or `gpu` (opens the Vulkan device; fails with
/// advice when there is none).
pub fn backend(name: &str) -> Result<Box<dyn RasterBackend>> {
    check_backend_name(name)?;
    Ok(if name == "gpu" {
        Box::new(crate::gpu::raster::GpuRaster::new()?)
    } else {
        Box::new(crate::raster::cpu::CpuRaster)
    })
}

/// Checks a backend name without opening anything (specs are validated before any work).
pub fn check_backend_name(name: &str) -> Result<()> {
    match name {
        "cpu" | "gpu" => Ok(()),
        other => Err(Error::usage(format!("unknown raster backend `{other}` (available: cpu, gpu)"))),
    }
}
