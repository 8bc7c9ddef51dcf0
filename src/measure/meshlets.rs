//! Meshlet metrics: what a triangle order makes of a mesh-shader pipeline (issue 19).
//!
//! Mesh-shader pipelines draw meshlets, small clusters of at most [`MAX_VERTICES`] vertices and
//! [`MAX_TRIANGLES`] triangles, whose vertices are shaded once per meshlet. A scan builder
//! (meshoptimizer's `buildMeshletsScan`) cuts the index buffer into meshlets in draw order,
//! starting a new one when the next triangle would overflow either limit, so the triangle order
//! decides the meshlets: an order that keeps neighbours together fills them, one that jumps
//! about leaves them half empty and shades shared vertices in several. Reported for the scan
//! builder on the order, and, as the peer, for meshoptimizer's own optimized builder
//! (`buildMeshlets`, cone weight [`CONE_WEIGHT`]), which regroups triangles itself:
//! - `meshlets`: how many;
//! - `meshlet_vertex_fill`, `meshlet_triangle_fill`: their mean vertex and triangle counts over the
//!   limits (1 is full);
//! - `meshlet_vertices_per_triangle`: the sum of their vertex counts over the triangles, the
//!   meshlet pipeline's ATVR-like cost (0.5 is the limit of a large regular mesh);
//! - `meshlet_cone_culled` (with a view set): the share of meshlets a normal cone rejects as back
//!   facing (`computeMeshletBounds`, meshoptimizer's test for perspective and orthographic
//!   views), the mean over views;
//! - the same with `_optimized` for the optimized builder.
//!
//! Buffers count as often as draws use them, as for the cache metrics; cone tests use each
//! frame's positions and the buffer that draws each view.

use meshopt::Meshlets;
use rayon::prelude::*;

use super::{Draws, MeasureOptions, Metric, Name, Value};
use crate::error::Result;
use crate::mesh::meshopt_positions;
use crate::raster::Camera;

/// The common mesh-shader limits (NVIDIA's recommendation; meshoptimizer's default example).
pub const MAX_VERTICES: usize = 64;
pub const MAX_TRIANGLES: usize = 124;
/// meshoptimizer's suggested balance between meshlet size and cone culling.
pub const CONE_WEIGHT: f32 = 0.25;

pub struct MeshletMetrics;

pub static METRIC: MeshletMetrics = MeshletMetrics;

static NAMES: &[Name] = &[
    Name { name: "meshlets", label: "meshlets (scan builder, 64 vertices, 124 triangles)", needs: "`meshlets = true`", optimum: None },
    Name { name: "meshlet_vertex_fill", label: "meshlet vertex fill (mean vertices ÷ 64)", needs: "`meshlets = true`", optimum: None },
    Name {
        name: "meshlet_triangle_fill",
        label: "meshlet triangle fill (mean triangles ÷ 124)",
        needs: "`meshlets = true`",
        optimum: None,
    },
    Name {
        name: "meshlet_vertices_per_triangle",
        label: "meshlet vertices per triangle (Σ meshlet vertices ÷ triangles)",
        needs: "`meshlets = true`",
        optimum: None,
    },
    Name {
        name: "meshlet_cone_culled",
        label: "share of meshlets a normal cone culls (mean over views)",
        needs: "`meshlets = true` and `views`",
        optimum: None,
    },
    Name {
        name: "meshlets_optimized",
        label: "meshlets (meshoptimizer's optimized builder)",
        needs: "`meshlets = true`",
        optimum: None,
    },
    Name {
        name: "meshlet_vertices_per_triangle_optimized",
        label: "meshlet vertices per triangle (optimized builder)",
        needs: "`meshlets = true`",
        optimum: None,
    },
    Name {
        name: "meshlet_cone_culled_optimized",
        label: "share of meshlets a normal cone culls (optimized builder)",
        needs: "`meshlets = true` and `views`",
        optimum: None,
    },
];

impl Metric for MeshletMetrics {
    fn names(&self) -> &'static [Name] {
        NAMES
    }

    fn reported(&self, options: &MeasureOptions) -> Vec<&'static str> {
        if !options.meshlets {
            return Vec::new();
        }
        let culled = ["meshlet_cone_culled", "meshlet_cone_culled_optimized"];
        NAMES.iter().map(|n| n.name).filter(|n| options.views.is_some() || !culled.contains(n)).collect()
    }

    fn measure(&self, draws: &Draws) -> Result<Vec<Value>> {
        let vertex_count = draws.scene.mesh.vertex_count();
        let rest = draws.scene.mesh.meshopt_positions();
        let buffers: Vec<[Meshlets; 2]> = (0..draws.orders.buffers.len())
            .map(|b| {
                let indices: Vec<u32> = draws.triangles(b).into_iter().flatten().collect();
                [
                    meshopt::build_meshlets_scan(&indices, vertex_count, MAX_VERTICES, MAX_TRIANGLES),
                    meshopt::build_meshlets(&indices, &rest, MAX_VERTICES, MAX_TRIANGLES, CONE_WEIGHT),
                ]
            })
            .collect();
        let mut values = Vec::new();
        for (builder, suffix) in [(0, ""), (1, "_optimized")] {
            let (mut uses, mut count, mut vertices, mut triangles) = (0u64, 0u64, 0u64, 0u64);
            for (b, n) in draws.used() {
                let meshlets = &buffers[b][builder].meshlets;
                uses += n;
                count += n * meshlets.len() as u64;
                vertices += n * meshlets.iter().map(|m| u64::from(m.vertex_count)).sum::<u64>();
                triangles += n * meshlets.iter().map(|m| u64::from(m.triangle_count)).sum::<u64>();
            }
            let per = |x: u64, of: u64| x as f64 / of.max(1) as f64;
            if builder == 0 {
                values.push(Value::new("meshlets", per(count, uses)));
                values.push(Value::new("meshlet_vertex_fill", per(vertices, count) / MAX_VERTICES as f64));
                values.push(Value::new("meshlet_triangle_fill", per(triangles, count) / MAX_TRIANGLES as f64));
                values.push(Value::new("meshlet_vertices_per_triangle", per(vertices, triangles)));
            } else {
                values.push(Value::new("meshlets_optimized", per(count, uses)));
                values.push(Value::new("meshlet_vertices_per_triangle_optimized", per(vertices, triangles)));
            }
            if draws.options.views.is_some() {
                let name = if suffix.is_empty() { "meshlet_cone_culled" } else { "meshlet_cone_culled_optimized" };
                let (mut culled, mut views) = (0.0, 0usize);
                for f in draws.frames.clone() {
                    let positions = meshopt_positions(draws.positions(f));
                    for (b, group) in draws.groups(f) {
                        let meshlets = &buffers[b][builder];
                        let bounds: Vec<meshopt::Bounds> =
                            meshlets.iter().map(|m| meshopt::compute_meshlet_bounds(m, &positions)).collect();
                        for v in group {
                            culled += cone_culled(&bounds, &draws.cameras[v]);
                            views += 1;
                        }
                    }
                }
                if views > 0 {
                    values.push(Value { views: draws.views(), ..Value::new(name, culled / views as f64) });
                }
            }
        }
        Ok(values)
    }

    /// The orders in parallel: meshoptimizer's builders are pure functions of their input, so
    /// the values are those of measuring the orders one by one.
    fn measure_many(&self, many: &[Draws]) -> Result<Vec<Vec<Value>>> {
        many.par_iter().map(|draws| self.measure(draws)).collect()
    }

    fn columns(&self, values: &[&Value]) -> Vec<(String, String)> {
        let find = |metric: &str| values.iter().find(|v| v.metric == metric).map(|v| v.value);
        let mut cell = match (find("meshlets"), find("meshlet_vertices_per_triangle")) {
            (Some(n), Some(vpt)) => format!("{n:.0}/{vpt:.3}"),
            _ => return Vec::new(),
        };
        if let Some(culled) = find("meshlet_cone_culled") {
            cell += &format!("/{:.1}%", culled * 100.0);
        }
        vec![("meshlets/verts per tri/cone-culled".to_string(), cell)]
    }
}

/// The share of `bounds` whose normal cone says every triangle faces away from `camera`, by
/// meshoptimizer's tests: `dot(normalize(apex − eye), axis) ≥ cutoff` for a perspective view,
/// `dot(view direction, axis) ≥ cutoff` for an orthographic one.
fn cone_culled(bounds: &[meshopt::Bounds], camera: &Camera) -> f64 {
    let culled = bounds
        .iter()
        .filter(|b| {
            let axis = glam::Vec3::from(b.cone_axis);
            let towards = if camera.perspective {
                (glam::Vec3::from(b.cone_apex) - camera.eye).normalize_or_zero()
            } else {
                camera.forward
            };
            towards.dot(axis) >= b.cone_cutoff
        })
        .count();
    culled as f64 / bounds.len().max(1) as f64
}
