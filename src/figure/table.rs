//! Tables drawn as SVG: one row per x value (e.g. per model), one column per series (e.g. per
//! method), the metric in each cell — for the papers' tables (Bogomjakov & Gotsman 2002 Tables 1
//! and 2), where the reader compares numbers, not shapes. The best value is bold, lower being
//! better for all of ours (misses, overdraw, blending errors, time): the best method of each row,
//! or of each column when the rows are the methods (`x = "method"` or `"method_name"`) or the columns are different
//! metrics (`series = "metric"`), which only compare within themselves.

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::axes::{self, Area, Colors, DrawResult, FONT, Frame, Swatch};
use super::bar::Bars;
use super::{Extent, Kind, XAxis};

/// Pixel sizes of the grid.
const ROW_H: i32 = 24;
/// Height of the column headings above their lines of text (`LINE_H` each).
const HEAD_BASE_H: i32 = 36;
const LINE_H: i32 = 14;
const FIRST_COL_W: i32 = 280;
const COL_W: i32 = 124;

/// The same values as a bar chart holds (panel × series × category), drawn as text.
pub struct Tables {
    pub bars: Bars,
    /// The columns (series) are different metrics: the best is marked per column, not per row.
    pub best_per_column: bool,
}

impl Tables {
    /// Each column's heading lines (see [`heading`]) and the headings' height.
    fn headings(&self) -> (Vec<Vec<String>>, i32) {
        let headings: Vec<Vec<String>> = self.bars.series.iter().map(|name| heading(name, &self.bars.series)).collect();
        let lines = headings.iter().map(Vec::len).max().unwrap_or(1).max(2);
        (headings, HEAD_BASE_H + LINE_H * lines as i32)
    }
}

impl Kind for Tables {
    /// The size that fits the table.
    fn panel_size(&self) -> Option<(usize, usize)> {
        let bars = &self.bars;
        let w = FIRST_COL_W + COL_W * bars.series.len() as i32 + 20;
        let h = self.headings().1 + ROW_H * bars.categories.len() as i32 + 40;
        Some((w.max(400) as usize, h as usize))
    }

    fn extent(&self, _: Option<usize>) -> Extent {
        Extent { x: XAxis::Categories(self.bars.categories.clone()), y: (0.0, 1.0), from_zero: true }
    }

    fn swatch(&self) -> Swatch {
        Swatch::Block
    }

    fn legend(&self) -> bool {
        false
    }

    fn draw(&self, index: usize, area: &Area, title: &str, _frame: &Frame, colors: &Colors) -> DrawResult {
        let bars = &self.bars;
        let values = &bars.values[index];
        let mut y = 8;
        if !title.is_empty() {
            area.draw_text(title, &TextStyle::from((FONT, 15).into_font().style(FontStyle::Bold)), (10, y))?;
            y += 24;
        }
        let (headings, head_h) = self.headings();
        let head = TextStyle::from((FONT, 12).into_font().style(FontStyle::Bold)).pos(Pos::new(HPos::Right, VPos::Top));
        for (j, name) in bars.series.iter().enumerate() {
            let x = FIRST_COL_W + COL_W * (j as i32 + 1) - 6;
            area.draw(&Rectangle::new(
                [(x - COL_W + 10, y + head_h - 30), (x, y + head_h - 27)],
                colors.of(name).filled(),
            ))?;
            for (k, line) in headings[j].iter().enumerate() {
                area.draw_text(&truncate(line, 17), &head, (x, y + 4 + LINE_H * k as i32))?;
            }
        }
        y += head_h - 20;
        let rule = |y: i32| {
            let right = FIRST_COL_W + COL_W * bars.series.len() as i32;
            area.draw(&PathElement::new(vec![(6, y), (right, y)], BLACK.stroke_width(1)))
        };
        rule(y)?;
        let label = TextStyle::from((FONT, 12)).pos(Pos::new(HPos::Left, VPos::Center));
        let plain = TextStyle::from((FONT, 12)).pos(Pos::new(HPos::Right, VPos::Center));
        let bold =
            TextStyle::from((FONT, 12).into_font().style(FontStyle::Bold)).pos(Pos::new(HPos::Right, VPos::Center));
        for (i, category) in bars.categories.iter().enumerate() {
            let mid = y + ROW_H * i as i32 + ROW_H / 2;
            if i % 2 == 1 {
                let right = FIRST_COL_W + COL_W * bars.series.len() as i32;
                area.draw(&Rectangle::new(
                    [(6, mid - ROW_H / 2), (right, mid + ROW_H / 2)],
                    RGBColor(0xf2, 0xf2, 0xf2).filled(),
                ))?;
            }
            area.draw_text(&truncate(category, 42), &label, (10, mid))?;
            let row: Vec<Option<f64>> = values.iter().map(|s| s[i]).collect();
            let lowest = |cells: &mut dyn Iterator<Item = f64>| cells.fold(f64::INFINITY, f64::min);
            let best_in_row = lowest(&mut row.iter().flatten().copied());
            for (j, value) in row.iter().enumerate() {
                let Some(v) = value else { continue };
                let best = if self.best_per_column {
                    *v == lowest(&mut values[j].iter().flatten().copied()) && bars.categories.len() > 1
                } else {
                    *v == best_in_row && bars.series.len() > 1
                };
                let style = if best { &bold } else { &plain };
                area.draw_text(&axes::number(*v), style, (FIRST_COL_W + COL_W * (j as i32 + 1) - 6, mid))?;
            }
        }
        rule(y + ROW_H * bars.categories.len() as i32)
    }
}

/// `text` cut to `max` characters with an ellipsis.
fn truncate(text: &str, max: usize) -> String {
    if text.chars().count() <= max { text.to_string() } else { text.chars().take(max - 1).chain(['…']).collect() }
}

/// A column heading, one line each: the method name, then the parameters that tell the column
/// apart from the other columns of the same method (all of a canonical spec's parameters would
/// not fit, and those the columns share say nothing). A name that is not a method spec is one line.
fn heading(name: &str, series: &[String]) -> Vec<String> {
    let Some((method, params)) = name.split_once(':') else {
        return vec![name.to_string()];
    };
    let others: Vec<&str> = series
        .iter()
        .filter(|s| s.as_str() != name)
        .filter_map(|s| s.strip_prefix(method)?.strip_prefix(':'))
        .collect();
    let varies = |kv: &&str| others.iter().any(|o| !o.split(',').any(|x| x == *kv));
    std::iter::once(method).chain(params.split(',').filter(varies)).map(str::to_string).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headings_keep_only_the_parameters_that_differ() {
        let series: Vec<String> =
            ["hs17:lambda=0.85,mode=single,seed=0", "hs17:lambda=3,mode=single,seed=0", "tipsify:cache=16", "model"]
                .map(String::from)
                .to_vec();
        assert_eq!(heading(&series[0], &series), ["hs17", "lambda=0.85"]);
        assert_eq!(heading(&series[2], &series), ["tipsify"]);
        assert_eq!(heading(&series[3], &series), ["model"]);
    }
}
