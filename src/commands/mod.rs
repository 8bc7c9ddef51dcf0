//! One function per subcommand. Each parses its strings into library types up front (so a bad
//! method, cache or view set fails before any work), calls the library, and prints.

mod asset;
mod experiments;
mod tables;

pub use experiments::{bench, gallery, merge, plot, reproduce, run};

use std::path::Path;

use triorder::gpu::render_time::{MAX_FRAMES, Shading};
use triorder::measure::vendor::Vendor;
use triorder::measure::{self, CacheModel, MeasureOptions, Measured};
use triorder::mesh::gltf::animation::ClipSelection;
use triorder::mesh::progressive::Update;
use triorder::mesh::source::{self, AnimationSource};
use triorder::mesh::{Mesh, Scene, Source};
use triorder::order::{self, METHODS, Orders, params::describe_kind};
use triorder::raster::{RasterBackend, ViewSet};
use triorder::{Error, Result};

use crate::{Animation, Common, EvalReport, Measure, Progressive, Writing};

/// Parsed measurement options plus the chosen backend.
struct Measuring {
    options: MeasureOptions,
    raster: Box<dyn RasterBackend>,
}

impl Measuring {
    fn new(m: &Measure, seed: u64) -> Result<Measuring> {
        let gpu_vertices = m.caches.iter().any(|c| c == measure::GPU_CACHE);
        let simulated: Vec<&String> = m.caches.iter().filter(|c| *c != measure::GPU_CACHE).collect();
        let caches = if m.caches.is_empty() {
            vec![CacheModel::Fifo(16)]
        } else {
            simulated.into_iter().map(|c| c.parse()).collect::<Result<_>>()?
        };
        let views = m.views.as_deref().map(str::parse::<ViewSet>).transpose()?;
        let raster = measure::backend(&m.backend)?;
        let render = m.render.iter().map(|s| Shading::parse(s)).collect::<Result<Vec<_>>>()?;
        if !render.is_empty() && views.is_none() {
            return Err(Error::usage("--render times every view of --views: give a view set"));
        }
        if m.translucency && views.is_none() {
            return Err(Error::usage("--translucency blends every view of --views: give a view set"));
        }
        if !(1..=MAX_FRAMES).contains(&m.render_frames) {
            return Err(Error::usage(format!("--render-frames {} is outside 1..={MAX_FRAMES}", m.render_frames)));
        }
        let options = MeasureOptions {
            caches,
            gpu_vertices,
            views,
            res: m.res,
            seed,
            render,
            render_frames: m.render_frames,
            per_draw_call: false,
            translucency: m.translucency,
            meshlets: m.meshlets,
        };
        Ok(Measuring { options, raster })
    }
}

/// Opens `source`, printing what is unusual about the mesh (and an animation's clips) on stderr.
fn open(source: &Source, common: &Common) -> Result<Scene> {
    let data = source::data_dir(common.data.as_deref());
    let scene = source.open(data.as_deref(), common.seed)?;
    let mut line = format!("{source}: {}", scene.report());
    if scene.frames.is_animation() {
        let clips: Vec<String> = scene.frames.clips.iter().map(|(n, r)| format!("{n} ({} frames)", r.len())).collect();
        line = format!("{line}; clips: {}", clips.join(", "));
    }
    eprintln!("{line}");
    Ok(scene)
}

pub fn methods() -> Result<()> {
    println!(
        "A method is written NAME, or NAME:KEY=VALUE,KEY=VALUE with any of its parameters, e.g.\n  \
         tipsify:cache=32   nehab:clusters=32,views=42   random:seed=7\n\
         Parameters left out take the defaults below; --seed is the default of every seed.\n"
    );
    for m in METHODS {
        let peer = if m.peer { "  [peer]" } else { "" };
        println!("{}{peer}\n    {}\n    source: {}", m.name, m.summary, m.source);
        for p in m.params {
            let default = if matches!(p.kind, order::ParamKind::Seed) { "--seed" } else { p.default };
            println!("    {}={default}  ({}) {}", p.name, describe_kind(p.kind), p.help);
        }
        println!();
    }
    println!(
        "Cache models (--cache, and `caches` in specs): fifo:K, lru:K, batch:CACHE,WARP,PRIMGROUP\n\
         (meshoptimizer's analyzeVertexCache), and the GPU vendors' models from published measurements:"
    );
    for vendor in Vendor::ALL {
        println!("  {:<7} {}", vendor.name(), vendor.describe());
    }
    Ok(())
}

pub fn eval(
    source: &str,
    methods: &[String],
    measure: &Measure,
    animation: &Animation,
    progressive: &Progressive,
    report: &EvalReport,
    common: &Common,
) -> Result<()> {
    let json = report.json;
    let mut measuring = Measuring::new(measure, common.seed)?;
    measuring.options.per_draw_call = report.draw_calls;
    let specs: Vec<&str> =
        if methods.is_empty() { vec!["input"] } else { methods.iter().map(String::as_str).collect() };
    let resolved = specs.iter().map(|s| order::resolve(s, common.seed)).collect::<Result<Vec<_>>>()?;
    let source = with_animation(Source::parse(source)?, animation)?;
    let update = Update::parse(&progressive.update)?;
    let mut scene = open(&source, common)?;
    if !progressive.levels.is_empty() {
        scene = with_levels(scene, &progressive.levels, update)?;
    }
    let buffers = scene.frames.is_animation() || resolved.iter().any(|r| r.method.per_node);
    let mut table = tables::EvalTable::new(buffers);
    // Every method orders, then their orders are measured together (each view rasterized once).
    let mut evaluations = resolved
        .iter()
        .map(|method| measure::order_timed(&scene, method, &measuring.options))
        .collect::<Result<Vec<_>>>()?;
    let orders: Vec<&Orders> = evaluations.iter().map(|e| &e.orders).collect();
    let measured = measure::measure_many(&scene, &orders, &measuring.options, measuring.raster.as_ref())?;
    for (e, measured) in evaluations.iter_mut().zip(measured) {
        e.measured = measured;
    }
    for e in &evaluations {
        if json {
            for line in tables::eval_json(&scene, e, &measuring.raster.describe()) {
                println!("{line}");
            }
        } else {
            table.push(&scene, e);
        }
    }
    if !json {
        print!("{}", table.render(&scene.mesh));
    }
    Ok(())
}

/// `source` as the animation the `--clip`/`--frames`/`--subdiv` options name, if they name one.
fn with_animation(source: Source, options: &Animation) -> Result<Source> {
    if options.clip.is_none() && options.frames.is_none() && options.subdiv.is_none() {
        return Ok(source);
    }
    let path = match source {
        Source::File(path) => path,
        Source::Animation(_) => {
            return Err(Error::usage(format!(
                "`{source}` names its animation after `#`; drop --clip, --frames and --subdiv"
            )));
        }
        other => return Err(Error::usage(format!("`{other}`: --clip, --frames and --subdiv are for a glTF/GLB file"))),
    };
    let frames = options
        .frames
        .map(source::check_frames)
        .transpose()
        .map_err(|why| Error::usage(format!("--frames {} {why}", options.frames.unwrap_or_default())))?;
    let subdiv = source::check_subdiv(options.subdiv.unwrap_or(0))
        .map_err(|why| Error::usage(format!("--subdiv {} {why}", options.subdiv.unwrap_or_default())))?;
    let clip = options.clip.clone().filter(|c| c != "all");
    Ok(Source::Animation(AnimationSource { path, selection: ClipSelection { clip, frames }, subdiv }))
}

pub fn order(
    source: &str,
    output: &Path,
    method: &str,
    writing: &Writing,
    measure: &Measure,
    progressive: &Progressive,
    common: &Common,
) -> Result<()> {
    let (remap_vertices, strict) = (writing.remap_vertices, writing.strict);
    let measuring = Measuring::new(measure, common.seed)?;
    let resolved = order::resolve(method, common.seed)?;
    if resolved.method.per_node {
        return Err(order::needs_one_order(resolved.method.name, "`order` cannot write it"));
    }
    let update = Update::parse(&progressive.update)?;
    let source = Source::parse(source)?;
    if source.is_animation() {
        return Err(Error::usage(format!(
            "`{source}`: `order` writes the asset with its triangles reordered, animations kept; \
             name the file without `#...`"
        )));
    }
    if output.is_dir() {
        return Err(Error::output(output, "is a directory"));
    }
    if !progressive.levels.is_empty() {
        if triorder::mesh::save::format_of(output).is_none() {
            return Err(Error::output(output, "unknown output format for levels (use .obj, .ply or .glb)"));
        }
        let scene = with_levels(open(&source, common)?, &progressive.levels, update)?;
        return order_levels(scene, output, &resolved, remap_vertices, &measuring);
    }
    if !asset::writable(output) {
        return Err(Error::output(output, "unknown output format (use .glb, .gltf, .obj or .ply)"));
    }
    let data = source::data_dir(common.data.as_deref());
    let input = source.file(data.as_deref()).transpose()?;
    let scene = open(&source, common)?;
    let identity = |scene: &Scene| Orders::from((0..scene.mesh.triangle_count() as u32).collect::<Vec<_>>());
    let (options, raster) = (&measuring.options, measuring.raster.as_ref());
    let before = measure::measure(&scene, &identity(&scene), options, raster)?;
    let written = asset::write(input.as_deref(), &scene, output, &resolved, remap_vertices, strict)?;
    // The file as written, drawn as an engine draws it: its draw calls in sequence.
    let out = Source::File(output.display().to_string()).open(None, common.seed)?;
    let after = measure::measure(&out, &identity(&out), options, raster)?;
    println!("{}", tables::before_after(&before, &after));
    for note in &written.notes {
        println!("note: {note}");
    }
    let calls = scene.draw_calls.len().max(1);
    println!(
        "wrote {} ({} triangles in {calls} draw call(s), each ordered on its own by {} in {:.3} s)",
        output.display(),
        out.mesh.triangle_count(),
        resolved.canonical(),
        written.seconds
    );
    Ok(())
}

/// `order --levels`: every level drawn in the method's sequence kept by the update, written
/// with the vertices shared. Before and after are printed per level, "before" being the level's
/// triangles in the order the simplification leaves them (survivors in input order, then the
/// triangles each removal added).
fn order_levels(
    mut scene: Scene,
    output: &Path,
    resolved: &order::Resolved,
    remap_vertices: bool,
    measuring: &Measuring,
) -> Result<()> {
    let (options, raster) = (&measuring.options, measuring.raster.as_ref());
    let after = measure::evaluate(&scene, resolved, options, raster)?;
    let update = scene.frames.levels().map_or(Update::Smart, |l| l.update);
    scene.set_update(Update::Reorder);
    let before = measure::evaluate(&scene, &order::resolve("input", 0)?, options, raster)?;
    scene.set_update(update);
    let levels = scene.frames.levels().expect("a scene with levels");
    let mut named: Vec<(String, Vec<[u32; 3]>)> = (0..levels.alive.len())
        .map(|f| {
            let triangles = levels.triangles(f);
            let buffer = &after.orders.buffers[after.orders.lookup.buffer(f, glam::Vec3::Z)].order;
            let ordered: Vec<[u32; 3]> = buffer.iter().map(|&i| triangles[i as usize]).collect();
            (format!("level {}: {} triangles", levels.fractions[f], ordered.len()), ordered)
        })
        .collect();
    let mut mesh = scene.mesh.clone();
    if remap_vertices {
        // One numbering for every level, by first use in the first: it uses every vertex the
        // others use, since removals only take vertices away.
        let all = Mesh { triangles: named.iter().flat_map(|(_, t)| t.iter().copied()).collect(), ..mesh };
        let remapped = all.remap_vertices_first_use();
        let mut rest = remapped.triangles.as_slice();
        for (_, triangles) in &mut named {
            let (level, others) = rest.split_at(triangles.len());
            triangles.copy_from_slice(level);
            rest = others;
        }
        mesh = Mesh { triangles: named[0].1.clone(), ..remapped };
    }
    let (saved, paths) = triorder::mesh::save::save_levels(&mesh, &named, output)?;
    warn_dropped(output, &saved.dropped);
    for (f, (name, _)) in named.iter().enumerate() {
        let at = |measured: &[Measured]| measured.iter().map(|m| m.at_level(Some(f))).collect::<Vec<_>>();
        println!("{name}\n{}", tables::before_after(&at(&before.measured), &at(&after.measured)));
    }
    let files: Vec<String> = paths.iter().map(|p| p.display().to_string()).collect();
    println!(
        "wrote {} ({} levels, {} kept by the {} update, ordered and updated in {:.3} s)",
        files.join(", "),
        named.len(),
        after.method,
        update.name(),
        after.seconds
    );
    Ok(())
}

fn warn_dropped(output: &Path, dropped: &[String]) {
    for dropped in dropped {
        eprintln!("warning: {}: not written: {dropped}", output.display());
    }
}

/// `scene` as a progressive mesh at `fractions`, saying on stderr which levels the history
/// could not reach.
fn with_levels(scene: Scene, fractions: &[f64], update: Update) -> Result<Scene> {
    let scene = scene.with_levels(fractions, update)?;
    if let Some(note) = scene.frames.levels().and_then(|l| l.note.as_ref()) {
        eprintln!("{}: note: {note}", scene.mesh.name);
    }
    Ok(scene)
}
