//! The results CSV: one row per measurement, in long ("tidy") form.
//!
//! Every number of a run is its own row, named by `metric` and described by the columns that
//! vary (model, method, cache, view), so one plotter serves every figure: a figure picks a
//! metric, an x column, a series column and a facet column. Each row also carries what is needed
//! to trust and reproduce it: model size, the method's canonical spec (every parameter), seed,
//! backend, machine, commit and triorder version.
//!
//! This is the contract between the runs that write results (`experiment`) and the figures that
//! read them (`figure`): the columns, the row type, and the orders file drawings read.

use serde::Serialize;

use crate::error::{Error, Result};
use crate::measure::Corner;
use crate::measure::Evaluation;
use crate::mesh::{Mesh, Scene, Source};

/// The CSV header, in order (checked against [`Row`] by a test).
pub const COLUMNS: &[&str] = &[
    "experiment",
    "model",
    "model_base",
    "model_triangles",
    "model_vertices",
    "clip",
    "level",
    "update",
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
    "error",
];

/// One measurement. Field order is the column order ([`COLUMNS`]); `None` writes an empty cell.
#[derive(Debug, Clone, Default, Serialize)]
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
    /// For a progressive mesh, the level a row measures, as the fraction of the mesh's triangles
    /// asked for (`model_triangles` is what the level has); empty otherwise.
    pub level: Option<f64>,
    /// For a progressive mesh, how the sequence follows the levels: simple, smart or reorder.
    pub update: Option<&'static str>,
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
    /// Wall time of the ordering alone: work it reused from an earlier ordering of the same
    /// scene (hs17's rasterized nodes) is counted at what it cost then
    /// ([`crate::order::Orders::reused`]).
    pub seconds: f64,
    pub machine: String,
    pub commit: String,
    pub triorder: &'static str,
    /// On an `error` row, why the model could not be loaded or measured (the run went on).
    pub error: Option<String>,
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
    /// The rows of one evaluation of `model` (as the spec names it) on `scene`: every value the
    /// metrics reported (per-view ones only when [`Context::per_view`]), then the number of
    /// buffers when `buffers` says the run compares them, the iterations of a method that
    /// iterates, and last the ordering's time.
    pub fn rows(&self, model: &str, source: &Source, scene: &Scene, eval: &Evaluation, buffers: bool) -> Vec<Row> {
        let all = scene.frames.is_animation().then(|| "all".to_string());
        let levels = scene.frames.levels();
        let base = Row {
            clip: all.clone(),
            update: levels.map(|l| l.update.name()),
            ..self.base(model, source, &scene.mesh, eval)
        };
        // The level a value is about, as its own model size.
        let at_level = |level: Option<usize>| match (levels, level) {
            (Some(levels), Some(f)) => {
                let triangles = levels.triangles(f);
                let vertices = crate::measure::cache::referenced(&triangles, scene.mesh.vertex_count());
                (Some(levels.fractions[f]), triangles.len(), vertices)
            }
            _ => (None, base.model_triangles, base.model_vertices),
        };
        let mut rows: Vec<Row> = eval
            .values()
            .filter(|v| self.per_view || v.view.is_none())
            .map(|v| (v, at_level(v.level)))
            .map(|(v, (level, model_triangles, model_vertices))| Row {
                level,
                model_triangles,
                model_vertices,
                metric: v.metric,
                cache: v.cache.as_ref().map(|c| c.name.clone()),
                cache_kind: v.cache.as_ref().map(|c| c.kind),
                cache_size: v.cache.as_ref().and_then(|c| c.size),
                views: v.views.map(|(views, _)| views.to_string()),
                res: v.views.map(|(_, res)| res),
                view: v.view,
                clip: v.clip.clone().or(all.clone()),
                backend: v.device.as_ref().map_or_else(|| self.backend.clone(), |d| format!("gpu: {d}")),
                value: v.value,
                ..base.clone()
            })
            .collect();
        let orders = &eval.orders;
        if buffers {
            rows.push(Row { metric: "buffers", value: orders.buffers.len() as f64, ..base.clone() });
        }
        // The clusters a static order is made of (nehab's chosen count, sander07's patches).
        if let Some(one) = orders.single().filter(|b| b.starts.len() > 2) {
            rows.push(Row { metric: "clusters", value: (one.starts.len() - 1) as f64, ..base.clone() });
        }
        if let Some(iterations) = orders.iterations {
            rows.push(Row { metric: "iterations", value: iterations as f64, ..base.clone() });
            rows.push(Row { metric: "converged", value: f64::from(u8::from(orders.converged)), ..base.clone() });
        }
        rows.push(base);
        rows
    }

    /// The `seconds` row of an evaluation, which every other row of it copies.
    fn base(&self, model: &str, source: &Source, mesh: &Mesh, eval: &Evaluation) -> Row {
        Row {
            model_triangles: mesh.triangle_count(),
            model_vertices: mesh.vertex_count(),
            method: eval.method.clone(),
            method_name: eval.method_name.to_string(),
            peer: eval.peer,
            value: eval.seconds,
            seconds: eval.seconds,
            ..self.blank(model, source, "seconds")
        }
    }

    /// The row recording that `model` could not be loaded (`method` is `None`) or could not be
    /// ordered or measured with `method`: metric `error`, no value, and the reason.
    pub fn error_row(
        &self,
        model: &str,
        source: &Source,
        method: Option<&crate::order::Resolved>,
        reason: &str,
    ) -> Row {
        Row {
            method: method.map(|m| m.canonical()).unwrap_or_default(),
            method_name: method.map(|m| m.method.name.to_string()).unwrap_or_default(),
            peer: method.is_some_and(|m| m.method.peer),
            value: f64::NAN,
            error: Some(reason.to_string()),
            ..self.blank(model, source, "error")
        }
    }

    /// A row of `metric` about `model` carrying the run's context, everything else empty.
    fn blank(&self, model: &str, source: &Source, metric: &'static str) -> Row {
        Row {
            experiment: self.experiment.clone(),
            model: model.to_string(),
            model_base: model_base(model, source),
            seed: self.seed,
            metric,
            backend: self.backend.clone(),
            machine: self.machine.clone(),
            commit: self.commit.clone(),
            triorder: env!("CARGO_PKG_VERSION"),
            ..Row::default()
        }
    }
}

/// The model without its `@N` resolution: the series of a resolution sweep.
fn model_base(name: &str, source: &Source) -> String {
    match source {
        Source::Simplified { base, .. } => base.to_string(),
        _ => name.to_string(),
    }
}

/// The orders file's header, in order (checked against [`OrderRow`] by a test).
pub const ORDER_COLUMNS: &[&str] =
    &["model", "method", "order", "clusters", "corners", "overdraw", "level", "update", "translucency"];

/// One line of a drawing spec's orders file: a whole order, the triangle ids in draw order
/// separated by spaces (one line per order keeps the file a seventh of one row per triangle).
#[derive(Debug, Clone, Default, Serialize, serde::Deserialize)]
pub struct OrderRow {
    pub model: String,
    /// Canonical method spec, as in the results CSV.
    pub method: String,
    pub order: String,
    /// Where the order's clusters start, separated by spaces, ending with the triangle count.
    pub clusters: String,
    /// For `corners` drawings: per cache model, `MODEL=` and the class of every corner of every
    /// drawn triangle ([`OrderRow::encode_corners`]), `;` between models. Empty otherwise.
    pub corners: String,
    /// For `overdraw` drawings: the fragments shaded at each pixel from the figure's view, a
    /// greyscale PNG in base64 ([`OrderRow::encode_counts`]). Empty otherwise.
    pub overdraw: String,
    /// For a progressive mesh: the level (fraction of the triangles) this order draws, whose
    /// triangles the order indexes, and the update that kept it. Empty otherwise (and in orders
    /// files written before levels existed).
    #[serde(default)]
    pub level: String,
    #[serde(default)]
    pub update: String,
    /// For `translucency` drawings: where the translucent blend goes wrong from the figure's view,
    /// a greyscale PNG in base64 of [`crate::measure::translucency::error_picture`]'s levels.
    /// Empty otherwise (and in orders files written before it existed).
    #[serde(default)]
    pub translucency: String,
}

/// The digits of [`OrderRow::encode_corners`].
const DIGITS: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

impl OrderRow {
    /// One base64 digit per triangle: `c0 + 4·c1 + 16·c2` over its three corners, each 0 for a
    /// hit, 1 for the vertex's first load, 2 for its first reload, 3 for a later one.
    pub fn encode_corners(classes: &[[Corner; 3]]) -> String {
        let class = |c: Corner| match c {
            Corner::Hit => 0,
            Corner::Miss(n) => usize::from(n.min(3)),
        };
        classes.iter().map(|t| char::from(DIGITS[class(t[0]) + 4 * class(t[1]) + 16 * class(t[2])])).collect()
    }

    /// The corner classes [`OrderRow::encode_corners`] wrote (a later reload reads as `Miss(3)`).
    pub fn decode_corners(text: &str) -> std::result::Result<Vec<[Corner; 3]>, String> {
        let class = |c: usize| if c == 0 { Corner::Hit } else { Corner::Miss(c as u8) };
        text.bytes()
            .map(|b| {
                let d = DIGITS
                    .iter()
                    .position(|&x| x == b)
                    .ok_or_else(|| format!("`{}` is not a corner digit", char::from(b)))?;
                Ok([class(d % 4), class(d / 4 % 4), class(d / 16)])
            })
            .collect()
    }

    /// `shaded` (a `res`×`res` image, row 0 at the bottom) as an 8-bit greyscale PNG, top row
    /// first, counts above 255 saturating.
    pub fn encode_counts(shaded: &[u32], res: u32) -> Result<Vec<u8>> {
        let n = res as usize;
        let grey: Vec<u8> =
            (0..n).rev().flat_map(|y| shaded[y * n..(y + 1) * n].iter().map(|&c| c.min(255) as u8)).collect();
        let mut bytes = Vec::new();
        let mut encoder = png::Encoder::new(&mut bytes, res, res);
        encoder.set_color(png::ColorType::Grayscale);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::High);
        let written = encoder.write_header().and_then(|mut w| w.write_image_data(&grey));
        written.map_err(|e| Error::usage(format!("internal error: cannot encode an overdraw picture: {e}")))?;
        Ok(bytes)
    }

    /// The image [`OrderRow::encode_counts`] wrote: its side and the counts, row 0 at the bottom.
    pub fn decode_counts(bytes: &[u8]) -> std::result::Result<(u32, Vec<u32>), String> {
        let mut reader = png::Decoder::new(std::io::Cursor::new(bytes)).read_info().map_err(|e| e.to_string())?;
        let mut grey = vec![0; reader.output_buffer_size().ok_or("the picture is too large")?];
        let info = reader.next_frame(&mut grey).map_err(|e| e.to_string())?;
        if info.color_type != png::ColorType::Grayscale
            || info.bit_depth != png::BitDepth::Eight
            || info.width != info.height
        {
            return Err("not a square 8-bit greyscale picture".into());
        }
        let n = info.width as usize;
        Ok((info.width, (0..n).rev().flat_map(|y| grey[y * n..(y + 1) * n].iter().map(|&c| u32::from(c))).collect()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn corner_classes_and_counts_survive_the_orders_file() {
        let classes =
            vec![[Corner::Hit, Corner::Miss(1), Corner::Miss(2)], [Corner::Miss(3), Corner::Hit, Corner::Hit]];
        assert_eq!(OrderRow::decode_corners(&OrderRow::encode_corners(&classes)).unwrap(), classes);
        // A fourth load saturates to "a later reload".
        let later = OrderRow::decode_corners(&OrderRow::encode_corners(&[[Corner::Miss(9); 3]])).unwrap();
        assert_eq!(later, vec![[Corner::Miss(3); 3]]);
        assert!(OrderRow::decode_corners("A*").is_err());
        let counts: Vec<u32> = (0..16).map(|i| [0, 1, 5, 300][i % 4]).collect();
        let (res, back) = OrderRow::decode_counts(&OrderRow::encode_counts(&counts, 4).unwrap()).unwrap();
        assert_eq!(res, 4);
        assert_eq!(back, counts.iter().map(|&c| c.min(255)).collect::<Vec<_>>());
    }

    #[test]
    fn header_matches_columns() {
        let row = Row::default();
        let mut writer = csv::Writer::from_writer(Vec::new());
        writer.serialize(&row).unwrap();
        let text = String::from_utf8(writer.into_inner().unwrap()).unwrap();
        assert_eq!(text.lines().next().unwrap(), COLUMNS.join(","));
        let order = OrderRow::default();
        let mut writer = csv::Writer::from_writer(Vec::new());
        writer.serialize(&order).unwrap();
        let text = String::from_utf8(writer.into_inner().unwrap()).unwrap();
        assert_eq!(text.lines().next().unwrap(), ORDER_COLUMNS.join(","));
    }
}
