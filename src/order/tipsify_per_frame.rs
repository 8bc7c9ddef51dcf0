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

use super::sander07::{Facing, LAMBDA, dot_rule_sort, patches};
use super::tipsify::FIFO_CACHE;
use super::{Clustered, Lookup, Cost, Method, Ordering, Orders, Params};
use crate::error::Result;
use crate::mesh::Scene;

pub static METHOD: Method = Method {
    name: "tipsify-per-frame",
    summary: "animated baseline: sander07 on each keyframe, one index buffer per keyframe",
    source: "Han & Sander 2017, Table 1 \"Tipsify\" (Sander, Nehab & Barczak 2007 per frame)",
    peer: false,
    per_node: true,
    cost: Cost::Linear,
    params: &[FIFO_CACHE, LAMBDA],
    build,
};

fn build(params: &Params) -> Box<dyn Ordering> {
    Box::new(TipsifyPerFrame { cache: params.int(&FIFO_CACHE) as u32, lambda: params.float(&LAMBDA) })
}

struct TipsifyPerFrame {
    cache: u32,
    lambda: f64,
}

impl Ordering for TipsifyPerFrame {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        let mesh = &scene.mesh;
        let patches = patches(mesh, &scene.topology.vertex_triangles, self.cache, self.lambda);
        let clusters: Vec<&[u32]> = patches.starts.windows(2).map(|w| &patches.order[w[0]..w[1]]).collect();
        let buffers: Vec<Clustered> = scene
            .frames
            .frames
            .par_iter()
            .map(|positions| {
                let sorted = dot_rule_sort(positions, &mesh.triangles, &clusters, Facing::Unit);
                Clustered::concat(sorted.iter().map(|&c| clusters[c]))
            })
            .collect();
        let frame_ids: Vec<u16> = (0..scene.frames.len()).map(|f| f as u16).collect();
        Ok(Orders { buffers, lookup: Lookup::per_frame(&frame_ids), iterations: None, converged: true, phases: vec![], reused: 0.0 })
    }
}
