//! The ratio figure (Nehab, Barczak & Sander 2006, Fig. 10): per view, method A's value over
//! method B's for two per-view metrics, one against the other, with Pearson's r per series. Their
//! figure puts the overdraw ratio of their ordering over Hoppe's against the ratio of render
//! times with a pixel-bound shader, one point per viewpoint, for two resolutions of the dragon.

use std::collections::HashMap;
use std::path::PathBuf;

use plotters::prelude::*;

use super::axes::{self, Area, Colors, DrawResult, Frame, Painter};
use super::data::Table;
use super::{Chart, Header, save};
use crate::error::{Error, Result};

/// Per series: (x ratio, y ratio) per view.
type Points = Vec<(String, Vec<(f64, f64)>)>;

/// The points: for each series value and view, A ÷ B of the x metric and of the y metric.
fn points(chart: &Chart, table: &Table) -> Result<Points> {
    let figure = chart.figure;
    let stale = |why: String| Error::input(table.path().display(), format!("{why}; rerun the experiment"));
    let (Some((a, b)), Some(x)) = (&figure.ratio, figure.x.as_deref().and_then(|x| x.strip_prefix("metric:"))) else {
        return Err(Error::spec(chart.spec, "kind = \"ratio\" needs figure.ratio and x = \"metric:NAME\""));
    };
    // (metric, series, model, view, method name) → value.
    let mut values: HashMap<(bool, String, String, String, String), f64> = HashMap::new();
    for (is_x, metric) in [(true, x), (false, figure.metric.as_str())] {
        for (cells, value) in table.rows(metric, &[&figure.series, "model", "view", "method_name"])? {
            if cells[2].is_empty() {
                return Err(stale(format!(
                    "`{metric}` has a row without a view: kind = \"ratio\" needs per-view metrics"
                )));
            }
            let [series, model, view, method] = <[String; 4]>::try_from(cells).unwrap_or_default();
            values.insert((is_x, series, model, view, method), value);
        }
    }
    let mut out: Points = Vec::new();
    let mut keys: Vec<_> = values.keys().filter(|k| k.0 && &k.4 == a).cloned().collect();
    keys.sort_by(|p, q| (&p.1, &p.2, p.3.parse::<u64>().ok()).cmp(&(&q.1, &q.2, q.3.parse::<u64>().ok())));
    for (_, series, model, view, _) in keys {
        let get = |is_x: bool, method: &str| {
            values.get(&(is_x, series.clone(), model.clone(), view.clone(), method.to_string()))
        };
        let (Some(xa), Some(xb), Some(ya), Some(yb)) = (get(true, a), get(true, b), get(false, a), get(false, b))
        else {
            continue;
        };
        if *xb > 0.0 && *yb > 0.0 {
            match out.iter_mut().find(|(s, _)| *s == series) {
                Some((_, p)) => p.push((xa / xb, ya / yb)),
                None => out.push((series, vec![(xa / xb, ya / yb)])),
            }
        }
    }
    if out.is_empty() {
        return Err(stale(format!("has no view where both `{a}` and `{b}` have `{x}` and `{}`", figure.metric)));
    }
    Ok(out)
}

/// Pearson's r of the points (0 when either coordinate is constant).
pub fn pearson(points: &[(f64, f64)]) -> f64 {
    let n = points.len() as f64;
    let (mx, my) = (points.iter().map(|p| p.0).sum::<f64>() / n, points.iter().map(|p| p.1).sum::<f64>() / n);
    let cov: f64 = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let vx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let vy: f64 = points.iter().map(|p| (p.1 - my).powi(2)).sum();
    if vx > 0.0 && vy > 0.0 { cov / (vx * vy).sqrt() } else { 0.0 }
}

/// Draws the figure; returns the SVG's path.
pub fn plot(chart: &Chart, table: &Table) -> Result<PathBuf> {
    let figure = chart.figure;
    let points = points(chart, table)?;
    let (a, b) = figure.ratio.clone().unwrap_or_default();
    let x_metric = figure.x.as_deref().and_then(|x| x.strip_prefix("metric:")).unwrap_or_default();
    let mut setup = format!(
        "{a} ÷ {b} per view · {}",
        points
            .iter()
            .map(|(s, p)| format!("{s}: r = {:.3} over {} views", pearson(p), p.len()))
            .collect::<Vec<_>>()
            .join(" · ")
    );
    setup.extend(super::measured_on(table).map(|m| format!(" · {m}")));
    if chart.quick {
        setup += " · quick run: small stand-in models, not the paper's";
    }
    let all = points.iter().flat_map(|(_, p)| p);
    let span =
        |f: fn(&(f64, f64)) -> f64| all.clone().map(f).fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v), h.max(v)));
    let ((x_lo, x_hi), (y_lo, y_hi)) = (span(|p| p.0), span(|p| p.1));
    let frame = Frame {
        x: super::pad(x_lo.min(1.0), x_hi.max(1.0), false),
        y: super::pad(y_lo.min(1.0), y_hi.max(1.0), false),
        x_log: false,
        y_log: false,
        x_desc: figure.x_label.clone().unwrap_or_else(|| format!("{x_metric}: {a} ÷ {b}")),
        y_desc: figure.y_label.clone().unwrap_or_else(|| format!("{}: {a} ÷ {b}", figure.metric)),
        categories: None,
        optimum: None,
    };
    let names: Vec<String> = points.iter().map(|(s, _)| s.clone()).collect();
    let colors = Colors::new(&figure.series, &names);
    let width = 760;
    let header = Header::new(chart, &setup, width);
    let legend_h = axes::legend_height(&colors, width);
    let path = chart.svg.clone();
    let mut svg = String::new();
    let drawn = (|| -> DrawResult {
        let root = SVGBackend::with_string(&mut svg, (width, header.height + 560 + legend_h)).into_drawing_area();
        root.fill(&WHITE)?;
        let (top, rest) = root.split_vertically(header.height);
        let (body, legend): (Area, Area) = rest.split_vertically(560);
        header.draw(&top)?;
        axes::panel(&body, "grey lines: equal (ratio 1)", &frame, &RatioPainter { points: &points, colors: &colors })?;
        axes::legend(&legend, &colors, axes::Swatch::Point)
    })();
    drawn.map_err(|e| Error::output(&path, format!("cannot draw the figure: {e}")))?;
    save(&path, &svg)?;
    Ok(path)
}

struct RatioPainter<'a> {
    points: &'a Points,
    colors: &'a Colors,
}

impl Painter for RatioPainter<'_> {
    fn paint<'a, 'b: 'a, X, Y>(&self, chart: &mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>) -> DrawResult
    where
        X: plotters::coord::ranged1d::Ranged<ValueType = f64> + plotters::coord::ranged1d::ValueFormatter<f64>,
        Y: plotters::coord::ranged1d::Ranged<ValueType = f64> + plotters::coord::ranged1d::ValueFormatter<f64>,
    {
        let (x, y) = (chart.x_range(), chart.y_range());
        let grey = RGBColor(0xaa, 0xaa, 0xaa).stroke_width(1);
        chart.draw_series(LineSeries::new([(1.0, y.start), (1.0, y.end)], grey))?;
        chart.draw_series(LineSeries::new([(x.start, 1.0), (x.end, 1.0)], grey))?;
        for (series, points) in self.points {
            let color = self.colors.of(series).mix(0.8).filled();
            super::axes::markers(chart, points, self.colors.marker(series), 3, color)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::pearson;

    #[test]
    fn pearson_of_lines_and_noise() {
        assert!((pearson(&[(1.0, 2.0), (2.0, 4.0), (3.0, 6.0)]) - 1.0).abs() < 1e-12);
        assert!((pearson(&[(1.0, 6.0), (2.0, 4.0), (3.0, 2.0)]) + 1.0).abs() < 1e-12);
        assert_eq!(pearson(&[(1.0, 2.0), (2.0, 2.0)]), 0.0);
    }
}
