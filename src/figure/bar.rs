//! Grouped bar charts: one group per x category (e.g. per model), one bar per series in each
//! group, always at the same place in its group so a series is found at a glance, its value (or
//! the figure's `label`, another metric of the same ordering) written on top when the bar is wide
//! enough.

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

/// The least and greatest of the runs a bar is the mean of.
type Range = (f64, f64);

/// Values per panel, per series (in legend order), per category.
pub struct Bars {
    pub categories: Vec<String>,
    pub series: Vec<String>,
    pub values: Vec<Vec<Vec<Option<f64>>>>,
    /// The same shape: the text written above each bar instead of its value, where not empty.
    pub labels: Vec<Vec<Vec<String>>>,
    /// The same shape: the least and greatest run a bar is the mean of (`figure.spread`).
    pub ranges: Vec<Vec<Vec<Option<Range>>>>,
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
        let (mut values, mut labels, mut ranges) = (Vec::new(), Vec::new(), Vec::new());
        for panel in panels {
            let (mut panel_values, mut panel_labels, mut panel_ranges) = (Vec::new(), Vec::new(), Vec::new());
            for name in &series {
                let found = panel.series.iter().find(|s| s.name == *name);
                let mut r = Vec::new();
                let (v, l): (Vec<Option<f64>>, Vec<String>) = categories
                    .iter()
                    .map(|c| {
                        let point = found.and_then(|s| Some((s, s.points.iter().position(|(x, _)| x == c)?)));
                        r.push(point.and_then(|(s, i)| s.ranges.get(i).copied().flatten()));
                        point.map_or((None, String::new()), |(s, i)| {
                            (Some(s.points[i].1), s.labels.get(i).cloned().unwrap_or_default())
                        })
                    })
                    .unzip();
                panel_values.push(v);
                panel_labels.push(l);
                panel_ranges.push(r);
            }
            values.push(panel_values);
            labels.push(panel_labels);
            ranges.push(panel_ranges);
        }
        Bars { categories, series, values, labels, ranges }
    }
}

impl Kind for Bars {
    fn extent(&self, panel: Option<usize>) -> Extent {
        let panels = match panel {
            Some(i) => &self.values[i..=i],
            None => &self.values[..],
        };
        let ranges = match panel {
            Some(i) => &self.ranges[i..=i],
            None => &self.ranges[..],
        };
        let mut all: Vec<f64> = panels.iter().flatten().flatten().flatten().copied().collect();
        // Whiskers must fit too (not counted as bars for the outlier rule: `bars` is `all` before).
        let whiskers = ranges.iter().flatten().flatten().flatten().flat_map(|&(lo, hi)| [lo, hi]);
        let bars = all.clone();
        all.extend(whiskers);
        Extent {
            x: XAxis::Categories(self.categories.clone()),
            y: super::span(all.iter().copied()).unwrap_or((0.0, 1.0)),
            from_zero: true,
            bars,
        }
    }

    /// Wide enough that no two category labels overlap: a label never gets cut or drawn over
    /// its neighbour, the panel grows instead.
    fn min_panel_width(&self) -> usize {
        let widest = self.categories.iter().map(|c| axes::text_width(c, 12.0)).max().unwrap_or(0);
        let shown = (0..self.values.len())
            .map(|p| (0..self.categories.len()).filter(|&i| self.values[p].iter().any(|s| s[i].is_some())).count())
            .max()
            .unwrap_or(0);
        shown * (widest as usize + 14) + 110
    }

    fn swatch(&self) -> Swatch {
        Swatch::Block
    }

    /// A panel shows only the categories it has values for (characters have different clips), so
    /// it is not padded with empty slots for the other panels' categories.
    fn draw(&self, index: usize, area: &Area, title: &str, frame: &Frame, colors: &Colors) -> DrawResult {
        let values = &self.values[index];
        let mut own: Vec<usize> =
            (0..self.categories.len()).filter(|&i| values.iter().any(|s| s[i].is_some())).collect();
        if own.is_empty() {
            own = (0..self.categories.len()).collect();
        }
        let frame = Frame {
            x: -0.5..own.len() as f64 - 0.5,
            categories: Some(own.iter().map(|&i| self.categories[i].clone()).collect()),
            ..frame.clone()
        };
        axes::panel(
            area,
            title,
            &frame,
            &BarPainter {
                bars: self,
                values: &keep_columns(values, &own),
                labels: &keep_columns(&self.labels[index], &own),
                ranges: &keep_columns(&self.ranges[index], &own),
                colors,
                base: frame.y.start,
            },
        )
    }
}

/// Each row of `rows` cut to the columns `keep`, in that order.
fn keep_columns<T: Clone>(rows: &[Vec<T>], keep: &[usize]) -> Vec<Vec<T>> {
    rows.iter().map(|row| keep.iter().map(|&i| row[i].clone()).collect()).collect()
}

struct BarPainter<'a> {
    bars: &'a Bars,
    values: &'a [Vec<Option<f64>>],
    labels: &'a [Vec<String>],
    ranges: &'a [Vec<Option<Range>>],
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
        // A panel whose categories each have one bar (the series are the categories) draws it
        // across the whole slot, not in a sliver of it.
        let categories = self.values.first().map_or(0, Vec::len);
        let single = (0..categories).all(|i| self.values.iter().filter(|s| s[i].is_some()).count() <= 1);
        let width = if single { GROUP_WIDTH } else { GROUP_WIDTH / self.bars.series.len() as f64 };
        let y_range = chart.y_range();
        let base = self.base.max(0.0).max(y_range.start);
        let pixels = chart.backend_coord(&(width, base)).0 - chart.backend_coord(&(0.0, base)).0;
        let label = TextStyle::from((FONT, 11)).pos(Pos::new(HPos::Center, VPos::Bottom));
        let clipped = TextStyle::from((FONT, 11).into_font().style(FontStyle::Bold))
            .color(&WHITE)
            .pos(Pos::new(HPos::Center, VPos::Top));
        for (j, ((name, values), labels)) in self.bars.series.iter().zip(self.values).zip(self.labels).enumerate() {
            let color = self.colors.of(name);
            for (i, value) in values.iter().enumerate() {
                let Some(y) = *value else { continue };
                let left = i as f64 - GROUP_WIDTH / 2.0 + if single { 0.0 } else { j as f64 * width };
                let text = match labels[i].parse::<f64>() {
                    Ok(v) => axes::number(v),
                    Err(_) if labels[i].is_empty() => axes::number(y),
                    Err(_) => labels[i].clone(),
                };
                if y > y_range.end {
                    // Beyond the axis (an outlier such as random's ACMR 3 among 0.6–0.9): drawn to
                    // the top, cut by a white break, its value written inside.
                    let top = y_range.end;
                    let cut = top - (top - base) * 0.06;
                    let rect =
                        |lo: f64, hi: f64, style: ShapeStyle| Rectangle::new([(left, lo), (left + width, hi)], style);
                    chart.draw_series([
                        rect(base, top, color.filled()),
                        rect(cut, cut + (top - base) * 0.015, WHITE.filled()),
                    ])?;
                    let inside = EmptyElement::at((left + width / 2.0, cut)) + Text::new(text, (0, 4), clipped.clone());
                    chart.draw_series(std::iter::once(inside))?;
                    continue;
                }
                chart
                    .draw_series(std::iter::once(Rectangle::new([(left, base), (left + width, y)], color.filled())))?;
                if let Some((lo, hi)) = self.ranges[j][i] {
                    // The spread of the runs (seeds) this bar is the mean of: a whisker with caps.
                    let (mid, cap) = (left + width / 2.0, width / 6.0);
                    let style = BLACK.stroke_width(2);
                    chart.draw_series([
                        PathElement::new(vec![(mid, lo), (mid, hi)], style),
                        PathElement::new(vec![(mid - cap, lo), (mid + cap, lo)], style),
                        PathElement::new(vec![(mid - cap, hi), (mid + cap, hi)], style),
                    ])?;
                }
                if pixels >= MIN_LABELLED_BAR {
                    // Above the whisker, where there is one.
                    let above = self.ranges[j][i].map_or(y, |(_, hi)| hi.max(y));
                    let top = EmptyElement::at((left + width / 2.0, above)) + Text::new(text, (0, -3), label.clone());
                    chart.draw_series(std::iter::once(top))?;
                }
            }
        }
        Ok(())
    }
}
