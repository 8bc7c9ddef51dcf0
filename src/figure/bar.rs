//! Grouped bar charts: one group per x category (e.g. per model), one bar per series in each
//! group, always at the same place in its group so a series is found at a glance, its value
//! written on top when the bar is wide enough.

use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::axes::{self, Area, Colors, DrawResult, FONT, Frame, Painter, Swatch};
use super::data::Panel;
use super::{Extent, Kind, XAxis};

/// Fraction of a category's width its bars fill.
const GROUP_WIDTH: f64 = 0.8;
/// Narrowest bar (pixels) that gets its value written on it.
const MIN_LABELLED_BAR: i32 = 30;

/// Values per panel, per series (in legend order), per category.
pub struct Bars {
    pub categories: Vec<String>,
    pub series: Vec<String>,
    pub values: Vec<Vec<Vec<Option<f64>>>>,
}

impl Bars {
    pub fn new(panels: &[Panel]) -> Bars {
        let mut categories: Vec<String> = Vec::new();
        let mut series: Vec<String> = Vec::new();
        for s in panels.iter().flat_map(|p| &p.series) {
            if !series.contains(&s.name) {
                series.push(s.name.clone());
            }
            for (x, _) in &s.points {
                if !categories.contains(x) {
                    categories.push(x.clone());
                }
            }
        }
        let values = panels
            .iter()
            .map(|panel| {
                series
                    .iter()
                    .map(|name| {
                        let points = panel.series.iter().find(|s| s.name == *name).map_or(&[][..], |s| &s.points);
                        categories.iter().map(|c| points.iter().find(|(x, _)| x == c).map(|&(_, y)| y)).collect()
                    })
                    .collect()
            })
            .collect();
        Bars { categories, series, values }
    }
}

impl Kind for Bars {
    fn extent(&self) -> Extent {
        let all = self.values.iter().flatten().flatten().flatten().copied();
        Extent {
            x: XAxis::Categories(self.categories.clone()),
            y: super::span(all).unwrap_or((0.0, 1.0)),
            from_zero: true,
        }
    }

    fn swatch(&self) -> Swatch {
        Swatch::Block
    }

    fn draw(&self, index: usize, area: &Area, title: &str, frame: &Frame, colors: &Colors) -> DrawResult {
        axes::panel(
            area,
            title,
            frame,
            &BarPainter { bars: self, values: &self.values[index], colors, base: frame.y.start },
        )
    }
}

struct BarPainter<'a> {
    bars: &'a Bars,
    values: &'a [Vec<Option<f64>>],
    colors: &'a Colors,
    /// Where bars start: 0, or the bottom of a log axis.
    base: f64,
}

impl Painter for BarPainter<'_> {
    fn paint<'a, 'b: 'a, X, Y>(&self, chart: &mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>) -> DrawResult
    where
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        let width = GROUP_WIDTH / self.bars.series.len() as f64;
        let base = self.base.max(0.0).max(chart.y_range().start);
        let pixels = chart.backend_coord(&(width, base)).0 - chart.backend_coord(&(0.0, base)).0;
        let label = TextStyle::from((FONT, 11)).pos(Pos::new(HPos::Center, VPos::Bottom));
        for (j, (name, values)) in self.bars.series.iter().zip(self.values).enumerate() {
            let color = self.colors.of(name);
            for (i, value) in values.iter().enumerate() {
                let Some(y) = *value else { continue };
                let left = i as f64 - GROUP_WIDTH / 2.0 + j as f64 * width;
                chart
                    .draw_series(std::iter::once(Rectangle::new([(left, base), (left + width, y)], color.filled())))?;
                if pixels >= MIN_LABELLED_BAR {
                    let top =
                        EmptyElement::at((left + width / 2.0, y)) + Text::new(axes::number(y), (0, -3), label.clone());
                    chart.draw_series(std::iter::once(top))?;
                }
            }
        }
        Ok(())
    }
}
