//! Line and scatter charts: the metric against a numeric x column (e.g. ACMR against cache
//! size, or ACMR against ordering time).

use std::path::Path;

use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::prelude::*;

use super::axes::{self, Area, Colors, DrawResult, Frame, Painter, Swatch};
use super::data::Panel;
use super::{Extent, Kind, XAxis};
use crate::error::{Error, Result};

/// Lines drawn with a marker at every point only when there are few enough to tell apart.
const MAX_MARKED_POINTS: usize = 24;

/// A series' name and its `(x, y)` points.
type Curve = (String, Vec<(f64, f64)>);

/// Numeric points per series per panel.
pub struct Xy {
    panels: Vec<Vec<Curve>>,
    lines: bool,
    /// Method names whose series are drawn last, with larger outlined markers.
    highlight: Vec<String>,
}

impl Xy {
    /// Parses every x as a number (`x` names the column, `csv` the file, for errors); `lines`
    /// joins each series' points in x order, otherwise they are a scatter; the series of the
    /// methods named in `highlight` are drawn on top of the others.
    pub fn new(panels: &[Panel], x: &str, lines: bool, highlight: &[String], csv: &Path) -> Result<Xy> {
        let panels = panels
            .iter()
            .map(|panel| {
                panel
                    .series
                    .iter()
                    .map(|series| {
                        let mut points = series
                            .points
                            .iter()
                            .map(|(text, y)| match text.parse::<f64>() {
                                Ok(v) if v.is_finite() => Ok((v, *y)),
                                _ => Err(Error::input(
                                    csv.display(),
                                    format!("column `{x}` has `{text}`, not a number: line and scatter charts need a numeric figure.x (use kind = \"bar\" for categories)"),
                                )),
                            })
                            .collect::<Result<Vec<_>>>()?;
                        points.sort_by(|a, b| a.0.total_cmp(&b.0));
                        Ok((series.name.clone(), points))
                    })
                    .collect::<Result<Vec<_>>>()
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Xy { panels, lines, highlight: highlight.to_vec() })
    }

    /// The points of panel `panel`, or of every panel.
    fn points(&self, panel: Option<usize>) -> impl Iterator<Item = (f64, f64)> + '_ {
        let panels = match panel {
            Some(i) => &self.panels[i..=i],
            None => &self.panels[..],
        };
        panels.iter().flatten().flat_map(|(_, p)| p.iter().copied())
    }
}

impl Kind for Xy {
    fn extent(&self, panel: Option<usize>) -> Extent {
        let (x, y) = super::span(self.points(panel).map(|p| p.0))
            .zip(super::span(self.points(panel).map(|p| p.1)))
            .unwrap_or(((0.0, 1.0), (0.0, 1.0)));
        Extent { x: XAxis::Data(x.0, x.1), y, from_zero: false }
    }

    fn swatch(&self) -> Swatch {
        if self.lines { Swatch::Line } else { Swatch::Point }
    }

    fn draw(&self, index: usize, area: &Area, title: &str, frame: &Frame, colors: &Colors) -> DrawResult {
        let painter = XyPainter { series: &self.panels[index], colors, lines: self.lines, highlight: &self.highlight };
        axes::panel(area, title, frame, &painter)
    }
}

struct XyPainter<'a> {
    series: &'a [Curve],
    colors: &'a Colors,
    lines: bool,
    highlight: &'a [String],
}

impl Painter for XyPainter<'_> {
    fn paint<'a, 'b: 'a, X, Y>(&self, chart: &mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>) -> DrawResult
    where
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let highlighted = |name: &str| self.highlight.iter().any(|h| name.split(':').next() == Some(h.as_str()));
        // The others first, so that the highlighted series are never hidden under them.
        let (on_top, rest): (Vec<&Curve>, Vec<&Curve>) = self.series.iter().partition(|(name, _)| highlighted(name));
        for (name, points) in rest.into_iter().chain(on_top) {
            let color = self.colors.of(name);
            if highlighted(name) {
                if self.lines {
                    chart.draw_series(LineSeries::new(points.iter().copied(), color.stroke_width(3)))?;
                }
                chart.draw_series(points.iter().map(|&p| Circle::new(p, 6, color.filled())))?;
                chart.draw_series(points.iter().map(|&p| Circle::new(p, 6, BLACK.stroke_width(2))))?;
            } else if self.lines {
                chart.draw_series(LineSeries::new(points.iter().copied(), color.stroke_width(2)))?;
                if points.len() <= MAX_MARKED_POINTS {
                    chart.draw_series(points.iter().map(|&p| Circle::new(p, 3, color.filled())))?;
                }
            } else {
                chart.draw_series(points.iter().map(|&p| Circle::new(p, 4, color.mix(0.85).filled())))?;
            }
        }
        Ok(())
    }
}
