//! `random`: a uniformly random permutation — the worst-case reference of Bogomjakov & Gotsman
//! 2002 (Fig. 5, "performs dismally", ACMR → 3 for small caches) and Nehab et al. 2006 (Fig. 7, 8).
//! Seeded with a portable generator (PCG 64 MCG) so a seed gives the same order on every machine.

use rand::SeedableRng;
use rand::seq::SliceRandom;

use super::{Cost, Method, Order, Ordering, Orders, ParamInfo, ParamKind, Params};
use crate::error::Result;
use crate::mesh::Scene;

pub static METHOD: Method = Method {
    name: "random",
    summary: "uniformly random permutation (worst-case reference)",
    source: "Bogomjakov & Gotsman 2002, Fig. 5; Nehab et al. 2006, Fig. 7-8",
    peer: false,
    per_node: false,
    cost: Cost::Trivial,
    params: &[ParamInfo { name: "seed", default: "", kind: ParamKind::Seed, help: "random seed" }],
    build,
};

fn build(params: &Params) -> Box<dyn Ordering> {
    Box::new(Random { seed: params.seed() })
}

struct Random {
    seed: u64,
}

impl Ordering for Random {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        let mut order: Order = (0..scene.mesh.triangle_count() as u32).collect();
        order.shuffle(&mut rand_pcg::Pcg64Mcg::seed_from_u64(self.seed));
        Ok(Orders::from(order))
    }
}
