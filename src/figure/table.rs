//! Tables drawn as SVG: one row per x value (e.g. per model), one column per series (e.g. per
//! method), the metric in each cell — for the papers' tables (Bogomjakov & Gotsman 2002 Tables 1
//! and 2), where the reader compares numbers, not shapes. The best value of each row is bold
//! when the metric is one where lower is better (all of ours are: misses, overdraw, time).

use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::axes::{self, Area, Colors, DrawResult, FONT, Frame, Swatch};
use super::bar::Bars;
use super::{Extent, Kind, XAxis};

/// Pixel sizes of the grid.
const ROW_H: i32 = 24;
const HEAD_H: i32 = 64;
const FIRST_COL_W: i32 = 230;
const COL_W: i32 = 104;

/// The same values as a bar chart holds (panel × series × category), drawn as text.
pub struct Tables(pub Bars);

impl Kind for Tables {
    /// The size that fits the table.
    fn panel_size(&self) -> Option<(usize, usize)> {
        let bars = &self.0;
        let w = FIRST_COL_W + COL_W * bars.series.len() as i32 + 20;
        let h = HEAD_H + ROW_H * bars.categories.len() as i32 + 40;
        Some((w.max(400) as usize, h as usize))
    }

    fn extent(&self) -> Extent {
        Extent { x: XAxis::Categories(self.0.categories.clone()), y: (0.0, 1.0), from_zero: true }
    }

    fn swatch(&self) -> Swatch {
        Swatch::Block
    }

    fn legend(&self) -> bool {
        false
    }

    fn draw(&self, index: usize, area: &Area, title: &str, _frame: &Frame, colors: &Colors) -> DrawResult {
        let bars = &self.0;
        let values = &bars.values[index];
        let mut y = 8;
        if !title.is_empty() {
            area.draw_text(title, &TextStyle::from((FONT, 15).into_font().style(FontStyle::Bold)), (10, y))?;
            y += 24;
        }
        let head = TextStyle::from((FONT, 12).into_font().style(FontStyle::Bold)).pos(Pos::new(HPos::Right, VPos::Top));
        for (j, name) in bars.series.iter().enumerate() {
            let x = FIRST_COL_W + COL_W * (j as i32 + 1) - 6;
            area.draw(&Rectangle::new(
                [(x - COL_W + 10, y + HEAD_H - 30), (x, y + HEAD_H - 27)],
                colors.of(name).filled(),
            ))?;
            // A method spec on two lines: the name, then its parameters.
            let (first, rest) = name.split_once(':').unwrap_or((name, ""));
            for (k, line) in [first, rest].iter().enumerate() {
                area.draw_text(&truncate(line, 14), &head, (x, y + 4 + 14 * k as i32))?;
            }
        }
        y += HEAD_H - 20;
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
            area.draw_text(&truncate(category, 32), &label, (10, mid))?;
            let row: Vec<Option<f64>> = values.iter().map(|s| s[i]).collect();
            let best = row.iter().flatten().copied().fold(f64::INFINITY, f64::min);
            for (j, value) in row.iter().enumerate() {
                let Some(v) = value else { continue };
                let style = if *v == best && bars.series.len() > 1 { &bold } else { &plain };
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
