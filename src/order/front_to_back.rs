//! `front-to-back`: triangles sorted nearest first for one view direction, the view-dependent
//! ideal that Nehab, Barczak & Sander 2006 (§1, Fig. 1a) compare with: least overdraw from that
//! view, poor vertex locality. The direction points from the model towards the eye, as figure
//! views do; triangles are sorted by decreasing centroid projection on it (stable, so ties keep
//! the input order).
//!
//! The depths are taken from the mesh's centre ([`Framing`]) in f64, each triangle's three corner
//! depths summed in increasing order, so the order does not depend on where the mesh stands or
//! its units: in f32 world coordinates a mesh far from the origin summed its offset into every
//! depth and lost the differences between them to rounding, and a 1e-30 or 1e30 one rounded
//! differently. They are not divided by the radius (the unit frame's scale, which would not
//! change their order): that rounding would break exact ties, and real meshes have them (two
//! triangles of `spot` whose corner heights sum to the same six-decimal value in the file).

use glam::{DVec3, Vec3};

use super::key_sort::by_increasing;
use super::{Cost, Method, Ordering, Orders, ParamInfo, ParamKind, Params};
use crate::error::{Error, Result};
use crate::mesh::Framing;
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
    cost: Cost::Linear,
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
        let center = Framing::of(&mesh.positions).center;
        let depth = centroid_depths(&mesh.positions, center, direction.as_dvec3(), &mesh.triangles);
        // Nearest first: by decreasing depth, which negation turns into increasing exactly.
        let nearness: Vec<f64> = depth.iter().map(|d| -d).collect();
        let order = by_increasing(&nearness);
        Ok(Orders::from(order))
    }
}

/// Each triangle's depth along `direction` (unit length) from `center`, three times its
/// centroid's: its corner depths in f64, summed in increasing order so that the sum does not
/// depend on which corner the triangle lists first.
pub(crate) fn centroid_depths(positions: &[Vec3], center: DVec3, direction: DVec3, triangles: &[[u32; 3]]) -> Vec<f64> {
    let vertex_depth: Vec<f64> = positions.iter().map(|p| (p.as_dvec3() - center).dot(direction)).collect();
    triangles
        .iter()
        .map(|t| {
            let mut d = t.map(|v| vertex_depth[v as usize]);
            d.sort_by(f64::total_cmp);
            d.iter().sum()
        })
        .collect()
}
