//! `meshopt-overdraw` (peer): meshoptimizer's `optimizeOverdraw` on top of `optimizeVertexCache`,
//! its take on Sander, Nehab & Barczak 2007 §4-5 (linear clustering at cache-flush boundaries,
//! then clusters sorted by the dot rule). Its threshold differs from the paper's λ: a cluster is
//! cut once its local ACMR is within `threshold` × the global ACMR.
//!
//! meshoptimizer is given the positions in the mesh's unit frame
//! ([`crate::mesh::frames::unit_positions`]), not as loaded: it computes its sort keys in f32, so
//! at 1e-30 scale its triangle normals underflow to zero, at 1e30 its areas overflow, and far from
//! the origin its centroids lose their offsets to rounding; each gave another order for the same
//! shape.

use super::order_from_index_buffer;
use crate::error::Result;
use crate::mesh::frames::unit_positions;
use crate::mesh::{Scene, meshopt_positions};
use crate::order::{Cost, Method, Ordering, Orders, ParamInfo, ParamKind, Params};

const THRESHOLD: ParamInfo = ParamInfo {
    name: "threshold",
    default: "1.05",
    kind: ParamKind::Float { min: 1.0, max: 3.0 },
    help: "allowed ACMR degradation (1.05 = 5%) in exchange for less overdraw",
};

pub static METHOD: Method = Method {
    name: "meshopt-overdraw",
    summary: "meshoptimizer optimizeVertexCache + optimizeOverdraw (Sander 2007 clustering) [peer]",
    source: "meshoptimizer via the meshopt crate; after Sander, Nehab & Barczak 2007, §4-5",
    peer: true,
    per_node: false,
    cost: Cost::Linear,
    params: &[THRESHOLD],
    build,
};

fn build(params: &Params) -> Box<dyn Ordering> {
    Box::new(MeshoptOverdraw { threshold: params.float(&THRESHOLD) as f32 })
}

struct MeshoptOverdraw {
    threshold: f32,
}

impl Ordering for MeshoptOverdraw {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        let mesh = &scene.mesh;
        let mut indices = meshopt::optimize_vertex_cache(&mesh.index_buffer(), mesh.vertex_count());
        let unit = unit_positions(&mesh.positions);
        meshopt::optimize_overdraw_in_place(&mut indices, &meshopt_positions(&unit), self.threshold);
        order_from_index_buffer(mesh, &scene.topology, &indices).map(Orders::from)
    }
}
