//! Distribution charts, for per-view overdraw: each series' values sorted ascending and drawn
//! against their percentile (a quantile curve: the left end is the best view, the right end the
//! worst, the slope the spread), the mean as a dashed line of the same colour, and mean, max and
//! variance written in the panel, so the summary the papers report (Nehab et al. 2006 §6: mean,
//! worst case, variance) sits beside the whole distribution it summarises.

use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::axes::{self, Area, Colors, DrawResult, FONT, Frame, Painter, Swatch};
use super::data::Panel;
use super::{Extent, Kind, XAxis};

/// One series of one panel: its values sorted ascending, and their statistics.
struct Sorted {
    name: String,
    values: Vec<f64>,
    mean: f64,
    max: f64,
    /// Population variance, as the results' `ovr_var`.
    variance: f64,
}

/// Sorted values per series per panel.
pub struct Distribution {
    panels: Vec<Vec<Sorted>>,
}

impl Distribution {
    pub fn new(panels: &[Panel]) -> Distribution {
        let panels = panels
            .iter()
            .map(|panel| {
                panel
                    .series
                    .iter()
                    .map(|series| {
                        let mut values: Vec<f64> = series.points.iter().map(|&(_, y)| y).collect();
                        values.sort_by(f64::total_cmp);
                        let n = values.len().max(1) as f64;
                        let mean = values.iter().sum::<f64>() / n;
                        let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
                        let max = values.last().copied().unwrap_or(f64::NAN);
                        Sorted { name: series.name.clone(), values, mean, max, variance }
                    })
                    .collect()
            })
            .collect();
        Distribution { panels }
    }
}

impl Kind for Distribution {
    fn extent(&self, panel: Option<usize>) -> Extent {
        let panels = match panel {
            Some(i) => &self.panels[i..=i],
            None => &self.panels[..],
        };
        let all = panels.iter().flatten().flat_map(|s| s.values.iter().copied());
        Extent {
            x: XAxis::Fixed(0.0..100.0),
            y: super::span(all).unwrap_or((0.0, 1.0)),
            from_zero: false,
            bars: Vec::new(),
        }
    }

    fn swatch(&self) -> Swatch {
        Swatch::Line
    }

    /// The lines of statistics under each panel name the series with their colours: no legend.
    fn legend(&self) -> bool {
        false
    }

    /// The usual panel, taller by a line of statistics per series.
    fn panel_size(&self) -> Option<(usize, usize)> {
        let (w, h) = if self.panels.len() == 1 { (760, 500) } else { (540, 400) };
        Some((w, h + self.stats_height() as usize))
    }

    fn draw(&self, index: usize, area: &Area, title: &str, frame: &Frame, colors: &Colors) -> DrawResult {
        let series = &self.panels[index];
        let (plot, stats) = area.split_vertically(area.dim_in_pixel().1.saturating_sub(self.stats_height()));
        axes::panel(&plot, title, frame, &DistributionPainter { series, colors })?;
        let style = TextStyle::from((FONT, 12)).pos(Pos::new(HPos::Left, VPos::Center));
        for (k, s) in series.iter().enumerate() {
            let y = (k as u32 * STATS_ROW + STATS_ROW / 2) as i32;
            let color = colors.of(&s.name);
            stats.draw(&PathElement::new(vec![(STATS_LEFT, y), (STATS_LEFT + 24, y)], color.stroke_width(3)))?;
            let text = format!(
                "{}: mean {} (dashed), max {}, variance {} (n = {})",
                s.name,
                axes::number(s.mean),
                axes::number(s.max),
                axes::significant(s.variance, 4),
                s.values.len()
            );
            stats.draw(&Text::new(text, (STATS_LEFT + 32, y), style.clone()))?;
        }
        Ok(())
    }
}

/// Height of one series' line of statistics under a panel.
const STATS_ROW: u32 = 17;

/// Where the statistics start: under the y axis' labels.
const STATS_LEFT: i32 = 20;

impl Distribution {
    /// Height of the statistics under each panel: a line for each series of the fullest panel.
    fn stats_height(&self) -> u32 {
        self.panels.iter().map(Vec::len).max().unwrap_or(0) as u32 * STATS_ROW + 6
    }
}

struct DistributionPainter<'a> {
    series: &'a [Sorted],
    colors: &'a Colors,
}

impl Painter for DistributionPainter<'_> {
    fn paint<'a, 'b: 'a, X, Y>(&self, chart: &mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>) -> DrawResult
    where
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
    {
        for s in self.series {
            let color = self.colors.of(&s.name);
            let n = s.values.len() as f64;
            let curve = s.values.iter().enumerate().map(|(i, &v)| (100.0 * (i as f64 + 0.5) / n, v));
            chart.draw_series(LineSeries::new(curve, color.stroke_width(2)))?;
            chart.draw_series(DashedLineSeries::new([(0.0, s.mean), (100.0, s.mean)], 6, 4, color.stroke_width(1)))?;
        }
        Ok(())
    }
}
