//! `front-to-back`: triangles sorted nearest first for one view direction, the view-dependent
//! ideal that Nehab, Barczak & Sander 2006 (§1, Fig. 1a) compare with: least overdraw from that
//! view, poor vertex locality. The direction points from the model towards the eye, as figure
//! views do; triangles are sorted by decreasing centroid projection on it (stable, so ties keep
//! the input order).

use glam::Vec3;

use super::{Method, Order, Ordering, Orders, ParamInfo, ParamKind, Params};
use crate::error::{Error, Result};
use crate::mesh::Scene;

const COMPONENT: ParamKind = ParamKind::Float { min: -1e6, max: 1e6 };

const X: ParamInfo = ParamInfo { name: "x", default: "0", kind: COMPONENT, help: "view direction (model → eye), x" };

const Y: ParamInfo = ParamInfo { name: "y", default: "0", kind: COMPONENT, help: "view direction, y" };

const Z: ParamInfo = ParamInfo { name: "z", default: "1", kind: COMPONENT, help: "view direction, z" };

pub static METHOD: Method = Method {
    name: "front-to-back",
    summary: "view-dependent: triangles sorted nearest first for one view direction",
    source: "Nehab, Barczak & Sander 2006, §1 and Fig. 1a (the depth-sorted reference)",
    peer: false,
    per_node: false,
    params: &[X, Y, Z],
    build,
};

fn build(params: &Params) -> Box<dyn Ordering> {
    let d = [&X, &Y, &Z].map(|p| params.float(p) as f32);
    Box::new(FrontToBack { direction: Vec3::from_array(d) })
}

struct FrontToBack {
    direction: Vec3,
}

impl Ordering for FrontToBack {
    fn order(&self, scene: &Scene) -> Result<Orders> {
        let direction = self.direction.try_normalize().ok_or_else(|| {
            Error::usage("method `front-to-back`: the view direction x, y, z must not be zero".to_string())
        })?;
        let mesh = &scene.mesh;
        let depth: Vec<f32> = mesh
            .triangles
            .iter()
            .map(|t| t.iter().map(|&v| mesh.positions[v as usize].dot(direction)).sum::<f32>())
            .collect();
        let mut order: Order = (0..mesh.triangle_count() as u32).collect();
        order.sort_by(|&a, &b| depth[b as usize].total_cmp(&depth[a as usize]));
        Ok(Orders::from(order))
    }
}
