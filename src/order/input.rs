//! `input`: the triangles in the order the file stores them — the baseline every paper reports
//! (Bogomjakov & Gotsman 2002, Table 2 "original"; Nehab et al. 2006 compare against it too).

use super::{Cost, Method, Order, Ordering, Orders, Params};
use crate::error::Result;
use crate::mesh::Scene;

pub static METHOD: Method = Method {
    name: "input",
    summary: "the file's own triangle order (baseline)",
    source: "baseline in every paper",
    peer: false,
    per_node: false,
    cost: Cost::Trivial,
    params: &[],
    build,
};

fn build(_: &Params) -> Box<dyn Ordering> {
    Box::new(Input)
}

struct Input;

impl Ordering for Input {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        Ok(Orders::from((0..scene.mesh.triangle_count() as u32).collect::<Order>()))
    }
}
