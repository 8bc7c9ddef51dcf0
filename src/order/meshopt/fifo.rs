//! `meshopt-fifo` (peer): meshoptimizer's `optimizeVertexCacheFifo`, its implementation of
//! Tipsify (Sander, Nehab & Barczak 2007, "Fast triangle reordering for vertex locality and
//! reduced overdraw", §3), run through the `meshopt` crate for a given FIFO size.

use super::order_from_index_buffer;
use crate::error::Result;
use crate::mesh::Scene;
use crate::order::{Cost, Method, Ordering, Orders, Params};

pub static METHOD: Method = Method {
    name: "meshopt-fifo",
    summary: "meshoptimizer optimizeVertexCacheFifo (Tipsify) [peer]",
    source: "meshoptimizer via the meshopt crate; after Sander, Nehab & Barczak 2007, §3",
    peer: true,
    per_node: false,
    cost: Cost::Linear,
    params: &[crate::order::tipsify::FIFO_CACHE],
    build,
};

fn build(params: &Params) -> Box<dyn Ordering> {
    Box::new(MeshoptFifo { cache: params.int(&crate::order::tipsify::FIFO_CACHE) as u32 })
}

struct MeshoptFifo {
    cache: u32,
}

impl Ordering for MeshoptFifo {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        let mesh = &scene.mesh;
        let indices = meshopt::optimize_vertex_cache_fifo(&mesh.index_buffer(), mesh.vertex_count(), self.cache);
        order_from_index_buffer(mesh, &scene.topology, &indices).map(Orders::from)
    }
}
