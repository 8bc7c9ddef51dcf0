//! `meshopt-fifo` (peer): meshoptimizer's `optimizeVertexCacheFifo`, its implementation of
//! Tipsify (Sander, Nehab & Barczak 2007, "Fast triangle reordering for vertex locality and
//! reduced overdraw", §3), run through the `meshopt` crate for a given FIFO size.

use super::{Method, Order, OrderInput, Ordering, Params};
use crate::error::Result;
use crate::peer;

pub static METHOD: Method = Method {
    name: "meshopt-fifo",
    summary: "meshoptimizer optimizeVertexCacheFifo (Tipsify) [peer]",
    source: "meshoptimizer via the meshopt crate; after Sander, Nehab & Barczak 2007, §3",
    peer: true,
    per_node: false,
    params: &[super::tipsify::FIFO_CACHE],
    build,
};

fn build(params: &Params) -> Box<dyn Ordering> {
    Box::new(MeshoptFifo { cache: params.int("cache") as u32 })
}

struct MeshoptFifo {
    cache: u32,
}

impl Ordering for MeshoptFifo {
    fn order(&self, input: &OrderInput) -> Result<Order> {
        let mesh = input.mesh;
        let indices = meshopt::optimize_vertex_cache_fifo(&peer::index_buffer(mesh), mesh.vertex_count(), self.cache);
        peer::order_from_index_buffer(mesh, input.topology, &indices)
    }
}
