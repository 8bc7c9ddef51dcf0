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
/// Narrowest first column; it grows to fit the longest row label.
const FIRST_COL_W: i32 = 280;
const COL_W: i32 = 124;

/// The same values as a bar chart holds (panel × series × category), drawn as text.
pub struct Tables {
    pub bars: Bars,
    /// The columns (series) are different metrics: the best is marked per column, not per row.
    pub best_per_column: bool,
    /// The cells are ratios where higher is better (`relative_to`), not costs.
    pub higher_better: bool,
}

impl Tables {
    /// Each column's heading lines (see [`heading`]) and the headings' height.
    fn headings(&self) -> (Vec<Vec<String>>, i32) {
        // Series names are already short (methods by what tells them apart, see
        // `data::display_names`); a long one wraps at spaces.
        let headings: Vec<Vec<String>> = self.bars.series.iter().map(|name| axes::wrap(name, 17)).collect();
        let lines = headings.iter().map(Vec::len).max().unwrap_or(1).max(2);
        (headings, HEAD_BASE_H + LINE_H * lines as i32)
    }
}

impl Kind for Tables {
    /// The size that fits the table.
    fn panel_size(&self) -> Option<(usize, usize)> {
        let bars = &self.bars;
        let w = first_col_w(&bars.categories) + COL_W * bars.series.len() as i32 + 20;
        let h = self.headings().1 + ROW_H * bars.categories.len() as i32 + 40;
        Some((w.max(400) as usize, h as usize))
    }

    fn extent(&self, _: Option<usize>) -> Extent {
        Extent { x: XAxis::Categories(self.bars.categories.clone()), y: (0.0, 1.0), from_zero: true, bars: Vec::new() }
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
        let first_w = first_col_w(&bars.categories);
        let formats: Vec<Format> = values.iter().map(|column| Format::of(column.iter().flatten().copied())).collect();
        let head = TextStyle::from((FONT, 12).into_font().style(FontStyle::Bold)).pos(Pos::new(HPos::Right, VPos::Top));
        for (j, name) in bars.series.iter().enumerate() {
            let x = first_w + COL_W * (j as i32 + 1) - 6;
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
            let right = first_w + COL_W * bars.series.len() as i32;
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
                let right = first_w + COL_W * bars.series.len() as i32;
                area.draw(&Rectangle::new(
                    [(6, mid - ROW_H / 2), (right, mid + ROW_H / 2)],
                    RGBColor(0xf2, 0xf2, 0xf2).filled(),
                ))?;
            }
            area.draw_text(category, &label, (10, mid))?;
            let row: Vec<Option<f64>> = values.iter().map(|s| s[i]).collect();
            let sign = if self.higher_better { -1.0 } else { 1.0 };
            let lowest =
                |cells: &mut dyn Iterator<Item = f64>| sign * cells.map(|v| sign * v).fold(f64::INFINITY, f64::min);
            let best_in_row =
                lowest(&mut row.iter().zip(&bars.series).filter(|(_, s)| contends(s)).filter_map(|(v, _)| *v));
            for (j, value) in row.iter().enumerate() {
                let Some(v) = value else { continue };
                let best = if self.best_per_column {
                    let column = values[j].iter().zip(&bars.categories).filter(|(_, c)| contends(c));
                    contends(category) && *v == lowest(&mut column.filter_map(|(v, _)| *v)) && bars.categories.len() > 1
                } else {
                    contends(&bars.series[j]) && *v == best_in_row && bars.series.len() > 1
                };
                let style = if best { &bold } else { &plain };
                area.draw_text(&formats[j].write(*v), style, (first_w + COL_W * (j as i32 + 1) - 6, mid))?;
            }
        }
        rule(y + ROW_H * bars.categories.len() as i32)
    }
}

/// How one column writes its numbers: all with the same decimals, so they line up and compare
/// at a glance (four significant digits of the column's smallest value), or, where that would
/// take more than six decimals, each with four significant digits; never in e-notation, which
/// a column of plain decimals would not be read alongside.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Format {
    Fixed(usize),
    Each,
}

impl Format {
    fn of(values: impl Iterator<Item = f64>) -> Format {
        let smallest = values.map(f64::abs).filter(|v| *v > 0.0).fold(f64::INFINITY, f64::min);
        if !smallest.is_finite() {
            return Format::Each;
        }
        let decimals = 3 - smallest.log10().floor() as i32;
        if decimals > 6 { Format::Each } else { Format::Fixed(decimals.max(0) as usize) }
    }

    fn write(self, v: f64) -> String {
        match self {
            Format::Fixed(decimals) => format!("{v:.decimals$}"),
            Format::Each if v == 0.0 || !v.is_finite() => axes::number(v),
            Format::Each => axes::significant(v, 4),
        }
    }
}

/// Whether a row or column competes for the bold best: not the input order, which is the
/// reference every ordering is measured against (it takes no time because it does nothing).
fn contends(name: &str) -> bool {
    name != "input"
}

/// The first column's width: room for every row label (never cut: a truncated model name
/// cannot be told from its neighbours).
fn first_col_w(categories: &[String]) -> i32 {
    categories.iter().map(|c| axes::text_width(c, 12.0) + 24).max().unwrap_or(0).max(FIRST_COL_W)
}

/// `text` cut to `max` characters with an ellipsis.
fn truncate(text: &str, max: usize) -> String {
    if text.chars().count() <= max { text.to_string() } else { text.chars().take(max - 1).chain(['…']).collect() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_column_writes_its_numbers_alike() {
        let times = Format::of([0.01106, 1.451, 0.4549].into_iter());
        assert_eq!(times, Format::Fixed(5));
        assert_eq!(times.write(1.451), "1.45100");
        let acmr = Format::of([0.6512, 2.999].into_iter());
        assert_eq!(acmr.write(2.999), "2.9990");
        let tiny = Format::of([3.3e-6, 0.2].into_iter());
        assert_eq!(tiny, Format::Each);
        assert_eq!(tiny.write(8.714e-5), "0.00008714");
        assert_eq!(tiny.write(0.01281), "0.01281");
    }

    #[test]
    fn the_first_column_fits_its_longest_row_label() {
        let narrow = first_col_w(&["bunny".to_string()]);
        let wide = first_col_w(&["animated/Michelle.glb#clip=Samba Dancing,subdiv=1 (12,345 triangles)".to_string()]);
        assert_eq!(narrow, FIRST_COL_W);
        assert!(wide > FIRST_COL_W);
    }
}
