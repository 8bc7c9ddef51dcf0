//! Drawings of meshes in their draw order, the pictures Bogomjakov & Gotsman 2002 explain their
//! orderings with:
//! - `sequence` (their Figs. 2 and 4): triangles coloured by position in the sequence, the path
//!   through consecutive centroids drawn thick where the two triangles share an edge and thin
//!   where the sequence jumps. Vector graphics: meant for meshes of a few thousand triangles.
//! - `corners` (their Figs. 10 and 11): every triangle corner coloured by what the cache did when
//!   that triangle used the corner's vertex — hit, first load, first reload, later reload. The
//!   paper codes "the number of cache misses for the corner's vertex" with green for the one
//!   first load each vertex has and blue and red for reloads; we read blue as the first reload and
//!   red as any later one. Drawn as the CPU rasterizer sees the mesh (the visible triangle at each
//!   pixel, same rules as the overdraw counts) into an image embedded in the SVG, so a mesh of any
//!   size stays legible and small on disk.
//!
//! Everything a drawing shows about an order comes from the run: the order and its clusters from
//! the orders file, the corner classes and the overdraw picture the run saved beside them, the
//! ACMR in each title from the results CSV (checked against the saved corners, so a figure never
//! silently shows stale data). The figure itself only lays the mesh out: it reads the models'
//! geometry and finds the visible triangle at each pixel to paint it.

use std::path::Path;

use base64::Engine;
use glam::{Vec2, Vec3};
use plotters::prelude::*;

use super::axes::{self, DrawResult, FONT};
use super::data::Table;
use super::spec::FigureKind;
use super::{Chart, Header, save};
use crate::error::{Error, Result};
use crate::measure::Corner;
use crate::mesh::progressive::Update;
use crate::mesh::{Mesh, Source, Topology, source};
use crate::order;
use crate::raster::{cpu, views};
use crate::results::OrderRow;

/// Panel width in pixels; the mesh fills it less a margin, at its own aspect ratio.
const PANEL_W: u32 = 520;
const MARGIN: u32 = 10;
const TITLE_H: u32 = 44;
const LEGEND_H: u32 = 40;

/// Corner colours: hit, first load, first reload, later reloads.
const HIT: [u8; 3] = [200, 200, 200];
const FIRST_LOAD: [u8; 3] = [40, 165, 70];
const RELOAD: [u8; 3] = [45, 100, 220];
const LATER_RELOAD: [u8; 3] = [220, 40, 40];

/// One panel: a model drawn in one method's order (and, for corners, under one cache).
struct Drawing<'a> {
    mesh: &'a Mesh,
    title: String,
    /// Triangles in draw order.
    triangles: Vec<[u32; 3]>,
    kind: Content,
}

enum Content {
    /// Consecutive triangles that share an edge (`adjacent[i]`: triangle i and i + 1).
    Sequence { adjacent: Vec<bool> },
    /// The class of each corner of each drawn triangle.
    Corners(Vec<[Corner; 3]>),
    /// The colour of each drawn triangle's cluster, and which cluster it is in.
    Clusters(Vec<([u8; 3], u32)>),
    /// Fragments shaded at each pixel of the figure's view, as the run saved them
    /// ([`views::DRAWING_RES`]² pixels, row 0 at the bottom).
    Overdraw(Vec<u32>),
    /// Where the translucent blend goes wrong at each pixel of the figure's view, as the run saved
    /// it (`measure::translucency::error_picture`'s levels, same layout).
    Translucency(Vec<u32>),
}

/// Per drawn triangle: its cluster's colour and index. Distinct colours are golden-ratio hues;
/// in `by_rank` the first cluster drawn is black and the last a light grey (the paper's white
/// would vanish into the page).
fn cluster_colours(starts: &[usize], by_rank: bool) -> Vec<([u8; 3], u32)> {
    let n = starts.len() - 1;
    let mut colours = Vec::with_capacity(*starts.last().unwrap_or(&0));
    for (c, w) in starts.windows(2).enumerate() {
        let colour = if by_rank {
            let g = (f64::from(LAST_GREY) * c as f64 / (n.max(2) - 1) as f64).round() as u8;
            [g, g, g]
        } else {
            let (r, g, b) = HSLColor((c as f64 * 0.618_034).fract(), 0.65, 0.55).rgb();
            [r, g, b]
        };
        colours.extend(std::iter::repeat_n((colour, c as u32), w[1] - w[0]));
    }
    colours
}

/// The grey of the last cluster drawn in a cluster-order drawing: as light as a reader can still
/// tell from the white page.
const LAST_GREY: u8 = 215;

/// Fewest page pixels a visible triangle must cover, on average, for triangle borders to be
/// drawn in a corners drawing (below it they would hide the corner colours).
const MIN_BORDERED_TRIANGLE: f32 = 40.0;

/// Grey levels of the overdraw heat map: 1, 2, 3, 4 and 5 or more fragments shaded at a pixel.
const OVERDRAW_GREYS: [u8; 5] = [235, 175, 120, 70, 20];

/// Draws a drawing spec's figure; returns the SVG's path.
pub fn plot(chart: &Chart, table: &Table) -> Result<std::path::PathBuf> {
    let saved = read_orders(&chart.orders)?;
    let stale = |what: String| Error::input(chart.orders.display(), format!("{what}; rerun the experiment"));
    let data = source::data_dir(chart.data.as_deref());
    let mut models: Vec<(&str, Mesh)> = Vec::new();
    for row in &saved {
        if !models.iter().any(|(m, _)| *m == row.model) {
            models.push((&row.model, Source::parse(&row.model)?.mesh(data.as_deref(), chart.seed)?));
        }
    }
    let levels = level_meshes(&saved, data.as_deref(), chart.seed)?;
    let kind = chart.figure.kind;
    // Results written before progressive meshes have no level or update columns.
    let key: &[&str] = if levels.is_empty() {
        &["model", "method", "cache"]
    } else {
        &["model", "method", "cache", "level", "update"]
    };
    let acmrs = table.rows("acmr", key)?;
    let one_method = saved.iter().all(|r| r.method == saved[0].method);
    let mut drawings = Vec::new();
    for row in &saved {
        let (model, method) = (row.model.as_str(), row.method.as_str());
        let mesh = match levels.iter().find(|(m, l, _)| *m == model && *l == row.level) {
            Some((_, _, mesh)) => mesh,
            None => &models.iter().find(|(m, _)| *m == model).expect("every model is loaded").1,
        };
        let mut label = if models.len() > 1 { format!("{}: ", short(model)) } else { String::new() };
        if !row.level.is_empty() {
            label += &format!("{} triangles · {} · ", mesh.triangle_count(), row.update);
        }
        let order: Vec<u32> = words(&row.order).map_err(|e| stale(format!("`{method}` on `{model}`: {e}")))?;
        let starts: Vec<usize> = words(&row.clusters).map_err(|e| stale(format!("`{method}` on `{model}`: {e}")))?;
        order::check_permutation(&order, mesh.triangle_count())
            .map_err(|why| stale(format!("`{method}` on `{model}` is not an order of this model ({why})")))?;
        if !order::tiles(&starts, order.len()) {
            return Err(stale(format!("the clusters of `{method}` on `{model}` do not tile its order")));
        }
        let triangles = mesh.triangles_in_order(&order);
        let recorded: Vec<(&str, f64)> = acmrs
            .iter()
            .filter(|(c, _)| c[0] == model && c[1] == method && (levels.is_empty() || same_level(&c[3..], row)))
            .map(|(c, v)| (c[2].as_str(), *v))
            .collect();
        // Panels that differ only by level name the level, not the one method.
        let name = if one_method && !row.level.is_empty() { "" } else { method.split(':').next().unwrap_or(method) };
        let label = if name.is_empty() { label.trim_end_matches(" · ").to_string() } else { label };
        match kind {
            FigureKind::Sequence => {
                let topology = Topology::new(mesh);
                let numbers: Vec<String> = recorded.iter().map(|(c, v)| format!("{c} {}", axes::number(*v))).collect();
                let adjacent =
                    order.windows(2).map(|w| topology.neighbors.row(w[0] as usize).contains(&w[1])).collect();
                drawings.push(Drawing {
                    mesh,
                    title: format!("{label}{name} · ACMR {}", numbers.join(", ")),
                    triangles,
                    kind: Content::Sequence { adjacent },
                });
            }
            FigureKind::Corners => {
                for entry in row.corners.split(';').filter(|e| !e.is_empty()) {
                    let (cache, digits) = entry.split_once('=').ok_or_else(|| stale(format!("corners `{entry}`")))?;
                    let classes =
                        OrderRow::decode_corners(digits).map_err(|e| stale(format!("corners of {cache}: {e}")))?;
                    let (_, acmr) = recorded.iter().find(|(c, _)| *c == cache).copied().ok_or_else(|| {
                        stale(format!("the results have no ACMR of `{method}` on `{model}` at {cache}"))
                    })?;
                    let misses = classes.iter().flatten().filter(|c| **c != Corner::Hit).count();
                    let drawn = misses as f64 / classes.len().max(1) as f64;
                    if classes.len() != triangles.len() || (drawn - acmr).abs() > 1e-9 * acmr.max(1.0) {
                        return Err(stale(format!(
                            "the corners of `{method}` on `{model}` at {cache} give ACMR {drawn}, the results say {acmr}"
                        )));
                    }
                    if !first_loads_fit(&triangles, &classes, mesh.vertex_count()) {
                        return Err(stale(format!(
                            "the corners of `{method}` on `{model}` at {cache} do not fit its order"
                        )));
                    }
                    drawings.push(Drawing {
                        mesh,
                        title: format!("{label}{name} · {cache} · ACMR {}", axes::number(acmr)),
                        triangles: triangles.clone(),
                        kind: Content::Corners(classes),
                    });
                }
            }
            kind => {
                let (cache, acmr) = *recorded.first().ok_or_else(|| stale("has no cache model".into()))?;
                let clusters = format!("{} clusters · ", starts.len() - 1);
                let (content, clusters) = match kind {
                    FigureKind::Clusters => (Content::Clusters(cluster_colours(&starts, false)), clusters),
                    FigureKind::ClusterOrder => (Content::Clusters(cluster_colours(&starts, true)), clusters),
                    _ => {
                        let (column, what) = match kind {
                            FigureKind::Translucency => (&row.translucency, "translucency error"),
                            _ => (&row.overdraw, "overdraw"),
                        };
                        let picture = |e: String| stale(format!("the {what} picture of `{method}` on `{model}`: {e}"));
                        let bytes = base64::engine::general_purpose::STANDARD
                            .decode(column)
                            .map_err(|e| picture(e.to_string()))?;
                        let (res, levels) = OrderRow::decode_counts(&bytes).map_err(picture)?;
                        if res != views::DRAWING_RES {
                            return Err(picture(format!("{res}² pixels")));
                        }
                        match kind {
                            FigureKind::Translucency => (Content::Translucency(levels), String::new()),
                            _ => {
                                // The overdraw ratio of exactly this picture (N06 Fig. 1 gives it per view).
                                let shaded: u64 = levels.iter().map(|&k| u64::from(k)).sum();
                                let covered = levels.iter().filter(|&&k| k > 0).count().max(1);
                                let ovr = shaded as f64 / covered as f64;
                                let note = format!("OVR {} from this view ({res}²) · ", axes::number(ovr));
                                (Content::Overdraw(levels), note)
                            }
                        }
                    }
                };
                drawings.push(Drawing {
                    mesh,
                    title: format!("{label}{name} · {clusters}ACMR {} at {cache}", axes::number(acmr)),
                    triangles,
                    kind: content,
                });
            }
        }
    }
    let path = chart.svg.clone();
    let svg = render(chart, &drawings).map_err(|e| Error::output(&path, format!("cannot draw: {e}")))?;
    save(&path, &svg)?;
    Ok(path)
}

/// Whether `classes` can be the corners of `triangles` drawn in order: every vertex's first use is
/// its one first load, and no later use is. Catches an order and corners saved by different runs
/// without replaying the cache.
fn first_loads_fit(triangles: &[[u32; 3]], classes: &[[Corner; 3]], vertex_count: usize) -> bool {
    let mut seen = vec![false; vertex_count];
    triangles.iter().zip(classes).all(|(t, c)| {
        (0..3).all(|k| {
            let first = !std::mem::replace(&mut seen[t[k] as usize], true);
            first == (c[k] == Corner::Miss(1))
        })
    })
}

/// `models/horse.ply@40000` → `horse.ply@40000`.
fn short(model: &str) -> &str {
    model.rsplit('/').next().unwrap_or(model)
}

/// Whitespace-separated numbers.
fn words<T: std::str::FromStr>(text: &str) -> std::result::Result<Vec<T>, String>
where
    T::Err: std::fmt::Display,
{
    text.split_whitespace().map(|w| w.parse::<T>().map_err(|e| format!("`{w}`: {e}"))).collect()
}

/// Whether the results' `[level, update]` cells are those of an orders row (levels compared as
/// numbers: the results write `1.0`, the orders `1`).
fn same_level(cells: &[String], row: &OrderRow) -> bool {
    cells[0].parse::<f64>().ok() == row.level.parse::<f64>().ok() && cells[1] == row.update
}

/// The meshes of the levels the orders draw, per model: `(model, level, mesh)`. The
/// simplification history is deterministic, so it is built again here rather than saved.
fn level_meshes<'a>(saved: &'a [OrderRow], data: Option<&Path>, seed: u64) -> Result<Vec<(&'a str, &'a str, Mesh)>> {
    let mut out = Vec::new();
    let mut models: Vec<&str> = Vec::new();
    for row in saved.iter().filter(|r| !r.level.is_empty()) {
        if !models.contains(&row.model.as_str()) {
            models.push(&row.model);
        }
    }
    for model in models {
        let mut asked: Vec<&str> = Vec::new();
        for row in saved.iter().filter(|r| r.model == model && !r.level.is_empty()) {
            if !asked.contains(&row.level.as_str()) {
                asked.push(&row.level);
            }
        }
        let fractions = asked
            .iter()
            .map(|l| {
                l.parse::<f64>().map_err(|_| Error::input(model, format!("level `{l}` in the orders is not a number")))
            })
            .collect::<Result<Vec<f64>>>()?;
        let scene = Source::parse(model)?.open(data, seed)?.with_levels(&fractions, Update::Smart)?;
        let levels = scene.frames.levels().expect("a scene with levels");
        for (&level, fraction) in asked.iter().zip(&fractions) {
            let f = levels.fractions.iter().position(|x| x == fraction).ok_or_else(|| {
                Error::input(model, format!("level {level} is not reached by the simplification; rerun the experiment"))
            })?;
            out.push((model, level, Mesh { triangles: levels.triangles(f), ..scene.mesh.clone() }));
        }
    }
    Ok(out)
}

/// The orders file's rows, in the order the run wrote them; a second row for the same model and
/// method is an error.
fn read_orders(path: &Path) -> Result<Vec<OrderRow>> {
    let mut reader = csv::Reader::from_path(path).map_err(|e| {
        Error::input(
            path.display(),
            format!("cannot read the orders ({e}); run the experiment first (`triorder run SPEC`)"),
        )
    })?;
    let mut rows: Vec<OrderRow> = Vec::new();
    for (i, row) in reader.deserialize::<OrderRow>().enumerate() {
        let line = i + 2;
        let row = row.map_err(|e| Error::input(path.display(), format!("line {line}: {e}")))?;
        if rows
            .iter()
            .any(|r| r.model == row.model && r.method == row.method && r.level == row.level && r.update == row.update)
        {
            return Err(Error::input(
                path.display(),
                format!("line {line}: a second order for the same model, method and level"),
            ));
        }
        rows.push(row);
    }
    Ok(rows)
}

/// Where a drawing's mesh lands: the orthographic projection of the spec's view, its bounding
/// box in normalised device coordinates, and the panel rectangle it maps to.
struct Placement {
    camera: views::Camera,
    lo: Vec2,
    hi: Vec2,
    width: u32,
    height: u32,
}

impl Placement {
    fn new(mesh: &Mesh, view: [f32; 3], up: Option<[f32; 3]>) -> Placement {
        let camera = views::drawing_camera(&mesh.positions, view, up);
        let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        for &p in &mesh.positions {
            let q = ndc(&camera, p);
            (lo, hi) = (lo.min(q), hi.max(q));
        }
        // A margin of 1% each side, so the extremes (a horse's hooves) do not touch the edge.
        let pad = (hi - lo) * 0.01;
        (lo, hi) = (lo - pad, hi + pad);
        let size = (hi - lo).max(Vec2::splat(1e-6));
        let width = PANEL_W - 2 * MARGIN;
        let height = ((width as f32 * size.y / size.x).round() as u32).clamp(40, 2 * width);
        Placement { camera, lo, hi, width, height }
    }

    /// Panel pixel (from the mesh rectangle's top left) of an NDC point.
    fn pixel(&self, q: Vec2) -> (f32, f32) {
        let t = (q - self.lo) / (self.hi - self.lo).max(Vec2::splat(1e-6));
        (t.x * self.width as f32, (1.0 - t.y) * self.height as f32)
    }
}

fn ndc(camera: &views::Camera, p: Vec3) -> Vec2 {
    let clip = camera.clip(p);
    Vec2::new(clip.x / clip.w, clip.y / clip.w)
}

/// The whole SVG: header, panels in a grid, a legend line.
fn render(chart: &Chart, drawings: &[Drawing]) -> std::result::Result<String, String> {
    let placements: Vec<Placement> =
        drawings.iter().map(|d| Placement::new(d.mesh, chart.figure.view, chart.figure.up)).collect();
    let cols = match drawings.len() {
        1 => 1,
        2 | 4 => 2,
        _ => 3,
    };
    let row_h: Vec<u32> =
        placements.chunks(cols).map(|row| TITLE_H + MARGIN + row.iter().map(|p| p.height).max().unwrap_or(0)).collect();
    let width = cols as u32 * PANEL_W;
    let setup = if chart.quick { "quick run: small stand-in models, not the paper's" } else { "" };
    let header = Header::new(chart, setup, width);
    let height = header.height + row_h.iter().sum::<u32>() + LEGEND_H;

    // Panel origins (top left of the title) in a grid, row heights fitting their tallest mesh.
    let mut origins = Vec::with_capacity(drawings.len());
    let mut top = header.height;
    for h in &row_h {
        for c in 0..cols {
            if origins.len() < drawings.len() {
                origins.push((c as u32 * PANEL_W, top));
            }
        }
        top += h;
    }
    let mut images = String::new();
    for ((drawing, place), &(left, top)) in drawings.iter().zip(&placements).zip(&origins) {
        if !matches!(drawing.kind, Content::Sequence { .. }) {
            images.push_str(&mesh_image(drawing, place, (left + MARGIN, top + TITLE_H))?);
        }
    }
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, (width, height)).into_drawing_area();
        let draw = || -> DrawResult {
            root.fill(&WHITE)?;
            header.draw(&root)?;
            let title = (FONT, 14).into_text_style(&root);
            for ((drawing, place), &(left, top)) in drawings.iter().zip(&placements).zip(&origins) {
                for (k, line) in axes::wrap(&drawing.title, 60).iter().take(2).enumerate() {
                    root.draw_text(line, &title, (left as i32 + 12, (top + 8 + 17 * k as u32) as i32))?;
                }
                if let Content::Sequence { adjacent } = &drawing.kind {
                    sequence(&root, drawing, adjacent, place, (left + MARGIN, top + TITLE_H))?;
                }
            }
            if let Some(first) = drawings.first() {
                legend(&root, &first.kind, (height - LEGEND_H + 12) as i32)?;
            }
            root.present()
        };
        draw().map_err(|e| e.to_string())?;
    }
    let end = svg.rfind("</svg>").ok_or("the SVG backend wrote no closing tag")?;
    svg.insert_str(end, &images);
    Ok(svg)
}

/// Triangles coloured from red (first) to violet (last), then the path through their centroids.
fn sequence(
    root: &super::axes::Area,
    drawing: &Drawing,
    adjacent: &[bool],
    place: &Placement,
    (ox, oy): (u32, u32),
) -> DrawResult {
    let at = |p: Vec3| {
        let (x, y) = place.pixel(ndc(&place.camera, p));
        (ox as i32 + x.round() as i32, oy as i32 + y.round() as i32)
    };
    let n = drawing.triangles.len().max(2) as f64;
    let mut centroids = Vec::with_capacity(drawing.triangles.len());
    for (i, tri) in drawing.triangles.iter().enumerate() {
        let corners = tri.map(|v| drawing.mesh.positions[v as usize]);
        let color = HSLColor(0.8 * i as f64 / (n - 1.0), 0.7, 0.62);
        root.draw(&Polygon::new(corners.iter().map(|&p| at(p)).collect::<Vec<_>>(), color.filled()))?;
        root.draw(&PathElement::new(
            [0, 1, 2, 0].iter().map(|&k| at(corners[k])).collect::<Vec<_>>(),
            WHITE.stroke_width(1),
        ))?;
        centroids.push(at((corners[0] + corners[1] + corners[2]) / 3.0));
    }
    for (pair, &adjacent) in centroids.windows(2).zip(adjacent) {
        let style = if adjacent { BLACK.stroke_width(2) } else { RGBColor(60, 60, 60).stroke_width(1) };
        root.draw(&PathElement::new(vec![pair[0], pair[1]], style))?;
    }
    Ok(())
}

/// The mesh as the CPU rasterizer sees it, as an `<image>` element. Corners: each visible pixel
/// takes the colour of the corner of its triangle it lies nearest (largest barycentric weight);
/// clusters: its cluster's colour; both shaded by the facet's angle to the view and darkened along
/// triangle (corners) or cluster (clusters) borders. Overdraw: the grey of the number of fragments
/// shaded at the pixel in draw order, lightly shaded so the shape reads.
fn mesh_image(drawing: &Drawing, place: &Placement, (ox, oy): (u32, u32)) -> std::result::Result<String, String> {
    // The rasterizer draws the NDC square [-1, 1]² at the resolution the run saved its pictures
    // at; the image is cropped to the mesh's box.
    let res = views::DRAWING_RES;
    let positions = &drawing.mesh.positions;
    let ids = cpu::visible_triangles(positions, &drawing.triangles, &place.camera, res).map_err(|e| e.to_string())?;
    let n = res as usize;
    let to_px = |v: f32| ((v + 1.0) * 0.5 * res as f32).clamp(0.0, res as f32);
    let (x0, x1) = (to_px(place.lo.x).floor() as usize, to_px(place.hi.x).ceil() as usize);
    let (y0, y1) = (to_px(place.lo.y).floor() as usize, to_px(place.hi.y).ceil() as usize);
    let (w, h) = (x1.saturating_sub(x0).max(1), y1.saturating_sub(y0).max(1));
    let projected: Vec<Vec2> = positions.iter().map(|&p| ndc(&place.camera, p)).collect();
    let id = |x: usize, y: usize| if x < n && y < n { ids[y * n + x] } else { u32::MAX };
    // Triangle borders only where triangles are large enough on the page for their colours to
    // show between them: at 40k triangles in a 500-pixel panel, borders alone would fill it.
    let covered = ids.iter().filter(|&&t| t != u32::MAX).count();
    let mut seen: Vec<u32> = ids.iter().copied().filter(|&t| t != u32::MAX).collect();
    seen.sort_unstable();
    seen.dedup();
    let page_scale = place.width as f32 / w as f32;
    let page_pixels = covered as f32 * page_scale * page_scale / seen.len().max(1) as f32;
    let triangle_borders = page_pixels >= MIN_BORDERED_TRIANGLE;
    let mut rgb = vec![255u8; w * h * 3];
    for row in 0..h {
        let y = y1 - 1 - row; // image rows run top-down, raster rows bottom-up
        for col in 0..w {
            let x = x0 + col;
            let t = id(x, y);
            if t == u32::MAX {
                continue;
            }
            let tri = drawing.triangles[t as usize];
            let (base, border) = match &drawing.kind {
                Content::Corners(classes) => {
                    let p =
                        Vec2::new((x as f32 + 0.5) / res as f32 * 2.0 - 1.0, (y as f32 + 0.5) / res as f32 * 2.0 - 1.0);
                    let [a, b, c] = tri.map(|v| projected[v as usize]);
                    let area = (b - a).perp_dot(c - a);
                    let weights = [
                        (c - b).perp_dot(p - b) / area,
                        (a - c).perp_dot(p - c) / area,
                        (b - a).perp_dot(p - a) / area,
                    ];
                    let corner = (0..3).max_by(|&i, &j| weights[i].total_cmp(&weights[j])).unwrap_or(0);
                    let base = match classes[t as usize][corner] {
                        Corner::Hit => HIT,
                        Corner::Miss(1) => FIRST_LOAD,
                        Corner::Miss(2) => RELOAD,
                        Corner::Miss(_) => LATER_RELOAD,
                    };
                    (base, triangle_borders && (id(x + 1, y) != t || id(x, y + 1) != t))
                }
                Content::Clusters(colours) => {
                    let cluster = |t: u32| colours.get(t as usize).map(|c| c.1);
                    let here = cluster(t);
                    (colours[t as usize].0, cluster(id(x + 1, y)) != here || cluster(id(x, y + 1)) != here)
                }
                Content::Overdraw(shaded) => {
                    let k = (shaded[y * n + x] as usize).clamp(1, OVERDRAW_GREYS.len());
                    ([OVERDRAW_GREYS[k - 1]; 3], false)
                }
                Content::Translucency(levels) => (error_colour(levels[y * n + x]), false),
                Content::Sequence { .. } => unreachable!("sequences are drawn as polygons"),
            };
            let [pa, pb, pc] = tri.map(|v| positions[v as usize]);
            let normal = (pb - pa).cross(pc - pa).normalize_or_zero();
            // Overdraw greys carry the data, so their facets are shaded only lightly.
            let relief =
                if matches!(drawing.kind, Content::Overdraw(_) | Content::Translucency(_)) { 0.15 } else { 0.5 };
            let mut shade = 1.0 - relief + relief * normal.dot(-place.camera.forward).abs();
            if border {
                shade *= 0.6;
            }
            let out = &mut rgb[(row * w + col) * 3..][..3];
            for k in 0..3 {
                out[k] = (f32::from(base[k]) * shade).round() as u8;
            }
        }
    }
    let mut png_bytes = Vec::new();
    {
        let mut encoder = png::Encoder::new(&mut png_bytes, w as u32, h as u32);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        encoder.set_compression(png::Compression::High);
        let mut writer = encoder.write_header().map_err(|e| e.to_string())?;
        writer.write_image_data(&rgb).map_err(|e| e.to_string())?;
    }
    let data = base64::engine::general_purpose::STANDARD.encode(&png_bytes);
    Ok(format!(
        "<image x=\"{ox}\" y=\"{oy}\" width=\"{}\" height=\"{}\" preserveAspectRatio=\"none\" href=\"data:image/png;base64,{data}\"/>\n",
        place.width, place.height
    ))
}

/// One line saying how to read the panels.
fn legend(root: &super::axes::Area, kind: &Content, y: i32) -> DrawResult {
    let style = (FONT, 13).into_text_style(root);
    match kind {
        Content::Sequence { .. } => root.draw_text(
            "colour: position in the sequence, first (red) to last (violet) · thick line: consecutive triangles share an edge · thin line: a jump",
            &style,
            (12, y),
        ),
        Content::Corners(_) => swatches(
            root,
            y,
            &[
                (HIT, "hit"),
                (FIRST_LOAD, "first load (one per vertex)"),
                (RELOAD, "first reload"),
                (LATER_RELOAD, "second or later reload"),
            ],
        ),
        Content::Clusters(colours) if colours.first().is_some_and(|c| c.0 == [0, 0, 0]) => swatches(
            root,
            y,
            &[([0, 0, 0], "first cluster drawn"), ([108, 108, 108], "…"), ([LAST_GREY; 3], "last cluster drawn")],
        ),
        Content::Clusters(_) => root.draw_text("colour: cluster (facets shaded by angle to the view)", &style, (12, y)),
        Content::Translucency(_) => swatches(
            root,
            y,
            &[
                (error_colour(1), "blended right"),
                (error_colour(2), "visibly wrong (1/255)"),
                (error_colour(17), "16/255"),
                (error_colour(65), "64/255 or more"),
            ],
        ),
        Content::Overdraw(_) => {
            let labels = ["1 fragment shaded", "2", "3", "4", "5 or more"];
            let entries: Vec<([u8; 3], &str)> = OVERDRAW_GREYS.iter().map(|&g| [g, g, g]).zip(labels).collect();
            swatches(root, y, &entries)
        }
    }
}

/// The colour of a translucency error level: light grey where the blend is right, then red from
/// light (just visible, 1/255) to dark (a large error, 64/255 or more).
fn error_colour(level: u32) -> [u8; 3] {
    if level <= 1 {
        return [225, 225, 225];
    }
    let t = ((level - 1) as f32 / 64.0).min(1.0);
    let mix = |light: f32, dark: f32| (light + (dark - light) * t).round() as u8;
    [mix(250.0, 120.0), mix(150.0, 0.0), mix(150.0, 0.0)]
}

/// A row of colour swatches with labels.
fn swatches(root: &super::axes::Area, y: i32, entries: &[([u8; 3], &str)]) -> DrawResult {
    let style = (FONT, 13).into_text_style(root);
    let mut x = 12;
    for &([r, g, b], label) in entries {
        root.draw(&Rectangle::new([(x, y), (x + 14, y + 14)], RGBColor(r, g, b).filled()))?;
        root.draw(&Rectangle::new([(x, y), (x + 14, y + 14)], RGBColor(90, 90, 90).stroke_width(1)))?;
        root.draw_text(label, &style, (x + 20, y))?;
        x += 44 + axes::text_width(label, 13.0);
    }
    Ok(())
}
