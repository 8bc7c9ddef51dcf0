//! The gallery's generated tables are what their CSVs give (issue 16: numbers quoted in
//! paper-figures/README.md had gone stale against the CSVs beside them). Every table between
//! `<!-- generated from … -->` and `<!-- end generated -->` is rebuilt from its CSV here; a
//! rerun that moves a number fails this test until `triorder gallery` rewrites the table.

use std::path::Path;

#[test]
fn every_generated_table_matches_its_csv() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let file = root.join("paper-figures/README.md");
    let text = std::fs::read_to_string(&file).expect("the gallery exists");
    let (fresh, sources) = triorder::figure::gallery::refresh(&text, root, &file).expect("every recipe reads its CSV");
    assert!(sources.len() >= 10, "expected the gallery's tables to be generated, found {}", sources.len());
    if fresh != text {
        let stale: Vec<String> = text
            .lines()
            .zip(fresh.lines())
            .enumerate()
            .filter(|(_, (a, b))| a != b)
            .take(5)
            .map(|(i, (a, b))| format!("line {}:\n  typed: {a}\n  CSV:   {b}", i + 1))
            .collect();
        panic!("generated tables differ from their CSVs; run `triorder gallery`:\n{}", stale.join("\n"));
    }
}

/// The numbers the gallery's prose quotes to one to four decimals are measurements: each must
/// be a value, rounded as written (a percentage may quote a share: `23.1%` for 0.231), of a CSV its section names (the spec ids in backticks in the
/// `##` and `###` headings above it, every `results/ID.csv` the `##` section links, and the ids a
/// line adds with `<!-- also: ID … -->`). So a rerun that moves a number fails here until the text
/// follows. Exempt: the paper's own numbers (a paragraph starting `**Paper`, and a table right
/// after it), generated tables (checked above), and lines that say why with
/// `<!-- unchecked: … -->` (differences and ratios computed from the CSVs, a previous run's
/// values, the paper quoted inline, `triorder bench` output).
#[test]
fn numbers_quoted_in_the_gallery_are_values_of_their_csvs() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut loaded: std::collections::HashMap<String, Vec<f64>> = std::collections::HashMap::new();
    let mut values_of = |id: &str| -> Vec<f64> {
        loaded
            .entry(id.to_string())
            .or_insert_with(|| {
                let Ok(mut reader) = csv::Reader::from_path(root.join(format!("results/{id}.csv"))) else {
                    return Vec::new();
                };
                let column = reader.headers().expect("a header").iter().position(|h| h == "value");
                let mut values: Vec<f64> = reader
                    .records()
                    .filter_map(|r| r.ok()?.get(column?)?.parse::<f64>().ok())
                    .filter(|v| v.is_finite())
                    .collect();
                values.sort_by(f64::total_cmp);
                values
            })
            .clone()
    };
    let measured = |values: &[f64], text: &str| {
        let decimals = text.split('.').nth(1).map_or(0, str::len) as i32;
        let (v, half) = (text.parse::<f64>().expect("digits"), 0.5 * 10f64.powi(-decimals) + 1e-12);
        let i = values.partition_point(|&x| x < v - half);
        values.get(i).is_some_and(|&x| x <= v + half)
    };
    let text = std::fs::read_to_string(root.join("paper-figures/README.md")).expect("the gallery exists");
    let (mut section, mut subsection): (Vec<String>, Vec<String>) = (Vec::new(), Vec::new());
    let (mut generated, mut paper, mut paper_table, mut checked) = (false, false, false, 0);
    let mut stray = Vec::new();
    let mut previous_blank_after_paper = false;
    for (n, line) in text.lines().enumerate() {
        if let Some(heading) = line.strip_prefix("## ") {
            (section, subsection) = (backticked(heading), Vec::new());
        } else if let Some(heading) = line.strip_prefix("### ") {
            subsection = backticked(heading);
        }
        if !line.starts_with("<!--") {
            section.extend(linked_results(line));
        }
        generated = (generated || line.starts_with("<!-- generated")) && !line.starts_with("<!-- end generated");
        paper_table = line.starts_with('|') && (paper_table || previous_blank_after_paper);
        previous_blank_after_paper = paper && line.trim().is_empty();
        paper = (paper || line.starts_with("**Paper")) && !line.trim().is_empty();
        if generated || paper || paper_table || line.contains("<!-- unchecked") {
            continue;
        }
        let also = line.split("<!-- also:").nth(1).map(|rest| backticked_words(rest.split("-->").next().unwrap_or("")));
        let scope: Vec<String> = section.iter().chain(&subsection).cloned().chain(also.into_iter().flatten()).collect();
        let mut values: Vec<f64> = scope.iter().flat_map(|id| values_of(id)).collect();
        values.sort_by(f64::total_cmp);
        for number in decimal_numbers(line) {
            checked += 1;
            // A percentage may quote a share (0.231 written 23.1%).
            let share = || {
                let after = &line[line.find(number).map_or(0, |at| at + number.len())..];
                let decimals = number.split('.').nth(1).map_or(0, str::len);
                let v = number.parse::<f64>().expect("digits") / 100.0;
                // `23.1%`, or the first of a range `26.9–27.5%`.
                let range_end =
                    after.strip_prefix('–').map(|r| r.trim_start_matches(|c: char| c.is_ascii_digit() || c == '.'));
                (after.starts_with('%') || range_end.is_some_and(|r| r.starts_with('%')))
                    && measured(&values, &format!("{v:.prec$}", prec = decimals + 2))
            };
            if !measured(&values, number) && !share() {
                stray.push(format!("line {}: {number} not in {scope:?}: `{}`", n + 1, line.trim()));
            }
        }
    }
    assert!(checked > 300, "expected the gallery's quoted numbers, found {checked}");
    assert!(stray.is_empty(), "numbers in paper-figures/README.md that their CSVs do not have:\n{}", stray.join("\n"));
}

/// The spec ids in backticks in a heading: `` `universal-acmr-vs-cache` ``.
fn backticked(heading: &str) -> Vec<String> {
    heading.split('`').skip(1).step_by(2).filter(|w| is_id(w)).map(str::to_string).collect()
}

/// The ids of an `<!-- also: a b -->` list.
fn backticked_words(list: &str) -> Vec<String> {
    list.split_whitespace().filter(|w| is_id(w)).map(str::to_string).collect()
}

fn is_id(word: &str) -> bool {
    !word.is_empty() && word.bytes().all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'-')
}

/// The ids of the `results/ID.csv` a line links.
fn linked_results(line: &str) -> Vec<String> {
    line.split("results/")
        .skip(1)
        .filter_map(|rest| rest.split_once(".csv").map(|(id, _)| id))
        .filter(|id| is_id(id))
        .map(str::to_string)
        .collect()
}

/// The numbers with one to four decimals in `line`, as written (`0.633`, `1.0913`), not parts
/// of longer tokens (versions, commits, `1.2.3`).
fn decimal_numbers(line: &str) -> Vec<&str> {
    let bytes = line.as_bytes();
    let mut found = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        let start = i;
        while i < bytes.len() && bytes[i].is_ascii_digit() {
            i += 1;
        }
        let glued = |b: u8| b.is_ascii_alphanumeric() || b == b'.' || b == b'_';
        if i > start && i < bytes.len() && bytes[i] == b'.' && (start == 0 || !glued(bytes[start - 1])) {
            let dot = i;
            i += 1;
            while i < bytes.len() && bytes[i].is_ascii_digit() {
                i += 1;
            }
            let decimals = i - dot - 1;
            if (1..=4).contains(&decimals) && (i == bytes.len() || !glued(bytes[i])) {
                found.push(&line[start..i]);
            }
        }
        i = i.max(start + 1);
    }
    found
}

#[test]
fn decimal_numbers_are_found_as_written() {
    assert_eq!(
        decimal_numbers("ACMR 0.633 vs 1.0913 and 12.34, 1.5 s, not v1.2.3, 1.23456 or a1.234"),
        ["0.633", "1.0913", "12.34", "1.5"]
    );
}
