//! How `eval` and `order` print: an aligned table, JSON lines, or a before/after summary.

use std::fmt::Write as _;

use serde_json::{Map, Value, json};
use triorder::eval::{Evaluation, MeasureOptions, Measurement};
use triorder::mesh::Mesh;

/// `eval`'s readable table: one row per method, ACMR/ATVR per cache, OVR when measured.
pub struct EvalTable {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl EvalTable {
    pub fn new(options: &MeasureOptions) -> EvalTable {
        let mut header = vec!["method".to_string(), "seconds".to_string()];
        header.extend(options.caches.iter().map(|c| format!("ACMR/ATVR {c}")));
        if let Some(views) = options.views {
            header.push(format!("OVR mean/max/var {views}@{}", options.res));
        }
        EvalTable { header, rows: Vec::new() }
    }

    pub fn push(&mut self, e: &Evaluation) {
        let mut row = vec![e.method.clone(), format!("{:.4}", e.seconds)];
        row.extend(e.measurement.caches.iter().map(|(_, s)| format!("{:.4}/{:.4}", s.acmr(), s.atvr())));
        if let Some(o) = &e.measurement.overdraw {
            row.push(match o.summary {
                Some(s) => format!("{:.4}/{:.4}/{:.5}", s.mean, s.max, s.variance),
                None => "no visible faces".into(),
            });
        }
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

/// One JSON object: the fields DESIGN.md promises (`method`, `triangles`, `vertices`, `cache`,
/// `acmr`, `atvr` for the first cache, `seconds`, and with views `views`, `res`, `ovr_mean`,
/// `ovr_max`), plus every cache under `caches` and the other overdraw statistics.
pub fn eval_json(mesh: &Mesh, e: &Evaluation, backend: &str) -> String {
    let mut o = Map::new();
    o.insert("mesh".into(), json!(mesh.name));
    o.insert("method".into(), json!(e.method));
    o.insert("peer".into(), json!(e.peer));
    o.insert("triangles".into(), json!(mesh.triangle_count()));
    o.insert("vertices".into(), json!(mesh.vertex_count()));
    o.insert("seconds".into(), json!(e.seconds));
    if let Some((model, s)) = e.measurement.caches.first() {
        o.insert("cache".into(), json!(model.to_string()));
        o.insert("acmr".into(), json!(s.acmr()));
        o.insert("atvr".into(), json!(s.atvr()));
    }
    let caches: Vec<Value> = e
        .measurement
        .caches
        .iter()
        .map(|(m, s)| json!({"cache": m.to_string(), "acmr": s.acmr(), "atvr": s.atvr(), "misses": s.misses}))
        .collect();
    o.insert("caches".into(), Value::Array(caches));
    if let Some(od) = &e.measurement.overdraw {
        o.insert("views".into(), json!(od.views.to_string()));
        o.insert("res".into(), json!(od.res));
        o.insert("backend".into(), json!(backend));
        let s = od.summary;
        o.insert("ovr_mean".into(), json!(s.map(|s| s.mean)));
        o.insert("ovr_max".into(), json!(s.map(|s| s.max)));
        o.insert("ovr_min".into(), json!(s.map(|s| s.min)));
        o.insert("ovr_var".into(), json!(s.map(|s| s.variance)));
        o.insert("ovr_ratio_of_sums".into(), json!(s.map(|s| s.ratio_of_sums)));
        o.insert("empty_views".into(), json!(s.map_or(od.per_view.len(), |s| s.empty_views)));
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
