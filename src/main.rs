//! The `triorder` command line: thin wrappers over the library, one function per subcommand in
//! `commands/`. Every error is printed as `error: FILE: problem` on stderr with exit status 2.

mod commands;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{Args, Parser, Subcommand};

/// Triangle-order optimization: reorder meshes, measure vertex-cache misses and overdraw, and
/// regenerate the figures of the triangle-ordering papers.
#[derive(Parser)]
#[command(name = "triorder", version, about, long_about = None, propagate_version = true, after_help = EXAMPLES)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    #[command(flatten)]
    common: Common,
}

const EXAMPLES: &str = "Examples:
  triorder reproduce --quick          every experiment on small meshes (no data needed), CSV + SVG
  triorder eval assets/spot.obj -m tipsify -m nehab:clusters=32 --views ico:42 --res 256
  triorder order assets/spot.obj -o spot.glb -m meshopt-overdraw

A model named like models/bun_zipper.ply is read from the data directory: --data DIR, else
$TRIORDER_DATA, else ../shared/data (scripts/fetch-data.sh downloads the models). README.md
explains every command, metric and figure.";

/// Options shared by every command that reads meshes.
#[derive(Args, Clone)]
struct Common {
    /// Directory that model paths are resolved against (default: $TRIORDER_DATA, else
    /// ../shared/data if it exists). scripts/fetch-data.sh downloads the public models.
    #[arg(long, value_name = "DIR", global = true)]
    data: Option<PathBuf>,
    /// Seed for randomised methods (`random`), seeded meshes (`disk:N`) and `random:N` views.
    #[arg(long, default_value_t = 0, global = true)]
    seed: u64,
    /// Let a glTF file's buffer URIs name files outside its own folder (absolute paths, file:
    /// URIs, ../ out of the folder). Off by default: assets come from anywhere, and a URI could
    /// otherwise read any file on disk.
    #[arg(long, global = true)]
    allow_outside_uris: bool,
}

/// What to measure, as in `eval` and `order`.
#[derive(Args, Clone)]
struct Measure {
    /// Vertex-cache model(s): fifo:K, lru:K or batch:CACHE,WARP,PRIMGROUP; nvidia, amd or intel
    /// (the vendors' batches and reuse from published measurements: Kerbl et al. 2018 for NVIDIA
    /// and AMD, Kapoulkine 2017 for Intel; `triorder methods` gives their parameters); or `gpu` to
    /// count vertex-shader invocations on the GPU (pipeline statistics). Repeatable; the first
    /// model is the one summarised. Default fifo:16.
    #[arg(long = "cache", value_name = "MODEL")]
    caches: Vec<String>,
    /// Measure overdraw over a view set: axis6, ico:N (12, 42, 162, 642, 2562) or random:N.
    #[arg(long, value_name = "SET")]
    views: Option<String>,
    /// Image side in pixels for overdraw.
    #[arg(long, default_value_t = 512)]
    res: u32,
    /// Time rendering on the GPU from every view of --views with this shader: pixel (procedural
    /// texture and per-pixel lighting) or vertex (a long per-vertex loop). Repeatable.
    #[arg(long, value_name = "pixel|vertex")]
    render: Vec<String>,
    /// Timed frames per view and shader for --render (their median is reported).
    #[arg(long, default_value_t = 30, value_name = "N")]
    render_frames: usize,
    /// Also measure, over --views, how wrong each order is when the mesh is drawn translucent
    /// (alpha 0.5, blended in draw order) against the exact depth-sorted blend: the share of
    /// covered pixels visibly wrong, the colour RMSE and the wrongly blended fragment pairs per
    /// pixel (CPU reference rasterizer).
    #[arg(long)]
    translucency: bool,
    /// Also measure the meshlets each order makes (meshoptimizer's scan builder, 64 vertices and
    /// 124 triangles, and its optimized builder as the peer): count, fill, vertices per triangle,
    /// and with --views the share of meshlets a normal cone culls.
    #[arg(long)]
    meshlets: bool,
    /// Raster backend for overdraw: cpu (the reference rasterizer) or gpu (Vulkan through wgpu;
    /// Mesa's lavapipe will do where there is no GPU).
    #[arg(long, default_value = "cpu", value_name = "cpu|gpu")]
    backend: String,
}

/// How `order` writes the asset.
#[derive(Args, Clone)]
struct Writing {
    /// Also renumber vertices in first-use order (vertex-fetch locality), each primitive's
    /// attributes and morph targets permuted together.
    #[arg(long)]
    remap_vertices: bool,
    /// Fail, writing nothing, when the output format cannot hold everything the input does (an
    /// animation written as OBJ, materials as PLY); without it that is one warning.
    #[arg(long)]
    strict: bool,
}

/// What `eval` orders and how it prints.
#[derive(Args, Clone)]
struct EvalReport {
    /// One JSON object per method per line instead of a table.
    #[arg(long)]
    json: bool,
    /// Order each draw call (glTF primitive, run of OBJ faces with one group and material) on its
    /// own and measure the calls in sequence, as an engine draws the asset and as `order` writes
    /// it. Without it the whole mesh is one order, as in the papers.
    #[arg(long)]
    draw_calls: bool,
}

/// Progressive levels to measure (`eval`) or write (`order`), for a static mesh.
#[derive(Args, Clone, Default)]
struct Progressive {
    /// Simplify the mesh by vertex removals (least quadric error first) to each of these
    /// fractions of its triangles, e.g. 1,0.5,0.25,0.1 (Bogomjakov & Gotsman 2002, §3): `eval`
    /// measures every level, `order` writes them.
    #[arg(long, value_name = "F,F,...", value_delimiter = ',')]
    levels: Vec<f64>,
    /// How the method's sequence follows the levels: smart or simple (the paper's updates, from
    /// the full mesh's sequence), or reorder (the method run anew on each level).
    #[arg(long, default_value = "smart", value_name = "smart|simple|reorder")]
    update: String,
}

/// Which animation to measure, for `eval` on a skinned glTF/GLB file.
#[derive(Args, Clone, Default)]
struct Animation {
    /// Measure the animation, not the rest mesh: this clip, or `all`. Every keyframe is drawn
    /// from every view of --views with the index buffer the method's lookup picks (Han & Sander
    /// 2017, §4); static methods order the rest mesh and use that one buffer throughout.
    #[arg(long, value_name = "NAME|all")]
    clip: Option<String>,
    /// Resample each clip to N evenly spaced frames instead of its keyframes (implies --clip all).
    #[arg(long, value_name = "N")]
    frames: Option<usize>,
    /// Levels of Loop subdivision of the rest mesh, skinning weights and morphs included
    /// (implies --clip all).
    #[arg(long, value_name = "L")]
    subdiv: Option<u32>,
}

/// The parts of `bench`.
#[derive(Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum BenchPart {
    /// Our cache simulators and overdraw counter vs meshoptimizer's analyzers.
    Metrics,
    /// Our orderings vs their meshoptimizer peers.
    Orderings,
    /// The GPU raster backend vs the CPU one (ico:162 at 512²); needs a Vulkan adapter.
    Backends,
    /// Progressive meshes: the simplification history vs meshoptimizer's simplifier, and the
    /// cost of the simple and smart updates per vertex removal.
    Progressive,
}

#[derive(Subcommand)]
enum Command {
    /// List every ordering method with its parameters, defaults and source paper or library.
    Methods,
    /// Reorder an asset for an engine: the same asset, only faster to draw.
    ///
    /// Each draw call (glTF primitive, run of OBJ faces with one group and material, a PLY) is
    /// ordered on its own. Same format in and out keeps everything else: a glTF/GLB is rewritten
    /// in place (nodes, skins, animations, morph targets, materials, every attribute and
    /// extension kept; only index data, or vertex data with --remap-vertices, changes), an OBJ
    /// keeps mtllib, usemtl, o, g and s, a PLY every element and property. Another output format
    /// keeps one mesh and says in one warning what it cannot hold (--strict: an error). Prints
    /// the ACMR of the draw calls in sequence before and after (and OVR with --views). Outputs
    /// are written atomically: on any failure no partial file is left.
    ///
    /// With --levels it writes a progressive mesh (Bogomjakov & Gotsman 2002, §3): the mesh
    /// simplified to each fraction of its triangles, the method's sequence kept by --update. A
    /// GLB holds the vertices once and one index buffer per level (scene i draws level i, the
    /// default scene the first); OBJ and PLY get one file per level, OUT.leveli.EXT, each with
    /// every vertex so vertex numbers hold across levels.
    Order {
        /// Input mesh: a file (OBJ, PLY, GLB/glTF) or a procedural spec such as grid:16x8.
        input: String,
        /// Output file; its extension picks the format.
        #[arg(short, long)]
        output: PathBuf,
        /// Ordering method with parameters, e.g. meshopt-overdraw:threshold=1.05.
        #[arg(short, long, default_value = "meshopt-vcache")]
        method: String,
        #[command(flatten)]
        writing: Writing,
        #[command(flatten)]
        measure: Measure,
        #[command(flatten)]
        progressive: Progressive,
    },
    /// Order a mesh with one or more methods and measure each order.
    ///
    /// With --clip (or --frames, --subdiv) the mesh is a skinned glTF/GLB animation; so it is
    /// when the mesh is written PATH#clip=NAME,frames=N,subdiv=L. Keyframe- and view-dependent
    /// methods (hs17, tipsify-per-frame) give several index buffers, counted in `buffers`. With
    /// --levels every method is measured at each level of a progressive mesh.
    Eval {
        /// Mesh file or procedural spec.
        mesh: String,
        /// Method spec(s), repeatable. Default: input.
        #[arg(short, long = "method", value_name = "SPEC")]
        methods: Vec<String>,
        #[command(flatten)]
        measure: Measure,
        #[command(flatten)]
        animation: Animation,
        #[command(flatten)]
        progressive: Progressive,
        #[command(flatten)]
        report: EvalReport,
    },
    /// Run an experiment spec (experiments/*.toml) and write results/ID.csv.
    Run {
        spec: PathBuf,
        /// Small models and views (seconds); writes under results/quick/.
        #[arg(long)]
        quick: bool,
        /// Raster backend for overdraw, overriding the spec's: cpu or gpu (Vulkan through wgpu).
        #[arg(long, value_name = "cpu|gpu")]
        backend: Option<String>,
        /// Run shard K of N (K = 1..N) of the spec's (model, method) units, balanced by estimated
        /// cost, into results/ID.shard-K-of-N.csv; `triorder merge SPEC` joins the shards into
        /// results/ID.csv. A shard already complete for this spec and version is skipped. For
        /// job arrays: scripts/slurm/submit.sh.
        #[arg(long, value_name = "K/N")]
        shard: Option<String>,
    },
    /// Join the shard files of a sharded run (run SPEC --shard K/N) into results/ID.csv, after
    /// checking that every shard is present and from this spec and version.
    Merge {
        spec: PathBuf,
        /// Merge the quick run's shards (results/quick/).
        #[arg(long)]
        quick: bool,
        /// The number of shards, when results/ holds shards of several cuts of the spec.
        #[arg(long, value_name = "N")]
        shards: Option<usize>,
    },
    /// Draw paper-figures/ID.svg from results/ID.csv (no recomputation).
    Plot {
        spec: PathBuf,
        /// Plot the quick run's CSV into paper-figures/quick/.
        #[arg(long)]
        quick: bool,
    },
    /// Rewrite the tables generated from results CSVs in the gallery (paper-figures/README.md):
    /// each sits between `<!-- generated from results/ID.csv: … -->` and `<!-- end generated -->`
    /// and is never typed by hand (src/figure/gallery.rs has the recipe syntax).
    Gallery {
        /// Only check: exit with status 2, naming the stale tables, when one differs from its CSV.
        #[arg(long)]
        check: bool,
        /// The markdown file to refresh.
        #[arg(long, default_value = "paper-figures/README.md")]
        file: PathBuf,
    },
    /// Run and plot every experiment in experiments/.
    Reproduce {
        /// Small models and views only: works on a fresh clone with no data directory.
        #[arg(long)]
        quick: bool,
        /// Only the experiment with this id.
        #[arg(long, value_name = "ID")]
        only: Option<String>,
        /// Raster backend for overdraw in every spec: cpu or gpu (Vulkan through wgpu).
        #[arg(long, value_name = "cpu|gpu")]
        backend: Option<String>,
        /// Skip the specs that need a GPU even where there is one: with only Mesa's software
        /// rasterizer (lavapipe) they time the CPU emulating a GPU, and the frame-time specs alone
        /// take minutes.
        #[arg(long, conflicts_with = "backend")]
        cpu_only: bool,
    },
    /// Time our metrics and orderings against meshoptimizer (the meshopt crate) in the same run.
    Bench {
        /// Repetitions per timing (the median is reported).
        #[arg(long, default_value_t = 11)]
        reps: usize,
        /// Mesh(es) to time, repeatable (default: three large shared models, or a procedural
        /// sphere and the bundled cow when there is no data directory).
        #[arg(long = "mesh", value_name = "MESH")]
        meshes: Vec<String>,
        /// Time one part only. Without it: metrics and orderings (the backends need a GPU).
        #[arg(long, value_enum)]
        only: Option<BenchPart>,
    },
}

fn main() -> ExitCode {
    quiet_mesa();
    // After quiet_mesa, which must run before any thread exists: this starts one.
    if let Err(e) = triorder::atomic::remove_temporaries_on_signals() {
        eprintln!("warning: cannot handle interrupts ({e}): an interrupted output may leave a .triorder-*.tmp file");
    }
    let cli = Cli::parse();
    let common = &cli.common;
    triorder::mesh::gltf::allow_outside_uris(common.allow_outside_uris);
    let result = match cli.command {
        Command::Methods => commands::methods(),
        Command::Order { input, output, method, writing, measure, progressive } => {
            commands::order(&input, &output, &method, &writing, &measure, &progressive, common)
        }
        Command::Eval { mesh, methods, measure, animation, progressive, report } => {
            commands::eval(&mesh, &methods, &measure, &animation, &progressive, &report, common)
        }
        Command::Run { spec, quick, backend, shard } => commands::run(&spec, quick, backend, shard.as_deref(), common),
        Command::Merge { spec, quick, shards } => commands::merge(&spec, quick, shards, common),
        Command::Plot { spec, quick } => commands::plot(&spec, quick, common),
        Command::Gallery { check, file } => commands::gallery(&file, check),
        Command::Reproduce { quick, only, backend, cpu_only } => {
            commands::reproduce(quick, only.as_deref(), backend, cpu_only, common)
        }
        Command::Bench { reps, meshes, only } => commands::bench(reps, &meshes, only, common),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", triorder::error::printable(&e.to_string()));
            ExitCode::from(2)
        }
    }
}

/// Mesa's Vulkan drivers print `error: XDG_RUNTIME_DIR is invalid or not set in the environment.`
/// for every device they open when that variable is unset: they look there for a display server,
/// which triorder, drawing off-screen, never uses. The message reads as triorder's own, so the
/// variable is pointed at the temporary directory when it is unset. This runs first, before any
/// thread exists, which is what makes changing the environment sound.
fn quiet_mesa() {
    if std::env::var_os("XDG_RUNTIME_DIR").is_none_or(|d| d.is_empty()) {
        // SAFETY: no other thread exists yet to read the environment concurrently.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", std::env::temp_dir()) };
    }
}
