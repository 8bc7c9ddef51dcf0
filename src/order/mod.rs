//! Triangle orderings: one file per method, all behind [`Ordering`], found by name in [`METHODS`].
//!
//! To add an ordering: write `src/order/<name>.rs` with a `pub static METHOD: Method` (its paper
//! cited at the top, its parameters declared in the schema) and add one line to [`METHODS`].
//! `triorder methods`, `eval`, every experiment that says `methods = "all"`, and the conformance
//! tests (permutation, winding, determinism, bad parameters) pick it up with no other change.

pub mod params;

mod centroid_grid;
pub(crate) mod forsyth;
mod grid_walk;
mod hilbert;
mod hoppe;
mod input;
mod kcache;
mod meshopt_fifo;
mod meshopt_overdraw;
mod meshopt_vcache;
mod mla;
mod random;
mod recursive_cut;
mod snake;
mod strips;
pub(crate) mod tipsify;

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::topology::Topology;
pub use params::{MethodSpec, ParamInfo, ParamKind, Params};

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
    &meshopt_overdraw::METHOD,
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
