//! The hardware-fit figure (issue 6 §3): which simulated vertex-cache model predicts what the GPU
//! really shades.
//!
//! Reads a run whose caches list both simulated models and `gpu` (vertex-shader invocations
//! counted by pipeline statistics). For every simulated model it pairs, per (model, ordering), the
//! simulated ACMR with the counted one and scores the prediction:
//! - RMSE: root mean square of simulated − counted ACMR (the model's absolute error);
//! - mean relative error: mean of |simulated − counted| ÷ counted;
//! - r: Pearson correlation (does the model at least rank orders as the GPU does?);
//! - best-order agreement: on how many meshes the order that is best under the model is also
//!   best on the GPU (what a user of the model wants to know).
//!
//! The figure shows the ranking of all models, and the winner's scatter: simulated against counted
//! ACMR, one point per (ordering, mesh), with y = x and the least-squares line.

use std::path::PathBuf;

use plotters::prelude::*;

use super::axes::{self, Area, Colors, DrawResult, FONT, Frame, Painter};
use super::data::Table;
use super::{Chart, Header, save};
use crate::error::{Error, Result};
use crate::measure::GPU_CACHE;

/// How well one simulated model predicts the counted ACMR.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    pub cache: String,
    pub rmse: f64,
    pub mean_relative_error: f64,
    pub pearson: f64,
    /// Meshes whose best order under this model is also the GPU's best, and the mesh count.
    pub best_agrees: (usize, usize),
    /// (simulated, counted, method name) per (mesh, ordering).
    pub points: Vec<(f64, f64, String)>,
    /// Per mesh: the best ordering under this model, and the best as counted.
    pub best: Vec<(String, String, String)>,
}

/// Every simulated model's fit, best (lowest RMSE) first.
pub fn fits(table: &Table) -> Result<Vec<Fit>> {
    let pairs = table.distinct(&["model", "method", "method_name"]);
    let caches: Vec<String> =
        table.distinct(&["cache"]).into_iter().map(|c| c[0].clone()).filter(|c| c != GPU_CACHE).collect();
    if !table.distinct(&["cache"]).iter().any(|c| c[0] == GPU_CACHE) || caches.is_empty() {
        return Err(Error::input(
            table.path().display(),
            format!("a hardware fit needs ACMR rows counted on the GPU (cache `{GPU_CACHE}`) beside simulated ones"),
        ));
    }
    let acmr = |model: &str, method: &str, cache: &str| {
        table.value("acmr", &[("model", model), ("method", method), ("cache", cache)])
    };
    let counted: Vec<f64> = pairs.iter().map(|p| acmr(&p[0], &p[1], GPU_CACHE)).collect::<Result<_>>()?;
    let mut fits = Vec::new();
    for cache in caches {
        let simulated: Vec<f64> = pairs.iter().map(|p| acmr(&p[0], &p[1], &cache)).collect::<Result<_>>()?;
        let n = simulated.len() as f64;
        let errors = simulated.iter().zip(&counted).map(|(s, c)| s - c);
        let rmse = (errors.clone().map(|e| e * e).sum::<f64>() / n).sqrt();
        let mean_relative_error = simulated.iter().zip(&counted).map(|(s, c)| (s - c).abs() / c).sum::<f64>() / n;
        let meshes: Vec<&String> = pairs.iter().map(|p| &p[0]).fold(Vec::new(), |mut seen, m| {
            if !seen.contains(&m) {
                seen.push(m);
            }
            seen
        });
        let best_of = |values: &[f64], mesh: &str| {
            (0..pairs.len()).filter(|&i| pairs[i][0] == mesh).min_by(|&a, &b| values[a].total_cmp(&values[b]))
        };
        let name = |i: Option<usize>| i.map_or_else(String::new, |i| pairs[i][2].clone());
        let best: Vec<(String, String, String)> =
            meshes.iter().map(|m| (m.to_string(), name(best_of(&simulated, m)), name(best_of(&counted, m)))).collect();
        let agree = meshes.iter().filter(|m| best_of(&simulated, m) == best_of(&counted, m)).count();
        fits.push(Fit {
            cache,
            rmse,
            mean_relative_error,
            pearson: super::ratio::pearson(&simulated.iter().copied().zip(counted.iter().copied()).collect::<Vec<_>>()),
            best_agrees: (agree, meshes.len()),
            points: simulated.iter().zip(&counted).zip(&pairs).map(|((&s, &c), p)| (s, c, p[2].clone())).collect(),
            best,
        });
    }
    fits.sort_by(|a, b| a.rmse.total_cmp(&b.rmse));
    Ok(fits)
}

/// Least-squares line y = a + b·x.
fn least_squares(points: &[(f64, f64)]) -> (f64, f64) {
    let n = points.len() as f64;
    let (mx, my) = (points.iter().map(|p| p.0).sum::<f64>() / n, points.iter().map(|p| p.1).sum::<f64>() / n);
    let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let b = if sxx > 0.0 { points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / sxx } else { 0.0 };
    (my - b * mx, b)
}

/// Rows of the ranking table drawn.
const TABLE_ROWS: usize = 14;

/// Draws the figure; returns the SVG's path.
pub fn plot(chart: &Chart, table: &Table) -> Result<PathBuf> {
    let fits = fits(table)?;
    let best = &fits[0];
    let setup = format!(
        "vertex-shader invocations {} · {} (mesh, ordering) pairs · {} simulated models",
        super::measured_on(table).unwrap_or_default(),
        best.points.len(),
        fits.len()
    );
    let path = chart.svg.clone();
    // The ranking, then a line per mesh under it; the scatter beside them needs 620 pixels.
    let lines = 34 + 22 * (TABLE_ROWS as u32 + 1) + 34 + 20 * best.best.len() as u32 + 30;
    let (width, body) = (1300u32, lines.max(620));
    let header = Header::new(chart, &setup, width);
    let mut names: Vec<String> = Vec::new();
    for (_, _, name) in &best.points {
        if !names.contains(name) {
            names.push(name.clone());
        }
    }
    let colors = Colors::new("method_name", &names);
    let legend_h = axes::legend_height(&colors, width);
    let mut svg = String::new();
    let drawn = (|| -> DrawResult {
        let root = SVGBackend::with_string(&mut svg, (width, header.height + body + legend_h)).into_drawing_area();
        root.fill(&WHITE)?;
        let (top, rest) = root.split_vertically(header.height);
        let (middle, legend) = rest.split_vertically(body);
        header.draw(&top)?;
        let (left, right) = middle.split_horizontally(560);
        ranking(&left, &fits)?;
        scatter(&right, best, &colors)?;
        axes::legend(&legend, &colors, axes::Swatch::Point)
    })();
    drawn.map_err(|e| Error::output(&path, format!("cannot draw the figure: {e}")))?;
    save(&path, &svg)?;
    Ok(path)
}

/// The ranking of the simulated models, as a text table.
fn ranking(area: &Area, fits: &[Fit]) -> DrawResult {
    let head = TextStyle::from((FONT, 14).into_font().style(FontStyle::Bold));
    let body = TextStyle::from((FONT, 13));
    let columns = [(20, "cache model"), (230, "RMSE"), (310, "mean rel. err."), (420, "r"), (480, "best agrees")];
    for (x, text) in columns {
        area.draw_text(text, &head, (x, 10))?;
    }
    for (row, fit) in fits.iter().take(TABLE_ROWS).enumerate() {
        let y = 34 + 22 * row as i32;
        let cells = [
            fit.cache.clone(),
            format!("{:.4}", fit.rmse),
            format!("{:.1}%", 100.0 * fit.mean_relative_error),
            format!("{:.3}", fit.pearson),
            format!("{}/{}", fit.best_agrees.0, fit.best_agrees.1),
        ];
        let style = if row == 0 { &head } else { &body };
        for ((x, _), text) in columns.iter().zip(cells) {
            area.draw_text(&text, style, (*x, y))?;
        }
    }
    let mut y = 34 + 22 * TABLE_ROWS as i32;
    if fits.len() > TABLE_ROWS {
        area.draw_text(&format!("… and {} more, worse", fits.len() - TABLE_ROWS), &body, (20, y))?;
    }
    y += 34;
    area.draw_text(&format!("best ordering under {} / as counted by the device", fits[0].cache), &head, (20, y))?;
    for (mesh, model_best, counted_best) in &fits[0].best {
        y += 20;
        let short = mesh.rsplit('/').next().unwrap_or(mesh);
        area.draw_text(&format!("{short}: {model_best} / {counted_best}"), &body, (20, y))?;
    }
    Ok(())
}

/// The best model's simulated ACMR (x) against the counted one (y).
fn scatter(area: &Area, fit: &Fit, colors: &Colors) -> DrawResult {
    let values = fit.points.iter().flat_map(|p| [p.0, p.1]);
    let (lo, hi) = values.fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
    let range = super::pad(lo, hi, false);
    let frame = Frame {
        x: range.clone(),
        y: range,
        x_log: false,
        y_log: false,
        x_desc: format!("simulated ACMR, {}", fit.cache),
        y_desc: "vertex-shader invocations per triangle, counted".into(),
        categories: None,
        optimum: None,
    };
    let title = format!("best fit: {} (RMSE {:.4}); grey: y = x; black: least squares", fit.cache, fit.rmse);
    axes::panel(area, &title, &frame, &FitPainter { fit, colors })
}

struct FitPainter<'a> {
    fit: &'a Fit,
    colors: &'a Colors,
}

impl Painter for FitPainter<'_> {
    fn paint<'a, 'b: 'a, X, Y>(&self, chart: &mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>) -> DrawResult
    where
        X: plotters::coord::ranged1d::Ranged<ValueType = f64> + plotters::coord::ranged1d::ValueFormatter<f64>,
        Y: plotters::coord::ranged1d::Ranged<ValueType = f64> + plotters::coord::ranged1d::ValueFormatter<f64>,
    {
        let xs = self.fit.points.iter().map(|p| p.0);
        let (lo, hi) = xs.fold((f64::MAX, f64::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
        chart.draw_series(LineSeries::new([(lo, lo), (hi, hi)], RGBColor(0xaa, 0xaa, 0xaa).stroke_width(2)))?;
        let (a, b) = least_squares(&self.fit.points.iter().map(|p| (p.0, p.1)).collect::<Vec<_>>());
        chart.draw_series(LineSeries::new([(lo, a + b * lo), (hi, a + b * hi)], BLACK.stroke_width(1)))?;
        for (x, y, name) in &self.fit.points {
            let style = self.colors.of(name).mix(0.85).filled();
            super::axes::markers(chart, &[(*x, *y)], self.colors.marker(name), 4, style)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A results CSV with, per (mesh, ordering), counted ACMR and two simulated models: `good`
    /// off by 0.01 everywhere, `bad` off by 0.5 and ranking the orders backwards on mesh b.
    fn table() -> (tempfile::TempDir, Table) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("fit.csv");
        let mut text = String::from("model,method,method_name,metric,cache,backend,value\n");
        let counted = [("a", "x", 0.7), ("a", "y", 0.9), ("b", "x", 1.2), ("b", "y", 0.8)];
        for (model, method, value) in counted {
            text += &format!("{model},{method},{method},acmr,gpu,gpu: test device,{value}\n");
            text += &format!("{model},{method},{method},acmr,good,cpu,{}\n", value + 0.01);
            let bad = if model == "b" { 2.0 - value } else { value + 0.5 };
            text += &format!("{model},{method},{method},acmr,bad,cpu,{bad}\n");
            text += &format!("{model},{method},{method},atvr,good,cpu,9\n");
        }
        std::fs::write(&path, text).unwrap();
        let table = Table::read(&path).unwrap();
        (dir, table)
    }

    #[test]
    fn fits_rank_models_by_error_and_check_the_best_orders() {
        let (_dir, table) = table();
        let fits = fits(&table).unwrap();
        assert_eq!(fits.iter().map(|f| f.cache.as_str()).collect::<Vec<_>>(), ["good", "bad"]);
        assert!((fits[0].rmse - 0.01).abs() < 1e-9 && (fits[0].pearson - 1.0).abs() < 1e-9);
        assert_eq!(fits[0].best_agrees, (2, 2));
        assert_eq!(fits[1].best_agrees, (1, 2));
        assert_eq!(fits[1].best[1], ("b".to_string(), "x".to_string(), "y".to_string()));
        assert_eq!(fits[0].points.len(), 4);
    }

    #[test]
    fn least_squares_on_a_line() {
        let x = [1.0, 2.0, 3.0, 4.0];
        let y = [3.0, 5.0, 7.0, 9.0];
        let (a, b) = least_squares(&x.iter().zip(&y).map(|(&a, &b)| (a, b)).collect::<Vec<_>>());
        assert!((a - 1.0).abs() < 1e-12 && (b - 2.0).abs() < 1e-12);
    }
}
