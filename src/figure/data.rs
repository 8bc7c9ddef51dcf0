//! Reading a results CSV and selecting what a figure draws: rows of one metric (and the spec's
//! filter), grouped into panels (facet values) and series, in order of first appearance, which
//! is the spec's order of models and methods.

use std::path::{Path, PathBuf};

use csv::StringRecord;

use crate::error::{Error, Result};
use crate::experiment::spec::{Figure, FigureKind};

/// A results CSV in memory: its header and its records as text.
pub struct Table {
    path: PathBuf,
    header: StringRecord,
    records: Vec<StringRecord>,
}

/// One small chart: the rows of one facet value.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    pub title: String,
    pub series: Vec<Series>,
}

/// The points of one series value: `(x as written in the CSV, value)`; `x` is empty for
/// distributions.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    pub name: String,
    pub points: Vec<(String, f64)>,
}

impl Table {
    /// Reads `path`; a missing file says how to produce it.
    pub fn read(path: &Path) -> Result<Table> {
        let mut reader = csv::Reader::from_path(path).map_err(|e| {
            Error::input(
                path.display(),
                format!("cannot read results ({e}); run the experiment first (`triorder run SPEC`)"),
            )
        })?;
        let header = reader.headers().map_err(|e| Error::input(path.display(), e))?.clone();
        let records = reader
            .records()
            .collect::<std::result::Result<Vec<_>, _>>()
            .map_err(|e| Error::input(path.display(), e))?;
        Ok(Table { path: path.to_path_buf(), header, records })
    }

    fn column(&self, name: &str) -> Result<usize> {
        self.header.iter().position(|h| h == name).ok_or_else(|| {
            Error::input(
                self.path.display(),
                format!("has no column `{name}` (the figure needs it; rerun the experiment)"),
            )
        })
    }

    /// The value of the one `metric` row whose columns equal `matches`; no such row, or several,
    /// is an error naming the CSV (the results are stale or the spec changed).
    pub fn value(&self, metric: &str, matches: &[(&str, &str)]) -> Result<f64> {
        let metric_col = self.column("metric")?;
        let value_col = self.column("value")?;
        let columns = matches.iter().map(|(c, v)| Ok((self.column(c)?, *v))).collect::<Result<Vec<_>>>()?;
        let mut found = self
            .records
            .iter()
            .filter(|r| &r[metric_col] == metric && columns.iter().all(|&(c, v)| &r[c] == v))
            .map(|r| &r[value_col]);
        let describe = || matches.iter().map(|(c, v)| format!("{c} = {v}")).collect::<Vec<_>>().join(", ");
        match (found.next(), found.next()) {
            (Some(text), None) => text.parse().map_err(|_| {
                Error::input(self.path.display(), format!("`{metric}` at {}: `{text}` is not a number", describe()))
            }),
            (None, _) => Err(Error::input(
                self.path.display(),
                format!("has no `{metric}` row at {}; rerun the experiment", describe()),
            )),
            (Some(_), Some(_)) => {
                Err(Error::input(self.path.display(), format!("has several `{metric}` rows at {}", describe())))
            }
        }
    }

    /// The distinct non-empty combinations of `columns` (missing columns: none), in order.
    pub fn distinct(&self, columns: &[&str]) -> Vec<Vec<String>> {
        let Ok(indices) = columns.iter().map(|c| self.column(c)).collect::<Result<Vec<_>>>() else {
            return Vec::new();
        };
        let mut seen: Vec<Vec<String>> = Vec::new();
        for record in &self.records {
            let values: Vec<String> = indices.iter().map(|&i| record[i].to_string()).collect();
            if values.iter().all(|v| !v.is_empty()) && !seen.contains(&values) {
                seen.push(values);
            }
        }
        seen
    }

    /// The panels `figure` draws. Errors name the CSV: no matching rows, a value that is not a
    /// number, or two rows at the same point of a line or bar chart (which would be ambiguous).
    pub fn select(&self, figure: &Figure) -> Result<Vec<Panel>> {
        let metric = self.column("metric")?;
        let value = self.column("value")?;
        let series = self.column(&figure.series)?;
        let facet = figure.facet.as_deref().map(|f| self.column(f)).transpose()?;
        let x = figure.x.as_deref().map(|x| self.column(x)).transpose()?;
        let filter = figure
            .filter
            .iter()
            .map(|(column, wanted)| Ok((self.column(column)?, wanted.as_str())))
            .collect::<Result<Vec<_>>>()?;
        let triangles =
            (figure.facet.as_deref() == Some("model")).then(|| self.column("model_triangles").ok()).flatten();

        let mut panels: Vec<Panel> = Vec::new();
        for (i, record) in self.records.iter().enumerate() {
            if &record[metric] != figure.metric.as_str() || filter.iter().any(|&(c, wanted)| &record[c] != wanted) {
                continue;
            }
            let line = i + 2;
            let y: f64 = record[value].parse().map_err(|_| {
                Error::input(self.path.display(), format!("line {line}: value `{}` is not a number", &record[value]))
            })?;
            let title = match (facet, triangles) {
                (None, _) => String::new(),
                (Some(f), None) => record[f].to_string(),
                (Some(f), Some(t)) => format!("{} ({} triangles)", &record[f], thousands(&record[t])),
            };
            let panel = match panels.iter().position(|p| p.title == title) {
                Some(p) => &mut panels[p],
                None => {
                    panels.push(Panel { title, series: Vec::new() });
                    panels.last_mut().expect("just pushed")
                }
            };
            let name = &record[series];
            let series = match panel.series.iter().position(|s| s.name == name) {
                Some(s) => &mut panel.series[s],
                None => {
                    panel.series.push(Series { name: name.to_string(), points: Vec::new() });
                    panel.series.last_mut().expect("just pushed")
                }
            };
            let x = x.map_or(String::new(), |c| record[c].to_string());
            if matches!(figure.kind, FigureKind::Line | FigureKind::Bar | FigureKind::Table)
                && series.points.iter().any(|(px, _)| *px == x)
            {
                return Err(Error::input(
                    self.path.display(),
                    format!(
                        "line {line}: a second `{}` row for series `{name}` at x = `{x}`{}; narrow the rows with figure.filter or split them with figure.series / figure.facet",
                        figure.metric,
                        if panel.title.is_empty() { String::new() } else { format!(" in panel `{}`", panel.title) },
                    ),
                ));
            }
            series.points.push((x, y));
        }
        if panels.is_empty() {
            let mut metrics: Vec<&str> = self.records.iter().map(|r| &r[metric]).collect();
            metrics.dedup();
            metrics.sort_unstable();
            metrics.dedup();
            let filter = if figure.filter.is_empty() { String::new() } else { " that pass figure.filter".to_string() };
            return Err(Error::input(
                self.path.display(),
                format!("has no `{}` rows{filter} (metrics present: {})", figure.metric, metrics.join(", ")),
            ));
        }
        Ok(panels)
    }
}

/// `47794` → `47,794`.
fn thousands(digits: &str) -> String {
    if !digits.bytes().all(|b| b.is_ascii_digit()) {
        return digits.to_string();
    }
    let mut out = String::new();
    for (i, c) in digits.chars().enumerate() {
        if i > 0 && (digits.len() - i).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}
