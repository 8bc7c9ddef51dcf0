//! Every committed figure is readable: no two of its texts (tick labels, bar values, legend
//! entries, titles) are drawn over each other. SVG carries no font metrics, so each text's box
//! is estimated from its length, size and anchor, on the narrow side (half an em a character:
//! real sans-serif text is wider), so only a real collision fails. Issue 16: tick labels printed
//! over each other made `nbs06-fig5-helix-overdraw` unreadable.
//!
//! Nor is any text drawn over data: no line, marker or mesh triangle in a series colour (not
//! black or white, the axes' and frames' colours) crosses a text's box, so a legend or label
//! placed inside a panel fails. Bars (rectangles) are left out: a bar cut at the top carries its
//! value inside it by design.

use std::path::Path;

/// A text's box in the SVG's pixels: left, top, right, bottom.
#[derive(Debug, Clone, Copy)]
struct Box {
    left: f64,
    top: f64,
    right: f64,
    bottom: f64,
}

/// The value of attribute `name` in a tag's attribute text.
fn attribute<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let start = tag.find(&format!(" {name}=\""))? + name.len() + 3;
    Some(&tag[start..start + tag[start..].find('"')?])
}

/// Characters as a reader sees them: an entity (`&amp;`) is one.
fn visible_chars(text: &str) -> usize {
    let mut count = 0;
    let mut in_entity = false;
    for c in text.trim().chars() {
        match c {
            '&' => in_entity = true,
            ';' if in_entity => {
                in_entity = false;
                count += 1;
            }
            _ if in_entity => {}
            _ => count += 1,
        }
    }
    count
}

/// The unrotated texts of an SVG as `(content, box)`.
fn texts(svg: &str) -> Vec<(String, Box)> {
    let mut out = Vec::new();
    let mut rest = svg;
    while let Some(at) = rest.find("<text ") {
        rest = &rest[at..];
        let Some(tag_end) = rest.find('>') else { break };
        let tag = &rest[..tag_end];
        let Some(close) = rest.find("</text>") else { break };
        let content = rest[tag_end + 1..close].trim().to_string();
        rest = &rest[close..];
        if tag.contains("transform=") || content.is_empty() {
            continue; // rotated axis titles stand apart from the rest by construction
        }
        let number = |name: &str| attribute(tag, name).and_then(|v| v.parse::<f64>().ok());
        let (Some(x), Some(y), Some(size)) = (number("x"), number("y"), number("font-size")) else { continue };
        let width = visible_chars(&content) as f64 * size * 0.5;
        let left = match attribute(tag, "text-anchor") {
            Some("middle") => x - width / 2.0,
            Some("end") => x - width,
            _ => x,
        };
        // Where the glyphs sit around y, by plotters' vertical anchors.
        let top = match attribute(tag, "dy") {
            Some("0.76em") => y,
            Some("0.5ex") => y - 0.5 * size,
            Some("-0.5ex") => y - size,
            _ => y - 0.8 * size,
        };
        // Glyphs fill about 70% of the em box: the rest is leading, which may touch.
        let shrink = 0.15 * size;
        out.push((content, Box { left, top: top + shrink, right: left + width, bottom: top + size - shrink }));
    }
    out
}

/// Pairs of texts whose boxes overlap by more than a pixel both ways.
fn collisions(texts: &[(String, Box)]) -> Vec<(String, String)> {
    let mut sorted: Vec<&(String, Box)> = texts.iter().collect();
    sorted.sort_by(|a, b| a.1.top.total_cmp(&b.1.top));
    let mut found = Vec::new();
    for (i, (a, ba)) in sorted.iter().enumerate() {
        for (b, bb) in &sorted[i + 1..] {
            if bb.top >= ba.bottom - 1.0 {
                break;
            }
            let overlap_x = ba.right.min(bb.right) - ba.left.max(bb.left);
            let overlap_y = ba.bottom.min(bb.bottom) - ba.top.max(bb.top);
            if overlap_x > 1.0 && overlap_y > 1.0 {
                found.push((a.clone(), b.clone()));
            }
        }
    }
    found
}

/// The segments of every polyline and polygon, and the centres of every circle (as a segment
/// of length 0), drawn in a colour other than black and white.
fn data_segments(svg: &str) -> Vec<((f64, f64), (f64, f64))> {
    let mut out = Vec::new();
    let mut rest = svg;
    while let Some(at) = rest.find('<') {
        rest = &rest[at + 1..];
        let Some(end) = rest.find('>') else { break };
        let tag = &rest[..end];
        let kind = tag.split_whitespace().next().unwrap_or_default();
        let colour = [attribute(tag, "stroke"), attribute(tag, "fill")]
            .into_iter()
            .flatten()
            .find(|c| *c != "none")
            .unwrap_or("none")
            .to_ascii_uppercase();
        if ["NONE", "#000000", "#FFFFFF"].contains(&colour.as_str()) {
            continue;
        }
        let number = |name: &str| attribute(tag, name).and_then(|v| v.parse::<f64>().ok());
        match kind {
            "circle" => {
                if let (Some(x), Some(y)) = (number("cx"), number("cy")) {
                    out.push(((x, y), (x, y)));
                }
            }
            "polyline" | "polygon" => {
                let points: Vec<(f64, f64)> = attribute(tag, "points")
                    .unwrap_or_default()
                    .split_whitespace()
                    .filter_map(|p| p.split_once(','))
                    .filter_map(|(x, y)| Some((x.parse().ok()?, y.parse().ok()?)))
                    .collect();
                out.extend(points.windows(2).map(|w| (w[0], w[1])));
            }
            _ => {}
        }
    }
    out
}

/// Whether the segment from `a` to `b` passes through `b0` shrunk by a pixel on every side
/// (Liang–Barsky clipping).
fn crosses(a: (f64, f64), b: (f64, f64), b0: &Box) -> bool {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut enter, mut leave) = (0.0f64, 1.0f64);
    for (p, q) in [
        (-dx, a.0 - (b0.left + 1.0)),
        (dx, (b0.right - 1.0) - a.0),
        (-dy, a.1 - (b0.top + 1.0)),
        (dy, (b0.bottom - 1.0) - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return false;
            }
        } else if p < 0.0 {
            enter = enter.max(q / p);
        } else {
            leave = leave.min(q / p);
        }
    }
    enter <= leave
}

/// Texts with data drawn through them.
fn texts_over_data(svg: &str) -> Vec<String> {
    let segments = data_segments(svg);
    texts(svg)
        .into_iter()
        .filter(|(_, b)| segments.iter().any(|&(p, q)| crosses(p, q, b)))
        .map(|(content, _)| content)
        .collect()
}

#[test]
fn a_legend_over_a_line_is_found() {
    let svg = r##"<polyline fill="none" stroke="#1F77B4" points="50,60 150,65 250,58"/>
<circle cx="300" cy="20" r="3" fill="#D62728"/>
<text x="100" y="58" dy="0.76em" font-size="12">tipsify cache=16</text>
<text x="290" y="15" dy="0.76em" font-size="12">marker</text>
<text x="100" y="120" dy="0.76em" font-size="12">below the data</text>
<polyline fill="none" stroke="#000000" points="0,130 400,130"/>"##;
    assert_eq!(texts_over_data(svg), ["tipsify cache=16", "marker"]);
}

#[test]
fn no_committed_figure_draws_text_over_data() {
    let mut failures = Vec::new();
    for svg in committed_svgs() {
        let over = texts_over_data(&std::fs::read_to_string(&svg).expect("readable SVG"));
        if let Some(first) = over.first() {
            let name = svg.file_name().unwrap_or_default().to_string_lossy();
            failures.push(format!("{name}: {} texts over data, first `{first}`", over.len()));
        }
    }
    assert!(failures.is_empty(), "figures with texts drawn over their data:\n{}", failures.join("\n"));
}

/// Every SVG under paper-figures/.
fn committed_svgs() -> Vec<std::path::PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("paper-figures");
    let mut svgs: Vec<_> = std::fs::read_dir(&dir)
        .expect("paper-figures/ exists")
        .map(|e| e.expect("readable entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "svg"))
        .collect();
    svgs.sort();
    assert!(svgs.len() > 30, "expected the committed figures in {}", dir.display());
    svgs
}

#[test]
fn overlapping_texts_are_found() {
    let svg = r#"<text x="100" y="50" dy="0.76em" text-anchor="middle" font-size="12">nehab:clusters=4,views=ico:42</text>
<text x="140" y="50" dy="0.76em" text-anchor="middle" font-size="12">nehab:clusters=8,views=ico:42</text>
<text x="400" y="50" dy="0.76em" text-anchor="middle" font-size="12">apart</text>
<text x="100" y="80" dy="0.76em" text-anchor="middle" font-size="12">below</text>"#;
    let found = collisions(&texts(svg));
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].0.starts_with("nehab") && found[0].1.starts_with("nehab"));
}

#[test]
fn no_committed_figure_draws_text_over_text() {
    let mut failures = Vec::new();
    for svg in &committed_svgs() {
        let text = std::fs::read_to_string(svg).expect("readable SVG");
        let found = collisions(&texts(&text));
        if let Some((a, b)) = found.first() {
            let name = svg.file_name().unwrap_or_default().to_string_lossy();
            failures.push(format!("{name}: {} collisions, first `{a}` over `{b}`", found.len()));
        }
    }
    assert!(failures.is_empty(), "figures with texts drawn over each other:\n{}", failures.join("\n"));
}
