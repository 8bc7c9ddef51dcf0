//! How `eval` and `order` print: an aligned table, JSON lines, or a before/after summary.

use std::fmt::Write as _;

use serde_json::{Map, Value, json};
use triorder::eval::{Evaluation, MeasureOptions, Measurement, NodeEvaluation};
use triorder::mesh::Mesh;
use triorder::mesh::keyframes::Keyframes;
use triorder::metrics::{CacheModel, OverdrawSummary};

/// `eval`'s readable table: one row per method, ACMR/ATVR per cache, OVR when measured.
pub struct EvalTable {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl EvalTable {
    pub fn new(options: &MeasureOptions) -> EvalTable {
        let mut header = vec!["method".to_string(), "seconds".to_string()];
        header.extend(options.caches.iter().map(|c| format!("ACMR/ATVR {c}")));
        if options.gpu_vertices {
            header.push("ACMR/ATVR counted on the GPU".into());
        }
        if let Some(views) = options.views {
            header.push(format!("OVR mean/max/var {views}@{}", options.res));
        }
        header.extend(options.render.iter().map(|s| format!("{} ms", s.name())));
        EvalTable { header, rows: Vec::new() }
    }

    /// The table for index buffers per (keyframe, view): a `buffers` column after the time.
    pub fn with_buffers(options: &MeasureOptions) -> EvalTable {
        let mut table = EvalTable::new(options);
        table.header.insert(2, "buffers".into());
        table
    }

    pub fn push_nodes(&mut self, e: &NodeEvaluation) {
        let mut row = vec![e.method.clone(), format!("{:.4}", e.seconds), e.nodes.buffers.len().to_string()];
        row.extend(e.measurement.caches.iter().map(|(_, acmr, atvr)| format!("{acmr:.4}/{atvr:.4}")));
        if let Some(all) = e.measurement.overdraw.first() {
            row.push(summary_cell(all.overdraw.summary));
        }
        self.rows.push(row);
    }

    pub fn push(&mut self, e: &Evaluation) {
        let mut row = vec![e.method.clone(), format!("{:.4}", e.seconds)];
        row.extend(e.measurement.caches.iter().map(|(_, s)| format!("{:.4}/{:.4}", s.acmr(), s.atvr())));
        if let Some(gpu) = &e.measurement.gpu_vertices {
            row.push(format!("{:.4}/{:.4}", gpu.stats.acmr(), gpu.stats.atvr()));
        }
        if let Some(o) = &e.measurement.overdraw {
            row.push(summary_cell(o.summary));
        }
        row.extend(e.measurement.render.iter().map(|r| format!("{:.3}", r.mean_ms())));
        self.rows.push(row);
    }

    pub fn render(&self, mesh: &Mesh) -> String {
        let columns = self.header.len();
        let widths: Vec<usize> = (0..columns)
            .map(|c| self.rows.iter().map(|r| r[c].len()).chain([self.header[c].len()]).max().unwrap_or(0))
            .collect();
        let mut out = format!("{}: {} triangles, {} vertices\n", mesh.name, mesh.triangle_count(), mesh.vertex_count());
        for row in std::iter::once(&self.header).chain(&self.rows) {
            let cells: Vec<String> = row.iter().zip(&widths).map(|(cell, w)| format!("{cell:<w$}")).collect();
            let _ = writeln!(out, "{}", cells.join("  ").trim_end());
        }
        out
    }
}

fn summary_cell(summary: Option<OverdrawSummary>) -> String {
    match summary {
        Some(s) => format!("{:.4}/{:.4}/{:.5}", s.mean, s.max, s.variance),
        None => "no visible faces".into(),
    }
}

/// One JSON object: the fields DESIGN.md promises (`method`, `triangles`, `vertices`, `cache`,
/// `acmr`, `atvr` for the first cache, `seconds`, and with views `views`, `res`, `ovr_mean`,
/// `ovr_max`), plus every cache under `caches` and the other overdraw statistics.
pub fn eval_json(mesh: &Mesh, e: &Evaluation, backend: &str) -> String {
    let first = e.measurement.caches.first().map(|(model, s)| (model, s.acmr(), s.atvr()));
    let mut o = head(mesh, &e.method, e.peer, e.seconds, 1, first);
    let caches: Vec<Value> = e
        .measurement
        .caches
        .iter()
        .map(|(m, s)| json!({"cache": m.to_string(), "acmr": s.acmr(), "atvr": s.atvr(), "misses": s.misses}))
        .collect();
    o.insert("caches".into(), Value::Array(caches));
    if let Some(gpu) = &e.measurement.gpu_vertices {
        let s = &gpu.stats;
        let counted = json!({"device": gpu.device, "acmr": s.acmr(), "atvr": s.atvr(), "invocations": s.misses});
        o.insert("gpu_vertices".into(), counted);
    }
    if let Some(od) = &e.measurement.overdraw {
        o.insert("views".into(), json!(od.views.to_string()));
        o.insert("res".into(), json!(od.res));
        o.insert("backend".into(), json!(backend));
        let s = od.summary;
        insert_summary(&mut o, s, od.per_view.len());
    }
    if !e.measurement.render.is_empty() {
        let render: Vec<Value> = e
            .measurement
            .render
            .iter()
            .map(|r| {
                let per_view: Vec<f64> = r.per_view.iter().map(|t| t.median_ms).collect();
                json!({
                    "shading": r.shading.name(),
                    "device": r.device,
                    "mean_ms": r.mean_ms(),
                    "spread_ms": r.spread_ms(),
                    "per_view_ms": per_view,
                })
            })
            .collect();
        o.insert("render".into(), Value::Array(render));
    }
    Value::Object(o).to_string()
}

/// The fields every `eval --json` line starts with; `first` is the first cache model with its
/// ACMR and ATVR.
fn head(
    mesh: &Mesh,
    method: &str,
    peer: bool,
    seconds: f64,
    buffers: usize,
    first: Option<(&CacheModel, f64, f64)>,
) -> Map<String, Value> {
    let mut o = Map::new();
    o.insert("mesh".into(), json!(mesh.name));
    o.insert("method".into(), json!(method));
    o.insert("peer".into(), json!(peer));
    o.insert("triangles".into(), json!(mesh.triangle_count()));
    o.insert("vertices".into(), json!(mesh.vertex_count()));
    o.insert("seconds".into(), json!(seconds));
    o.insert("buffers".into(), json!(buffers));
    if let Some((model, acmr, atvr)) = first {
        o.insert("cache".into(), json!(model.to_string()));
        o.insert("acmr".into(), json!(acmr));
        o.insert("atvr".into(), json!(atvr));
    }
    o
}

/// The overdraw statistics of one summary, under the names `eval --json` uses.
fn insert_summary(o: &mut Map<String, Value>, s: Option<OverdrawSummary>, views: usize) {
    o.insert("ovr_mean".into(), json!(s.map(|s| s.mean)));
    o.insert("ovr_max".into(), json!(s.map(|s| s.max)));
    o.insert("ovr_min".into(), json!(s.map(|s| s.min)));
    o.insert("ovr_var".into(), json!(s.map(|s| s.variance)));
    o.insert("ovr_ratio_of_sums".into(), json!(s.map(|s| s.ratio_of_sums)));
    o.insert("empty_views".into(), json!(s.map_or(views, |s| s.empty_views)));
}

/// [`eval_json`]'s fields for index buffers per (keyframe, view): ACMR and ATVR averaged over
/// the draws, OVR over every keyframe and view, plus `buffers` (index buffers the method needs),
/// `keyframes`, the optimizer's `iterations`, `converged` and `phases` (seconds per phase) where
/// it reports them, and `clips` with each clip's overdraw when there are several.
pub fn nodes_json(mesh: &Mesh, keyframes: &Keyframes, e: &NodeEvaluation, backend: &str) -> String {
    let first = e.measurement.caches.first().map(|(model, acmr, atvr)| (model, *acmr, *atvr));
    let mut o = head(mesh, &e.method, e.peer, e.seconds, e.nodes.buffers.len(), first);
    o.insert("keyframes".into(), json!(keyframes.len()));
    o.insert("iterations".into(), json!(e.nodes.iterations));
    o.insert("converged".into(), json!(e.nodes.converged));
    let phases: Map<String, Value> = e.nodes.phases.iter().map(|(p, s)| (p.to_string(), json!(s))).collect();
    o.insert("phases".into(), Value::Object(phases));
    let caches: Vec<Value> = e
        .measurement
        .caches
        .iter()
        .map(|(m, acmr, atvr)| json!({"cache": m.to_string(), "acmr": acmr, "atvr": atvr}))
        .collect();
    o.insert("caches".into(), Value::Array(caches));
    if let Some(all) = e.measurement.overdraw.first() {
        o.insert("views".into(), json!(all.overdraw.views.to_string()));
        o.insert("res".into(), json!(all.overdraw.res));
        o.insert("backend".into(), json!(backend));
        insert_summary(&mut o, all.overdraw.summary, all.overdraw.per_view.len());
        let clips: Vec<Value> = e.measurement.overdraw[1..]
            .iter()
            .map(|c| {
                let mut clip = Map::new();
                clip.insert("clip".into(), json!(c.clip));
                insert_summary(&mut clip, c.overdraw.summary, c.overdraw.per_view.len());
                Value::Object(clip)
            })
            .collect();
        o.insert("clips".into(), Value::Array(clips));
    }
    Value::Object(o).to_string()
}

/// What `order` logs: each metric before → after, as build pipelines want it.
pub fn before_after(before: &Measurement, after: &Evaluation) -> String {
    let mut out = String::new();
    for ((model, b), (_, a)) in before.caches.iter().zip(&after.measurement.caches) {
        let _ = writeln!(
            out,
            "ACMR {model}: {:.4} -> {:.4}   ATVR: {:.4} -> {:.4}",
            b.acmr(),
            a.acmr(),
            b.atvr(),
            a.atvr()
        );
    }
    if let (Some(b), Some(a)) = (&before.overdraw, &after.measurement.overdraw) {
        match (b.summary, a.summary) {
            (Some(b_s), Some(a_s)) => {
                let _ = writeln!(
                    out,
                    "OVR {}@{}: mean {:.4} -> {:.4}   max {:.4} -> {:.4}",
                    a.views, a.res, b_s.mean, a_s.mean, b_s.max, a_s.max
                );
            }
            _ => {
                let _ = writeln!(out, "OVR {}@{}: no view sees a front face", a.views, a.res);
            }
        }
    }
    out.trim_end().to_string()
}
