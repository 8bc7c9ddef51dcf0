//! The results CSV: one row per measurement, in long ("tidy") form.
//!
//! Every number of a run is its own row, named by `metric` and described by the columns that
//! vary (model, method, cache, view), so one plotter serves every figure: a figure picks a
//! metric, an x column, a series column and a facet column. Each row also carries what is needed
//! to trust and reproduce it: model size, the method's canonical spec (every parameter), seed,
//! backend, machine, commit and triorder version.

use serde::Serialize;

use crate::eval::{Evaluation, GPU_CACHE, NodeEvaluation, Overdraw, RenderTime};
use crate::gpu::render_time::Shading;
use crate::mesh::{Mesh, simplify};
use crate::metrics::CacheModel;

/// The CSV header, in order (checked against [`Row`] by a test).
pub const COLUMNS: &[&str] = &[
    "experiment",
    "model",
    "model_base",
    "model_triangles",
    "model_vertices",
    "clip",
    "method",
    "method_name",
    "peer",
    "seed",
    "metric",
    "cache",
    "cache_kind",
    "cache_size",
    "views",
    "res",
    "view",
    "backend",
    "value",
    "seconds",
    "machine",
    "commit",
    "triorder",
];

/// What a metric's rows need from the spec.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Needs {
    Nothing,
    Caches,
    Views,
}

/// A metric a run writes: its name in the `metric` column and how an axis labels it.
#[derive(Debug, Clone, Copy)]
pub struct Metric {
    pub name: &'static str,
    pub label: &'static str,
    pub needs: Needs,
}

/// Every metric a run writes. Cache metrics come once per cache model; overdraw summaries once
/// per view set (for an animation: once over all frames and once per clip); `ovr` once per view
/// that sees the mesh (empty views have no ratio and are counted by `ovr_empty` instead), and
/// only when the spec's figure draws `ovr`. Runs of animations, or of keyframe- and view-dependent
/// methods, also write `buffers`, and `iterations` and `converged` for methods that iterate.
pub const METRICS: &[Metric] = &[
    Metric { name: "acmr", label: "ACMR (vertex-cache misses per triangle)", needs: Needs::Caches },
    Metric { name: "atvr", label: "ATVR (misses per referenced vertex)", needs: Needs::Caches },
    Metric { name: "seconds", label: "ordering time (s)", needs: Needs::Nothing },
    Metric { name: "buffers", label: "index buffers", needs: Needs::Nothing },
    Metric { name: "iterations", label: "optimization iterations", needs: Needs::Nothing },
    Metric { name: "converged", label: "converged before the iteration cap (1) or not (0)", needs: Needs::Nothing },
    Metric { name: "ovr", label: "overdraw ratio (shaded ÷ covered pixels)", needs: Needs::Views },
    Metric { name: "ovr_mean", label: "mean overdraw ratio over views", needs: Needs::Views },
    Metric { name: "ovr_max", label: "worst-view overdraw ratio", needs: Needs::Views },
    Metric { name: "ovr_min", label: "best-view overdraw ratio", needs: Needs::Views },
    Metric { name: "ovr_var", label: "variance of the overdraw ratio over views", needs: Needs::Views },
    Metric { name: "ovr_sum", label: "overdraw ratio (Σ shaded ÷ Σ covered)", needs: Needs::Views },
    Metric { name: "ovr_empty", label: "views that see nothing", needs: Needs::Views },
    Metric {
        name: "render_ms_pixel",
        label: "frame time, pixel-bound shader (ms, mean over views)",
        needs: Needs::Views,
    },
    Metric {
        name: "render_ms_vertex",
        label: "frame time, vertex-bound shader (ms, mean over views)",
        needs: Needs::Views,
    },
    Metric {
        name: "render_spread_pixel",
        label: "frame-time spread p90 − p10, pixel-bound (ms, mean over views)",
        needs: Needs::Views,
    },
    Metric {
        name: "render_spread_vertex",
        label: "frame-time spread p90 − p10, vertex-bound (ms, mean over views)",
        needs: Needs::Views,
    },
    Metric { name: "render_ms_pixel_view", label: "frame time, pixel-bound shader (ms)", needs: Needs::Views },
    Metric { name: "render_ms_vertex_view", label: "frame time, vertex-bound shader (ms)", needs: Needs::Views },
];

/// One measurement. Field order is the column order ([`COLUMNS`]); `None` writes an empty cell.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    pub experiment: String,
    pub model: String,
    /// The model without its `@N` resolution suffix: the series of a resolution sweep.
    pub model_base: String,
    pub model_triangles: usize,
    pub model_vertices: usize,
    /// For an animation, the clip a row measures, or `all` for all its frames (and for the rows
    /// that do not depend on the clip: times, caches, buffers); empty for a static mesh.
    pub clip: Option<String>,
    /// Canonical method spec (every parameter).
    pub method: String,
    pub method_name: String,
    pub peer: bool,
    pub seed: u64,
    pub metric: &'static str,
    pub cache: Option<String>,
    pub cache_kind: Option<&'static str>,
    pub cache_size: Option<u32>,
    pub views: Option<String>,
    pub res: Option<u32>,
    /// Index of the view in its set, for per-view metrics.
    pub view: Option<usize>,
    pub backend: String,
    pub value: f64,
    /// Wall time of the ordering alone.
    pub seconds: f64,
    pub machine: String,
    pub commit: String,
    pub triorder: &'static str,
}

/// Where and with what a run happened: the columns shared by all its rows.
#[derive(Debug, Clone)]
pub struct Context {
    pub experiment: String,
    pub seed: u64,
    pub backend: String,
    pub machine: String,
    pub commit: String,
    /// Whether to write the per-view rows (`ovr`, `render_ms_*_view`): only when the figure draws them. They are
    /// one row per view per (model, method), which would make a 162-view run of every method
    /// on every model an 8 MB file, while the summaries are what the other figures read.
    pub per_view: bool,
}

impl Context {
    /// The rows of one evaluation of `model` (as the spec names it).
    pub fn rows(&self, model: &str, mesh: &Mesh, method_name: &str, eval: &Evaluation) -> Vec<Row> {
        let base = self.base(model, mesh, &eval.method, method_name, eval.peer, eval.seconds);
        let mut rows = Vec::new();
        for (cache, stats) in &eval.measurement.caches {
            rows.extend(cache_rows(&base, cache, stats.acmr(), stats.atvr()));
        }
        if let Some(gpu) = &eval.measurement.gpu_vertices {
            // Counted, not simulated: the cache is the device, named in `backend`.
            let counted = Row {
                cache: Some(GPU_CACHE.into()),
                cache_kind: Some(GPU_CACHE),
                backend: format!("{GPU_CACHE}: {}", gpu.device),
                ..base.clone()
            };
            rows.push(Row { metric: "acmr", value: gpu.stats.acmr(), ..counted.clone() });
            rows.push(Row { metric: "atvr", value: gpu.stats.atvr(), ..counted });
        }
        if let Some(overdraw) = &eval.measurement.overdraw {
            self.overdraw_rows(&base, overdraw, &mut rows);
            for render in &eval.measurement.render {
                self.render_rows(&base, overdraw, render, &mut rows);
            }
        }
        rows.push(base);
        rows
    }

    /// The render-time rows of one shader: the mean over views of the median frame time and of the
    /// spread (p90 − p10), and the median per view when the figure draws them. Each names the device that rendered; `seconds` stays the ordering's time.
    fn render_rows(&self, base: &Row, overdraw: &Overdraw, render: &RenderTime, rows: &mut Vec<Row>) {
        let (mean, spread, per_view) = match render.shading {
            Shading::Pixel => ("render_ms_pixel", "render_spread_pixel", "render_ms_pixel_view"),
            Shading::Vertex => ("render_ms_vertex", "render_spread_vertex", "render_ms_vertex_view"),
        };
        let timed = Row {
            views: Some(overdraw.views.to_string()),
            res: Some(overdraw.res),
            backend: format!("gpu: {}", render.device),
            ..base.clone()
        };
        rows.push(Row { metric: mean, value: render.mean_ms(), ..timed.clone() });
        rows.push(Row { metric: spread, value: render.spread_ms(), ..timed.clone() });
        for (i, t) in render.per_view.iter().enumerate().filter(|_| self.per_view) {
            rows.push(Row { metric: per_view, view: Some(i), value: t.median_ms, ..timed.clone() });
        }
    }

    /// The rows of one index-buffer evaluation of `model` (as the spec names it): draw-weighted
    /// cache metrics, overdraw over all frames (clip `all`, or empty when `animated` is false:
    /// a static mesh seen as one frame) and per clip, the time, and how many buffers the method
    /// needs, with its iterations and whether it converged when it reports them.
    pub fn node_rows(
        &self,
        model: &str,
        mesh: &Mesh,
        method_name: &str,
        eval: &NodeEvaluation,
        animated: bool,
    ) -> Vec<Row> {
        let all = animated.then(|| "all".to_string());
        let base =
            Row { clip: all.clone(), ..self.base(model, mesh, &eval.method, method_name, eval.peer, eval.seconds) };
        let mut rows = Vec::new();
        for &(cache, acmr, atvr) in &eval.measurement.caches {
            rows.extend(cache_rows(&base, &cache, acmr, atvr));
        }
        for clip in &eval.measurement.overdraw {
            let clip_base = Row { clip: clip.clip.clone().or(all.clone()), ..base.clone() };
            self.overdraw_rows(&clip_base, &clip.overdraw, &mut rows);
        }
        rows.push(Row { metric: "buffers", value: eval.nodes.buffers.len() as f64, ..base.clone() });
        if let Some(iterations) = eval.nodes.iterations {
            rows.push(Row { metric: "iterations", value: iterations as f64, ..base.clone() });
            rows.push(Row { metric: "converged", value: f64::from(u8::from(eval.nodes.converged)), ..base.clone() });
        }
        rows.push(base);
        rows
    }

    /// The `seconds` row of an evaluation (no clip), which every other row of it copies.
    fn base(&self, model: &str, mesh: &Mesh, method: &str, method_name: &str, peer: bool, seconds: f64) -> Row {
        Row {
            experiment: self.experiment.clone(),
            model: model.to_string(),
            model_base: simplify::parse_source(model).map_or(model, |(base, _)| base).to_string(),
            model_triangles: mesh.triangle_count(),
            model_vertices: mesh.vertex_count(),
            clip: None,
            method: method.to_string(),
            method_name: method_name.to_string(),
            peer,
            seed: self.seed,
            metric: "seconds",
            cache: None,
            cache_kind: None,
            cache_size: None,
            views: None,
            res: None,
            view: None,
            backend: self.backend.clone(),
            value: seconds,
            seconds,
            machine: self.machine.clone(),
            commit: self.commit.clone(),
            triorder: env!("CARGO_PKG_VERSION"),
        }
    }

    /// The overdraw rows of one view set (and, for an animation, one clip) appended to `rows`.
    fn overdraw_rows(&self, base: &Row, overdraw: &Overdraw, rows: &mut Vec<Row>) {
        let views = Row { views: Some(overdraw.views.to_string()), res: Some(overdraw.res), ..base.clone() };
        let empty = overdraw.per_view.iter().filter(|v| v.ovr().is_none()).count();
        rows.push(Row { metric: "ovr_empty", value: empty as f64, ..views.clone() });
        if let Some(s) = &overdraw.summary {
            for (metric, value) in [
                ("ovr_mean", s.mean),
                ("ovr_max", s.max),
                ("ovr_min", s.min),
                ("ovr_var", s.variance),
                ("ovr_sum", s.ratio_of_sums),
            ] {
                rows.push(Row { metric, value, ..views.clone() });
            }
        }
        for (i, counts) in overdraw.per_view.iter().enumerate().filter(|_| self.per_view) {
            if let Some(value) = counts.ovr() {
                rows.push(Row { metric: "ovr", view: Some(i), value, ..views.clone() });
            }
        }
    }
}

/// The `acmr` and `atvr` rows of one cache model.
fn cache_rows(base: &Row, cache: &CacheModel, acmr: f64, atvr: f64) -> [Row; 2] {
    let cache = Row {
        cache: Some(cache.to_string()),
        cache_kind: Some(cache.kind()),
        cache_size: Some(cache.size()),
        ..base.clone()
    };
    [Row { metric: "acmr", value: acmr, ..cache.clone() }, Row { metric: "atvr", value: atvr, ..cache }]
}

/// One line of a drawing spec's orders file: a whole order, the triangle ids in draw order
/// separated by spaces (one line per order keeps the file a seventh of one row per triangle).
#[derive(Debug, Clone, Serialize, serde::Deserialize)]
pub struct OrderRow {
    pub model: String,
    /// Canonical method spec, as in the results CSV.
    pub method: String,
    pub order: String,
    /// Where the order's clusters start, separated by spaces, ending with the triangle count.
    pub clusters: String,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_matches_columns() {
        let row = Row {
            experiment: String::new(),
            model: String::new(),
            model_base: String::new(),
            model_triangles: 0,
            model_vertices: 0,
            clip: None,
            method: String::new(),
            method_name: String::new(),
            peer: false,
            seed: 0,
            metric: "acmr",
            cache: None,
            cache_kind: None,
            cache_size: None,
            views: None,
            res: None,
            view: None,
            backend: String::new(),
            value: 0.0,
            seconds: 0.0,
            machine: String::new(),
            commit: String::new(),
            triorder: "",
        };
        let mut writer = csv::Writer::from_writer(Vec::new());
        writer.serialize(&row).unwrap();
        let text = String::from_utf8(writer.into_inner().unwrap()).unwrap();
        assert_eq!(text.lines().next().unwrap(), COLUMNS.join(","));
    }
}
