//! Triangle orderings: one file per method, all behind [`Ordering`], found by name in [`METHODS`].
//!
//! To add an ordering: write `src/order/<name>.rs` with a `pub static METHOD: Method` (its paper
//! cited at the top, its parameters declared in the schema) and add one line to [`METHODS`].
//! `triorder methods`, `eval`, every experiment that says `methods = "all"`, and the conformance
//! tests (permutation, winding, determinism, bad parameters) pick it up with no other change.

pub mod params;

mod centroid_grid;
pub mod feedback_arc_set;
pub(crate) mod forsyth;
mod front_to_back;
mod grid_walk;
mod hilbert;
mod hoppe;
mod hs17;
mod input;
mod kcache;
mod meshopt_fifo;
mod meshopt_overdraw;
mod meshopt_vcache;
mod mla;
mod nehab;
pub mod overdraw_graph;
pub mod per_node;
pub(crate) mod planar_clusters;
mod random;
mod recursive_cut;
pub(crate) mod sander07;
mod snake;
mod strips;
pub(crate) mod tipsify;
mod tipsify_per_frame;

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::mesh::keyframes::Keyframes;
use crate::topology::Topology;
pub use params::{MethodSpec, ParamInfo, ParamKind, Params};
pub use per_node::{Lookup, NodeOrders};

/// A draw order: position `i` holds the id of the triangle drawn `i`-th. Always a permutation of
/// `0..triangle_count`; triangles keep their vertex order (and so their winding).
pub type Order = Vec<u32>;

/// What an ordering gets: the mesh and the connectivity derived from it once.
#[derive(Clone, Copy)]
pub struct OrderInput<'a> {
    pub mesh: &'a Mesh,
    pub topology: &'a Topology,
}

/// A triangle-ordering algorithm with its parameters already bound.
pub trait Ordering: Send + Sync {
    fn order(&self, input: &OrderInput) -> Result<Order>;

    /// The order with the clusters it was built from, for methods that draw clusters one after
    /// another (figures colour them); any other method is one cluster.
    fn clustered(&self, input: &OrderInput) -> Result<Clustered> {
        Ok(Clustered::single(self.order(input)?))
    }

    /// The index buffers for drawing `keyframes` (framed poses of `input.mesh`'s connectivity)
    /// and the table that picks one per keyframe and view direction. A static method orders the
    /// rest mesh `input.mesh` once and uses that one buffer everywhere, as an engine would ship
    /// it; keyframe- and view-dependent methods (those registered with `per_node`) override this.
    fn order_nodes(&self, input: &OrderInput, keyframes: &Keyframes) -> Result<NodeOrders> {
        Ok(NodeOrders::single(self.order(input)?, keyframes.len()))
    }
}

/// A draw order made of clusters drawn one after another: cluster `i` is
/// `order[starts[i]..starts[i + 1]]`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Clustered {
    pub order: Order,
    pub starts: Vec<usize>,
}

impl Clustered {
    pub fn single(order: Order) -> Clustered {
        let starts = vec![0, order.len()];
        Clustered { order, starts }
    }

    /// The clusters drawn in the given sequence.
    pub fn concat<'a>(clusters: impl Iterator<Item = &'a [u32]>) -> Clustered {
        let (mut order, mut starts) = (Vec::new(), vec![0]);
        for cluster in clusters {
            order.extend_from_slice(cluster);
            starts.push(order.len());
        }
        Clustered { order, starts }
    }

    pub fn cluster_count(&self) -> usize {
        self.starts.len() - 1
    }
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
    /// True for methods whose output is several index buffers chosen per keyframe and view
    /// ([`Ordering::order_nodes`]); their single-order [`Ordering::order`] is an error.
    pub per_node: bool,
    pub params: &'static [ParamInfo],
    pub build: fn(&Params) -> Box<dyn Ordering>,
}

/// Every method, in the order `triorder methods` lists them.
pub static METHODS: &[&Method] = &[
    &input::METHOD,
    &random::METHOD,
    &snake::METHOD,
    &hilbert::METHOD,
    &recursive_cut::METHOD,
    &mla::METHOD,
    &strips::METHOD,
    &hoppe::METHOD,
    &tipsify::METHOD,
    &forsyth::METHOD,
    &kcache::METHOD,
    &meshopt_vcache::METHOD,
    &meshopt_fifo::METHOD,
    &sander07::METHOD,
    &meshopt_overdraw::METHOD,
    &nehab::METHOD,
    &front_to_back::METHOD,
    &tipsify_per_frame::METHOD,
    &hs17::METHOD,
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

/// Runs `resolved` on `input` and checks the result is a permutation, so no caller ever measures
/// or writes a wrong order silently.
pub fn run(resolved: &Resolved, input: &OrderInput) -> Result<Order> {
    let order = resolved.ordering.order(input)?;
    check_permutation(&order, input.mesh.triangle_count()).map_err(|why| {
        Error::usage(format!("internal error: `{}` returned an invalid order: {why}", resolved.canonical()))
    })?;
    Ok(order)
}

/// [`run`] keeping the clusters, checked too: they must tile the order.
pub fn run_clustered(resolved: &Resolved, input: &OrderInput) -> Result<Clustered> {
    let clustered = resolved.ordering.clustered(input)?;
    let n = input.mesh.triangle_count();
    check_permutation(&clustered.order, n)
        .and_then(
            |()| if tiles(&clustered.starts, n) { Ok(()) } else { Err("its clusters do not tile the order".into()) },
        )
        .map_err(|why| {
            Error::usage(format!("internal error: `{}` returned an invalid order: {why}", resolved.canonical()))
        })?;
    Ok(clustered)
}

/// [`run`] for every method and any animation: checks that each buffer is a permutation and that
/// the lookup covers every keyframe with a buffer that exists.
pub fn run_nodes(resolved: &Resolved, input: &OrderInput, keyframes: &Keyframes) -> Result<NodeOrders> {
    let nodes = resolved.ordering.order_nodes(input, keyframes)?;
    let n = input.mesh.triangle_count();
    let checked = nodes
        .buffers
        .iter()
        .enumerate()
        .try_for_each(|(i, b)| check_permutation(b, n).map_err(|why| format!("buffer {i}: {why}")))
        .and_then(|()| {
            if nodes.lookup.frames() != keyframes.len() {
                Err(format!("its lookup has {} frames for {} keyframes", nodes.lookup.frames(), keyframes.len()))
            } else if nodes.lookup.cells().iter().any(|&b| usize::from(b) >= nodes.buffers.len()) {
                Err(format!("its lookup names a buffer beyond its {}", nodes.buffers.len()))
            } else {
                Ok(())
            }
        });
    checked.map_err(|why| {
        Error::usage(format!("internal error: `{}` returned invalid index buffers: {why}", resolved.canonical()))
    })?;
    Ok(nodes)
}

/// The error a per-node method gives when asked for one order.
pub fn needs_nodes(method: &str) -> Error {
    Error::usage(format!(
        "method `{method}` draws with several index buffers chosen per keyframe and view, not one order: \
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
