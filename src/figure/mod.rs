//! Figures: a results CSV → one SVG, drawn as the spec's `[figure]` table says.
//!
//! A figure reads only the CSV (never recomputes), so it can be redrawn, restyled or reviewed
//! without the models or the time to measure them. Layout: the title, the paper's claim as a
//! caption under it, one panel per facet value (small multiples sharing their axes), and one
//! legend strip for the whole figure with a colour per series that stays that series' colour in
//! every figure ([`axes::Colors`]). The kinds differ only in how a panel's data is drawn:
//! [`xy`] (line, scatter), [`bar`] and [`distribution`].

mod axes;
mod bar;
pub(crate) mod data;
mod distribution;
mod drawing;
pub mod gallery;
mod hardware_fit;
mod ratio;
pub mod spec;
mod table;
mod verdicts;
mod xy;

use std::ops::Range;
use std::path::{Path, PathBuf};

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::error::{Error, Result};
use crate::measure;
use axes::{Area, Colors, DrawResult, FONT, Frame, Swatch};
use data::{Panel, Table};
use spec::{Figure, FigureKind};

/// Where a figure's results are read and the figure written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlotOptions {
    /// Plot the quick run (`results/quick/` → `paper-figures/quick/`).
    pub quick: bool,
    /// The project root holding `results/` and `paper-figures/`.
    pub out_dir: PathBuf,
    /// Where drawings find the models' geometry (else `TRIORDER_DATA`, else `../shared/data`).
    pub data: Option<PathBuf>,
}

impl Default for PlotOptions {
    fn default() -> Self {
        PlotOptions { quick: false, out_dir: PathBuf::from("."), data: None }
    }
}

/// What one figure is drawn from and where it goes: its spec's `[figure]` table and header, its
/// results, and where drawings find the models' geometry.
pub struct Chart<'a> {
    pub figure: &'a Figure,
    /// The spec file, for errors about the figure.
    pub spec: &'a Path,
    pub title: &'a str,
    pub claim: Option<&'a str>,
    /// The results CSV and, for drawings, the orders file beside it.
    pub csv: PathBuf,
    pub orders: PathBuf,
    pub svg: PathBuf,
    /// A quick run's figure (stand-in models): its header says so.
    pub quick: bool,
    /// Where drawings find the models' geometry: as for runs, else `TRIORDER_DATA`, else
    /// `../shared/data`.
    pub data: Option<PathBuf>,
    /// Seeds the seeded procedural models (`disk:N`) drawings rebuild.
    pub seed: u64,
}

/// Draws `chart` from its CSV; returns the SVG's path.
pub fn plot(chart: &Chart) -> Result<PathBuf> {
    let csv = &chart.csv;
    let table = Table::read(csv)?;
    // Panels of series, for the chart kinds; the other kinds lay out their own figure.
    let panels;
    let figure = chart.figure;
    let mut setup: Vec<String> = table
        .distinct(&["views", "res"])
        .iter()
        .map(|v| format!("views {} at {}×{} pixels", v[0], v[1], v[1]))
        .collect();
    setup.extend(measured_on(&table));
    setup.extend(unindexed(&table));
    if chart.quick {
        setup.push("quick run: small stand-in models, not the paper's".into());
    }
    let kind: Box<dyn Kind> = match figure.kind {
        FigureKind::Line | FigureKind::Scatter => {
            panels = table.select(figure)?;
            let x = figure.x.as_deref().unwrap_or_default();
            Box::new(xy::Xy::new(&panels, x, figure.kind == FigureKind::Line, &figure.highlight, csv)?)
        }
        FigureKind::Bar => {
            panels = table.select(figure)?;
            Box::new(bar::Bars::new(&panels))
        }
        FigureKind::Distribution => {
            panels = table.select(figure)?;
            Box::new(distribution::Distribution::new(&panels))
        }
        FigureKind::Table => {
            panels = match &figure.relative_to {
                Some(reference) => relative_to(table.select(figure)?, reference),
                None => table.select(figure)?,
            };
            // Methods are what a table compares: when they are the rows, the best is marked
            // down each column; so too when the columns are different metrics.
            let best_per_column =
                figure.series == "metric" || matches!(figure.x.as_deref(), Some("method" | "method_name"));
            let higher_better = figure.relative_to.is_some();
            Box::new(table::Tables { bars: bar::Bars::new(&panels), best_per_column, higher_better })
        }
        FigureKind::Sequence
        | FigureKind::Corners
        | FigureKind::Clusters
        | FigureKind::ClusterOrder
        | FigureKind::Overdraw
        | FigureKind::Translucency => return drawing::plot(chart, &table),
        FigureKind::HardwareFit => return hardware_fit::plot(chart, &table),
        FigureKind::Ratio => return ratio::plot(chart, &table),
    };
    // Panels share their axes, except panels of different metrics, whose units differ (each
    // titled by its metric), and those a spec asks to fit on their own.
    let frames = if figure.facet.as_deref() == Some("metric") {
        (0..panels.len())
            .map(|i| frame(kind.as_ref(), figure, csv, Some((i, Some(&panels[i].title)))))
            .collect::<Result<Vec<_>>>()?
    } else if figure.own_axes {
        (0..panels.len()).map(|i| frame(kind.as_ref(), figure, csv, Some((i, None)))).collect::<Result<Vec<_>>>()?
    } else {
        vec![frame(kind.as_ref(), figure, csv, None)?]
    };
    let mut names: Vec<String> = Vec::new();
    for s in panels.iter().flat_map(|p| &p.series) {
        if !names.contains(&s.name) {
            names.push(s.name.clone());
        }
    }
    let mut colors = Colors::new(&figure.series, &names);
    if figure.kind == FigureKind::Line && !figure.highlight.is_empty() && names.len() > MAX_COLOURED_LINES {
        // More lines than a reader can tell apart: the highlighted ones in colour, the rest as
        // grey context (the paper's series against every other ordering).
        let context = names.iter().filter(|n| !figure.highlight.iter().any(|h| axes::family(n) == h)).cloned();
        colors = colors.context(context.collect());
    }

    let path = chart.svg.clone();
    let mut svg = String::new();
    draw(&mut svg, chart, &setup.join(" · "), &panels, kind.as_ref(), &frames, &colors)
        .map_err(|e| Error::output(&path, format!("cannot draw the figure: {e}")))?;
    save(&path, &svg)?;
    Ok(path)
}

/// Every value of `panels` as the value of the series of method `reference` at the same x,
/// divided by it: how many times lower than the reference each is (the reference itself is 1).
/// Points without a reference value at their x are dropped.
fn relative_to(mut panels: Vec<Panel>, reference: &str) -> Vec<Panel> {
    for panel in &mut panels {
        let Some(base) = panel.series.iter().find(|s| axes::family(&s.name) == reference).cloned() else { continue };
        for series in &mut panel.series {
            series.points.retain_mut(|(x, v)| {
                let Some((_, r)) = base.points.iter().find(|(bx, _)| bx == x) else { return false };
                *v = r / *v;
                v.is_finite()
            });
        }
    }
    panels
}

/// "measured on DEVICE" for the GPUs that counted or timed rows of `table` (their `backend` is
/// `gpu: DEVICE`), saying when one is a software rasterizer: its counts are exact, but its
/// vertex reuse and times are the CPU's that emulates a GPU, not a GPU's.
fn measured_on(table: &Table) -> Option<String> {
    let mut devices: Vec<String> = Vec::new();
    for row in table.distinct(&["backend"]) {
        if let Some(device) = row[0].strip_prefix("gpu: ").filter(|d| !devices.iter().any(|k| k == d)) {
            devices.push(device.to_string());
        }
    }
    if devices.is_empty() {
        return None;
    }
    let software = ["llvmpipe", "lavapipe", "swiftshader", "softpipe"];
    let emulated = devices.iter().any(|d| software.iter().any(|s| d.to_lowercase().contains(s)));
    let note = if emulated { " (a software rasterizer on the CPU, not a GPU)" } else { "" };
    Some(format!("measured on {}{note}", devices.join(", ")))
}

/// A note naming the models of `table` with three vertices per triangle: unindexed meshes, which
/// miss three vertices a triangle in any order (their cache metrics cannot tell orders apart).
fn unindexed(table: &Table) -> Option<String> {
    let unindexed: Vec<String> = table
        .distinct(&["model", "model_triangles", "model_vertices"])
        .into_iter()
        .filter(|r| r[1].parse::<usize>().is_ok_and(|t| t > 1 && r[2].parse::<usize>().is_ok_and(|v| v >= 3 * t)))
        .map(|r| r[0].clone())
        .collect();
    (!unindexed.is_empty()).then(|| {
        format!("{}: no shared vertices (unindexed), so every order misses 3 vertices a triangle", unindexed.join(", "))
    })
}

/// Writes a finished figure to `path` atomically, creating its folder.
fn save(path: &Path, svg: &str) -> Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| Error::output(path, e))?;
    }
    crate::atomic::write(path, svg.as_bytes())
}

/// A chart kind: its data, prepared from the panels, and how one panel of it is drawn.
trait Kind {
    /// The extent of the data of one panel, or (`None`) of all panels, for axes they share.
    fn extent(&self, panel: Option<usize>) -> Extent;
    fn swatch(&self) -> Swatch;
    /// Whether the figure needs a colour legend (tables name their columns themselves).
    fn legend(&self) -> bool {
        true
    }
    /// The size of one panel, when the kind needs its own (tables grow with their rows).
    fn panel_size(&self) -> Option<(usize, usize)> {
        None
    }
    /// The narrowest a panel may be (bars: room for their category labels).
    fn min_panel_width(&self) -> usize {
        0
    }
    /// Draws panel `index` into `area`.
    fn draw(&self, index: usize, area: &Area, title: &str, frame: &Frame, colors: &Colors) -> DrawResult;
}

/// What the data spans.
struct Extent {
    x: XAxis,
    /// Smallest and largest y.
    y: (f64, f64),
    /// Bars: a linear y axis starts at zero (or at the metric's optimum).
    from_zero: bool,
    /// Bars: every value drawn, to find outliers that would flatten the rest.
    bars: Vec<f64>,
}

enum XAxis {
    /// Smallest and largest x, padded for the axis.
    Data(f64, f64),
    /// Exactly this range (distribution percentiles).
    Fixed(Range<f64>),
    /// Categories at 0, 1, 2, …
    Categories(Vec<String>),
}

/// `(min, max)` of `values`, `None` if empty.
fn span(values: impl Iterator<Item = f64>) -> Option<(f64, f64)> {
    values.fold(None, |acc, v| match acc {
        None => Some((v, v)),
        Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
    })
}

/// The axes: data extent padded by 5% (multiplicatively on log axes), the spec's y range if it
/// gives one, and the axis titles. For all panels, or for the one panel `(index, title)` alone
/// (its y axis then titled by the panel's title where one is given).
fn frame(kind: &dyn Kind, figure: &Figure, csv: &Path, panel: Option<(usize, Option<&str>)>) -> Result<Frame> {
    let extent = kind.extent(panel.map(|(i, _)| i));
    let log_error = |key: &str, lo: f64| {
        Error::input(csv.display(), format!("figure.{key} asks for a log axis, but the data has a value {lo} ≤ 0"))
    };
    let (x, categories) = match extent.x {
        XAxis::Data(lo, hi) => {
            if figure.x_log && lo <= 0.0 {
                return Err(log_error("x_log", lo));
            }
            (pad(lo, hi, figure.x_log), None)
        }
        XAxis::Fixed(range) => (range, None),
        XAxis::Categories(names) => (-0.5..names.len() as f64 - 0.5, Some(names)),
    };
    let (lo, hi) = extent.y;
    // The metric's optimum, when every metric drawn shares one: marked, and where bars grow from.
    let optimums: Vec<Option<f64>> = figure.metrics.iter().map(|m| measure::optimum(m)).collect();
    let optimum = optimums.first().copied().flatten().filter(|o| optimums.iter().all(|p| *p == Some(*o)));
    let y = match figure.y_range {
        Some((lo, hi)) => lo..hi,
        None if figure.y_log && lo <= 0.0 => return Err(log_error("y_log", lo)),
        None if extent.from_zero && !figure.y_log => {
            // Bars grow from the optimum when nothing lies below it (an overdraw ratio's 1), so
            // their heights are the excess over it; else from zero.
            let base = optimum.filter(|&o| lo >= o).unwrap_or(0.0);
            let hi = below_outliers(&extent.bars, base).unwrap_or(hi);
            let padded = pad(lo.min(base), hi.max(base), false);
            (if lo >= base { base } else { padded.start })..(if hi <= base { base } else { padded.end })
        }
        None => pad(lo, hi, figure.y_log),
    };
    let label = |name: &str| measure::label(name).to_string();
    let metric = if figure.metrics.len() == 1 { label(&figure.metric) } else { figure.metrics.join(" / ") };
    let x_desc = match (&figure.x_label, &figure.x) {
        (Some(label), _) => label.clone(),
        (None, Some(column)) => column_label(column).to_string(),
        (None, None) if figure.metric == "ovr" => "views, sorted by overdraw ratio (percentile)".to_string(),
        (None, None) => "values, sorted (percentile)".to_string(),
    };
    let mut y_desc = match panel {
        Some((_, Some(title))) => title.to_string(),
        _ => figure.y_label.clone().unwrap_or(metric),
    };
    if let Some(o) = optimum.filter(|&o| o == y.start && extent.from_zero) {
        // Bars growing from the optimum: it is the axis itself, so it is named, not drawn.
        y_desc = format!("{y_desc} (bars from the optimum, {})", axes::number(o));
    }
    Ok(Frame { x, y, x_log: figure.x_log, y_log: figure.y_log, x_desc, y_desc, categories, optimum })
}

/// Fewest bars among which one can be called an outlier: with two or three, a tall bar is the
/// comparison itself.
const MIN_BARS_FOR_OUTLIERS: usize = 8;

/// The top of the bars above `base` once a few far taller ones are left out: a bar more than
/// four times the median height, when at most a quarter of the bars are, is an outlier (random's
/// ACMR 3 beside orderings at 0.6–0.9) that would leave the differences the figure is about a
/// sliver of the height. The outliers are then drawn cut at the top with their values written
/// (`bar`). `None` when there is no outlier.
fn below_outliers(values: &[f64], base: f64) -> Option<f64> {
    let mut heights: Vec<f64> = values.iter().map(|v| v - base).filter(|h| *h >= 0.0).collect();
    heights.sort_by(f64::total_cmp);
    let median = *heights.get(heights.len() / 2)?;
    let limit = 4.0 * median;
    let outliers = heights.iter().filter(|&&h| h > limit).count();
    if median <= 0.0 || outliers == 0 || outliers * 4 > heights.len() || heights.len() < MIN_BARS_FOR_OUTLIERS {
        return None;
    }
    heights.iter().rev().find(|&&h| h <= limit).map(|h| h + base)
}

/// `lo..hi` widened by 5% of the span each side (a ratio on log axes); a single value gets a
/// span around it.
fn pad(lo: f64, hi: f64, log: bool) -> Range<f64> {
    if log {
        let ratio = if hi > lo { (hi / lo).powf(0.05) } else { 1.5 };
        return lo / ratio..hi * ratio;
    }
    let margin = if hi > lo { (hi - lo) * 0.05 } else { lo.abs().max(1.0) * 0.1 };
    lo - margin..hi + margin
}

/// An axis title for a CSV column, with its unit.
fn column_label(column: &str) -> &str {
    match column {
        "cache_size" => "cache size (vertices)",
        "model_triangles" => "triangles",
        "model_vertices" => "vertices",
        "seconds" => "ordering time (s)",
        "res" => "image size (pixels per side)",
        "view" => "view (index in the set)",
        "method" | "method_name" => "ordering",
        other => other,
    }
}

/// Most lines drawn each in its own colour when a figure highlights some: past it the others
/// are grey context. Eight is about what distinct hues and markers keep apart.
const MAX_COLOURED_LINES: usize = 8;

/// Widest panel that is drawn beside another.
const MAX_SIDE_BY_SIDE_W: usize = 1000;

/// Draws the whole figure into `svg`; `setup` (how the data was measured) goes under the title.
fn draw(
    svg: &mut String,
    chart: &Chart,
    setup: &str,
    panels: &[Panel],
    kind: &dyn Kind,
    frames: &[Frame],
    colors: &Colors,
) -> DrawResult {
    let n = panels.len();
    // Panels wider than a screen's half (tables with many columns) stack, so the figure stays
    // readable at page width.
    let (panel_w, panel_h) = kind.panel_size().unwrap_or(if n == 1 { (760, 500) } else { (540, 400) });
    let panel_w = panel_w.max(kind.min_panel_width());
    let cols = match (n, panel_w) {
        (1, _) => 1,
        (_, w) if w > MAX_SIDE_BY_SIDE_W => 1,
        (2 | 4, _) => 2,
        (_, w) if w > MAX_SIDE_BY_SIDE_W / 2 + 100 => 2,
        _ => 3,
    };
    let rows = n.div_ceil(cols);
    let width = (cols * panel_w) as u32;
    let header = Header::new(chart, setup, width);
    let legend_h = if kind.legend() { axes::legend_height(colors, width) } else { 0 };
    let height = header.height + (rows * panel_h) as u32 + legend_h;

    let root = SVGBackend::with_string(svg, (width, height)).into_drawing_area();
    root.fill(&WHITE)?;
    let (top, rest) = root.split_vertically(header.height);
    let (body, legend) = rest.split_vertically((rows * panel_h) as u32);
    header.draw(&top)?;
    for (i, (area, panel)) in body.split_evenly((rows, cols)).iter().zip(panels).enumerate() {
        kind.draw(i, area, &panel.title, &frames[i.min(frames.len() - 1)], colors)?;
    }
    if kind.legend() {
        axes::legend(&legend, colors, kind.swatch())?;
    }
    root.present()
}

/// A figure's header: its title, how the data was measured, and the paper's claim, wrapped to
/// the figure's width.
struct Header {
    width: u32,
    title: Vec<String>,
    setup: Vec<String>,
    claim: Vec<String>,
    /// Pixels it takes.
    height: u32,
}

impl Header {
    fn new(chart: &Chart, setup: &str, width: u32) -> Header {
        let chars = |size: f64| (f64::from(width - 40) / (size * 0.55)) as usize;
        let title = axes::wrap(chart.title, chars(20.0));
        let setup = axes::wrap(setup, chars(13.0));
        let claim = chart.claim.map_or_else(Vec::new, |c| axes::wrap(&format!("Paper: {c}"), chars(13.0)));
        let height = 16 + 28 * title.len() as u32 + 18 * (setup.len() + claim.len()) as u32 + 10;
        Header { width, title, setup, claim, height }
    }

    fn draw(&self, area: &Area) -> DrawResult {
        let center = Pos::new(HPos::Center, VPos::Top);
        let title_style = TextStyle::from((FONT, 20).into_font().style(FontStyle::Bold)).pos(center);
        let grey = RGBColor(0x44, 0x44, 0x44);
        let setup_style = TextStyle::from((FONT, 13)).color(&grey).pos(center);
        let claim_style = TextStyle::from((FONT, 13).into_font().style(FontStyle::Italic)).color(&grey).pos(center);
        let mid = self.width as i32 / 2;
        let mut y = 16;
        for line in &self.title {
            area.draw_text(line, &title_style, (mid, y))?;
            y += 28;
        }
        let lines = self.setup.iter().map(|l| (l, &setup_style)).chain(self.claim.iter().map(|l| (l, &claim_style)));
        for (line, style) in lines {
            area.draw_text(line, style, (mid, y))?;
            y += 18;
        }
        Ok(())
    }
}
