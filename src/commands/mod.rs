//! One function per subcommand. Each parses its strings into library types up front (so a bad
//! method, cache or view set fails before any work), calls the library, and prints.

mod experiments;
mod tables;

pub use experiments::{bench, plot, reproduce, run};

use std::path::Path;

use triorder::eval::{self, MeasureOptions};
use triorder::gpu::render_time::{MAX_FRAMES, Shading};
use triorder::mesh::keyframes::Keyframes;
use triorder::mesh::source::AnimationSource;
use triorder::mesh::{self, Mesh, report::MeshReport};
use triorder::metrics::CacheModel;
use triorder::order::{self, METHODS, params::describe_kind};
use triorder::raster::{self, RasterBackend, ViewSet};
use triorder::topology::Topology;
use triorder::{Error, Result};

use crate::{Animation, Common, Measure};

/// Parsed measurement options plus the chosen backend.
struct Measuring {
    options: MeasureOptions,
    raster: Box<dyn RasterBackend>,
}

impl Measuring {
    fn new(m: &Measure, seed: u64) -> Result<Measuring> {
        let gpu_vertices = m.caches.iter().any(|c| c == eval::GPU_CACHE);
        let simulated: Vec<&String> = m.caches.iter().filter(|c| *c != eval::GPU_CACHE).collect();
        let caches = if m.caches.is_empty() {
            vec![CacheModel::Fifo(16)]
        } else {
            simulated.into_iter().map(|c| c.parse()).collect::<Result<_>>()?
        };
        let views = m.views.as_deref().map(str::parse::<ViewSet>).transpose()?;
        let raster = raster::backend(&m.backend)?;
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

/// Loads a mesh, derives its topology and prints what is unusual about it on stderr.
fn open(source: &str, common: &Common) -> Result<(Mesh, Topology)> {
    let data = mesh::source::data_dir(common.data.as_deref());
    let mesh = mesh::source::open(source, data.as_deref(), common.seed)?;
    let topology = Topology::new(&mesh);
    let report = MeshReport::new(&mesh, &topology);
    eprintln!("{source}: {report}");
    Ok((mesh, topology))
}

pub fn methods() -> Result<()> {
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
    json: bool,
    common: &Common,
) -> Result<()> {
    let measuring = Measuring::new(measure, common.seed)?;
    let specs: Vec<&str> =
        if methods.is_empty() { vec!["input"] } else { methods.iter().map(String::as_str).collect() };
    let resolved = specs.iter().map(|s| order::resolve(s, common.seed)).collect::<Result<Vec<_>>>()?;
    let animation = animation_source(source, animation)?;
    if animation.is_some() || resolved.iter().any(|r| r.method.per_node) {
        return eval_nodes(source, animation, &resolved, &measuring, json, common);
    }
    let (mesh, topology) = open(source, common)?;
    let mut table = tables::EvalTable::new(&measuring.options);
    for method in &resolved {
        let e = eval::evaluate(&mesh, &topology, method, &measuring.options, measuring.raster.as_ref())?;
        if json {
            println!("{}", tables::eval_json(&mesh, &e, &measuring.raster.describe()));
        } else {
            table.push(&e);
        }
    }
    if !json {
        print!("{}", table.render(&mesh));
    }
    Ok(())
}

/// The animation `source` and the `--clip`/`--frames`/`--subdiv` options name, if any.
fn animation_source(source: &str, options: &Animation) -> Result<Option<AnimationSource>> {
    let given = options.clip.is_some() || options.frames.is_some() || options.subdiv.is_some();
    if !given {
        return AnimationSource::parse(source).transpose();
    }
    if source.contains('#') {
        return Err(Error::usage(format!(
            "`{source}` names its animation after `#`; drop --clip, --frames and --subdiv"
        )));
    }
    let mut keys = vec![format!("clip={}", options.clip.as_deref().unwrap_or("all"))];
    keys.extend(options.frames.map(|n| format!("frames={n}")));
    keys.extend(options.subdiv.map(|l| format!("subdiv={l}")));
    AnimationSource::parse(&format!("{source}#{}", keys.join(","))).transpose()
}

/// `eval` through index buffers per (keyframe, view): an animation, or a static mesh as one
/// frame when a method is keyframe- or view-dependent.
fn eval_nodes(
    source: &str,
    animation: Option<AnimationSource>,
    methods: &[order::Resolved],
    measuring: &Measuring,
    json: bool,
    common: &Common,
) -> Result<()> {
    let (mesh, topology, keyframes) = match animation {
        Some(animation) => {
            let data = mesh::source::data_dir(common.data.as_deref());
            let (mesh, keyframes) = animation.open(data.as_deref())?;
            let topology = Topology::new(&mesh);
            let clips: Vec<String> = keyframes.clips.iter().map(|(n, r)| format!("{n} ({} frames)", r.len())).collect();
            eprintln!("{source}: {}; clips: {}", MeshReport::new(&mesh, &topology), clips.join(", "));
            (mesh, topology, keyframes)
        }
        None => {
            let (mesh, topology) = open(source, common)?;
            let keyframes = Keyframes::still(&mesh);
            (mesh, topology, keyframes)
        }
    };
    let mut table = tables::EvalTable::with_buffers(&measuring.options);
    for method in methods {
        let e =
            eval::evaluate_nodes(&mesh, &topology, &keyframes, method, &measuring.options, measuring.raster.as_ref())?;
        if json {
            println!("{}", tables::nodes_json(&mesh, &keyframes, &e, &measuring.raster.describe()));
        } else {
            table.push_nodes(&e);
        }
    }
    if !json {
        print!("{}", table.render(&mesh));
    }
    Ok(())
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
        return Err(order::needs_nodes(resolved.method.name));
    }
    if AnimationSource::parse(source).is_some() {
        return Err(Error::usage(format!(
            "`{source}`: `order` writes a static mesh and would drop the animation; \
             name the file without `#...` to reorder its rest mesh"
        )));
    }
    if output.is_dir() {
        return Err(Error::output(output, "is a directory"));
    }
    if mesh::save::format_of(output).is_none() {
        return Err(Error::output(output, "unknown output format (use .obj, .ply or .glb)"));
    }
    let (mesh, topology) = open(source, common)?;
    let identity: Vec<u32> = (0..mesh.triangle_count() as u32).collect();
    let before = eval::measure(&mesh, &identity, &measuring.options, measuring.raster.as_ref())?;
    let after = eval::evaluate(&mesh, &topology, &resolved, &measuring.options, measuring.raster.as_ref())?;
    let mut reordered = mesh.reordered(&after.order);
    if remap_vertices {
        reordered = reordered.remap_vertices_first_use();
    }
    let saved = mesh::save::save(&reordered, output)?;
    for dropped in &saved.dropped {
        eprintln!("warning: {}: not written: {dropped}", output.display());
    }
    println!("{}", tables::before_after(&before, &after));
    println!(
        "wrote {} ({} triangles, {} ordered in {:.3} s)",
        output.display(),
        reordered.triangle_count(),
        after.method,
        after.seconds
    );
    Ok(())
}
