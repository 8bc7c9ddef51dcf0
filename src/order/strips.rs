//! `strips` (peer): the "triangle strips" column of Bogomjakov & Gotsman 2002, Table 2 — the
//! order a stripifier draws triangles in, which is what a strip-era renderer's vertex cache saw
//! (B&G: ACMR 1.06–1.10 at k = 10, against 0.81–0.83 for their recursive cut). We use
//! meshoptimizer's strip pipeline through the `meshopt` crate: `meshopt_optimizeVertexCacheStrip`
//! (a Forsyth-style order with a score table tuned for strips), `meshopt_stripify` (after Evans,
//! Skiena & Varshney 1996), then `meshopt_unstripify` to the triangle list the strip draws, mapped
//! back to our triangle ids. Not our code: a labelled peer.
//!
//! Why the pre-pass: the stripifier only joins triangles found in an 8-triangle window of its
//! input, so on a file's scan order it makes almost no strips (bunny_2k: ACMR 2.45 at k = 10,
//! barely below the input's 2.55). With it, the strips are long and the order behaves like the
//! strips B&G measured — about one new vertex per triangle (ACMR ≈ 1.00 at k = 10 on bunny_2k,
//! bun_zipper, horse and spot; B&G: 1.06–1.10 with Xiang, Held & Mitchell's stripper): the
//! stripifier discards the cache locality of the order it was given.
//!
//! Unstripify drops zero-area index triples, so the input's degenerate triangles (a repeated
//! corner) would vanish: they are kept out of the strip and drawn after it, in input order.
//! Strip triangles come back rotated but with their winding (the stripifier only joins a
//! triangle through an edge in the direction the strip's parity needs);
//! [`order_from_index_buffer`] accepts rotations and rejects anything else, so a wrong
//! strip would be an error, never a silently flipped triangle.

use super::meshopt::order_from_index_buffer;
use super::{Cost, Method, Ordering, Orders, Params};
use crate::error::{Error, Result};
use crate::mesh::Scene;

pub static METHOD: Method = Method {
    name: "strips",
    summary: "meshoptimizer strip order + stripify, drawn as the strip's triangles (B&G Table 2 strips) [peer]",
    source: "meshoptimizer via the meshopt crate (after Evans et al. 1996); Bogomjakov & Gotsman 2002, Table 2",
    peer: true,
    per_node: false,
    cost: Cost::Linear,
    params: &[],
    build,
};

fn build(_: &Params) -> Box<dyn Ordering> {
    Box::new(Strips)
}

struct Strips;

/// No primitive restart: strips are joined by degenerate triangles, as on B&G's hardware
/// (meshoptimizer reads restart index 0 as "none").
const NO_RESTART: u32 = 0;

impl Ordering for Strips {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        let mesh = &scene.mesh;
        let degenerate = |t: &[u32; 3]| t[0] == t[1] || t[1] == t[2] || t[2] == t[0];
        let proper: Vec<u32> = mesh.triangles.iter().filter(|t| !degenerate(t)).flatten().copied().collect();
        let peer_error = |e: meshopt::Error| Error::usage(format!("internal error: meshopt stripify failed: {e}"));
        // The stripifier joins triangles found in an 8-triangle window of its input, so it is
        // given meshoptimizer's strip-oriented order first, as meshoptimizer prescribes. With no
        // proper triangle there is nothing to strip (and meshoptimizer asserts that its input and
        // output buffers differ, which two empty vectors do not).
        let mut list = if proper.is_empty() {
            Vec::new()
        } else {
            let proper = meshopt::optimize_vertex_cache_strip(&proper, mesh.vertex_count());
            let strip = meshopt::stripify(&proper, mesh.vertex_count(), NO_RESTART).map_err(peer_error)?;
            meshopt::unstripify(&strip, NO_RESTART).map_err(peer_error)?
        };
        list.extend(mesh.triangles.iter().filter(|t| degenerate(t)).flatten());
        order_from_index_buffer(mesh, &scene.topology, &list).map(Orders::from)
    }
}
