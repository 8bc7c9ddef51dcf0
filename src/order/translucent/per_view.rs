//! `translucent-per-view`: the reference a static sort is measured against (issue 18's baseline):
//! for each optimization viewpoint, the triangles sorted back to front by centroid depth, the
//! per-frame sort an engine does when it can afford one. Its buffers are picked by the viewpoint
//! nearest the eye (and by keyframe for an animation), as Han & Sander 2017's are ([`Lookup`]),
//! so from its own viewpoints it is the centroid sort exactly. It is not exact per pixel: two
//! triangles whose centroids sort one way can overlap the other way (long thin ones, or ones that
//! cross). Depths are the sums of the three corner depths in f64 from the frame's centre, as
//! `front-to-back` takes them; ties keep the input order.

use rayon::prelude::*;

use super::super::front_to_back::centroid_depths;
use super::super::key_sort::by_increasing;
use super::super::orders::Lookup;
use super::super::{Clustered, Cost, Method, Ordering, Orders, ParamInfo, ParamKind, Params};
use crate::error::{Error, Result};
use crate::mesh::Scene;
use crate::raster::views::icosphere_directions;

const VIEWS: ParamInfo = ParamInfo {
    name: "views",
    default: "162",
    kind: ParamKind::Choice(&["12", "42", "162", "642"]),
    help: "optimization viewpoints: an icosphere of this many directions (ico:N views use the same)",
};

pub static METHOD: Method = Method {
    name: "translucent-per-view",
    summary: "translucent reference: back to front by centroid depth, one buffer per viewpoint",
    source: "the per-frame sort of engines; baseline of the static sorts of Austin 2014 (seed 003)",
    peer: false,
    per_node: true,
    cost: Cost::Heavy,
    params: &[VIEWS],
    build,
};

fn build(params: &Params) -> Box<dyn Ordering> {
    Box::new(PerView { views: params.word(&VIEWS).parse().expect("the schema lists only numbers") })
}

struct PerView {
    views: u32,
}

impl Ordering for PerView {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        let directions = icosphere_directions(self.views);
        let frames = &scene.frames;
        let count = frames.len() * directions.len();
        if count > usize::from(u16::MAX) {
            return Err(Error::usage(format!(
                "translucent-per-view: {} keyframes × {} viewpoints is over 65535 index buffers; use fewer views",
                frames.len(),
                directions.len()
            )));
        }
        let mut buffers = Vec::with_capacity(count);
        for f in 0..frames.len() {
            // From the centre, not divided by the radius (which would not change the order, but
            // its rounding would break exact ties differently in a rescaled copy), as
            // `front-to-back` takes them. Farthest from the eye (smallest projection on the
            // direction to it) first. The viewpoints are sorted in parallel: each is a sort of
            // every triangle, and they are independent.
            let triangles = frames.triangles(f, &scene.mesh);
            let positions = &frames.frames[f];
            buffers.par_extend(directions.par_iter().map(|direction| {
                let depth = centroid_depths(positions, frames.framing.center, direction.as_dvec3(), &triangles);
                Clustered::single(by_increasing(&depth))
            }));
        }
        let assignment: Vec<u16> = (0..count as u16).collect();
        Ok(Orders {
            buffers,
            lookup: Lookup::nearest(&directions, &assignment),
            iterations: None,
            converged: true,
            phases: vec![],
            reused: 0.0,
        })
    }
}
