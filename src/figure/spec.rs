//! The `[figure]` table of an experiment spec: what kind of figure, which metric against which
//! column, series and facets. Checked when the spec is loaded against what its run will write
//! ([`Writes`]), so a figure that could not be drawn fails before any work.

use serde::Deserialize;

use super::data;
use crate::measure;
use crate::mesh::source;
use crate::results::COLUMNS;

/// What a spec's run writes, as far as its figure cares.
pub struct Writes<'a> {
    /// Every metric name its rows can have.
    pub metrics: Vec<&'static str>,
    /// Its method specs, canonical.
    pub methods: &'a [String],
    /// Whether some model is an animation (so `source:KEY` columns exist).
    pub animated: bool,
    /// What the rows vary along beside the metric (models, methods, caches, levels, updates),
    /// each with the columns that tell its values apart (a name ending in `:` stands for every
    /// column it begins). A line, bar or table figure must use one of them for each, or rows
    /// would collide at one point.
    pub varies: Vec<Varies>,
}

/// One thing a run's rows vary along: see [`Writes::varies`].
pub struct Varies {
    /// What varies, as a user reads it: "3 models".
    pub what: String,
    pub columns: &'static [&'static str],
    /// Whether it splits the rows of a metric (the ordering's time is one for all levels).
    pub splits: fn(&str) -> bool,
}

impl Varies {
    fn told_apart_by(&self, column: &str) -> bool {
        self.columns.iter().any(|c| *c == column || (c.ends_with(':') && column.starts_with(c)))
    }
}

/// How the figure is drawn from the CSV.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    pub kind: FigureKind,
    /// The first of [`Figure::metrics`]: the one that names the y axis.
    pub metric: String,
    /// Every metric drawn; with more than one, `series` or `facet` is `metric`.
    pub metrics: Vec<String>,
    pub x: Option<String>,
    pub series: String,
    pub facet: Option<String>,
    /// `(column, value)` pairs a row must match to be drawn.
    pub filter: Vec<(String, String)>,
    pub x_label: Option<String>,
    pub y_label: Option<String>,
    pub x_log: bool,
    pub y_log: bool,
    pub y_range: Option<(f64, f64)>,
    /// Bars: `metric:NAME`, the metric written above each bar instead of its value (e.g. the
    /// iterations an ordering took above its time, Han & Sander 2017 Fig. 5).
    pub label: Option<String>,
    /// Drawing kinds: the direction the model is seen from (centre → eye), default +z.
    pub view: [f32; 3],
    /// Drawing kinds: the world direction drawn upwards (default +y, or +z when seen along y).
    pub up: Option<[f32; 3]>,
    /// Kind `ratio`: the method names whose values are divided, numerator first.
    pub ratio: Option<(String, String)>,
    /// Line and scatter charts of methods: the method names drawn on top with larger, outlined
    /// markers (a new method and its peers among every ordering, issue 19).
    pub highlight: Vec<String>,
    /// A method parameter (`seed`) whose runs are folded into one point: their mean, drawn with
    /// whiskers from the least to the greatest (bars, lines and scatters).
    pub spread: Option<String>,
    /// Tables of methods: each cell shows this method's value ÷ the cell's (how many times lower
    /// than the reference, the form of Nehab et al.'s "variance drops 50×"); higher is better.
    pub relative_to: Option<String>,
    /// Each panel's axes fitted to its own data (`axes = "own"`) rather than shared: for facets
    /// whose values lie far apart, as welded meshes' ACMR near 0.65 beside unwelded ones' 3,
    /// where shared axes squeeze the differences a panel is about into a sliver.
    pub own_axes: bool,
}

/// The chart kinds `triorder plot` draws.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FigureKind {
    /// y against a numeric x, one line per series (e.g. ACMR against cache size).
    Line,
    /// y against a numeric x, one point per row (e.g. ACMR against ordering time).
    Scatter,
    /// Grouped bars: categories on x, one bar per series in each group.
    Bar,
    /// Every value of each series sorted ascending (a quantile curve) with its mean dashed, and
    /// mean, max and variance written in the chart: for per-view overdraw.
    Distribution,
    /// A table of numbers: one row per x value, one column per series (the papers' tables).
    Table,
    /// Each (model, method) drawn as its triangles coloured by position in the sequence, with the
    /// path through their centroids (Bogomjakov & Gotsman 2002, Figs. 2 and 4). Needs the
    /// orders, which runs of drawing specs save next to the CSV.
    Sequence,
    /// Each (model, method, cache) drawn with every triangle corner coloured by whether its vertex
    /// hit, was loaded the first time, or reloaded (Bogomjakov & Gotsman 2002, Figs. 10 and 11).
    Corners,
    /// Each (model, method) drawn with its clusters in distinct colours (Nehab et al. 2006, Fig. 3).
    Clusters,
    /// Each (model, method) drawn with its clusters shaded black (drawn first) to white (drawn
    /// last) (Nehab et al. 2006, Fig. 6).
    #[serde(rename = "cluster-order")]
    ClusterOrder,
    /// Each (model, method) drawn as a heat map of the fragments shaded at each pixel from the
    /// figure's view: darker, more overdraw (Nehab et al. 2006, Fig. 1).
    Overdraw,
    /// Each (model, method) drawn with where its translucent blend goes wrong from the figure's
    /// view: grey where blending in draw order gives the exact colour, red where it is visibly
    /// wrong, darker the larger the error (seed 003's "per-triangle" speckle against consistent
    /// regions; `measure::translucency`).
    Translucency,
    /// Which simulated cache model predicts the vertex-shader invocations counted on the GPU
    /// (caches must list simulated models and `gpu`): every model ranked by its error, and the
    /// winner's simulated against counted ACMR (issue 6).
    #[serde(rename = "hardware-fit")]
    HardwareFit,
    /// Per view, one method's value over another's (`ratio = [A, B]`) of the x metric against
    /// that of the y metric, with Pearson's r per series (Nehab et al. 2006, Fig. 10: overdraw
    /// ratio against render-time ratio, nehab over hoppe).
    Ratio,
}

impl FigureKind {
    /// Kinds whose layout is their own: they read `acmr` rows and take no x or log axes.
    pub fn fixed_layout(self) -> bool {
        self.draws_meshes() || self == FigureKind::HardwareFit
    }

    /// Kinds that draw the meshes themselves and so need the orders saved by the run.
    pub fn draws_meshes(self) -> bool {
        matches!(
            self,
            FigureKind::Sequence
                | FigureKind::Corners
                | FigureKind::Clusters
                | FigureKind::ClusterOrder
                | FigureKind::Overdraw
                | FigureKind::Translucency
        )
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawFigure {
    kind: FigureKind,
    metric: OneOrMany,
    x: Option<String>,
    series: Option<String>,
    facet: Option<String>,
    #[serde(default)]
    filter: toml::Table,
    x_label: Option<String>,
    y_label: Option<String>,
    #[serde(default)]
    x_log: bool,
    #[serde(default)]
    y_log: bool,
    y_range: Option<[f64; 2]>,
    label: Option<String>,
    view: Option<[f32; 3]>,
    up: Option<[f32; 3]>,
    ratio: Option<[String; 2]>,
    #[serde(default)]
    highlight: Vec<String>,
    relative_to: Option<String>,
    spread: Option<String>,
    axes: Option<String>,
}

/// `metric = "acmr"` or `metric = ["ovr_mean", "acmr"]`.
#[derive(Deserialize)]
#[serde(untagged)]
enum OneOrMany {
    One(String),
    Many(Vec<String>),
}

impl RawFigure {
    /// Checks the figure against what the run will write.
    pub fn check(self, writes: &Writes) -> std::result::Result<Figure, String> {
        let methods = writes.methods;
        let metrics = match self.metric {
            OneOrMany::One(m) => vec![m],
            OneOrMany::Many(ms) if ms.is_empty() => return Err("figure.metric is an empty list".into()),
            OneOrMany::Many(ms) => ms,
        };
        for name in &metrics {
            let metric = measure::names().find(|m| m.name == name).ok_or_else(|| {
                let mut known: Vec<_> = measure::names().map(|m| m.name).collect();
                known.dedup();
                format!("figure.metric `{name}` is not a metric the CSV has (metrics: {})", known.join(", "))
            })?;
            if !writes.metrics.contains(&metric.name) {
                return Err(format!("figure.metric = \"{}\" needs {}", metric.name, metric.needs));
            }
        }
        let metric = metrics[0].clone();
        if metrics.len() > 1 && self.series.as_deref() != Some("metric") && self.facet.as_deref() != Some("metric") {
            return Err("figure.metric lists several metrics: set figure.series or figure.facet to \"metric\"".into());
        }
        // A CSV column; `param:NAME`, a parameter of the spec's methods; `source:KEY`, a key of its
        // animated models; or, where `metric_ok`, `metric:NAME`, another metric joined on model
        // and method (`metric:NAME@COLUMN=VALUE` where that has several rows).
        let column = |key: &str, name: &str, metric_ok: bool| {
            if let Some(source_key) = name.strip_prefix("source:") {
                if !source::KEYS.contains(&source_key) {
                    return Err(format!(
                        "{key} `{name}`: `{source_key}` is not a key of an animated model (keys: {})",
                        source::KEYS.join(", ")
                    ));
                }
                if !writes.animated {
                    return Err(format!("{key} `{name}`: no model of this spec is an animation (PATH#…)"));
                }
                return Ok(());
            }
            if let Some(param) = name.strip_prefix("param:") {
                if methods.iter().any(|m| data::parameter(m, param).is_some()) {
                    return Ok(());
                }
                return Err(format!("{key} `{name}`: no method of this spec has a parameter `{param}`"));
            }
            if let Some(other) = name.strip_prefix("metric:").filter(|_| metric_ok) {
                let (other, conditions) = data::metric_where(other).map_err(|e| format!("{key}: {e}"))?;
                if let Some((column, _)) = conditions.iter().find(|(c, _)| !COLUMNS.contains(&c.as_str())) {
                    return Err(format!("{key} `{name}`: `{column}` is not a CSV column"));
                }
                if measure::names().any(|m| m.name == other) {
                    return Ok(());
                }
                return Err(format!("{key} `{name}`: `{other}` is not a metric"));
            }
            if COLUMNS.contains(&name) {
                Ok(())
            } else {
                Err(format!(
                    "{key} `{name}` is not a CSV column (columns: {}; or param:NAME, source:KEY{})",
                    COLUMNS.join(", "),
                    if metric_ok { ", metric:NAME" } else { "" }
                ))
            }
        };
        let view = match (self.kind.draws_meshes(), self.view) {
            (false, Some(_)) => return Err("figure.view is only for the kinds that draw meshes".into()),
            (true, Some(v)) if !(v.iter().all(|c| c.is_finite()) && v.iter().any(|&c| c != 0.0)) => {
                return Err(format!("figure.view = {v:?} must be a finite, non-zero direction"));
            }
            (_, v) => v.unwrap_or([0.0, 0.0, 1.0]),
        };
        let up = match (self.kind.draws_meshes(), self.up) {
            (false, Some(_)) => return Err("figure.up is only for the kinds that draw meshes".into()),
            (true, Some(u)) => {
                let (u3, v3) = (glam::Vec3::from(u), glam::Vec3::from(view));
                if !(u.iter().all(|c| c.is_finite()) && u3.cross(v3).length() > 1e-3 * u3.length() * v3.length()) {
                    return Err(format!("figure.up = {u:?} must be a finite direction not along figure.view"));
                }
                Some(u)
            }
            (_, None) => None,
        };
        if self.kind.fixed_layout() && metrics != ["acmr"] {
            return Err(format!(
                "figure.metric = {metrics:?}: kind = \"{}\" reads ACMR, so metric must be \"acmr\"",
                kind_name(self.kind)
            ));
        }
        match (self.kind, &self.x) {
            (k, Some(_)) if k.fixed_layout() => {
                return Err(format!("figure.x is not used by kind = \"{}\": remove it", kind_name(k)));
            }
            (k, None) if k.fixed_layout() => {}
            (FigureKind::Distribution, Some(_)) => {
                return Err(
                    "figure.x is not used by kind = \"distribution\" (it sorts the values itself): remove it".into()
                );
            }
            (FigureKind::Distribution, None) => {}
            (_, None) => return Err(format!("figure.x is required for kind = \"{}\"", kind_name(self.kind))),
            (k, Some(x)) => column("figure.x", x, matches!(k, FigureKind::Scatter | FigureKind::Ratio))?,
        }
        if (self.x_log || self.y_log) && (self.kind == FigureKind::Table || self.kind.fixed_layout()) {
            return Err(format!("figure.x_log / y_log: kind = \"{}\" has no axes", kind_name(self.kind)));
        }
        if self.x_log && matches!(self.kind, FigureKind::Bar | FigureKind::Distribution) {
            return Err(format!("figure.x_log: kind = \"{}\" has no numeric x axis", kind_name(self.kind)));
        }
        // Series and panels may join columns: `model+method`.
        let joined = |key: &str, name: &str| name.split('+').try_for_each(|part| column(key, part, false));
        let series = self.series.unwrap_or_else(|| "method".into());
        joined("figure.series", &series)?;
        if let Some(facet) = &self.facet {
            joined("figure.facet", facet)?;
        }
        if matches!(self.kind, FigureKind::Line | FigureKind::Bar | FigureKind::Table) {
            let mut used: Vec<&str> = series.split('+').chain(self.x.as_deref()).collect();
            used.extend(self.facet.as_deref().map(|f| f.split('+')).into_iter().flatten());
            used.extend(self.filter.keys().map(String::as_str));
            let splits = |v: &Varies| metrics.iter().any(|m| (v.splits)(m));
            if let Some(v) = writes.varies.iter().find(|v| splits(v) && !used.iter().any(|c| v.told_apart_by(c))) {
                return Err(format!(
                    "the run measures {}, but figure.x, series and facet do not tell them apart (nor does \
                     figure.filter pick one), so their rows would fall on the same points: use one of {} there",
                    v.what,
                    v.columns.join(", ")
                ));
            }
        }
        let mut filter = Vec::new();
        for (key, value) in self.filter {
            column("figure.filter key", &key, false)?;
            let value = match value {
                toml::Value::String(s) => s,
                toml::Value::Integer(i) => i.to_string(),
                toml::Value::Boolean(b) => b.to_string(),
                other => return Err(format!("figure.filter.{key} = {other}: expected a string, integer or boolean")),
            };
            filter.push((key, value));
        }
        if let Some(label) = &self.label {
            if self.kind != FigureKind::Bar {
                return Err(format!("figure.label is for kind = \"bar\", not \"{}\"", kind_name(self.kind)));
            }
            if !label.starts_with("metric:") {
                return Err(format!("figure.label `{label}`: expected metric:NAME"));
            }
            column("figure.label", label, true)?;
        }
        let ratio = match (self.kind, self.ratio) {
            (FigureKind::Ratio, None) => {
                return Err("figure.ratio = [A, B] (method names) is required for kind = \"ratio\"".into());
            }
            (FigureKind::Ratio, Some([a, b])) => {
                let names: Vec<&str> = methods.iter().map(|m| m.split(':').next().unwrap_or(m)).collect();
                if let Some(missing) = [&a, &b].into_iter().find(|n| !names.contains(&n.as_str())) {
                    return Err(format!("figure.ratio names `{missing}`, which is not a method of this spec"));
                }
                if !self.x.as_deref().is_some_and(|x| x.starts_with("metric:")) || metrics.len() != 1 {
                    return Err("kind = \"ratio\" needs x = \"metric:NAME\" and one metric, both per view".into());
                }
                Some((a, b))
            }
            (_, Some(_)) => {
                return Err(format!("figure.ratio is for kind = \"ratio\", not \"{}\"", kind_name(self.kind)));
            }
            (_, None) => None,
        };
        if !self.highlight.is_empty() {
            if !matches!(self.kind, FigureKind::Line | FigureKind::Scatter)
                || !matches!(series.as_str(), "method" | "method_name")
            {
                return Err("figure.highlight is for line and scatter charts whose series are methods (series = \"method_name\")".into());
            }
            let names: Vec<&str> = methods.iter().map(|m| m.split(':').next().unwrap_or(m)).collect();
            if let Some(missing) = self.highlight.iter().find(|n| !names.contains(&n.as_str())) {
                return Err(format!("figure.highlight names `{missing}`, which is not a method of this spec"));
            }
        }
        if let Some(reference) = &self.relative_to {
            if self.kind != FigureKind::Table || !matches!(series.as_str(), "method" | "method_name") {
                return Err("figure.relative_to is for tables whose series are methods (series = \"method\")".into());
            }
            if !methods.iter().any(|m| m.split(':').next() == Some(reference.as_str())) {
                return Err(format!("figure.relative_to names `{reference}`, which is not a method of this spec"));
            }
        }
        if let Some(param) = &self.spread {
            if !matches!(self.kind, FigureKind::Bar | FigureKind::Line | FigureKind::Scatter) {
                return Err(format!(
                    "figure.spread is for bar, line and scatter charts, not \"{}\"",
                    kind_name(self.kind)
                ));
            }
            if series != "method" && self.x.as_deref() != Some("method") {
                return Err("figure.spread folds method specs: set series or x to \"method\"".into());
            }
            if !methods.iter().any(|m| data::parameter(m, param).is_some()) {
                return Err(format!("figure.spread `{param}`: no method of this spec has that parameter"));
            }
        }
        let y_range = match self.y_range {
            Some([lo, hi]) if !(lo.is_finite() && hi.is_finite() && lo < hi) => {
                return Err(format!("figure.y_range = [{lo}, {hi}] must be two finite numbers, low < high"));
            }
            Some([lo, _]) if self.y_log && lo <= 0.0 => {
                return Err(format!("figure.y_range starts at {lo}, but a log axis needs values > 0"));
            }
            r => r.map(|[lo, hi]| (lo, hi)),
        };
        let own_axes = match self.axes.as_deref() {
            None | Some("shared") => false,
            Some("own") if self.facet.is_none() => {
                return Err("figure.axes = \"own\" fits each panel's axes: it needs figure.facet".into());
            }
            Some("own") if matches!(self.kind, FigureKind::Line | FigureKind::Scatter) => true,
            Some("own") => return Err("figure.axes = \"own\" is for line and scatter charts".into()),
            Some(other) => return Err(format!("figure.axes = \"{other}\": expected \"shared\" or \"own\"")),
        };
        Ok(Figure {
            kind: self.kind,
            metric,
            metrics,
            x: self.x,
            series,
            facet: self.facet,
            filter,
            x_label: self.x_label,
            y_label: self.y_label,
            x_log: self.x_log,
            y_log: self.y_log,
            y_range,
            label: self.label,
            view,
            up,
            ratio,
            highlight: self.highlight,
            relative_to: self.relative_to,
            spread: self.spread,
            own_axes,
        })
    }
}

pub fn kind_name(kind: FigureKind) -> &'static str {
    match kind {
        FigureKind::Line => "line",
        FigureKind::Scatter => "scatter",
        FigureKind::Bar => "bar",
        FigureKind::Distribution => "distribution",
        FigureKind::Table => "table",
        FigureKind::Sequence => "sequence",
        FigureKind::Clusters => "clusters",
        FigureKind::ClusterOrder => "cluster-order",
        FigureKind::Overdraw => "overdraw",
        FigureKind::Translucency => "translucency",
        FigureKind::Corners => "corners",
        FigureKind::HardwareFit => "hardware-fit",
        FigureKind::Ratio => "ratio",
    }
}
