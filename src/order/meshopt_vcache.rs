//! `meshopt-vcache` (peer): meshoptimizer's `optimizeVertexCache`, a Forsyth-style
//! (Forsyth 2006, "Linear-Speed Vertex Cache Optimisation") greedy ordering with a tuned score
//! table, run through the `meshopt` crate. A labelled peer: not our code, our yardstick.

use super::{Method, Order, OrderInput, Ordering, Params};
use crate::error::Result;
use crate::peer;

pub static METHOD: Method = Method {
    name: "meshopt-vcache",
    summary: "meshoptimizer optimizeVertexCache (Forsyth-style) [peer]",
    source: "meshoptimizer via the meshopt crate; after Forsyth 2006",
    peer: true,
    per_node: false,
    params: &[],
    build,
};

fn build(_: &Params) -> Box<dyn Ordering> {
    Box::new(MeshoptVcache)
}

struct MeshoptVcache;

impl Ordering for MeshoptVcache {
    fn order(&self, input: &OrderInput) -> Result<Order> {
        let mesh = input.mesh;
        let indices = meshopt::optimize_vertex_cache(&peer::index_buffer(mesh), mesh.vertex_count());
        peer::order_from_index_buffer(mesh, input.topology, &indices)
    }
}
