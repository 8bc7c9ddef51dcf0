//! What every chart kind shares: the panel frame (axes, linear or log, with the same ranges in
//! every panel so small multiples compare at a glance), series colours, the legend strip and
//! number formatting.

use std::ops::Range;

use plotters::coord::Shift;
use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

pub type Area<'a> = DrawingArea<SVGBackend<'a>, Shift>;
pub type DrawResult = std::result::Result<(), DrawingAreaErrorKind<std::io::Error>>;

/// The font family of every text: plain SVG text, rendered by the viewer's sans-serif font.
pub const FONT: &str = "sans-serif";

/// Axes shared by every panel of a figure.
#[derive(Clone)]
pub struct Frame {
    pub x: Range<f64>,
    pub y: Range<f64>,
    pub x_log: bool,
    pub y_log: bool,
    pub x_desc: String,
    pub y_desc: String,
    /// Category names at x = 0, 1, 2, … (bar charts): the x axis shows them instead of numbers.
    pub categories: Option<Vec<String>>,
    /// The metric's best possible value, drawn as a dashed line where it is inside the y range.
    pub optimum: Option<f64>,
}

/// Draws one panel's data into its chart, whatever the axes' scales.
pub trait Painter {
    fn paint<'a, 'b: 'a, X, Y>(&self, chart: &mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>) -> DrawResult
    where
        X: Ranged<ValueType = f64> + ValueFormatter<f64>,
        Y: Ranged<ValueType = f64> + ValueFormatter<f64>;
}

/// Draws a panel titled `title` with `frame`'s axes into `area`, then `painter`'s data.
pub fn panel(area: &Area, title: &str, frame: &Frame, painter: &impl Painter) -> DrawResult {
    let mut builder = ChartBuilder::on(area);
    builder.margin(10).margin_right(20).x_label_area_size(48).y_label_area_size(72);
    if !title.is_empty() {
        builder.caption(title, (FONT, 15));
    }
    let (x, y) = (frame.x.clone(), frame.y.clone());
    let log = |r: Range<f64>| {
        let ticks = log_ticks(r.start, r.end);
        r.log_scale().with_key_points(ticks)
    };
    match (frame.x_log, frame.y_log) {
        (false, false) => finish(builder.build_cartesian_2d(x, y)?, frame, painter),
        (true, false) => finish(builder.build_cartesian_2d(log(x), y)?, frame, painter),
        (false, true) => finish(builder.build_cartesian_2d(x, log(y))?, frame, painter),
        (true, true) => finish(builder.build_cartesian_2d(log(x), log(y))?, frame, painter),
    }
}

/// Tick values for a log axis over `lo..hi` (both > 0): m·10^k for the sparsest set of
/// mantissas whose tick count is nearest seven, or evenly spaced round values when the range is
/// too narrow for any to give four. plotters' own log ticks are powers of the base only, which leaves a
/// range like 0.5..3 labelled at 1, 2, 3 and nowhere below 1.
fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    const MANTISSAS: [&[f64]; 4] =
        [&[1.0], &[1.0, 2.0, 5.0], &[1.0, 2.0, 3.0, 5.0], &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]];
    let at = |m: f64, k: i32| if k < 0 { m / 10f64.powi(-k) } else { m * 10f64.powi(k) };
    let (first, last) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let ticks = |mantissas: &[f64]| -> Vec<f64> {
        (first..=last)
            .flat_map(|k| mantissas.iter().map(move |&m| at(m, k)))
            .filter(|v| (lo..=hi).contains(v))
            .collect()
    };
    let best = MANTISSAS.iter().map(|m| ticks(m)).min_by_key(|t| t.len().abs_diff(7)).unwrap_or_default();
    if best.len() >= 4 {
        return best;
    }
    let raw = (hi - lo) / 5.0;
    let magnitude = raw.log10().floor() as i32;
    let step = [1.0, 2.0, 5.0, 10.0].iter().map(|&m| at(m, magnitude)).find(|&s| s >= raw).unwrap_or(raw);
    let start = (lo / step).ceil() as i64;
    (start..).map(|i| i as f64 * step).take_while(|&v| v <= hi).collect()
}

fn finish<'a, 'b: 'a, X, Y>(
    mut chart: ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>,
    frame: &Frame,
    painter: &impl Painter,
) -> DrawResult
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let category = |v: &f64| {
        let i = v.round();
        match &frame.categories {
            Some(names) if (v - i).abs() < 1e-6 && i >= 0.0 => names.get(i as usize).cloned().unwrap_or_default(),
            _ => String::new(),
        }
    };
    let (x_span, y_span) = (chart.x_range().end - chart.x_range().start, chart.y_range().end - chart.y_range().start);
    let (x_value, y_value) = (move |v: &f64| tick(*v, x_span), move |v: &f64| tick(*v, y_span));
    let mut mesh = chart.configure_mesh();
    mesh.x_label_formatter(&x_value)
        .y_label_formatter(&y_value)
        .x_desc(frame.x_desc.as_str())
        .y_desc(frame.y_desc.as_str())
        .label_style((FONT, 12))
        .axis_desc_style((FONT, 13))
        .bold_line_style(BLACK.mix(0.12))
        .light_line_style(BLACK.mix(0.04));
    if let Some(names) = &frame.categories {
        mesh.x_labels(names.len()).x_label_formatter(&category).disable_x_mesh();
    }
    mesh.draw()?;
    painter.paint(&mut chart)?;
    let (x, y) = (chart.x_range(), chart.y_range());
    if let Some(o) = frame.optimum.filter(|o| y.start < *o && *o <= y.end) {
        let grey = RGBColor(0x33, 0x33, 0x33);
        chart.draw_series(DashedLineSeries::new([(x.start, o), (x.end, o)], 6, 4, grey.stroke_width(1)))?;
        let style = TextStyle::from((FONT, 11)).color(&grey).pos(Pos::new(HPos::Right, VPos::Bottom));
        let text = EmptyElement::at((x.end, o)) + Text::new(format!("optimum {}", number(o)), (-4, -2), style);
        chart.draw_series(std::iter::once(text))?;
    }
    Ok(())
}

/// Colours chosen so that a series keeps its colour from figure to figure, by its name alone:
/// the two reference orders have their own (`input` grey, `random` red), and every other family
/// (a method's name without its parameters, or any other series value) prefers the palette slot
/// its name hashes to among the rest; variants of one method (a parameter grid) are lighter and
/// darker shades of it. Two families of one figure never share a slot while the palette lasts:
/// where their preferred slots collide, the family first in alphabetical order keeps its slot
/// and the other takes the next free one. So adding a method to the registry changes no figure
/// it is not in, and a figure's colours do not depend on its legend order.
///
/// Each series also has a marker shape (its family's slot, shifted per variant), so lines and
/// points stay apart in greyscale and where two colours are close. In a crowded line chart the
/// series that are not highlighted can be drawn as grey context ([`Colors::context`]): one
/// legend entry stands for them all.
pub struct Colors {
    entries: Vec<(String, RGBColor)>,
    markers: Vec<Marker>,
    /// Series drawn as grey context, not in the legend one by one.
    context: Vec<String>,
}

/// A point marker's shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    Circle,
    Square,
    Triangle,
    Diamond,
    Cross,
}

const MARKERS: [Marker; 5] = [Marker::Circle, Marker::Square, Marker::Triangle, Marker::Diamond, Marker::Cross];

/// The grey of context series.
const CONTEXT: RGBColor = RGBColor(0xbb, 0xbb, 0xbb);

/// What a series name is a variant of: a method's name without its parameters (`tipsify` of
/// `tipsify:cache=8`, or of its display name `tipsify cache=8`).
pub fn family(name: &str) -> &str {
    name.split([':', ' ']).next().unwrap_or(name)
}

/// Methods with a palette slot of their own, in slot order: the file's order and the worst case.
const RESERVED: [&str; 2] = ["input", "random"];

const PALETTE: [RGBColor; 28] = [
    RGBColor(0x4d, 0x4d, 0x4d), // grey
    RGBColor(0xe1, 0x57, 0x59), // red
    RGBColor(0x4e, 0x79, 0xa7), // blue
    RGBColor(0xf2, 0x8e, 0x2b), // orange
    RGBColor(0x59, 0xa1, 0x4f), // green
    RGBColor(0xb0, 0x7a, 0xa1), // purple
    RGBColor(0x76, 0xb7, 0xb2), // teal
    RGBColor(0x9c, 0x75, 0x5f), // brown
    RGBColor(0xed, 0xc9, 0x48), // yellow
    RGBColor(0xff, 0x9d, 0xa7), // pink
    RGBColor(0x17, 0xbe, 0xcf), // cyan
    RGBColor(0xbc, 0xbd, 0x22), // yellow-green
    RGBColor(0x7f, 0x3c, 0x8d), // dark purple
    RGBColor(0x1b, 0x6e, 0x3b), // dark green
    RGBColor(0x1f, 0x3a, 0x93), // navy
    RGBColor(0xe3, 0x77, 0xc2), // magenta
    RGBColor(0x8c, 0x8c, 0x00), // olive
    RGBColor(0x00, 0x80, 0x80), // dark teal
    RGBColor(0xc0, 0x40, 0x00), // rust
    RGBColor(0x99, 0x99, 0xff), // lavender
    RGBColor(0xa6, 0xce, 0xe3), // light blue
    RGBColor(0xb8, 0x86, 0x0b), // dark gold
    RGBColor(0x4b, 0x00, 0x82), // indigo
    RGBColor(0xd2, 0xb4, 0x8c), // tan
    RGBColor(0x80, 0x00, 0x00), // maroon
    RGBColor(0x70, 0x80, 0x90), // slate
    RGBColor(0x8d, 0xd3, 0xc7), // mint
    RGBColor(0xc7, 0x15, 0x85), // violet red
];

impl Colors {
    /// Colours for the series `names` (in legend order) of the CSV column `column`.
    pub fn new(column: &str, names: &[String]) -> Colors {
        let methods = column == "method" || column == "method_name";
        let family = |name: &str| if methods { family(name) } else { name }.to_string();
        let mut families: Vec<String> = names.iter().map(|n| family(n)).collect();
        families.sort();
        families.dedup();
        let reserved = |key: &str| if methods { RESERVED.iter().position(|&r| r == key) } else { None };
        let mut slots: Vec<(String, usize)> =
            families.iter().filter_map(|key| Some((key.clone(), reserved(key)?))).collect();
        let free = PALETTE.len() - RESERVED.len();
        for key in families.iter().filter(|key| reserved(key).is_none()) {
            let mut slot = RESERVED.len() + fnv1a(key) % free;
            while slots.len() < PALETTE.len() && slots.iter().any(|&(_, s)| s == slot) {
                slot = RESERVED.len() + (slot + 1 - RESERVED.len()) % free;
            }
            slots.push((key.clone(), slot));
        }
        let (entries, markers) = names
            .iter()
            .map(|name| {
                let key = family(name);
                let slot = slots.iter().find(|(k, _)| *k == key).map_or(0, |&(_, s)| s);
                let mut variants: Vec<&String> = names.iter().filter(|n| family(n) == key).collect();
                variants.sort_by_key(|n| natural(n));
                variants.dedup();
                let k = variants.iter().position(|n| *n == name).unwrap_or(0);
                ((name.clone(), shade(PALETTE[slot], k, variants.len())), MARKERS[(slot + k) % MARKERS.len()])
            })
            .unzip();
        Colors { entries, markers, context: Vec::new() }
    }

    /// The same colours, with `names` drawn as grey context and listed as one legend entry.
    pub fn context(mut self, names: Vec<String>) -> Colors {
        self.context = names;
        self
    }

    pub fn of(&self, name: &str) -> RGBColor {
        if self.is_context(name) {
            return CONTEXT;
        }
        self.entries.iter().find(|(n, _)| n == name).map_or(BLACK, |&(_, c)| c)
    }

    pub fn marker(&self, name: &str) -> Marker {
        self.entries.iter().position(|(n, _)| n == name).map_or(Marker::Circle, |i| self.markers[i])
    }

    pub fn is_context(&self, name: &str) -> bool {
        self.context.iter().any(|c| c == name)
    }

    /// The legend's entries: every series not drawn as context, then one for the context.
    fn legend_entries(&self) -> Vec<(String, RGBColor, Option<Marker>)> {
        let mut entries: Vec<_> = self
            .entries
            .iter()
            .zip(&self.markers)
            .filter(|((n, _), _)| !self.is_context(n))
            .map(|((n, c), m)| (n.clone(), *c, Some(*m)))
            .collect();
        if !self.context.is_empty() {
            let label = format!("{} other orderings (grey; each named in the CSV)", self.context.len());
            entries.push((label, CONTEXT, None));
        }
        entries
    }
}

/// Draws `size`-pixel markers of `shape` at `points`.
pub fn markers<'a, 'b: 'a, X, Y>(
    chart: &mut ChartContext<'a, SVGBackend<'b>, Cartesian2d<X, Y>>,
    points: &[(f64, f64)],
    shape: Marker,
    size: i32,
    style: ShapeStyle,
) -> DrawResult
where
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let at = |p: &(f64, f64)| EmptyElement::at(*p);
    let s = size;
    match shape {
        Marker::Circle => chart.draw_series(points.iter().map(|p| Circle::new(*p, s, style)))?,
        Marker::Square => {
            chart.draw_series(points.iter().map(|p| at(p) + Rectangle::new([(-s, -s), (s, s)], style)))?
        }
        Marker::Triangle => chart.draw_series(points.iter().map(|p| TriangleMarker::new(*p, s + 1, style)))?,
        Marker::Diamond => chart.draw_series(
            points.iter().map(|p| at(p) + Polygon::new(vec![(0, -s - 1), (s + 1, 0), (0, s + 1), (-s - 1, 0)], style)),
        )?,
        // At least 2 pixels wide, so that a cross reads as a marker; wider as an outline.
        Marker::Cross => chart
            .draw_series(points.iter().map(|p| Cross::new(*p, s, style.stroke_width(style.stroke_width.max(2)))))?,
    };
    Ok(())
}

/// `text` as runs of letters and numbers, numbers compared by value: `cache=8` before `cache=16`.
fn natural(text: &str) -> Vec<(String, u64)> {
    let mut runs = Vec::new();
    let mut rest = text;
    while !rest.is_empty() {
        let digits = rest.find(|c: char| !c.is_ascii_digit()).unwrap_or(rest.len());
        if digits > 0 {
            runs.push((String::new(), rest[..digits].parse().unwrap_or(u64::MAX)));
            rest = &rest[digits..];
        } else {
            let letters = rest.find(|c: char| c.is_ascii_digit()).unwrap_or(rest.len());
            runs.push((rest[..letters].to_string(), 0));
            rest = &rest[letters..];
        }
    }
    runs
}

/// Variant `k` of `n` of a colour: from 45% darker to 45% lighter.
fn shade(color: RGBColor, k: usize, n: usize) -> RGBColor {
    if n <= 1 {
        return color;
    }
    let t = k as f64 / (n - 1) as f64 * 0.9 - 0.45;
    let channel = |c: u8| {
        let c = f64::from(c);
        (if t < 0.0 { c * (1.0 + t) } else { c + (255.0 - c) * t }).round() as u8
    };
    RGBColor(channel(color.0), channel(color.1), channel(color.2))
}

/// FNV-1a: a hash that, unlike std's, is the same in every build and on every machine.
fn fnv1a(text: &str) -> usize {
    let hash = text.bytes().fold(0xcbf2_9ce4_8422_2325u64, |h, b| (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3));
    (hash % (1 << 31)) as usize
}

/// How the legend shows a series.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Swatch {
    Line,
    /// A line with the series' marker on it (line charts, which mark their points).
    MarkedLine,
    Point,
    Block,
}

const LEGEND_ROW: i32 = 22;
const LEGEND_FONT: f64 = 13.0;

/// Rough width of `text` in pixels at `size` (SVG has no font metrics; sans-serif averages ~0.55 em).
pub fn text_width(text: &str, size: f64) -> i32 {
    (text.chars().count() as f64 * size * 0.55).ceil() as i32
}

/// Where each legend entry goes in a strip `width` wide: `(x, row)`, entries flowing left to
/// right and wrapping.
fn legend_layout(entries: &[(String, RGBColor, Option<Marker>)], width: i32) -> Vec<(i32, i32)> {
    let (mut x, mut row) = (20, 0);
    entries
        .iter()
        .map(|(label, _, _)| {
            let w = 34 + text_width(label, LEGEND_FONT) + 24;
            if x > 20 && x + w > width - 20 {
                x = 20;
                row += 1;
            }
            let at = (x, row);
            x += w;
            at
        })
        .collect()
}

/// Height of the legend strip for `colors` in `width` pixels.
pub fn legend_height(colors: &Colors, width: u32) -> u32 {
    let rows = legend_layout(&colors.legend_entries(), width as i32).last().map_or(0, |&(_, r)| r + 1);
    (rows * LEGEND_ROW + 12) as u32
}

/// Draws the legend strip: a swatch (with the series' marker for lines and points) and the
/// series name per entry.
pub fn legend(area: &Area, colors: &Colors, swatch: Swatch) -> DrawResult {
    let width = area.dim_in_pixel().0 as i32;
    let style = TextStyle::from((FONT, LEGEND_FONT)).pos(Pos::new(HPos::Left, VPos::Center));
    let entries = colors.legend_entries();
    for ((label, color, marker), (x, row)) in entries.iter().zip(legend_layout(&entries, width)) {
        let y = 6 + row * LEGEND_ROW + LEGEND_ROW / 2;
        let (mx, s) = (x + 13, 4);
        let shape = |area: &Area, marker: Marker, style: ShapeStyle| -> DrawResult {
            match marker {
                Marker::Circle => area.draw(&Circle::new((mx, y), s + 1, style)),
                Marker::Square => area.draw(&Rectangle::new([(mx - s, y - s), (mx + s, y + s)], style)),
                Marker::Triangle => area.draw(&TriangleMarker::new((mx, y), s + 1, style)),
                Marker::Diamond => area.draw(&Polygon::new(
                    vec![(mx, y - s - 1), (mx + s + 1, y), (mx, y + s + 1), (mx - s - 1, y)],
                    style,
                )),
                Marker::Cross => area.draw(&Cross::new((mx, y), s, style.stroke_width(2))),
            }
        };
        match (swatch, marker) {
            (Swatch::Line, _) => area.draw(&PathElement::new(vec![(x, y), (x + 26, y)], color.stroke_width(3)))?,
            (Swatch::MarkedLine, _) => {
                area.draw(&PathElement::new(vec![(x, y), (x + 26, y)], color.stroke_width(3)))?;
                if let Some(m) = marker {
                    shape(area, *m, color.filled())?;
                }
            }
            (Swatch::Point, Some(m)) => shape(area, *m, color.filled())?,
            (Swatch::Point, None) => area.draw(&Circle::new((mx, y), 5, color.filled()))?,
            (Swatch::Block, _) => area.draw(&Rectangle::new([(x + 4, y - 7), (x + 22, y + 7)], color.filled()))?,
        }
        area.draw(&Text::new(label.clone(), (x + 34, y), style.clone()))?;
    }
    Ok(())
}

/// A value with about four significant digits and no trailing zeros: `0.6512`, `1.25`, `3`,
/// and `2.5e-5` for very small or large magnitudes.
pub fn number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return v.to_string();
    }
    if !(1e-3..1e6).contains(&v.abs()) {
        let text = format!("{v:.3e}");
        let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
        return format!("{}e{exponent}", mantissa.trim_end_matches('0').trim_end_matches('.'));
    }
    let decimals = (3 - v.abs().log10().floor() as i32).clamp(0, 8) as usize;
    let text = format!("{v:.decimals$}");
    if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.').to_string() } else { text }
}

/// A tick label of an axis `span` long: [`number`], with as many more decimals as ticks about a
/// tenth of the span apart need to read apart (on an axis from 2.2286 to 2.2305, four
/// significant digits label every tick 2.229).
fn tick(v: f64, span: f64) -> String {
    let plain = number(v);
    if v == 0.0 || !(span > 0.0 && span.is_finite()) || !(1e-3..1e6).contains(&v.abs()) {
        return plain;
    }
    let needed = (-(span / 10.0).log10().floor() as i32).clamp(0, 12) as usize;
    let digits = plain.split_once('.').map_or(0, |(_, fraction)| fraction.len());
    if needed <= digits {
        return plain;
    }
    let text = format!("{v:.needed$}");
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// `v` with `digits` significant digits in plain decimals, never e-notation (`0.0000123`,
/// `1.23`), for tables whose numbers are read side by side.
pub fn significant(v: f64, digits: usize) -> String {
    let decimals = if v == 0.0 || !v.is_finite() {
        0
    } else {
        (digits as i32 - 1 - v.abs().log10().floor() as i32).clamp(0, 12) as usize
    };
    format!("{v:.decimals$}")
}

/// Splits `text` into lines of at most `max` characters at spaces.
pub fn wrap(text: &str, max: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split_whitespace() {
        match lines.last_mut() {
            Some(line) if line.chars().count() + 1 + word.chars().count() <= max => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    lines
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ticks on a narrow axis get the decimals that tell them apart; elsewhere they read as
    /// [`number`] writes them.
    #[test]
    fn ticks_of_a_narrow_axis_read_apart() {
        assert_eq!(tick(2.2288, 0.002), "2.2288");
        assert_eq!(tick(2.229, 0.002), "2.229");
        assert_eq!(tick(0.72, 0.2), "0.72");
        assert_eq!(tick(1.0512, 0.1), number(1.0512));
        assert_eq!(tick(0.0, 0.002), "0");
    }

    #[test]
    fn numbers_and_wrapping() {
        assert_eq!(number(0.651234), "0.6512");
        assert_eq!(number(1.25), "1.25");
        assert_eq!(number(3.0), "3");
        assert_eq!(number(1234.6), "1235");
        assert_eq!(number(0.000123456), "1.235e-4");
        assert_eq!(number(0.00002), "2e-5");
        assert_eq!(number(0.0012), "0.0012");
        assert_eq!(wrap("a bb ccc dddd", 6), ["a bb", "ccc", "dddd"]);
        assert_eq!(log_ticks(0.45, 3.3), [0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 2.0, 3.0]);
        assert_eq!(log_ticks(0.9, 120.0), [1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0]);
        assert_eq!(log_ticks(1e-6, 2e-3), [1e-6, 1e-5, 1e-4, 1e-3]);
        assert_eq!(log_ticks(1.01, 1.3).len(), 3); // 1.1, 1.2, 1.3 (round values, not decades)
    }

    #[test]
    fn colours_are_stable_and_distinct() {
        let names: Vec<String> =
            ["input", "random:seed=0", "meshopt-fifo:cache=8", "meshopt-fifo:cache=16"].map(String::from).to_vec();
        let colors = Colors::new("method", &names);
        assert_eq!(colors.of("input"), PALETTE[0]);
        assert_eq!(colors.of("random:seed=0"), PALETTE[1]);
        assert_ne!(colors.of("meshopt-fifo:cache=8"), colors.of("meshopt-fifo:cache=16"));
        let distinct: std::collections::HashSet<_> = names.iter().map(|n| format!("{:?}", colors.of(n))).collect();
        assert_eq!(distinct.len(), names.len());
        // The same series in another figure, with other company or in another legend order,
        // keeps its colour: it comes from its name.
        let alone = Colors::new("method", &["random:seed=0".to_string()]);
        assert_eq!(alone.of("random:seed=0"), colors.of("random:seed=0"));
        let reversed: Vec<String> = names.iter().rev().cloned().collect();
        let again = Colors::new("method", &reversed);
        assert!(names.iter().all(|n| again.of(n) == colors.of(n)));
        // Every registered method of one figure gets its own colour.
        let all: Vec<String> = crate::order::METHODS.iter().map(|m| m.name.to_string()).collect();
        let every = Colors::new("method", &all);
        let distinct: std::collections::HashSet<_> = all.iter().map(|n| format!("{:?}", every.of(n))).collect();
        assert_eq!(distinct.len(), all.len());
        let models = Colors::new("model", &["a".to_string(), "b".to_string()]);
        assert_ne!(models.of("a"), models.of("b"));
    }
}
