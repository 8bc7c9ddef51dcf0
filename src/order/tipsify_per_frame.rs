//! `tipsify-per-frame`: the static method of Sander, Nehab & Barczak 2007 (our `sander07`)
//! applied to every keyframe separately, one index buffer per keyframe: the "Tipsify" columns
//! of Han & Sander 2017, Table 1, which "reduces overdraw significantly, but requires between
//! 30-70 index buffers".
//!
//! Tipsify and the fast linear clustering read connectivity only, so they run once; only the
//! dot-rule sort of the clusters, which reads positions, is done per frame, on that frame's
//! framed positions. The buffer of frame f is exactly what `sander07` gives for the mesh posed at
//! frame f.

use rayon::prelude::*;

use super::per_node::{Lookup, NodeOrders};
use super::sander07::{LAMBDA, dot_rule_sort, patches};
use super::tipsify::FIFO_CACHE;
use super::{Clustered, Method, Order, OrderInput, Ordering, Params, needs_nodes};
use crate::error::Result;
use crate::mesh::keyframes::Keyframes;

pub static METHOD: Method = Method {
    name: "tipsify-per-frame",
    summary: "animated baseline: sander07 on each keyframe, one index buffer per keyframe",
    source: "Han & Sander 2017, Table 1 \"Tipsify\" (Sander, Nehab & Barczak 2007 per frame)",
    peer: false,
    per_node: true,
    params: &[FIFO_CACHE, LAMBDA],
    build,
};

fn build(params: &Params) -> Box<dyn Ordering> {
    Box::new(TipsifyPerFrame { cache: params.int("cache") as u32, lambda: params.float("lambda") })
}

struct TipsifyPerFrame {
    cache: u32,
    lambda: f64,
}

impl Ordering for TipsifyPerFrame {
    fn order(&self, _: &OrderInput) -> Result<Order> {
        Err(needs_nodes(METHOD.name))
    }

    fn order_nodes(&self, input: &OrderInput, keyframes: &Keyframes) -> Result<NodeOrders> {
        let mesh = input.mesh;
        let patches = patches(mesh, &input.topology.vertex_triangles, self.cache, self.lambda);
        let clusters: Vec<&[u32]> = patches.starts.windows(2).map(|w| &patches.order[w[0]..w[1]]).collect();
        let buffers: Vec<Order> = keyframes
            .frames
            .par_iter()
            .map(|positions| {
                let sorted = dot_rule_sort(positions, &mesh.triangles, &clusters);
                Clustered::concat(sorted.iter().map(|&c| clusters[c])).order
            })
            .collect();
        let frame_ids: Vec<u16> = (0..keyframes.len()).map(|f| f as u16).collect();
        Ok(NodeOrders {
            buffers,
            lookup: Lookup::per_frame(&frame_ids),
            iterations: None,
            converged: true,
            phases: vec![],
        })
    }
}
