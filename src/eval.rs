//! Order a mesh with a method and measure the result: the one code path `eval`, `order` and
//! experiments share, so every number triorder prints is computed the same way.

use std::time::Instant;

use crate::error::{Error, Result};
use crate::gpu::render_time::{self, Shading, Timing};
use crate::gpu::vertex_reuse;
use crate::mesh::Mesh;
use crate::mesh::keyframes::Keyframes;
use crate::metrics::{CacheModel, CacheStats, OverdrawSummary, cache};
use crate::order::{self, NodeOrders, Order, OrderInput, Resolved};
use crate::raster::{Framing, RasterBackend, ViewCounts, ViewSet};
use crate::topology::Topology;

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
}

/// Render times of one draw order on the GPU, per view of the overdraw view set.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderTime {
    pub shading: Shading,
    /// The device and driver that rendered.
    pub device: String,
    /// Median frame time per view (with its 10th and 90th percentiles).
    pub per_view: Vec<Timing>,
}

impl RenderTime {
    /// Mean over views of the median frame time, in milliseconds.
    pub fn mean_ms(&self) -> f64 {
        self.per_view.iter().map(|t| t.median_ms).sum::<f64>() / self.per_view.len().max(1) as f64
    }

    /// Mean over views of the spread of frame times (90th minus 10th percentile), in milliseconds.
    pub fn spread_ms(&self) -> f64 {
        self.per_view.iter().map(|t| t.p90_ms - t.p10_ms).sum::<f64>() / self.per_view.len().max(1) as f64
    }
}

/// The cache entry, in `--cache` and a spec's `caches`, that counts the GPU's own vertex reuse
/// instead of simulating a model.
pub const GPU_CACHE: &str = "gpu";

/// Vertex reuse counted on a GPU.
#[derive(Debug, Clone, PartialEq)]
pub struct GpuVertices {
    /// The device and driver that counted.
    pub device: String,
    /// Misses are vertex-shader invocations.
    pub stats: CacheStats,
}

/// Overdraw of one order over a view set.
#[derive(Debug, Clone, PartialEq)]
pub struct Overdraw {
    pub views: ViewSet,
    pub res: u32,
    pub per_view: Vec<ViewCounts>,
    /// `None` when no view sees any front face.
    pub summary: Option<OverdrawSummary>,
}

/// The metrics of one draw order.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    pub caches: Vec<(CacheModel, CacheStats)>,
    pub gpu_vertices: Option<GpuVertices>,
    pub overdraw: Option<Overdraw>,
    pub render: Vec<RenderTime>,
}

/// Measures the draw order `order` of `mesh`.
pub fn measure(
    mesh: &Mesh,
    order: &[u32],
    options: &MeasureOptions,
    raster: &dyn RasterBackend,
) -> Result<Measurement> {
    let triangles = mesh.triangles_in_order(order);
    let caches =
        options.caches.iter().map(|&model| (model, cache::simulate(model, &triangles, mesh.vertex_count()))).collect();
    let gpu_vertices = if options.gpu_vertices {
        let counter = vertex_reuse::shared()?;
        Some(GpuVertices { device: counter.device(), stats: counter.count(&mesh.positions, &triangles)? })
    } else {
        None
    };
    let framed = options.views.map(|views| (views, views.cameras(Framing::of(&mesh.positions), options.seed)));
    let overdraw = match &framed {
        None => None,
        Some((views, cameras)) => {
            let per_view = raster.count(&mesh.positions, &triangles, cameras, options.res)?;
            let summary = OverdrawSummary::of(&per_view);
            Some(Overdraw { views: *views, res: options.res, per_view, summary })
        }
    };
    let mut render = Vec::new();
    if !options.render.is_empty() {
        let (_, cameras) = framed.ok_or_else(|| Error::usage("render timing needs a view set (--views)"))?;
        let timer = render_time::shared()?;
        for &shading in &options.render {
            let per_view = cameras
                .iter()
                .map(|camera| {
                    timer.time(&mesh.positions, &triangles, camera, options.res, shading, options.render_frames)
                })
                .collect::<Result<_>>()?;
            render.push(RenderTime { shading, device: timer.device(), per_view });
        }
    }
    Ok(Measurement { caches, gpu_vertices, overdraw, render })
}

/// One method's result on one mesh.
#[derive(Debug, Clone)]
pub struct Evaluation {
    /// The method spec with every parameter (canonical form).
    pub method: String,
    pub peer: bool,
    /// Wall time of the ordering alone.
    pub seconds: f64,
    pub order: Order,
    /// Where the order's clusters start, ending with its length (`[0, n]` for methods without
    /// clusters).
    pub cluster_starts: Vec<usize>,
    pub measurement: Measurement,
}

/// Orders `mesh` with `method` (timed) and measures the order.
pub fn evaluate(
    mesh: &Mesh,
    topology: &Topology,
    method: &Resolved,
    options: &MeasureOptions,
    raster: &dyn RasterBackend,
) -> Result<Evaluation> {
    let start = Instant::now();
    let clustered = order::run_clustered(method, &OrderInput { mesh, topology })?;
    let seconds = start.elapsed().as_secs_f64();
    let measurement = measure(mesh, &clustered.order, options, raster)?;
    Ok(Evaluation {
        method: method.canonical(),
        peer: method.method.peer,
        seconds,
        order: clustered.order,
        cluster_starts: clustered.starts,
        measurement,
    })
}

/// The overdraw of one clip (or, with `clip` `None`, of every frame) over keyframes × views.
#[derive(Debug, Clone, PartialEq)]
pub struct ClipOverdraw {
    pub clip: Option<String>,
    /// `per_view` is frame-major: keyframe × view.
    pub overdraw: Overdraw,
}

/// The metrics of index buffers drawn per (keyframe, view) as their lookup picks, measured as Han
/// & Sander 2017 §4 do: every keyframe from every view of the set, each draw with its buffer.
#[derive(Debug, Clone, PartialEq)]
pub struct NodeMeasurement {
    /// Per cache model: ACMR and ATVR averaged over the draws, each draw counting its buffer's
    /// ratio (so a buffer the lookup never picks costs nothing). Without a view set there are no
    /// draws, and each buffer counts as often as lookup cells pick it.
    pub caches: Vec<(CacheModel, f64, f64)>,
    /// All frames first, then each clip when there are several; empty without a view set.
    pub overdraw: Vec<ClipOverdraw>,
}

/// Measures `nodes`, index buffers for `mesh`'s triangles, over the framed `keyframes`.
pub fn measure_nodes(
    mesh: &Mesh,
    keyframes: &Keyframes,
    nodes: &NodeOrders,
    options: &MeasureOptions,
    raster: &dyn RasterBackend,
) -> Result<NodeMeasurement> {
    if options.gpu_vertices || !options.render.is_empty() {
        return Err(Error::usage(format!(
            "the `{GPU_CACHE}` cache and render timing measure one index buffer on the GPU: measure a static mesh with a static method"
        )));
    }
    let mut uses = vec![0u64; nodes.buffers.len()];
    let mut overdraw = Vec::new();
    if let Some(views) = options.views {
        let cameras = views.cameras(keyframes.framing(), options.seed);
        let mut per_view = vec![ViewCounts::default(); keyframes.len() * cameras.len()];
        for (f, positions) in keyframes.frames.iter().enumerate() {
            let mut by_buffer: Vec<Vec<usize>> = vec![Vec::new(); nodes.buffers.len()];
            for (v, camera) in cameras.iter().enumerate() {
                by_buffer[nodes.lookup.buffer(f, camera.eye)].push(v);
            }
            for (b, group) in by_buffer.iter().enumerate().filter(|(_, g)| !g.is_empty()) {
                uses[b] += group.len() as u64;
                let triangles = mesh.triangles_in_order(&nodes.buffers[b]);
                let group_cameras: Vec<_> = group.iter().map(|&v| cameras[v]).collect();
                let counts = raster.count(positions, &triangles, &group_cameras, options.res)?;
                for (&v, c) in group.iter().zip(counts) {
                    per_view[f * cameras.len() + v] = c;
                }
            }
        }
        let summary = |clip: Option<String>, frames: std::ops::Range<usize>| {
            let per_view = per_view[frames.start * cameras.len()..frames.end * cameras.len()].to_vec();
            let summary = OverdrawSummary::of(&per_view);
            ClipOverdraw { clip, overdraw: Overdraw { views, res: options.res, per_view, summary } }
        };
        overdraw.push(summary(None, 0..keyframes.len()));
        if keyframes.clips.len() > 1 {
            overdraw.extend(keyframes.clips.iter().map(|(name, frames)| summary(Some(name.clone()), frames.clone())));
        }
    } else {
        for &b in nodes.lookup.cells() {
            uses[usize::from(b)] += 1;
        }
    }
    let total = uses.iter().sum::<u64>() as f64;
    let caches = options
        .caches
        .iter()
        .map(|&model| {
            let (mut acmr, mut atvr) = (0.0, 0.0);
            for (buffer, &n) in nodes.buffers.iter().zip(&uses).filter(|(_, n)| **n > 0) {
                let stats = cache::simulate(model, &mesh.triangles_in_order(buffer), mesh.vertex_count());
                acmr += n as f64 * stats.acmr() / total;
                atvr += n as f64 * stats.atvr() / total;
            }
            (model, acmr, atvr)
        })
        .collect();
    Ok(NodeMeasurement { caches, overdraw })
}

/// One method's index buffers for an animation (or a static mesh as one frame), measured.
#[derive(Debug, Clone)]
pub struct NodeEvaluation {
    pub method: String,
    pub peer: bool,
    /// Wall time of the ordering alone (posing the keyframes is loading, not ordering).
    pub seconds: f64,
    pub nodes: NodeOrders,
    pub measurement: NodeMeasurement,
}

/// Orders `mesh` (the rest pose of `keyframes`) with `method` for every keyframe and view (timed)
/// and measures the buffers.
pub fn evaluate_nodes(
    mesh: &Mesh,
    topology: &Topology,
    keyframes: &Keyframes,
    method: &Resolved,
    options: &MeasureOptions,
    raster: &dyn RasterBackend,
) -> Result<NodeEvaluation> {
    let start = Instant::now();
    let nodes = order::run_nodes(method, &OrderInput { mesh, topology }, keyframes)?;
    let seconds = start.elapsed().as_secs_f64();
    let measurement = measure_nodes(mesh, keyframes, &nodes, options, raster)?;
    Ok(NodeEvaluation { method: method.canonical(), peer: method.method.peer, seconds, nodes, measurement })
}
