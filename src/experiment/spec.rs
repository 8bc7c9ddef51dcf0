//! Experiment specs: one TOML file per paper figure under `experiments/`.
//!
//! A spec says what to measure (models × methods × cache models × view set) and how to draw it,
//! so that `triorder run` and `triorder plot` need nothing else and a figure can be reproduced
//! from its file alone. Everything is checked when the spec is loaded (unknown keys, unknown
//! methods or parameters, bad cache models, ranges or view sets, figure columns that the CSV
//! will not have), before any mesh is loaded or ordered, and every error names the file and the
//! key.
//!
//! ```toml
//! id = "acmr-vs-fifo"              # file names: results/ID.csv, paper-figures/ID.svg; must equal
//!                                  # the spec's file name without .toml
//! title = "ACMR vs FIFO size"      # the figure's title
//! question = "How many vertices…"  # what the figure answers (one sentence)
//! claim = "Typical optimized…"     # optional: the paper's claim, with its source; drawn as a
//!                                  # caption under the title
//! models = ["models/bunny_2k.ply", "sphere:20480"]
//!                                  # paths (tried as given, then in the data directory: --data,
//!                                  # TRIORDER_DATA, ../shared/data) or procedural specs; an
//!                                  # animation is PATH#clip=NAME,frames=N,subdiv=L (every method
//!                                  # measured over its keyframes, rows per clip)
//!                                  # or a corpus, expanded when the run starts: a folder
//!                                  # ("corpus/": every OBJ, PLY, glTF, GLB under it), a glob
//!                                  # ("corpus/**/*.ply") or a list file ("corpus.txt", a model
//!                                  # per line); see experiment/corpus.rs
//! methods = "all"                  # every registered method with its defaults, or a list of
//!                                  # method specs; any parameter may be a grid:
//!                                  # ["input", "meshopt-fifo:cache={8,16,32}", "random:seed={1..3}"]
//! caches = ["fifo:4..64", "lru:16", "batch:32,32,32"]
//!                                  # cache models; `KIND:LO..HI` is every size from LO to HI
//!                                  # inclusive, `KIND:LO..HI/STEP` every STEP-th (fifo, lru);
//!                                  # "gpu" counts vertex-shader invocations on the GPU instead
//!                                  # (rows with cache = "gpu"; static meshes and methods only)
//! views = "ico:162"                # optional: measure overdraw over this view set (axis6,
//!                                  # ico:N, random:N)
//! res = 512                        # optional, with views only: image size R×R (default 512)
//! seed = 0                         # optional (default 0): seeds random orders, random views, disk:N
//! backend = "cpu"                  # optional (default cpu): the raster backend, cpu or gpu
//! render = ["pixel", "vertex"]     # optional, with views: time rendering on the GPU from every
//!                                  # view with a pixel-bound and/or a vertex-bound shader
//! render_frames = 30               # optional: timed frames per view and shader (default 30)
//! translucency = true              # optional, with views: also measure how wrong each order
//!                                  # is blended as a translucent mesh (measure/translucency.rs)
//! meshlets = true                  # optional: also measure the meshlets the order makes
//!                                  # (measure/meshlets.rs; cone culling needs views)
//! levels = [1.0, 0.5, 0.25]        # optional: measure each static model as a progressive mesh
//!                                  # at these fractions of its triangles (rows name `level`)
//! updates = ["simple", "smart"]    # optional, with levels: how each method's sequence follows
//!                                  # the levels: simple, smart (default) or reorder (rows name
//!                                  # `update`)
//!
//! [figure]
//! kind = "line"                    # line | scatter | bar | distribution | table |
//!                                  # sequence | corners | clusters | cluster-order | overdraw
//!                                  # (drawings of the meshes) | hardware-fit (simulated cache
//!                                  # models against the GPU's counts) | ratio (per view, method
//!                                  # A over B of x against y; needs ratio = ["A", "B"])
//! metric = "acmr"                  # the y values: rows whose `metric` column is this
//!                                  # (acmr, atvr, seconds, ovr, ovr_mean, ovr_max, ovr_min,
//!                                  # ovr_var, ovr_sum, ovr_empty), or a list of metrics drawn
//!                                  # together (then series or facet = "metric")
//! x = "cache_size"                 # CSV column on x (line, scatter: numeric; bar: categories;
//!                                  # table: its rows;
//!                                  # distribution: not allowed, it sorts the values itself).
//!                                  # x, series, facet and filter keys may also name a method
//!                                  # parameter, "param:clusters", or a key of an animated
//!                                  # model, "source:subdiv" (clip, frames, subdiv); a scatter's x
//!                                  # may name another metric of the same model and method,
//!                                  # "metric:acmr" (with a row per cache model,
//!                                  # "metric:acmr@cache=nvidia": the row named)
//! series = "method"                # optional (default method): one colour per value
//! facet = "model"                  # optional: one small chart per value, all in one SVG;
//!                                  # series and facet may join columns, "model+method"
//! filter = { cache_kind = "fifo" } # optional: keep only rows whose columns equal these values
//! x_label = "FIFO size"            # optional axis labels (defaults name the column or metric)
//! y_label = "ACMR"
//! x_log = false                    # optional log axes (default false)
//! y_log = false
//! y_range = [0.5, 3.2]             # optional y axis range (default: fits the data)
//! label = "metric:iterations"      # bar: write this metric of the same model and method above
//!                                  # each bar instead of the bar's value
//! view = [0, 0, 1]                 # sequence, corners: direction the model is seen from
//! up = [0, 0, 1]                   # drawings: the world direction drawn upwards (default +y)
//! spread = "seed"                  # bar, line, scatter: fold the runs of each seed into their
//!                                  # mean, with whiskers from the least to the greatest
//! highlight = ["cheap-cuts"]       # line, scatter with methods as series: these methods drawn
//!                                  # last, with larger outlined markers; a line chart of more
//!                                  # than 8 series draws the others as grey context
//! relative_to = "hoppe"            # table with methods as series: each cell is that method's
//!                                  # value ÷ the cell's (times lower; higher is better)
//! axes = "own"                     # line, scatter with a facet: each panel's axes fitted to
//!                                  # its own data (default "shared")
//!
//! Figures name methods by what tells them apart (`tipsify cache=8`; the full spec is in the
//! CSV), grow bars from the metric's optimum where it has one (an overdraw ratio's 1), cut a
//! few far taller bars at the top with their values written, and break lines where nothing was
//! measured.
//!
//! [quick]                          # what `--quick` runs: procedural models and assets/ only,
//! models = ["assets/spot.obj"]     # done in seconds; caches, views, res and render_frames
//! caches = ["fifo:4..64/4"]        # override the full run's when given
//! views = "ico:42"
//! res = 128
//! render_frames = 3
//! ```
//!
//! Grids (`{…}`) may appear anywhere in a method or cache spec; each item is a literal or an
//! integer range `LO..HI[/STEP]` (inclusive), and several grids in one spec give their cartesian
//! product. Specs that resolve to the same canonical method are run once.

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use serde::Deserialize;

use crate::error::{Error, Result};
use crate::figure::spec::{Figure, FigureKind, RawFigure, Varies, Writes, kind_name};
use crate::figure::{Chart, PlotOptions};
use crate::gpu::render_time::{MAX_FRAMES, Shading};
use crate::measure::{self, CacheModel, GPU_CACHE, MeasureOptions};
use crate::mesh::Source;
use crate::mesh::progressive::Update;
use crate::order::{self, METHODS};
use crate::raster::ViewSet;

/// Overdraw image size when a spec gives views but no `res` (Nehab et al. 2006 use 512×512).
pub const DEFAULT_RES: u32 = 512;

/// Timed frames per view and shader when a spec renders but does not say how many.
pub const DEFAULT_RENDER_FRAMES: usize = 30;

/// Largest image side a spec may ask for: beyond it one depth buffer alone needs gigabytes.
const MAX_RES: u32 = 16384;

/// Most values one range or grid may produce: a typo like `fifo:4..4000000` is an error, not an
/// hour-long run.
const MAX_EXPANSION: usize = 10_000;

/// A checked experiment spec.
#[derive(Debug, Clone, PartialEq)]
pub struct Spec {
    /// The file it was loaded from (errors name it).
    pub path: PathBuf,
    /// The TOML as written: a sharded run's fingerprint hashes it.
    pub text: String,
    pub id: String,
    pub title: String,
    pub question: String,
    pub claim: Option<String>,
    pub seed: u64,
    pub backend: String,
    /// Shaders to time rendering with on the GPU, from every view (`render = ["pixel", "vertex"]`).
    pub render: Vec<Shading>,
    /// Also measure the translucency error over the view set (`translucency = true`).
    pub translucency: bool,
    /// Also measure the meshlets each order makes (`meshlets = true`).
    pub meshlets: bool,
    /// Canonical method specs (every parameter written out), grids expanded, duplicates
    /// removed, in the order the spec lists them.
    pub methods: Vec<String>,
    /// With levels: how each method's sequence follows them (default smart).
    pub updates: Vec<Update>,
    /// What a full run measures.
    pub full: Workload,
    /// What `--quick` measures, if the spec has a `[quick]` table.
    pub quick: Option<Workload>,
    pub figure: Figure,
}

/// A model as the spec names it (the name results record) and what it names.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Model {
    pub name: String,
    pub source: Source,
}

/// The models and measurements of one run (full or quick).
#[derive(Debug, Clone, PartialEq)]
pub struct Workload {
    pub models: Vec<Model>,
    pub caches: Vec<CacheModel>,
    /// The caches list names [`GPU_CACHE`]: count vertex-shader invocations on the GPU too.
    pub gpu_vertices: bool,
    pub views: Option<ViewSet>,
    pub res: u32,
    /// Timed frames per view and shader when the spec renders.
    pub render_frames: usize,
    /// Progressive levels, as fractions of each model's triangles, most first; empty: the models
    /// as they are.
    pub levels: Vec<f64>,
}

impl Spec {
    /// Reads and checks the spec at `path`.
    pub fn load(path: &Path) -> Result<Spec> {
        let text = std::fs::read_to_string(path).map_err(|e| Error::spec(path, format!("cannot read: {e}")))?;
        Spec::parse(&text, path)
    }

    /// Checks the spec text `text`, read from `path` (which errors name and the id must match).
    pub fn parse(text: &str, path: &Path) -> Result<Spec> {
        // An editor's UTF-8 byte-order mark is not part of the first key.
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let raw: RawSpec = toml::from_str(text).map_err(|e| Error::spec(path, e.to_string().trim_end()))?;
        Ok(Spec { text: text.to_string(), ..raw.check(path)? })
    }

    /// What a run measures: the `[quick]` table's workload when `quick`.
    pub fn workload(&self, quick: bool) -> Result<&Workload> {
        match (quick, &self.quick) {
            (false, _) => Ok(&self.full),
            (true, Some(quick)) => Ok(quick),
            (true, None) => Err(Error::spec(&self.path, "has no [quick] table, so it cannot run with --quick")),
        }
    }

    /// What a run of `work` measures.
    pub fn measure_options(&self, work: &Workload) -> MeasureOptions {
        MeasureOptions {
            caches: work.caches.clone(),
            gpu_vertices: work.gpu_vertices,
            views: work.views,
            res: work.res,
            seed: self.seed,
            render: self.render.clone(),
            render_frames: work.render_frames,
            // Specs measure whole meshes, as the papers do.
            per_draw_call: false,
            translucency: self.translucency,
            meshlets: self.meshlets,
        }
    }

    /// Whether the spec asks for a GPU itself (its backend or a metric), in either run.
    pub fn needs_gpu(&self) -> bool {
        let needs = |w: &Workload| self.measure_options(w).needs_gpu();
        self.backend == "gpu" || needs(&self.full) || self.quick.as_ref().is_some_and(needs)
    }

    /// What the figure is drawn from, under `opts`.
    pub fn chart(&self, opts: &PlotOptions) -> Chart<'_> {
        Chart {
            figure: &self.figure,
            spec: &self.path,
            title: &self.title,
            claim: self.claim.as_deref(),
            csv: self.csv_path(&opts.out_dir, opts.quick),
            orders: self.orders_path(&opts.out_dir, opts.quick),
            svg: self.svg_path(&opts.out_dir, opts.quick),
            quick: opts.quick,
            data: opts.data.clone(),
            seed: self.seed,
        }
    }

    /// `ROOT/results/ID.csv`, or `ROOT/results/quick/ID.csv` for quick runs.
    pub fn csv_path(&self, root: &Path, quick: bool) -> PathBuf {
        output_dir(root, "results", quick).join(format!("{}.csv", self.id))
    }

    /// `ROOT/results/ID.orders.csv` (or under `quick/`): the orders a drawing spec's figure draws.
    pub fn orders_path(&self, root: &Path, quick: bool) -> PathBuf {
        output_dir(root, "results", quick).join(format!("{}.orders.csv", self.id))
    }

    /// `ROOT/paper-figures/ID.svg`, or `ROOT/paper-figures/quick/ID.svg` for quick runs.
    pub fn svg_path(&self, root: &Path, quick: bool) -> PathBuf {
        output_dir(root, "paper-figures", quick).join(format!("{}.svg", self.id))
    }
}

fn output_dir(root: &Path, kind: &str, quick: bool) -> PathBuf {
    let dir = root.join(kind);
    if quick { dir.join("quick") } else { dir }
}

/// The spec as written; [`RawSpec::check`] turns it into a [`Spec`].
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSpec {
    id: String,
    title: String,
    question: String,
    claim: Option<String>,
    models: Vec<String>,
    methods: RawMethods,
    #[serde(default)]
    caches: Vec<String>,
    views: Option<String>,
    res: Option<u32>,
    #[serde(default)]
    seed: u64,
    backend: Option<String>,
    #[serde(default)]
    render: Vec<String>,
    render_frames: Option<usize>,
    levels: Option<Vec<f64>>,
    #[serde(default)]
    updates: Vec<String>,
    #[serde(default)]
    translucency: bool,
    #[serde(default)]
    meshlets: bool,
    figure: RawFigure,
    quick: Option<RawQuick>,
}

/// `methods = "all"` or a list of method specs.
enum RawMethods {
    Word(String),
    List(Vec<String>),
}

/// By hand rather than `#[serde(untagged)]`, so a wrong type says what is expected instead of
/// "did not match any variant".
impl<'de> Deserialize<'de> for RawMethods {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> std::result::Result<Self, D::Error> {
        struct Expect;
        impl<'de> serde::de::Visitor<'de> for Expect {
            type Value = RawMethods;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("\"all\" or a list of method specs")
            }
            fn visit_str<E: serde::de::Error>(self, word: &str) -> std::result::Result<RawMethods, E> {
                Ok(RawMethods::Word(word.to_string()))
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> std::result::Result<RawMethods, A::Error> {
                let mut list = Vec::new();
                while let Some(spec) = seq.next_element::<String>()? {
                    list.push(spec);
                }
                Ok(RawMethods::List(list))
            }
        }
        deserializer.deserialize_any(Expect)
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawQuick {
    models: Vec<String>,
    caches: Option<Vec<String>>,
    views: Option<String>,
    res: Option<u32>,
    render_frames: Option<usize>,
    levels: Option<Vec<f64>>,
}

impl RawSpec {
    fn check(self, path: &Path) -> Result<Spec> {
        let err = |problem: String| Error::spec(path, problem);
        let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
        if self.id.is_empty() || !self.id.chars().all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_') {
            return Err(err(format!("id `{}` must be non-empty letters, digits, `-` or `_`", self.id)));
        }
        if self.id != stem {
            return Err(err(format!(
                "id `{}` must equal the file name `{stem}` (so results/{stem}.csv is this spec's)",
                self.id
            )));
        }
        for (key, text) in [("title", &self.title), ("question", &self.question)] {
            if text.trim().is_empty() {
                return Err(err(format!("{key} is empty")));
            }
        }
        let methods = check_methods(&self.methods, self.seed).map_err(err)?;
        let updates = match (self.levels.is_some(), self.updates.is_empty()) {
            (false, false) => return Err(err("updates is set but levels is not".into())),
            (_, true) => vec![Update::Smart],
            (true, false) => self
                .updates
                .iter()
                .map(|u| Update::parse(u))
                .collect::<Result<Vec<_>>>()
                .map_err(|e| err(format!("updates: {e}")))?,
        };
        if self.levels.is_some()
            && let Some(m) = methods.iter().find(|m| order::resolve(m, self.seed).is_ok_and(|r| r.method.per_node))
        {
            return Err(err(format!(
                "levels keep one sequence per model, but method `{m}` gives an index buffer per (keyframe, view)"
            )));
        }
        let backend = self.backend.unwrap_or_else(|| "cpu".into());
        crate::measure::check_backend_name(&backend).map_err(|e| err(format!("backend: {e}")))?;

        let render_frames = self.render_frames.unwrap_or(DEFAULT_RENDER_FRAMES);
        let levels = self.levels.clone().unwrap_or_default();
        let full =
            check_workload("", &self.models, &self.caches, self.views.as_deref(), self.res, render_frames, &levels)
                .map_err(err)?;
        let quick = match &self.quick {
            None => None,
            Some(q) => {
                let caches = q.caches.as_ref().unwrap_or(&self.caches);
                let views = q.views.as_deref().or(self.views.as_deref());
                let res = q.res.or(self.res);
                let frames = q.render_frames.unwrap_or(render_frames);
                let quick_levels = q.levels.as_ref().unwrap_or(&levels);
                let work =
                    check_workload("quick.", &q.models, caches, views, res, frames, quick_levels).map_err(err)?;
                if let Some((i, model)) = work.models.iter().enumerate().find(|(_, m)| !m.source.is_bundled()) {
                    return Err(err(format!(
                        "quick.models[{i}] `{}`: quick runs use procedural models and files under assets/ only, so they work on a fresh clone",
                        model.name
                    )));
                }
                Some(work)
            }
        };
        let render = self
            .render
            .iter()
            .map(|s| Shading::parse(s))
            .collect::<Result<Vec<_>>>()
            .map_err(|e| err(format!("render: {e}")))?;
        if !render.is_empty() && (full.views.is_none() || quick.as_ref().is_some_and(|q| q.views.is_none())) {
            return Err(err("render times every view of `views`: set views".into()));
        }
        if self.translucency && (full.views.is_none() || quick.as_ref().is_some_and(|q| q.views.is_none())) {
            return Err(err("translucency blends every view of `views`: set views".into()));
        }
        let options = MeasureOptions {
            caches: full.caches.clone(),
            gpu_vertices: full.gpu_vertices,
            views: full.views,
            render: render.clone(),
            translucency: self.translucency,
            meshlets: self.meshlets,
            ..Default::default()
        };
        let writes = Writes {
            metrics: measure::ORDERING.iter().map(|n| n.name).chain(options.reported()).collect(),
            methods: &methods,
            animated: full.models.iter().any(|m| m.source.is_animation()),
            varies: varies(&full, quick.as_ref(), &methods, &updates),
        };
        let figure = self.figure.check(&writes).map_err(err)?;
        let fits = |w: &Workload| w.gpu_vertices && !w.caches.is_empty();
        if figure.kind == FigureKind::HardwareFit && !(fits(&full) && quick.as_ref().is_none_or(fits)) {
            return Err(err(format!(
                "figure.kind = \"hardware-fit\" compares simulated caches with the GPU's counts: caches must list simulated models and `{GPU_CACHE}`"
            )));
        }
        // Drawings draw one order per model and method.
        let per_node = methods.iter().find(|m| order::resolve(m, self.seed).is_ok_and(|r| r.method.per_node));
        let animated = full.models.iter().chain(quick.iter().flat_map(|q| &q.models)).find(|m| m.source.is_animation());
        let several = per_node.map(|m| format!("method `{m}`")).or(animated.map(|m| format!("model `{}`", m.name)));
        if figure.kind.draws_meshes()
            && let Some(what) = &several
        {
            return Err(err(format!(
                "figure.kind = \"{}\" draws one order per model and method, but {what} gives an index buffer per (keyframe, view): use a chart kind (line, bar, table, …)",
                kind_name(figure.kind)
            )));
        }
        Ok(Spec {
            path: path.to_path_buf(),
            text: String::new(),
            id: self.id,
            title: self.title,
            question: self.question,
            claim: self.claim.filter(|c| !c.trim().is_empty()),
            seed: self.seed,
            backend,
            render,
            translucency: self.translucency,
            meshlets: self.meshlets,
            methods,
            updates,
            full,
            quick,
            figure,
        })
    }
}

/// Expands and resolves the method list; the canonical specs, deduplicated, in order.
fn check_methods(methods: &RawMethods, seed: u64) -> std::result::Result<Vec<String>, String> {
    let written: Vec<(String, String)> = match methods {
        RawMethods::Word(w) if w == "all" => {
            METHODS.iter().map(|m| ("methods".to_string(), m.name.to_string())).collect()
        }
        RawMethods::Word(w) => {
            return Err(format!("methods = \"{w}\": expected \"all\" or a list of method specs"));
        }
        RawMethods::List(list) if list.is_empty() => return Err("methods is an empty list".into()),
        RawMethods::List(list) => {
            let mut out = Vec::new();
            for (i, text) in list.iter().enumerate() {
                let key = format!("methods[{i}]");
                let specs = expand_grid(text).map_err(|why| format!("{key} `{text}` {why}"))?;
                out.extend(specs.into_iter().map(|s| (key.clone(), s)));
            }
            out
        }
    };
    let mut seen = HashSet::new();
    let mut canonical = Vec::new();
    for (key, text) in written {
        let resolved = order::resolve(&text, seed).map_err(|e| format!("{key} `{text}`: {e}"))?;
        let name = resolved.canonical();
        if seen.insert(name.clone()) {
            canonical.push(name);
        }
    }
    Ok(canonical)
}

/// Checks one run's models, caches, views and res; `prefix` is `quick.` for the `[quick]` table
/// (whose missing keys the caller has already filled from the full run's).
fn check_workload(
    prefix: &str,
    models: &[String],
    caches: &[String],
    views: Option<&str>,
    res: Option<u32>,
    render_frames: usize,
    levels: &[f64],
) -> std::result::Result<Workload, String> {
    if models.is_empty() {
        return Err(format!("{prefix}models is empty"));
    }
    if let Some((i, _)) = models.iter().enumerate().find(|(_, m)| m.trim().is_empty()) {
        return Err(format!("{prefix}models[{i}] is empty"));
    }
    let models = models
        .iter()
        .enumerate()
        .map(|(i, name)| match Source::parse(name) {
            Ok(source) => Ok(Model { name: name.clone(), source }),
            Err(e) => Err(format!("{prefix}models[{i}]: {e}")),
        })
        .collect::<std::result::Result<Vec<_>, _>>()?;
    let mut parsed = Vec::new();
    let gpu_vertices = caches.iter().any(|c| c == GPU_CACHE);
    for (i, text) in caches.iter().enumerate().filter(|(_, c)| *c != GPU_CACHE) {
        let key = format!("{prefix}caches[{i}]");
        for model in expand_cache(text).map_err(|why| format!("{key} `{text}` {why}"))? {
            let model: CacheModel = model.parse().map_err(|e| format!("{key}: {e}"))?;
            if !parsed.contains(&model) {
                parsed.push(model);
            }
        }
    }
    let views = views.map(|v| v.parse::<ViewSet>().map_err(|e| format!("{prefix}views: {e}"))).transpose()?;
    let res = match (views, res) {
        (None, Some(_)) => {
            return Err(format!("{prefix}res is set but views is not (res is the overdraw image size)"));
        }
        (_, Some(r)) if !(1..=MAX_RES).contains(&r) => {
            return Err(format!("{prefix}res = {r} is not in 1..={MAX_RES}"));
        }
        (_, Some(r)) => r,
        (_, None) => DEFAULT_RES,
    };
    if parsed.is_empty() && !gpu_vertices && views.is_none() {
        return Err(format!("{prefix}caches is empty and views is not set: nothing to measure but time"));
    }
    if !(1..=MAX_FRAMES).contains(&render_frames) {
        return Err(format!("{prefix}render_frames = {render_frames} is not in 1..={MAX_FRAMES}"));
    }
    if let Some(bad) = levels.iter().find(|f| !(**f > 0.0 && **f <= 1.0)) {
        return Err(format!("{prefix}levels: {bad} is not a fraction of the triangles in (0, 1]"));
    }
    if !levels.is_empty()
        && let Some(model) = models.iter().find(|m| m.source.is_animation())
    {
        return Err(format!("{prefix}levels are for static meshes, but `{}` is an animation", model.name));
    }
    let mut levels = levels.to_vec();
    levels.sort_by(|a, b| b.total_cmp(a));
    levels.dedup();
    Ok(Workload { models, caches: parsed, gpu_vertices, views, res, render_frames, levels })
}

/// Expands a cache spec: `KIND:LO..HI[/STEP]` is shorthand for `KIND:{LO..HI[/STEP]}`; any
/// other `{…}` grid expands as in method specs.
fn expand_cache(text: &str) -> std::result::Result<Vec<String>, String> {
    let text = text.trim();
    match text.split_once(':') {
        Some((kind, args)) if !text.contains('{') && args.contains("..") => {
            if args.contains(',') {
                return Err(
                    "puts a range in a multi-size cache model: write the grid in braces, e.g. batch:{16..32/16},32,32"
                        .into(),
                );
            }
            expand_grid(&format!("{kind}:{{{args}}}"))
        }
        _ => expand_grid(text),
    }
}

/// Expands every `{…}` group of `text` into the cartesian product of its items, left to right.
/// An item is a literal (`16`, `0.85`, `hoppe`) or an inclusive integer range `LO..HI[/STEP]`.
pub fn expand_grid(text: &str) -> std::result::Result<Vec<String>, String> {
    let Some(open) = text.find('{') else {
        return if text.contains('}') { Err("has a `}` without `{`".into()) } else { Ok(vec![text.to_string()]) };
    };
    let prefix = &text[..open];
    if prefix.contains('}') {
        return Err("has a `}` without `{`".into());
    }
    let close = text[open..].find('}').map(|i| open + i).ok_or("has a `{` without `}`")?;
    let inner = &text[open + 1..close];
    if inner.contains('{') {
        return Err("nests `{` inside `{…}`".into());
    }
    let mut items = Vec::new();
    for item in inner.split(',').map(str::trim) {
        if item.is_empty() {
            return Err(format!("has an empty item in `{{{inner}}}`"));
        }
        match item.split_once("..") {
            Some((lo, hi)) => items.extend(integer_range(lo, hi)?.into_iter().map(|v| v.to_string())),
            None => items.push(item.to_string()),
        }
    }
    let rest = expand_grid(&text[close + 1..])?;
    if items.len() * rest.len() > MAX_EXPANSION {
        return Err(format!("expands to {} specs (at most {MAX_EXPANSION})", items.len() * rest.len()));
    }
    Ok(items.iter().flat_map(|item| rest.iter().map(move |r| format!("{prefix}{item}{r}"))).collect())
}

/// `LO..HI` or `LO..HI/STEP` (the text after `..` is `hi`): LO, LO+STEP, … up to HI inclusive.
fn integer_range(lo: &str, hi: &str) -> std::result::Result<Vec<i64>, String> {
    let (hi, step) = hi.split_once('/').unwrap_or((hi, "1"));
    let int = |s: &str, what: &str| {
        s.trim().parse::<i64>().map_err(|_| format!("has a range {what} `{}` that is not an integer", s.trim()))
    };
    let (lo, hi, step) = (int(lo, "start")?, int(hi, "end")?, int(step, "step")?);
    if step < 1 {
        return Err(format!("has a range step {step} (must be ≥ 1)"));
    }
    if lo > hi {
        return Err(format!("has an empty range {lo}..{hi} (start after end)"));
    }
    let count = (hi - lo) / step + 1;
    if count > MAX_EXPANSION as i64 {
        return Err(format!("has a range of {count} values (at most {MAX_EXPANSION})"));
    }
    Ok((0..count).map(|i| lo + i * step).collect())
}

/// What the rows of a run of `full` (or of `quick`) vary along, for the figure check: several
/// models, methods, caches, levels or updates.
fn varies(full: &Workload, quick: Option<&Workload>, methods: &[String], updates: &[Update]) -> Vec<Varies> {
    let most = |count: fn(&Workload) -> usize| quick.map_or(0, count).max(count(full));
    let every: fn(&str) -> bool = |_| true;
    let per_cache: fn(&str) -> bool =
        |m| crate::measure::Metric::names(&crate::measure::cache::METRIC).iter().any(|n| n.name == m);
    let per_level: fn(&str) -> bool = |m| !crate::measure::ORDERING.iter().any(|n| n.name == m);
    let model_columns = &["model", "model_base", "model_triangles", "model_vertices", "source:"][..];
    [
        // A corpus entry names many models (how many is known only when the run starts).
        (
            most(|w| w.models.iter().map(|m| if super::corpus::is_corpus(&m.name) { 2 } else { 1 }).sum()),
            "models",
            model_columns,
            every,
        ),
        (methods.len(), "methods", &["method", "method_name", "seed", "peer", "param:"][..], every),
        (most(|w| w.caches.len()), "cache models", &["cache", "cache_kind", "cache_size"][..], per_cache),
        (most(|w| w.levels.len()), "levels", &["level", "model_triangles", "model_vertices"][..], per_level),
        (updates.len(), "updates", &["update"][..], every),
    ]
    .into_iter()
    .filter(|(count, ..)| *count > 1)
    .map(|(count, what, columns, splits)| Varies { what: format!("{count} {what}"), columns, splits })
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grids_and_ranges_expand() {
        assert_eq!(expand_grid("m:cache={8,16}").unwrap(), ["m:cache=8", "m:cache=16"]);
        assert_eq!(expand_grid("m:a={1..3},b={x,y}").unwrap().len(), 6);
        assert_eq!(expand_grid("m:a={1..3},b={x,y}").unwrap()[1], "m:a=1,b=y");
        assert_eq!(expand_cache("fifo:4..16/4").unwrap(), ["fifo:4", "fifo:8", "fifo:12", "fifo:16"]);
        assert_eq!(expand_cache("fifo:4..5").unwrap(), ["fifo:4", "fifo:5"]);
        assert_eq!(expand_cache("batch:{16,32},32,32").unwrap(), ["batch:16,32,32", "batch:32,32,32"]);
        assert_eq!(expand_cache("lru:16").unwrap(), ["lru:16"]);
        for bad in ["m:{1,2", "m:1}", "m:{}", "m:{{1}}", "m:{1..x}", "m:{5..1}", "m:{1..9/0}", "m:{0..99999}"] {
            assert!(expand_grid(bad).is_err(), "{bad}");
        }
        assert!(expand_cache("batch:16..32,32,32").is_err());
    }
}
