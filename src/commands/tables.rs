//! How `eval` and `order` print: an aligned table, JSON lines, or a before/after summary. All three
//! are written from the values the metrics report, so a new metric shows up in each unchanged.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use serde::Serialize;
use triorder::measure::{Evaluation, Measured, Value};
use triorder::mesh::{Mesh, Scene};

/// `eval`'s readable table: one row per method, the columns its metrics show.
pub struct EvalTable {
    /// Whether to show how many index buffers each method needs.
    buffers: bool,
    rows: Vec<Vec<(String, String)>>,
}

impl EvalTable {
    pub fn new(buffers: bool) -> EvalTable {
        EvalTable { buffers, rows: Vec::new() }
    }

    /// The row of `e`, or on a progressive mesh one row per level.
    pub fn push(&mut self, scene: &Scene, e: &Evaluation) {
        for (level, fraction, triangles) in levels(scene) {
            let mut row = vec![("method".to_string(), e.method.clone())];
            if let Some(fraction) = fraction {
                row.push(("level".into(), format!("{fraction}")));
                row.push(("triangles".into(), triangles.to_string()));
            }
            row.push(("seconds".into(), format!("{:.4}", e.seconds)));
            if self.buffers {
                row.push(("buffers".into(), e.orders.buffers.len().to_string()));
            }
            row.extend(e.measured.iter().flat_map(|m| m.at_level(level).columns()));
            self.rows.push(row);
        }
    }

    pub fn render(&self, mesh: &Mesh) -> String {
        let mut header: Vec<&str> = Vec::new();
        for (title, _) in self.rows.iter().flatten() {
            if !header.contains(&title.as_str()) {
                header.push(title);
            }
        }
        let cells: Vec<Vec<&str>> = self
            .rows
            .iter()
            .map(|row| {
                header.iter().map(|h| row.iter().find(|(t, _)| t == h).map_or("", |(_, c)| c.as_str())).collect()
            })
            .collect();
        let widths: Vec<usize> = (0..header.len())
            .map(|c| cells.iter().map(|r| r[c].chars().count()).chain([header[c].chars().count()]).max().unwrap_or(0))
            .collect();
        let mut out = format!("{}: {} triangles, {} vertices\n", mesh.name, mesh.triangle_count(), mesh.vertex_count());
        for row in std::iter::once(&header).chain(&cells) {
            let padded: Vec<String> = row.iter().zip(&widths).map(|(cell, w)| format!("{cell:<w$}")).collect();
            let _ = writeln!(out, "{}", padded.join("  ").trim_end());
        }
        out
    }
}

/// One `eval --json` line (one per level for a progressive mesh): the evaluation, then every
/// value under its metric's name. Summary
/// values (all frames, no single view and no cache) are top-level fields, as DESIGN.md promises
/// for `ovr_mean` and `ovr_max`; the first cache's `acmr` and `atvr` are too. Values per cache
/// model are grouped under `caches`, per clip under `clips`, and per view under `per_view` (one
/// array per metric, `null` for a view without a value).
#[derive(Serialize)]
struct EvalLine<'a> {
    mesh: &'a str,
    method: &'a str,
    peer: bool,
    /// For a progressive mesh: the fraction of the triangles this level asked for, and the update.
    #[serde(skip_serializing_if = "Option::is_none")]
    level: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    update: Option<&'static str>,
    triangles: usize,
    vertices: usize,
    frames: usize,
    seconds: f64,
    buffers: usize,
    iterations: Option<usize>,
    converged: bool,
    phases: BTreeMap<&'static str, f64>,
    backend: &'a str,
    /// The GPU that timed or counted values, if one did.
    #[serde(skip_serializing_if = "Option::is_none")]
    device: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    cache: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    views: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    res: Option<u32>,
    #[serde(flatten)]
    summary: BTreeMap<&'static str, f64>,
    caches: Vec<Group<'a>>,
    clips: Vec<Group<'a>>,
    per_view: BTreeMap<&'static str, Vec<Option<f64>>>,
}

/// The values of one cache model or one clip.
#[derive(Serialize)]
struct Group<'a> {
    #[serde(skip_serializing_if = "Option::is_none")]
    cache: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    clip: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    device: Option<&'a str>,
    #[serde(flatten)]
    values: BTreeMap<&'static str, f64>,
}

pub fn eval_json(scene: &Scene, e: &Evaluation, backend: &str) -> Vec<String> {
    levels(scene)
        .into_iter()
        .map(|(level, fraction, triangles)| json_line(scene, e, backend, level, fraction, triangles))
        .collect()
}

/// The level index, fraction and triangle count of each level of `scene`, or one entry of `None`s
/// (and the mesh's count) for a scene without levels.
fn levels(scene: &Scene) -> Vec<(Option<usize>, Option<f64>, usize)> {
    match scene.frames.levels() {
        Some(levels) => {
            (0..levels.alive.len()).map(|f| (Some(f), Some(levels.fractions[f]), levels.alive[f].len())).collect()
        }
        None => vec![(None, None, scene.mesh.triangle_count())],
    }
}

/// One `--json` line: the evaluation, or one level of it.
fn json_line(
    scene: &Scene,
    e: &Evaluation,
    backend: &str,
    level: Option<usize>,
    fraction: Option<f64>,
    triangles: usize,
) -> String {
    let mesh = &scene.mesh;
    let levels = scene.frames.levels();
    let update = levels.map(|l| l.update.name());
    let vertices = levels.map_or(mesh.vertex_count(), |l| {
        triorder::measure::cache::referenced(&l.triangles(level.unwrap_or(0)), mesh.vertex_count())
    });
    let mut line = EvalLine {
        mesh: &mesh.name,
        method: &e.method,
        peer: e.peer,
        level: fraction,
        update,
        triangles,
        vertices,
        frames: scene.frames.len(),
        seconds: e.seconds,
        buffers: e.orders.buffers.len(),
        iterations: e.orders.iterations,
        converged: e.orders.converged,
        phases: e.orders.phases.iter().copied().collect(),
        backend,
        device: None,
        cache: None,
        views: None,
        res: None,
        summary: BTreeMap::new(),
        caches: Vec::new(),
        clips: Vec::new(),
        per_view: BTreeMap::new(),
    };
    for v in e.values().filter(|v| v.level == level) {
        if let Some((views, res)) = v.views {
            line.views = Some(views.to_string());
            line.res = Some(res);
        }
        if let Some(device) = &v.device {
            line.device = Some(device);
        }
        match (&v.cache, &v.clip, v.view) {
            (_, _, Some(view)) => {
                let slots = line.per_view.entry(v.metric).or_default();
                if slots.len() <= view {
                    slots.resize(view + 1, None);
                }
                slots[view] = Some(v.value);
            }
            (Some(cache), _, None) => {
                if line.cache.is_none() {
                    line.cache = Some(&cache.name);
                }
                if Some(cache.name.as_str()) == line.cache {
                    line.summary.insert(v.metric, v.value);
                }
                in_group(&mut line.caches, |g| g.cache == Some(&cache.name), v).cache = Some(&cache.name);
            }
            (None, Some(clip), None) => {
                in_group(&mut line.clips, |g| g.clip == Some(clip), v).clip = Some(clip);
            }
            (None, None, None) => {
                line.summary.insert(v.metric, v.value);
            }
        }
    }
    serde_json::to_string(&line).expect("JSON lines serialize")
}

/// The group `is` picks (a new one if none), with `v`'s value added.
fn in_group<'a, 'g>(groups: &'g mut Vec<Group<'a>>, is: impl Fn(&Group) -> bool, v: &'a Value) -> &'g mut Group<'a> {
    let i = groups.iter().position(is).unwrap_or_else(|| {
        groups.push(Group { cache: None, clip: None, device: None, values: BTreeMap::new() });
        groups.len() - 1
    });
    let group = &mut groups[i];
    group.values.insert(v.metric, v.value);
    if let Some(device) = &v.device {
        group.device = Some(device);
    }
    group
}

/// What `order` logs: each metric's summary before → after, as build pipelines want it.
pub fn before_after(before: &[Measured], after: &[Measured]) -> String {
    let mut out = String::new();
    for (b, a) in before.iter().zip(after) {
        for ((title, was), (_, is)) in b.columns().into_iter().zip(a.columns()) {
            let _ = writeln!(out, "{title}: {was} -> {is}");
        }
    }
    out.trim_end().to_string()
}
