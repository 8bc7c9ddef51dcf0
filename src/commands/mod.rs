//! One function per subcommand. Each parses its strings into library types up front (so a bad
//! method, cache or view set fails before any work), calls the library, and prints.

mod experiments;
mod tables;

pub use experiments::{bench, plot, reproduce, run};

use std::path::Path;

use triorder::gpu::render_time::{MAX_FRAMES, Shading};
use triorder::measure::{self, CacheModel, MeasureOptions};
use triorder::mesh::gltf::animation::ClipSelection;
use triorder::mesh::progressive::Update;
use triorder::mesh::source::{self, AnimationSource};
use triorder::mesh::{Scene, Source};
use triorder::order::{self, METHODS, Orders, params::describe_kind};
use triorder::raster::{RasterBackend, ViewSet};
use triorder::{Error, Result};

use crate::{Animation, Common, Measure, Progressive};

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
        if !(1..=MAX_FRAMES).contains(&m.render_frames) {
            return Err(Error::usage(format!("--render-frames {} is outside 1..={MAX_FRAMES}", m.render_frames)));
        }
        let options =
            MeasureOptions { caches, gpu_vertices, views, res: m.res, seed, render, render_frames: m.render_frames };
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
    Ok(())
}

pub fn eval(
    source: &str,
    methods: &[String],
    measure: &Measure,
    animation: &Animation,
    progressive: &Progressive,
    json: bool,
    common: &Common,
) -> Result<()> {
    let measuring = Measuring::new(measure, common.seed)?;
    let specs: Vec<&str> =
        if methods.is_empty() { vec!["input"] } else { methods.iter().map(String::as_str).collect() };
    let resolved = specs.iter().map(|s| order::resolve(s, common.seed)).collect::<Result<Vec<_>>>()?;
    let source = with_animation(Source::parse(source)?, animation)?;
    let update = Update::parse(&progressive.update)?;
    let mut scene = open(&source, common)?;
    if !progressive.levels.is_empty() {
        scene = scene.with_levels(&progressive.levels, update)?;
        if let Some(note) = scene.frames.levels().and_then(|l| l.note(&progressive.levels)) {
            eprintln!("{}: note: {note}", scene.mesh.name);
        }
    }
    let buffers = scene.frames.is_animation() || resolved.iter().any(|r| r.method.per_node);
    let mut table = tables::EvalTable::new(buffers);
    for method in &resolved {
        let e = measure::evaluate(&scene, method, &measuring.options, measuring.raster.as_ref())?;
        if json {
            for line in tables::eval_json(&scene, &e, &measuring.raster.describe()) {
                println!("{line}");
            }
        } else {
            table.push(&scene, &e);
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
    remap_vertices: bool,
    measure: &Measure,
    common: &Common,
) -> Result<()> {
    let measuring = Measuring::new(measure, common.seed)?;
    let resolved = order::resolve(method, common.seed)?;
    if resolved.method.per_node {
        return Err(order::needs_one_order(resolved.method.name, "`order` cannot write it"));
    }
    let source = Source::parse(source)?;
    if source.is_animation() {
        return Err(Error::usage(format!(
            "`{source}`: `order` writes a static mesh and would drop the animation; \
             name the file without `#...` to reorder its rest mesh"
        )));
    }
    if output.is_dir() {
        return Err(Error::output(output, "is a directory"));
    }
    if triorder::mesh::save::format_of(output).is_none() {
        return Err(Error::output(output, "unknown output format (use .obj, .ply or .glb)"));
    }
    let scene = open(&source, common)?;
    let identity: Vec<u32> = (0..scene.mesh.triangle_count() as u32).collect();
    let before = measure::measure(&scene, &Orders::from(identity), &measuring.options, measuring.raster.as_ref())?;
    let after = measure::evaluate(&scene, &resolved, &measuring.options, measuring.raster.as_ref())?;
    let buffer =
        after.orders.single().ok_or_else(|| order::needs_one_order(after.method_name, "`order` cannot write it"))?;
    let mut reordered = scene.mesh.reordered(&buffer.order);
    if remap_vertices {
        reordered = reordered.remap_vertices_first_use();
    }
    let saved = triorder::mesh::save::save(&reordered, output)?;
    for dropped in &saved.dropped {
        eprintln!("warning: {}: not written: {dropped}", output.display());
    }
    println!("{}", tables::before_after(&before, &after.measured));
    println!(
        "wrote {} ({} triangles, {} ordered in {:.3} s)",
        output.display(),
        reordered.triangle_count(),
        after.method,
        after.seconds
    );
    Ok(())
}
