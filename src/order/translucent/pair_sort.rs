//! What the pair-based sorts (topo, coverage, peeling) share: their parameters (which viewpoints
//! find the overlapping pairs) and the ordering that finds the pairs and hands them, with the
//! triangles' facets, to each sort's own last step.

use super::super::{Order, Ordering, Orders, ParamInfo, ParamKind, Params};
use super::pairs::{self, Facet, Pair};
use crate::error::Result;
use crate::mesh::Scene;

pub const VIEWS: ParamInfo = ParamInfo {
    name: "views",
    default: "42",
    kind: ParamKind::Choice(&["12", "42", "162", "642"]),
    help: "viewpoints that find the overlapping pairs: an icosphere of this many directions",
};

pub const RES: ParamInfo = ParamInfo {
    name: "res",
    default: "256",
    kind: ParamKind::Int { min: 16, max: 4096 },
    help: "image size for finding overlapping pairs (pixels per side)",
};

/// A sort's last step: the draw order from the facets and the overlapping pairs.
pub type Step = fn(&[Facet], &[Pair]) -> Order;

/// The ordering of a pair-based sort whose last step is `step`, with `params`' viewpoints.
pub fn build(params: &Params, step: Step) -> Box<dyn Ordering> {
    Box::new(PairSort {
        views: params.word(&VIEWS).parse().expect("the schema lists only numbers"),
        res: params.int(&RES) as u32,
        step,
    })
}

struct PairSort {
    views: u32,
    res: u32,
    step: Step,
}

impl Ordering for PairSort {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        let facets = pairs::facets(scene);
        let overlapping = pairs::overlapping(scene, self.views, self.res)?;
        Ok(Orders::from((self.step)(&facets, &overlapping)))
    }
}
