//! Triangle orderings: one file per method, all behind [`Ordering`], found by name in [`METHODS`].
//!
//! To add an ordering: write `src/order/<name>.rs` with a `pub static METHOD: Method` (its paper
//! cited at the top, its parameters declared as consts in the schema) and add its name to the
//! `registry!` list below, which declares the module and lists it in [`METHODS`]. `triorder
//! methods`, `eval`, every experiment that says `methods = "all"`, and the conformance tests
//! (well-formed and deterministic orders on every test mesh, what `order` writes, bad
//! parameters) pick it up with no other change.
//!
//! The files here are the methods, except [`orders`] (what a method returns), [`params`]
//! (method specs) and [`key_sort`] (the radix sort by depth or distance that some share);
//! families that share helpers have a folder: `curves/` (snake, Hilbert), `meshopt/` (the peers),
//! `mla/`, `nehab/` and `cheap_cuts/` (their helpers beside them).

pub mod key_sort;
pub mod levels;
pub mod orders;
pub mod params;

pub mod curves;
pub mod meshopt;

use crate::error::{Error, Result};
use crate::mesh::Scene;
use crate::mesh::frames::Kind;
pub use orders::{Clustered, Lookup, Orders};
pub use params::{MethodSpec, ParamInfo, ParamKind, Params};

/// A draw order: position `i` holds the id of the triangle drawn `i`-th. Always a permutation of
/// `0..triangle_count`; triangles keep their vertex order (and so their winding).
pub type Order = Vec<u32>;

/// A triangle-ordering algorithm with its parameters already bound.
pub trait Ordering: Send + Sync {
    /// Orders the triangles of `scene.mesh`. A static method returns one order
    /// (`Ok(order.into())`, or a [`Clustered`] order for methods that draw clusters one after
    /// another); a keyframe- or view-dependent method returns several buffers and the
    /// [`Lookup`] that picks one per frame of `scene.frames` and view direction.
    fn order(&self, scene: &Scene) -> Result<Orders>;
}

/// A registered method: what `triorder methods` shows, and how to build it from checked parameters.
pub struct Method {
    pub name: &'static str,
    /// One line: what it does.
    pub summary: &'static str,
    /// The paper (with section) or library it follows.
    pub source: &'static str,
    /// True for methods that call another library (the `meshopt` crate) rather than our own code.
    pub peer: bool,
    /// True for methods whose [`Orders`] may hold several buffers, picked per frame and view.
    /// Declared so that what needs one order (`triorder order`, the drawings of a mesh in its
    /// draw order) can refuse the method before running it.
    pub per_node: bool,
    /// How long it takes per triangle, by order of magnitude: what sharded runs balance by.
    pub cost: Cost,
    pub params: &'static [ParamInfo],
    pub build: fn(&Params) -> Box<dyn Ordering>,
}

/// A method's time per triangle by order of magnitude, as measured on an AMD EPYC (2 threads) over
/// the shared models (`universal-acmr-vs-cache`, the `seconds` rows): what a sharded run
/// balances its shards by before anything has run (`experiment::shard`). A class, not a
/// measurement: within a class methods differ by up to 3×, and the classes 10× and more.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cost {
    /// A copy or a shuffle: input, random (about 0.01 µs per triangle).
    Trivial,
    /// One or a few linear passes: curves, strips, Tipsify, Forsyth, the meshopt peers (0.05–0.5 µs).
    Linear,
    /// Local searches or per-view work: Hoppe, K-cache, Han–Sander (1–3 µs).
    Heavy,
    /// Global optimizations: METIS cuts, minimum linear arrangement, Nehab's clustering (5–12 µs).
    Heaviest,
}

impl Cost {
    /// The class's typical time per triangle, in microseconds.
    pub fn micros_per_triangle(self) -> f64 {
        match self {
            Cost::Trivial => 0.01,
            Cost::Linear => 0.25,
            Cost::Heavy => 2.0,
            Cost::Heaviest => 8.0,
        }
    }
}

/// Declares a method's module, unless it lives in a family's folder (`family::method`).
macro_rules! declare {
    ($module:ident) => {
        pub mod $module;
    };
    ($family:ident :: $module:ident) => {};
}

/// The registry: each entry declares its module and lists its `METHOD` in [`METHODS`], in the
/// order `triorder methods` shows them and `methods = "all"` runs them.
macro_rules! registry {
    ($($($segment:ident)::+),* $(,)?) => {
        $(declare!($($segment)::+);)*

        /// Every method, in the order `triorder methods` lists them.
        pub static METHODS: &[&Method] = &[$(&$($segment)::+::METHOD),*];
    };
}

pub mod draw_calls;
pub mod translucent;

registry![
    input,
    random,
    curves::snake,
    curves::hilbert,
    recursive_cut,
    mla,
    strips,
    hoppe,
    hoppe_d3dx,
    tipsify,
    forsyth,
    kcache,
    meshopt::vcache,
    meshopt::fifo,
    sander07,
    meshopt::overdraw,
    cheap_cuts,
    nehab,
    front_to_back,
    tipsify_per_frame,
    hs17,
    translucent::topo,
    translucent::coverage,
    translucent::dist_angle,
    translucent::peeling,
    translucent::per_view,
];

/// A method spec resolved against the registry: ready to run, with its canonical name.
pub struct Resolved {
    pub method: &'static Method,
    pub params: Params,
    pub ordering: Box<dyn Ordering>,
}

impl Resolved {
    /// The spec with every parameter written out, as results record it.
    pub fn canonical(&self) -> String {
        self.params.canonical()
    }
}

/// Looks a method up by name; an unknown name lists the known ones.
pub fn find(name: &str) -> Result<&'static Method> {
    METHODS.iter().copied().find(|m| m.name == name).ok_or_else(|| {
        let known: Vec<_> = METHODS.iter().map(|m| m.name).collect();
        Error::usage(format!("unknown method `{name}` (known: {}; see `triorder methods`)", known.join(", ")))
    })
}

/// Parses and checks `spec` (`name:k=v,...`); randomised methods default to `run_seed`.
pub fn resolve(spec: &str, run_seed: u64) -> Result<Resolved> {
    let parsed = MethodSpec::parse(spec)?;
    let method = find(&parsed.name)?;
    let params = Params::resolve(method.name, method.params, &parsed, run_seed)?;
    let ordering = (method.build)(&params);
    Ok(Resolved { method, params, ordering })
}

/// Runs `resolved` on `scene` and checks what it returns: every buffer a permutation whose
/// clusters tile it, a lookup for one frame or for every frame of the scene, naming buffers that
/// exist. So no caller ever measures or writes a wrong order silently.
pub fn run(resolved: &Resolved, scene: &Scene) -> Result<Orders> {
    let orders = match &scene.frames.kind {
        Kind::Levels(levels) => levels::run(resolved, scene, levels)?,
        _ => resolved.ordering.order(scene)?,
    };
    let frames = scene.frames.len();
    let checked = orders
        .buffers
        .iter()
        .enumerate()
        .try_for_each(|(i, b)| {
            let n = drawn_by(&orders.lookup, i, frames)
                .map_or(scene.mesh.triangle_count(), |f| scene.frames.triangles(f, &scene.mesh).len());
            check_permutation(&b.order, n)
                .and_then(|()| if tiles(&b.starts, n) { Ok(()) } else { Err("its clusters do not tile it".into()) })
                .map_err(|why| format!("buffer {i}: {why}"))
        })
        .and_then(|()| {
            if orders.buffers.is_empty() {
                Err("no buffer".to_string())
            } else if orders.lookup.frames() != 1 && orders.lookup.frames() != frames {
                Err(format!("its lookup has {} frames for {frames}", orders.lookup.frames()))
            } else if orders.lookup.cells().iter().any(|&b| usize::from(b) >= orders.buffers.len()) {
                Err(format!("its lookup names a buffer beyond its {}", orders.buffers.len()))
            } else {
                Ok(())
            }
        });
    checked.map_err(|why| {
        Error::usage(format!("internal error: `{}` returned invalid orders: {why}", resolved.canonical()))
    })?;
    Ok(orders)
}

/// The first of `frames` frames whose lookup cells pick buffer `b`: the frame whose triangles it
/// orders (on a progressive mesh each level has its own).
pub fn drawn_by(lookup: &Lookup, b: usize, frames: usize) -> Option<usize> {
    let cells = lookup.cells_per_frame();
    (0..frames).find(|&f| {
        let f = f.min(lookup.frames() - 1);
        lookup.cells()[f * cells..(f + 1) * cells].iter().any(|&c| usize::from(c) == b)
    })
}

/// The error for a method with several buffers where one order is needed.
pub fn needs_one_order(method: &str, what: &str) -> Error {
    Error::usage(format!(
        "method `{method}` draws with several index buffers chosen per keyframe and view, not one order, so {what}; \
         measure it with `triorder eval` (add --views; for an animation, --clip), or in an experiment"
    ))
}

/// True when cluster `starts` cut an order of `n` triangles into consecutive runs: from 0 to `n`,
/// never decreasing.
pub fn tiles(starts: &[usize], n: usize) -> bool {
    starts.first() == Some(&0) && starts.last() == Some(&n) && starts.windows(2).all(|w| w[0] <= w[1])
}

/// Ok when `order` holds each of `0..n` exactly once.
pub fn check_permutation(order: &[u32], n: usize) -> std::result::Result<(), String> {
    if order.len() != n {
        return Err(format!("{} entries for {n} triangles", order.len()));
    }
    let mut seen = vec![false; n];
    for &t in order {
        match seen.get_mut(t as usize) {
            None => return Err(format!("triangle id {t} out of range")),
            Some(true) => return Err(format!("triangle {t} appears twice")),
            Some(s) => *s = true,
        }
    }
    Ok(())
}
