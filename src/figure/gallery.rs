//! Tables of numbers in the gallery (`paper-figures/README.md`) generated from the results
//! CSVs, never typed: a typed number goes stale the day its spec is rerun (issue 16 found
//! timings quoted from an older run than the CSV beside them).
//!
//! A generated table sits between two comments that say where it comes from:
//!
//! ```text
//! <!-- generated from results/ID.csv: rows=model cols=method_name cells=ovr_mean/ovr_max -->
//! | model | random | hoppe | … |
//! …
//! <!-- end generated -->
//! ```
//!
//! - `rows`, `cols`: the CSV columns whose values are the table's rows and columns (several
//!   joined with `+`: `rows=model+method`), in the order they first appear in the CSV (`model` rows are named by file and triangle count;
//!   `method` values by what tells them apart, as in the figures).
//! - `cells`: what each cell shows, one or more values joined by ` / `: a metric name, optionally
//!   with conditions on other columns, `acmr@cache_size=16`. With `cols=cells` each of them is a
//!   column of its own instead.
//! - `filter` (optional): `COLUMN=V1|V2;COLUMN=V` keeps only rows with one of those values (a
//!   `method` value may name only some parameters: `nehab:clusters=64`).
//! - `digits` (optional, default 3): decimals of every number, or `s3` for three significant
//!   digits each (times that span orders of magnitude).
//! - `relative_to` (optional): a value of `cols`; each cell shows that column's value in the
//!   same row divided by its own, written `N×` (how many times lower), higher then best.
//! - `percent=yes` (optional): shares written as percentages.
//! - `spread` (optional): a method parameter (`seed`) whose runs fold into one cell, written as
//!   their mean with the least and greatest in brackets.
//! - `argmin=COLUMN` (optional): each cell is the lowest of its rows, written with that row's
//!   COLUMN (`argmin=method_name`: which ordering wins, and its value).
//! - `slope=N` (optional): each cell is instead the least-squares slope of log value against log
//!   triangle count over its rows of at least N triangles (1: linear growth).
//! - `best` (optional): `row` or `col` writes the lowest of each value of a cell across its row
//!   or column in bold (lower is better for every metric we have); `input` never counts as best.
//!
//! A recipe with `checks=` is a table of targets met instead ([`super::verdicts`]).
//!
//! `triorder gallery` rewrites every such table from its CSV; `tests/gallery.rs` fails when one
//! differs from what its CSV gives, so a rerun that moves a number cannot leave the text behind.

use std::fmt::Write as _;
use std::path::Path;

use super::data::{Table, display_names, metric_where};
use super::verdicts::Verdicts;
use crate::error::{Error, Result};

const OPEN: &str = "<!-- generated from ";
const CLOSE: &str = "<!-- end generated -->";

/// One generated table's recipe, as its opening comment gives it.
#[derive(Debug, Clone, PartialEq)]
struct Recipe {
    csv: String,
    rows: String,
    cols: String,
    /// Per value in a cell: the metric and the `(column, value)` conditions it must meet.
    cells: Vec<(String, Vec<(String, String)>)>,
    filter: Vec<(String, Vec<String>)>,
    digits: Digits,
    best: Best,
    /// The column (a value of `cols`) each cell is divided into: `REF ÷ cell`, written `N×`.
    relative_to: Option<String>,
    /// Shares written as percentages (× 100, `%`).
    percent: bool,
    /// A method parameter (`seed`) whose runs fold into one cell: their mean, then the least to
    /// the greatest in brackets.
    spread: Option<String>,
    /// Each cell is the least-squares slope of log value against log triangle count over the
    /// cell's rows of at least this many triangles (how an ordering's time grows).
    slope: Option<u64>,
    /// Each cell is the lowest of the cell's rows, named by this column (`method_name`): which
    /// ordering wins there.
    argmin: Option<String>,
}

/// How numbers are written: fixed decimals, or significant digits (for times spanning orders of
/// magnitude), never in e-notation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Digits {
    Decimals(usize),
    Significant(usize),
}

impl Digits {
    fn write(self, v: f64) -> String {
        match self {
            Digits::Decimals(d) => format!("{v:.d$}"),
            // Counts (rounds, buffers) are whole numbers: written whole.
            Digits::Significant(_) if v.fract() == 0.0 => format!("{v:.0}"),
            Digits::Significant(n) => super::axes::significant(v, n),
        }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Best {
    None,
    Row,
    Col,
}

impl Recipe {
    /// Parses the text between `<!-- generated from ` and ` -->`.
    fn parse(text: &str) -> std::result::Result<Recipe, String> {
        let (csv, options) = text.split_once(':').ok_or("expected `CSV: rows=… cols=… cells=…`")?;
        let mut recipe = Recipe {
            csv: csv.trim().to_string(),
            rows: String::new(),
            cols: String::new(),
            cells: Vec::new(),
            filter: Vec::new(),
            digits: Digits::Decimals(3),
            best: Best::None,
            relative_to: None,
            percent: false,
            spread: None,
            slope: None,
            argmin: None,
        };
        for option in options.split_whitespace() {
            let (key, value) = option.split_once('=').ok_or_else(|| format!("`{option}` is not KEY=VALUE"))?;
            match key {
                "rows" => recipe.rows = value.to_string(),
                "cols" => recipe.cols = value.to_string(),
                "cells" => {
                    for cell in value.split('/') {
                        recipe.cells.push(metric_where(cell)?);
                    }
                }
                "filter" => {
                    for f in value.split(';') {
                        let (column, values) =
                            f.split_once('=').ok_or_else(|| format!("filter `{f}` is not COLUMN=V1|V2"))?;
                        recipe.filter.push((column.to_string(), values.split('|').map(str::to_string).collect()));
                    }
                }
                "digits" => {
                    let bad = || format!("digits `{value}`: expected decimals (3) or significant digits (s3)");
                    recipe.digits = match value.strip_prefix('s') {
                        Some(n) => Digits::Significant(n.parse().map_err(|_| bad())?),
                        None => Digits::Decimals(value.parse().map_err(|_| bad())?),
                    };
                }
                "best" => {
                    recipe.best = match value {
                        "row" => Best::Row,
                        "col" => Best::Col,
                        "none" => Best::None,
                        _ => return Err(format!("best `{value}`: expected row, col or none")),
                    }
                }
                "relative_to" => recipe.relative_to = Some(value.to_string()),
                "percent" => recipe.percent = value == "yes",
                "spread" => recipe.spread = Some(value.to_string()),
                "argmin" => recipe.argmin = Some(value.to_string()),
                "slope" => {
                    recipe.slope = Some(value.parse().map_err(|_| format!("slope `{value}` is not a triangle count"))?)
                }
                _ => {
                    return Err(format!(
                        "unknown option `{key}` (rows, cols, cells, filter, digits, best, relative_to, percent, spread, slope, argmin)"
                    ));
                }
            }
        }
        if recipe.rows.is_empty() || recipe.cols.is_empty() || recipe.cells.is_empty() {
            return Err("rows=, cols= and cells= are required".into());
        }
        Ok(recipe)
    }

    /// The markdown table, from the CSV under `root`.
    fn table(&self, root: &Path) -> Result<String> {
        let table = Table::read(&root.join(&self.csv))?;
        let path = table.path().display().to_string();
        // `cols=cells`: a column per cell value, one number a cell.
        let by_cell = self.cols == "cells";
        let row_parts: Vec<&str> = self.rows.split('+').collect();
        let col_parts: Vec<&str> = if by_cell { Vec::new() } else { self.cols.split('+').collect() };
        let mut columns: Vec<&str> = row_parts.iter().chain(&col_parts).copied().collect();
        let (n_rows, keys) = (row_parts.len(), row_parts.len() + col_parts.len());
        columns.push("model_triangles");
        columns.extend(self.filter.iter().map(|(c, _)| c.as_str()));
        columns.extend(self.cells.iter().flat_map(|(_, conds)| conds.iter().map(|(c, _)| c.as_str())));
        let filter_at = keys + 1;
        // `argmin`: its column last, so the others keep their places.
        if let Some(column) = &self.argmin {
            columns.push(column.as_str());
        }
        let named_at = columns.len() - 1;
        let mut named: Vec<((usize, usize, usize), f64, String)> = Vec::new();

        let (mut rows, mut cols): (Vec<Vec<String>>, Vec<Vec<String>>) = (Vec::new(), Vec::new());
        let mut triangles: Vec<(String, u64)> = Vec::new();
        // (row, col, cell index) → value.
        let mut values: Vec<((usize, usize, usize), f64)> = Vec::new();
        let mut cond_at = filter_at + self.filter.len();
        // With `slope`: (cell, ln triangles, ln value) of every row, fitted below.
        let mut sloped: Vec<((usize, usize, usize), f64, f64)> = Vec::new();
        for (k, (metric, conds)) in self.cells.iter().enumerate() {
            for (mut cells, value) in table.rows(metric, &columns)? {
                // A model is named by its full triangle count: the most any of its rows has
                // (progressive levels have fewer).
                if let Some(m) = columns.iter().position(|c| *c == "model") {
                    let count: u64 = cells[keys].parse().unwrap_or(0);
                    match triangles.iter_mut().find(|(name, _)| *name == cells[m]) {
                        Some((_, most)) => *most = (*most).max(count),
                        None => triangles.push((cells[m].clone(), count)),
                    }
                }
                let kept = self
                    .filter
                    .iter()
                    .enumerate()
                    .all(|(i, (column, vs))| vs.iter().any(|v| matches(column, v, &cells[filter_at + i])));
                let met = conds.iter().enumerate().all(|(i, (_, v))| cells[cond_at + i] == *v);
                if !kept || !met {
                    continue;
                }
                if let Some(param) = &self.spread {
                    for p in (0..keys).filter(|&p| columns[p] == "method") {
                        cells[p] = super::data::without_parameter(&cells[p], param);
                    }
                }
                let index = |list: &mut Vec<Vec<String>>, key: &[String]| {
                    list.iter().position(|x| x == key).unwrap_or_else(|| {
                        list.push(key.to_vec());
                        list.len() - 1
                    })
                };
                let r = index(&mut rows, &cells[..n_rows]);
                let (c, k) = if by_cell {
                    (index(&mut cols, &[self.cells[k].0.clone(), k.to_string()]), 0)
                } else {
                    (index(&mut cols, &cells[n_rows..keys]), k)
                };
                if self.argmin.is_some() {
                    named.push(((r, c, k), value, cells[named_at].clone()));
                    continue;
                }
                if let Some(least) = self.slope {
                    let triangles: f64 = cells[keys].parse().unwrap_or(0.0);
                    if triangles >= least as f64 && value > 0.0 {
                        sloped.push(((r, c, k), triangles.ln(), value.ln()));
                    }
                    continue;
                }
                if self.spread.is_none() && values.iter().any(|(key, _)| *key == (r, c, k)) {
                    return Err(Error::input(
                        &path,
                        format!(
                            "several `{metric}` rows at {} = {}, {} = {}: narrow the gallery table with filter= or cell conditions",
                            self.rows,
                            cells[..n_rows].join(", "),
                            self.cols,
                            cells[n_rows..keys].join(", ")
                        ),
                    ));
                }
                values.push(((r, c, k), value));
            }
            cond_at += conds.len();
        }
        // With `argmin`: the lowest of each cell's rows, and whose it is.
        let mut winners: Vec<((usize, usize, usize), String)> = Vec::new();
        for (key, value, name) in &named {
            let lowest = named.iter().filter(|(k, _, _)| k == key).all(|(_, v, _)| value <= v);
            if lowest && !winners.iter().any(|(k, _)| k == key) {
                winners.push((*key, name.clone()));
                values.push((*key, *value));
            }
        }
        let mut cells_fitted: Vec<(usize, usize, usize)> = sloped.iter().map(|(key, _, _)| *key).collect();
        cells_fitted.sort_unstable();
        cells_fitted.dedup();
        for key in cells_fitted {
            let points: Vec<(f64, f64)> =
                sloped.iter().filter(|(k, _, _)| *k == key).map(|&(_, x, y)| (x, y)).collect();
            let n = points.len() as f64;
            let (mx, my) = (points.iter().map(|p| p.0).sum::<f64>() / n, points.iter().map(|p| p.1).sum::<f64>() / n);
            let sxx: f64 = points.iter().map(|p| (p.0 - mx).powi(2)).sum();
            if points.len() >= 2 && sxx > 0.0 {
                values.push((key, points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / sxx));
            }
        }
        if rows.is_empty() {
            return Err(Error::input(&path, "no rows match the gallery table's cells and filter"));
        }
        // Each part of a key as a reader names it: models by file and triangle count, method
        // specs by what tells them apart.
        let label = |parts: &[&str], keys: &[Vec<String>]| -> Vec<String> {
            let per_part: Vec<Vec<String>> = parts
                .iter()
                .enumerate()
                .map(|(p, column)| {
                    let names: Vec<String> = keys.iter().map(|k| k[p].clone()).collect();
                    match *column {
                        "method" => {
                            let mut distinct = names.clone();
                            distinct.sort();
                            distinct.dedup();
                            let short = display_names(&distinct);
                            names.iter().map(|n| short[distinct.binary_search(n).unwrap_or(0)].clone()).collect()
                        }
                        "model" => names
                            .iter()
                            .map(|m| {
                                let file = m.rsplit('/').next().unwrap_or(m);
                                let t = triangles
                                    .iter()
                                    .find(|(n, _)| n == m)
                                    .map(|(_, t)| super::data::thousands(&t.to_string()));
                                t.map_or(file.to_string(), |t| format!("{file} ({t})"))
                            })
                            .collect(),
                        _ => names,
                    }
                })
                .collect();
            (0..keys.len()).map(|i| per_part.iter().map(|p| p[i].as_str()).collect::<Vec<_>>().join(", ")).collect()
        };
        let (row_names, col_names) = if by_cell {
            // Cells are read in order, so their columns are too (a cell with no rows has none).
            let title = |key: &Vec<String>| {
                let (metric, conds) = &self.cells[key[1].parse::<usize>().unwrap_or(0)];
                let title = cell_title(metric, conds);
                if self.slope.is_some() { format!("slope of log {title} on log triangles") } else { title }
            };
            (label(&row_parts, &rows), cols.iter().map(title).collect())
        } else {
            (label(&row_parts, &rows), label(&col_parts, &cols))
        };
        let cell_count = if by_cell { 1 } else { self.cells.len() };
        // Every run at a cell (several only with `spread`): their mean, and their range.
        let runs = |r: usize, c: usize, k: usize| -> Vec<f64> {
            values.iter().filter(|(key, _)| *key == (r, c, k)).map(|(_, v)| *v).collect()
        };
        let raw = |r: usize, c: usize, k: usize| {
            let all = runs(r, c, k);
            (!all.is_empty()).then(|| all.iter().sum::<f64>() / all.len() as f64)
        };
        let range = |r: usize, c: usize, k: usize| {
            let all = runs(r, c, k);
            (all.len() > 1)
                .then(|| all.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v))))
        };
        let reference =
            match &self.relative_to {
                None => None,
                Some(name) => Some(cols.iter().position(|key| key.iter().any(|p| p == name)).ok_or_else(|| {
                    Error::input(&path, format!("relative_to = {name} is not a value of {}", self.cols))
                })?),
            };
        let value = |r: usize, c: usize, k: usize| match reference {
            None => raw(r, c, k),
            Some(reference) => Some(raw(r, reference, k)? / raw(r, c, k)?).filter(|v| v.is_finite()),
        };
        let contends = |key: &[String]| !key.iter().any(|part| part == "input");
        // Whether value `k` of cell (r, c) is the lowest of its row or column.
        let best = |r: usize, c: usize, k: usize| -> bool {
            let Some(v) = value(r, c, k) else { return false };
            let competitors: Vec<f64> = match self.best {
                Best::None => return false,
                Best::Row if contends(&cols[c]) => {
                    (0..cols.len()).filter(|&j| contends(&cols[j])).filter_map(|j| value(r, j, k)).collect()
                }
                Best::Col if contends(&rows[r]) => {
                    (0..rows.len()).filter(|&i| contends(&rows[i])).filter_map(|i| value(i, c, k)).collect()
                }
                _ => return false,
            };
            // Ratios to a reference are better higher; everything else lower.
            let better = |a: f64, b: f64| if reference.is_some() { a >= b } else { a <= b };
            competitors.len() > 1 && competitors.iter().all(|&o| better(v, o))
        };
        let digits = self.digits;
        let (suffix, scale) = match (self.relative_to.is_some(), self.percent) {
            (true, _) => ("×", 1.0),
            (false, true) => ("%", 100.0),
            (false, false) => ("", 1.0),
        };
        let mut out = String::new();
        let _ = writeln!(out, "| {} | {} |", row_parts.join(", "), col_names.join(" | "));
        let _ = writeln!(out, "|---{}|", "|---".repeat(cols.len()));
        for (r, name) in row_names.iter().enumerate() {
            let cells: Vec<String> = (0..cols.len())
                .map(|c| {
                    let parts: Vec<String> = (0..cell_count)
                        .map(|k| match value(r, c, k) {
                            None => "–".to_string(),
                            Some(v) => {
                                let text = format!("{}{suffix}", digits.write(v * scale));
                                let text = match winners.iter().find(|(key, _)| *key == (r, c, k)) {
                                    Some((_, name)) => format!("{name} {text}"),
                                    None => text,
                                };
                                let text = if best(r, c, k) { format!("**{text}**") } else { text };
                                match range(r, c, k).filter(|_| reference.is_none()) {
                                    Some((lo, hi)) => {
                                        format!("{text} ({}–{})", digits.write(lo * scale), digits.write(hi * scale))
                                    }
                                    None => text,
                                }
                            }
                        })
                        .collect();
                    parts.join(" / ")
                })
                .collect();
            let _ = writeln!(out, "| {name} | {} |", cells.join(" | "));
        }
        Ok(out)
    }
}

/// Whether a filter value `wanted` keeps a row whose `column` is `cell`: equal, or for a
/// method spec, the same method with at least the parameters `wanted` names at its values
/// (`nehab:clusters=64` keeps `nehab:clusters=64,views=162,…`).
fn matches(column: &str, wanted: &str, cell: &str) -> bool {
    if wanted == cell {
        return true;
    }
    let (Some((name, params)), Some((cell_name, cell_params))) = (wanted.split_once(':'), cell.split_once(':')) else {
        return false;
    };
    column == "method" && name == cell_name && params.split(',').all(|kv| cell_params.split(',').any(|c| c == kv))
}

/// A column heading for a cell value: the metric, then its conditions.
fn cell_title(metric: &str, conditions: &[(String, String)]) -> String {
    std::iter::once(metric.to_string())
        .chain(conditions.iter().map(|(c, v)| format!("{c}={v}")))
        .collect::<Vec<_>>()
        .join(" ")
}

/// A generated table's recipe: a table of numbers, or of targets met.
enum Generated {
    Numbers(Recipe),
    Verdicts(Verdicts),
}

/// `markdown` with every generated table rewritten from its CSV under `root` (the project root),
/// and the CSVs they came from. An unclosed table or a bad recipe is an error naming `file`.
pub fn refresh(markdown: &str, root: &Path, file: &Path) -> Result<(String, Vec<String>)> {
    let mut out = String::with_capacity(markdown.len());
    let mut sources = Vec::new();
    let mut rest = markdown;
    while let Some(at) = rest.find(OPEN) {
        let line = markdown.len() - rest.len() + at;
        let line = markdown[..line].lines().count() + 1;
        let head_end = rest[at..].find("-->").ok_or_else(|| {
            Error::input(file.display(), format!("line {line}: a generated table's comment is not closed"))
        })? + at;
        let text = &rest[at + OPEN.len()..head_end];
        let at_line = |e: String| Error::input(file.display(), format!("line {line}: {e}"));
        let recipe = if Verdicts::wanted(text) {
            Generated::Verdicts(Verdicts::parse(text).map_err(at_line)?)
        } else {
            Generated::Numbers(Recipe::parse(text).map_err(at_line)?)
        };
        let body_start = head_end + 3;
        let close = rest[body_start..]
            .find(CLOSE)
            .ok_or_else(|| Error::input(file.display(), format!("line {line}: a generated table has no `{CLOSE}`")))?
            + body_start;
        let (csv, table) = match recipe {
            Generated::Numbers(recipe) => (recipe.csv.clone(), recipe.table(root)?),
            Generated::Verdicts(verdicts) => (verdicts.csv.clone(), verdicts.table(root)?),
        };
        out.push_str(&rest[..body_start]);
        out.push('\n');
        out.push_str(&table);
        out.push_str(CLOSE);
        sources.push(csv);
        rest = &rest[close + CLOSE.len()..];
    }
    out.push_str(rest);
    Ok((out, sources))
}

#[cfg(test)]
mod tests {
    use super::*;

    const CSV: &str = "model,model_triangles,method,method_name,metric,cache_size,value
models/a.ply,100,input,input,acmr,16,2.0
models/a.ply,100,tipsify:cache=16,tipsify,acmr,16,0.7
models/a.ply,100,hoppe:cache=16,hoppe,acmr,16,0.6
models/a.ply,100,hoppe:cache=16,hoppe,acmr,32,0.55
models/b.ply,2000,input,input,acmr,16,0.5
models/b.ply,2000,tipsify:cache=16,tipsify,acmr,16,0.8
models/b.ply,2000,hoppe:cache=16,hoppe,acmr,16,0.9
";

    #[test]
    fn tables_are_written_from_the_csv_and_stale_ones_rewritten() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("results")).unwrap();
        std::fs::write(dir.path().join("results/x.csv"), CSV).unwrap();
        assert_eq!(Digits::Significant(3).write(0.000012345), "0.0000123");
        assert_eq!(Digits::Significant(3).write(1.2345), "1.23");
        assert_eq!(Digits::Significant(2).write(9.0), "9");
        let text = "intro\n<!-- generated from results/x.csv: rows=model cols=method_name cells=acmr@cache_size=16/acmr@cache_size=32 digits=2 best=row -->\n| stale |\n<!-- end generated -->\nafter\n";
        let (fresh, sources) = refresh(text, dir.path(), Path::new("README.md")).unwrap();
        assert_eq!(sources, ["results/x.csv"]);
        let want = "intro\n<!-- generated from results/x.csv: rows=model cols=method_name cells=acmr@cache_size=16/acmr@cache_size=32 digits=2 best=row -->\n\
| model | input | tipsify | hoppe |\n|---|---|---|---|\n\
| a.ply (100) | 2.00 / – | 0.70 / – | **0.60** / 0.55 |\n\
| b.ply (2,000) | 0.50 / – | **0.80** / – | 0.90 / – |\n<!-- end generated -->\nafter\n";
        assert_eq!(fresh, want);
        // Regenerating a fresh table changes nothing.
        assert_eq!(refresh(&fresh, dir.path(), Path::new("README.md")).unwrap().0, want);
    }

    #[test]
    fn runs_of_several_seeds_fold_into_their_mean_and_range() {
        let dir = tempfile::tempdir().unwrap();
        let csv = "model,model_triangles,method,method_name,metric,value
m,10,\"nehab:clusters=64,seed=0\",nehab,ovr_mean,1.10
m,10,\"nehab:clusters=64,seed=1\",nehab,ovr_mean,1.20
m,10,sander07,sander07,ovr_mean,1.12
";
        std::fs::write(dir.path().join("s.csv"), csv).unwrap();
        let text = "<!-- generated from s.csv: rows=model cols=method cells=ovr_mean digits=2 spread=seed -->\n<!-- end generated -->";
        let fresh = refresh(text, dir.path(), Path::new("G.md")).unwrap().0;
        assert!(fresh.contains("| m (10) | 1.15 (1.10–1.20) | 1.12 |"), "{fresh}");
    }

    #[test]
    fn argmin_names_the_lowest_row_of_each_cell() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("results")).unwrap();
        std::fs::write(dir.path().join("results/x.csv"), CSV).unwrap();
        let text = "<!-- generated from results/x.csv: rows=model cols=cache_size cells=acmr argmin=method_name digits=2 -->\n<!-- end generated -->";
        let fresh = refresh(text, dir.path(), Path::new("G.md")).unwrap().0;
        assert!(fresh.contains("| a.ply (100) | hoppe 0.60 | hoppe 0.55 |"), "{fresh}");
        assert!(fresh.contains("| b.ply (2,000) | input 0.50 | – |"), "{fresh}");
    }

    #[test]
    fn slopes_fit_log_value_against_log_triangles() {
        let dir = tempfile::tempdir().unwrap();
        let csv = "model,model_triangles,method,method_name,metric,value
a,1000,m,m,seconds,1.0
a,1000,n,n,seconds,1.0
b,4000,m,m,seconds,4.0
b,4000,n,n,seconds,2.0
c,16000,m,m,seconds,16.0
c,16000,n,n,seconds,4.0
d,100,m,m,seconds,50.0
";
        std::fs::write(dir.path().join("t.csv"), csv).unwrap();
        let text = "<!-- generated from t.csv: rows=method cols=cells cells=seconds slope=1000 digits=2 -->\n<!-- end generated -->";
        let fresh = refresh(text, dir.path(), Path::new("G.md")).unwrap().0;
        // Linear in the triangles from 1,000 up; the 100-triangle row is left out.
        assert!(fresh.contains("| m | 1.00 |") && fresh.contains("| n | 0.50 |"), "{fresh}");
    }

    #[test]
    fn bad_recipes_say_what_is_wrong() {
        let dir = tempfile::tempdir().unwrap();
        let bad = |text: &str| refresh(text, dir.path(), Path::new("G.md")).unwrap_err().to_string();
        assert!(bad("<!-- generated from r.csv: rows=model -->\n<!-- end generated -->").contains("required"));
        assert!(bad("<!-- generated from r.csv: rows=a cols=b cells=c shade=1 -->").contains("unknown option"));
        assert!(bad("<!-- generated from r.csv: rows=a cols=b cells=c -->\n| x |\n").contains("end generated"));
        assert!(bad("<!-- generated from r.csv: rows=a cols=b cells=c -->\n<!-- end generated -->").contains("r.csv"));
    }
}
