//! `meshopt-vcache` (peer): meshoptimizer's `optimizeVertexCache`, a Forsyth-style
//! (Forsyth 2006, "Linear-Speed Vertex Cache Optimisation") greedy ordering with a tuned score
//! table, run through the `meshopt` crate. A labelled peer: not our code, our yardstick.

use super::order_from_index_buffer;
use crate::error::Result;
use crate::mesh::Scene;
use crate::order::{Cost, Method, Ordering, Orders, Params};

pub static METHOD: Method = Method {
    name: "meshopt-vcache",
    summary: "meshoptimizer optimizeVertexCache (Forsyth-style) [peer]",
    source: "meshoptimizer via the meshopt crate; after Forsyth 2006",
    peer: true,
    per_node: false,
    cost: Cost::Linear,
    params: &[],
    build,
};

fn build(_: &Params) -> Box<dyn Ordering> {
    Box::new(MeshoptVcache)
}

struct MeshoptVcache;

impl Ordering for MeshoptVcache {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        let mesh = &scene.mesh;
        let indices = meshopt::optimize_vertex_cache(&mesh.index_buffer(), mesh.vertex_count());
        order_from_index_buffer(mesh, &scene.topology, &indices).map(Orders::from)
    }
}
