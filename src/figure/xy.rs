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

/// A series' name, its `(x, y)` points, and per point the range of the runs it is the mean of.
type Curve = (String, Vec<(f64, f64)>, Vec<Option<(f64, f64)>>);

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
                            .enumerate()
                            .map(|(i, (text, y))| match text.parse::<f64>() {
                                Ok(v) if v.is_finite() => Ok(((v, *y), series.ranges.get(i).copied().flatten())),
                                _ => Err(Error::input(
                                    csv.display(),
                                    format!("column `{x}` has `{text}`, not a number: line and scatter charts need a numeric figure.x (use kind = \"bar\" for categories)"),
                                )),
                            })
                            .collect::<Result<Vec<_>>>()?;
                        points.sort_by(|a, b| a.0.0.total_cmp(&b.0.0));
                        let (points, ranges) = points.into_iter().unzip();
                        Ok((series.name.clone(), points, ranges))
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
        // Whisker ends count as points, so that the axes hold them.
        panels.iter().flatten().flat_map(|(_, p, r)| {
            p.iter()
                .copied()
                .chain(p.iter().zip(r).filter_map(|(&(x, _), r)| r.map(|(lo, hi)| [(x, lo), (x, hi)])).flatten())
        })
    }
}

impl Kind for Xy {
    fn extent(&self, panel: Option<usize>) -> Extent {
        let (x, y) = super::span(self.points(panel).map(|p| p.0))
            .zip(super::span(self.points(panel).map(|p| p.1)))
            .unwrap_or(((0.0, 1.0), (0.0, 1.0)));
        Extent { x: XAxis::Data(x.0, x.1), y, from_zero: false, bars: Vec::new() }
    }

    fn swatch(&self) -> Swatch {
        if self.lines { Swatch::MarkedLine } else { Swatch::Point }
    }

    fn draw(&self, index: usize, area: &Area, title: &str, frame: &Frame, colors: &Colors) -> DrawResult {
        let painter = XyPainter {
            series: &self.panels[index],
            colors,
            lines: self.lines,
            highlight: &self.highlight,
            x_log: frame.x_log,
        };
        axes::panel(area, title, frame, &painter)
    }
}

struct XyPainter<'a> {
    series: &'a [Curve],
    colors: &'a Colors,
    lines: bool,
    highlight: &'a [String],
    x_log: bool,
}

fn draw_runs<'a, 'b: 'a, X, Y>(
    chart: &mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>,
    runs: &[&[(f64, f64)]],
    style: ShapeStyle,
) -> DrawResult
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    for run in runs {
        chart.draw_series(LineSeries::new(run.iter().copied(), style))?;
    }
    Ok(())
}

/// A line's points cut into runs at the gaps where nothing was measured: a step along x (on the
/// axis' scale) more than three times the series' median step, as from FIFO 64 to FIFO 1024 in a
/// sweep of 1–64. A straight line across such a gap would show values never measured.
fn measured_runs(points: &[(f64, f64)], x_log: bool) -> Vec<&[(f64, f64)]> {
    let at = |x: f64| if x_log { x.log10() } else { x };
    let steps: Vec<f64> = points.windows(2).map(|w| at(w[1].0) - at(w[0].0)).collect();
    let mut sorted = steps.clone();
    sorted.sort_by(f64::total_cmp);
    let Some(&median) = sorted.get(sorted.len() / 2).filter(|_| steps.len() >= 3) else {
        return vec![points];
    };
    let mut runs = Vec::new();
    let mut start = 0;
    for (i, step) in steps.iter().enumerate() {
        if *step > 3.0 * median && median > 0.0 {
            runs.push(&points[start..=i]);
            start = i + 1;
        }
    }
    runs.push(&points[start..]);
    runs
}

impl Painter for XyPainter<'_> {
    fn paint<'a, 'b: 'a, X, Y>(&self, chart: &mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>) -> DrawResult
    where
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let highlighted = |name: &str| self.highlight.iter().any(|h| axes::family(name) == h.as_str());
        // Grey context first, then the others, so that the highlighted series are never hidden.
        let rank = |name: &str| usize::from(!self.colors.is_context(name)) + usize::from(highlighted(name));
        let mut order: Vec<&Curve> = self.series.iter().collect();
        order.sort_by_key(|(name, _, _)| rank(name));
        for (name, points, ranges) in order {
            let (color, shape) = (self.colors.of(name), self.colors.marker(name));
            let runs = if self.lines { measured_runs(points, self.x_log) } else { Vec::new() };
            // A dense line is marked at a few evenly spaced points, enough to tell its marker,
            // and at any point alone between gaps, which would otherwise vanish.
            let step = points.len().div_ceil(MAX_MARKED_POINTS / 2).max(1);
            let marked: Vec<(f64, f64)> = if points.len() <= MAX_MARKED_POINTS {
                points.clone()
            } else {
                let lone = runs.iter().filter(|r| r.len() == 1).map(|r| r[0]);
                points.iter().step_by(step).copied().chain(lone).collect()
            };
            // The spread of the runs (seeds) a point is the mean of: a whisker.
            for (&(x, _), range) in points.iter().zip(ranges) {
                if let Some((lo, hi)) = range {
                    chart.draw_series(std::iter::once(PathElement::new(
                        vec![(x, *lo), (x, *hi)],
                        color.stroke_width(2),
                    )))?;
                }
            }
            if self.colors.is_context(name) {
                draw_runs(chart, &runs, color.stroke_width(1))?;
            } else if highlighted(name) && self.lines {
                draw_runs(chart, &runs, color.stroke_width(3))?;
                // The black outline beneath and the colour on top: a cross is all outline, and
                // drawn the other way round it came out black, like every other highlighted cross.
                axes::markers(chart, &marked, shape, 5, BLACK.stroke_width(3))?;
                axes::markers(chart, &marked, shape, 5, color.filled())?;
            } else if highlighted(name) {
                axes::markers(chart, points, shape, 6, BLACK.stroke_width(4))?;
                axes::markers(chart, points, shape, 6, color.filled())?;
            } else if self.lines {
                draw_runs(chart, &runs, color.stroke_width(2))?;
                axes::markers(chart, &marked, shape, 3, color.filled())?;
            } else {
                axes::markers(chart, points, shape, 4, color.mix(0.85).filled())?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_break_where_nothing_was_measured() {
        let sweep: Vec<(f64, f64)> = [1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 1024.0].iter().map(|&x| (x, 1.0)).collect();
        let runs = measured_runs(&sweep, true);
        assert_eq!(runs.len(), 2);
        assert_eq!(runs[1], [(1024.0, 1.0)]);
        // Evenly measured: one run.
        assert_eq!(measured_runs(&sweep[..7], true).len(), 1);
        assert_eq!(measured_runs(&sweep[..7], false).len(), 2); // 32 → 64 is a wide step on a linear axis
    }
}
