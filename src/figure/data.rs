//! Reading a results CSV and selecting what a figure draws: rows of one metric (and the spec's
//! filter), grouped into panels (facet values) and series, in order of first appearance, which
//! is the spec's order of models and methods.

use std::path::{Path, PathBuf};

use csv::StringRecord;

use super::spec::{Figure, FigureKind};
use crate::error::{Error, Result};
use crate::measure;
use crate::mesh::Source;

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
    /// Per point, the figure's `label` cell (empty without one, or where the row has none).
    pub labels: Vec<String>,
    /// Per point, the least and greatest value it is the mean of, where the figure's `spread`
    /// folded several runs (seeds) into it; empty otherwise.
    pub ranges: Vec<Option<(f64, f64)>>,
}

/// `METRIC[@COLUMN=VALUE…]`, as a scatter's x (`metric:acmr@cache=nvidia`), a gallery table's
/// cells and a verdict table's checks name a metric: the metric, and the columns its rows must
/// have where one model and method has several (one per cache model, say).
pub(super) fn metric_where(text: &str) -> std::result::Result<(String, Vec<(String, String)>), String> {
    let mut parts = text.split('@');
    let metric = parts.next().unwrap_or_default().to_string();
    let conditions = parts
        .map(|c| {
            c.split_once('=')
                .map(|(k, v)| (k.to_string(), v.to_string()))
                .ok_or_else(|| format!("`{text}`: the condition `{c}` is not COLUMN=VALUE"))
        })
        .collect::<std::result::Result<_, _>>()?;
    Ok((metric, conditions))
}

/// The value of `key` in the animated model `model` (a `model` cell of a results CSV), defaults
/// written out; see [`Source::key`].
pub fn source_key(model: &str, key: &str) -> Option<String> {
    Source::parse(model).ok()?.key(key)
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

    /// The CSV this table was read from.
    pub fn path(&self) -> &Path {
        &self.path
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

    /// Every row of `metric`: the cells of `columns`, and the value.
    pub fn rows(&self, metric: &str, columns: &[&str]) -> Result<Vec<(Vec<String>, f64)>> {
        let (metric_col, value_col) = (self.column("metric")?, self.column("value")?);
        let indices = columns.iter().map(|c| self.column(c)).collect::<Result<Vec<_>>>()?;
        self.records
            .iter()
            .filter(|r| &r[metric_col] == metric)
            .map(|r| {
                let value = r[value_col].parse().map_err(|_| {
                    Error::input(self.path.display(), format!("`{metric}` value `{}` is not a number", &r[value_col]))
                })?;
                Ok((indices.iter().map(|&i| r[i].to_string()).collect(), value))
            })
            .collect()
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

    /// Where a figure reads a column `name`: a CSV column; `param:NAME`, a parameter of the method
    /// (read from its canonical spec); `source:KEY`, a key of the animated model; or, for x and
    /// bar labels only, `metric:NAME`, the value of that metric for the same model and method (so
    /// one metric can be plotted against, or written on, another; `metric:NAME@COLUMN=VALUE` where
    /// it has several rows, `metric:acmr@cache=nvidia`); `A+B`, several of them joined
    /// (series or panels by, say, model and method at once).
    fn resolve(&self, name: &str) -> Result<Column> {
        if name.contains('+') {
            return Ok(Column::Joined(name.split('+').map(|part| self.resolve(part)).collect::<Result<_>>()?));
        }
        if let Some(param) = name.strip_prefix("param:") {
            return Ok(Column::Param(self.column("method")?, param.to_string()));
        }
        if let Some(key) = name.strip_prefix("source:") {
            return Ok(Column::Source(self.column("model")?, key.to_string()));
        }
        let Some(wanted) = name.strip_prefix("metric:") else {
            return Ok(Column::Plain(self.column(name)?));
        };
        let (metric, conditions) = metric_where(wanted).map_err(|e| Error::input(self.path.display(), e))?;
        let conditions =
            conditions.iter().map(|(c, v)| Ok((self.column(c)?, v.as_str()))).collect::<Result<Vec<_>>>()?;
        let (metric_col, value, model, method) =
            (self.column("metric")?, self.column("value")?, self.column("model")?, self.column("method")?);
        let mut values: Vec<((String, String), String)> = Vec::new();
        for record in
            self.records.iter().filter(|r| r[metric_col] == metric && conditions.iter().all(|&(c, v)| &r[c] == v))
        {
            let key = (record[model].to_string(), record[method].to_string());
            match values.iter().find(|(k, _)| *k == key) {
                Some((_, v)) if v != &record[value] => {
                    return Err(Error::input(
                        self.path.display(),
                        format!(
                            "has several `{metric}` values for model {} and method {}, so x = \"{name}\" is ambiguous (name the rows: metric:{metric}@COLUMN=VALUE)",
                            key.0, key.1
                        ),
                    ));
                }
                Some(_) => {}
                None => values.push((key, record[value].to_string())),
            }
        }
        if values.is_empty() {
            let at: String = conditions.iter().map(|&(c, v)| format!(" at {} = {v}", &self.header[c])).collect();
            return Err(Error::input(self.path.display(), format!("has no `{metric}` rows{at} for x = \"{name}\"")));
        }
        Ok(Column::Metric { model, method, values })
    }

    /// The panels `figure` draws. Errors name the CSV: no matching rows, a value that is not a
    /// number, or two rows at the same point of a line or bar chart (which would be ambiguous).
    pub fn select(&self, figure: &Figure) -> Result<Vec<Panel>> {
        let metric = self.column("metric")?;
        let value = self.column("value")?;
        let series = self.resolve(&figure.series)?;
        let facet = figure.facet.as_deref().map(|f| self.resolve(f)).transpose()?;
        let x = figure.x.as_deref().map(|x| self.resolve(x)).transpose()?;
        let label = figure.label.as_deref().map(|l| self.resolve(l)).transpose()?;
        let filter = figure
            .filter
            .iter()
            .map(|(column, wanted)| Ok((self.resolve(column)?, wanted.as_str())))
            .collect::<Result<Vec<_>>>()?;
        let triangles =
            (figure.facet.as_deref() == Some("model")).then(|| self.column("model_triangles").ok()).flatten();
        // A table's rows of models say what each model is, as the papers' tables do.
        let counts = (figure.kind == FigureKind::Table && figure.x.as_deref() == Some("model"))
            .then(|| Some((self.column("model_vertices").ok()?, self.column("model_triangles").ok()?)))
            .flatten();

        let mut panels: Vec<Panel> = Vec::new();
        for (i, record) in self.records.iter().enumerate() {
            if !figure.metrics.iter().any(|m| m == &record[metric])
                || filter.iter().any(|(c, wanted)| c.cell(record) != *wanted)
            {
                continue;
            }
            let line = i + 2;
            let y: f64 = record[value].parse().map_err(|_| {
                Error::input(self.path.display(), format!("line {line}: value `{}` is not a number", &record[value]))
            })?;
            let mut x = x.as_ref().map_or(String::new(), |c| c.cell(record));
            if let Some((v, t)) = counts {
                x = format!("{x} ({} vertices, {} triangles)", thousands(&record[v]), thousands(&record[t]));
            }
            if x.is_empty() && figure.x.as_deref().is_some_and(|c| c.contains(':')) {
                continue; // a method without that parameter, a static model, or not measured by the x metric
            }
            let title = match (&facet, triangles) {
                (None, _) => String::new(),
                (Some(f), None) => f.label(record),
                (Some(f), Some(t)) => format!("{} ({} triangles)", f.label(record), thousands(&record[t])),
            };
            let panel = match panels.iter().position(|p| p.title == title) {
                Some(p) => &mut panels[p],
                None => {
                    panels.push(Panel { title, series: Vec::new() });
                    panels.last_mut().expect("just pushed")
                }
            };
            let mut name = series.label(record);
            if let Some(p) = &figure.spread {
                // Runs that differ only in the spread parameter are one series (or category).
                if figure.series == "method" {
                    name = without_parameter(&name, p);
                }
                if figure.x.as_deref() == Some("method") {
                    x = without_parameter(&x, p);
                }
            }
            let series = match panel.series.iter().position(|s| s.name == name) {
                Some(s) => &mut panel.series[s],
                None => {
                    panel.series.push(Series {
                        name: name.clone(),
                        points: Vec::new(),
                        labels: Vec::new(),
                        ranges: Vec::new(),
                    });
                    panel.series.last_mut().expect("just pushed")
                }
            };
            if matches!(figure.kind, FigureKind::Line | FigureKind::Bar | FigureKind::Table)
                && figure.spread.is_none()
                && series.points.iter().any(|(px, _)| *px == x)
            {
                return Err(Error::input(
                    self.path.display(),
                    format!(
                        "line {line}: a second `{}` row for series `{name}` at x = `{x}`{}; narrow the rows with figure.filter or split them with figure.series / figure.facet",
                        &record[metric],
                        if panel.title.is_empty() { String::new() } else { format!(" in panel `{}`", panel.title) },
                    ),
                ));
            }
            series.points.push((x, y));
            series.labels.push(label.as_ref().map_or(String::new(), |l| l.cell(record)));
        }
        if figure.spread.is_some() {
            for series in panels.iter_mut().flat_map(|p| &mut p.series) {
                fold_spread(series);
            }
        }
        shorten_methods(figure, &mut panels);
        if panels.is_empty() {
            let mut metrics: Vec<&str> = self.records.iter().map(|r| &r[metric]).collect();
            metrics.sort_unstable();
            metrics.dedup();
            let filter = if figure.filter.is_empty() { String::new() } else { " that pass figure.filter".to_string() };
            return Err(Error::input(
                self.path.display(),
                format!(
                    "has no `{}` rows{filter} (metrics present: {})",
                    figure.metrics.join("`, `"),
                    metrics.join(", ")
                ),
            ));
        }
        Ok(panels)
    }
}

/// A column as [`Table::resolve`] finds it.
enum Column {
    Plain(usize),
    /// The method column and the parameter's name.
    Param(usize, String),
    /// The model column and the animation key.
    Source(usize, String),
    /// Another metric's value per (model, method): the model and method columns and the values.
    Metric {
        model: usize,
        method: usize,
        values: Vec<((String, String), String)>,
    },
    /// Several columns, read together.
    Joined(Vec<Column>),
}

impl Column {
    fn cell(&self, record: &StringRecord) -> String {
        match self {
            Column::Plain(i) => record[*i].to_string(),
            Column::Param(method, name) => parameter(&record[*method], name).unwrap_or_default().to_string(),
            Column::Source(model, key) => source_key(&record[*model], key).unwrap_or_default(),
            Column::Metric { model, method, values } => values
                .iter()
                .find(|((m, s), _)| m == &record[*model] && s == &record[*method])
                .map_or(String::new(), |(_, v)| v.clone()),
            Column::Joined(parts) => parts.iter().map(|c| c.cell(record)).collect::<Vec<_>>().join(" "),
        }
    }

    /// The cell as a legend or panel title shows it: metric names become their labels, and an
    /// animation key is written `KEY=VALUE` (a bare `1` says nothing about what it counts).
    fn label(&self, record: &StringRecord) -> String {
        let cell = self.cell(record);
        match (self, measure::names().find(|m| m.name == cell)) {
            (Column::Plain(_), Some(m)) => m.label.to_string(),
            (Column::Source(_, key), _) if !cell.is_empty() => format!("{key}={cell}"),
            // Among other columns a bare parameter value says nothing of what it sets, and a part
            // that is empty (a method without the parameter) is left out.
            (Column::Joined(parts), _) => parts
                .iter()
                .filter_map(|c| match c {
                    Column::Param(_, name) => {
                        Some(c.cell(record)).filter(|v| !v.is_empty()).map(|v| format!("{name}={v}"))
                    }
                    _ => Some(c.label(record)).filter(|v| !v.is_empty()),
                })
                .collect::<Vec<_>>()
                .join(", "),
            _ => cell,
        }
    }
}

/// `spec` (`method:k=v,…`) without parameter `name`.
pub(crate) fn without_parameter(spec: &str, name: &str) -> String {
    let Some((method, params)) = spec.split_once(':') else { return spec.to_string() };
    let kept: Vec<&str> = params.split(',').filter(|kv| kv.split('=').next() != Some(name)).collect();
    if kept.is_empty() { method.to_string() } else { format!("{method}:{}", kept.join(",")) }
}

/// The points of `series` that share an x folded into one: their mean, with the least and
/// greatest as its range (a single point has none).
fn fold_spread(series: &mut Series) {
    let mut xs: Vec<String> = Vec::new();
    for (x, _) in &series.points {
        if !xs.contains(x) {
            xs.push(x.clone());
        }
    }
    let (mut points, mut labels, mut ranges) = (Vec::new(), Vec::new(), Vec::new());
    for x in xs {
        let at: Vec<usize> = (0..series.points.len()).filter(|&i| series.points[i].0 == x).collect();
        let values: Vec<f64> = at.iter().map(|&i| series.points[i].1).collect();
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        let (lo, hi) = values.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
        labels.push(series.labels[at[0]].clone());
        ranges.push((values.len() > 1).then_some((lo, hi)));
        points.push((x, mean));
    }
    (series.points, series.labels, series.ranges) = (points, labels, ranges);
}

/// Writes the method specs a figure shows (as series, x categories or panel titles) as their
/// [`display_names`], each set named together so two variants of one method stay apart.
fn shorten_methods(figure: &Figure, panels: &mut [Panel]) {
    fn rename(names: &mut [&mut String]) {
        let mut specs: Vec<String> = names.iter().map(|n| n.to_string()).collect();
        specs.sort();
        specs.dedup();
        let short = display_names(&specs);
        for name in names {
            if let Ok(i) = specs.binary_search(name) {
                **name = short[i].clone();
            }
        }
    }
    if figure.series == "method" {
        rename(&mut panels.iter_mut().flat_map(|p| p.series.iter_mut().map(|s| &mut s.name)).collect::<Vec<_>>());
    }
    if figure.x.as_deref() == Some("method") {
        let mut xs: Vec<&mut String> = panels
            .iter_mut()
            .flat_map(|p| p.series.iter_mut().flat_map(|s| s.points.iter_mut().map(|(x, _)| x)))
            .collect();
        rename(&mut xs);
    }
    if figure.facet.as_deref() == Some("method") {
        rename(&mut panels.iter_mut().map(|p| &mut p.title).collect::<Vec<_>>());
    }
}

/// How a figure names canonical method specs (`tipsify:cache=16,lambda=...`): the method's
/// name, then only the parameters whose values differ between the specs of that method in
/// `specs` (`tipsify cache=8`, `tipsify cache=16`). A method that appears once is its bare
/// name. The full spec stays in the CSV; a legend or tick label shows what tells series apart.
pub fn display_names(specs: &[String]) -> Vec<String> {
    let split = |spec: &str| -> (String, Vec<(String, String)>) {
        let (name, params) = spec.split_once(':').unwrap_or((spec, ""));
        let params = params
            .split(',')
            .filter(|kv| !kv.is_empty())
            .map(|kv| {
                let (k, v) = kv.split_once('=').unwrap_or((kv, ""));
                (k.to_string(), v.to_string())
            })
            .collect();
        (name.to_string(), params)
    };
    let parsed: Vec<_> = specs.iter().map(|s| split(s)).collect();
    parsed
        .iter()
        .map(|(name, params)| {
            let same_method: Vec<&Vec<(String, String)>> =
                parsed.iter().filter(|(n, _)| n == name).map(|(_, p)| p).collect();
            let differs = |key: &str, value: &str| {
                same_method.iter().any(|other| other.iter().find(|(k, _)| k == key).is_none_or(|(_, v)| v != value))
            };
            let shown: Vec<String> =
                params.iter().filter(|(k, v)| differs(k, v)).map(|(k, v)| format!("{k}={v}")).collect();
            if shown.is_empty() { name.clone() } else { format!("{name} {}", shown.join(" ")) }
        })
        .collect()
}

/// The value of parameter `name` in a canonical method spec `method:k=v,k=v`.
pub fn parameter<'a>(spec: &'a str, name: &str) -> Option<&'a str> {
    let (_, params) = spec.split_once(':')?;
    params.split(',').find_map(|kv| kv.split_once('=').filter(|(k, _)| *k == name).map(|(_, v)| v))
}

/// `47794` → `47,794`.
pub(crate) fn thousands(digits: &str) -> String {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_of_several_seeds_fold_into_a_mean_and_its_range() {
        assert_eq!(without_parameter("nehab:clusters=64,seed=3", "seed"), "nehab:clusters=64");
        assert_eq!(without_parameter("random:seed=3", "seed"), "random");
        let mut series = Series {
            name: "nehab".into(),
            points: vec![("a".into(), 1.0), ("b".into(), 5.0), ("a".into(), 3.0)],
            labels: vec![String::new(); 3],
            ranges: Vec::new(),
        };
        fold_spread(&mut series);
        assert_eq!(series.points, [("a".to_string(), 2.0), ("b".to_string(), 5.0)]);
        assert_eq!(series.ranges, [Some((1.0, 3.0)), None]);
    }

    #[test]
    fn method_specs_are_shown_by_what_tells_them_apart() {
        let specs: Vec<String> =
            ["random:seed=0", "tipsify:cache=8,lambda=1", "tipsify:cache=16,lambda=1", "hoppe:cache=16"]
                .map(String::from)
                .to_vec();
        assert_eq!(display_names(&specs), ["random", "tipsify cache=8", "tipsify cache=16", "hoppe"]);
        assert_eq!(display_names(&["nehab".to_string()]), ["nehab"]);
    }

    /// A joined legend names a parameter with its value, and leaves out a method without it.
    #[test]
    fn joined_labels_name_parameters_and_skip_empty_parts() {
        let series = Column::Joined(vec![Column::Plain(0), Column::Param(1, "cache".into())]);
        let label = |name: &str, spec: &str| series.label(&StringRecord::from(vec![name, spec]));
        assert_eq!(label("cheap-cuts", "cheap-cuts:budget=0.02,cache=128"), "cheap-cuts, cache=128");
        assert_eq!(label("meshopt-overdraw", "meshopt-overdraw:threshold=1.05"), "meshopt-overdraw");
    }

    #[test]
    fn source_keys_read_the_animation_with_defaults() {
        let model = "animated/Soldier.glb#clip=Run,subdiv=2";
        assert_eq!(source_key(model, "clip").as_deref(), Some("Run"));
        assert_eq!(source_key(model, "subdiv").as_deref(), Some("2"));
        assert_eq!(source_key(model, "frames"), None);
        assert_eq!(source_key("animated/Soldier.glb#frames=10", "clip").as_deref(), Some("all"));
        assert_eq!(source_key("animated/Soldier.glb#frames=10", "subdiv").as_deref(), Some("0"));
        assert_eq!(source_key("models/bunny.ply", "clip"), None);
    }
}
