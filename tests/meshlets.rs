//! The meshlet metrics (`--meshlets`, src/measure/meshlets.rs) on meshes whose answer is known,
//! and against meshoptimizer's builders called directly.

use triorder::measure::{self, MeasureOptions, Value};
use triorder::mesh::Source;
use triorder::order;
use triorder::raster::ViewSet;

fn options(views: Option<&str>) -> MeasureOptions {
    MeasureOptions {
        meshlets: true,
        views: views.map(|v| v.parse::<ViewSet>().unwrap()),
        res: 64,
        ..MeasureOptions::default()
    }
}

/// The summary values of `method` on `mesh`, by metric name.
fn values(mesh: &str, method: &str, options: &MeasureOptions) -> std::collections::HashMap<&'static str, f64> {
    let scene = Source::parse(mesh).unwrap().open(None, 0).unwrap();
    let raster = measure::backend("cpu").unwrap();
    let evaluation = measure::evaluate(&scene, &order::resolve(method, 0).unwrap(), options, raster.as_ref()).unwrap();
    evaluation.values().filter(|v: &&Value| v.is_summary()).map(|v| (v.metric, v.value)).collect()
}

#[test]
fn four_separate_squares_make_one_meshlet_of_sixteen_vertices() {
    // layers:4 is four unit squares, each of two triangles and four vertices of its own.
    let v = values("layers:4", "input", &options(None));
    assert_eq!(v["meshlets"], 1.0);
    assert_eq!(v["meshlet_vertices_per_triangle"], 16.0 / 8.0);
    assert_eq!(v["meshlet_vertex_fill"], 16.0 / 64.0);
    assert_eq!(v["meshlet_triangle_fill"], 8.0 / 124.0);
    assert!(!v.contains_key("meshlet_cone_culled"), "cone culling needs a view set");
}

#[test]
fn counts_are_meshoptimizers_scan_of_the_order() {
    let scene = Source::parse("sphere:3000").unwrap().open(None, 0).unwrap();
    let method = order::resolve("tipsify", 0).unwrap();
    let order = &method.ordering.order(&scene).unwrap().buffers[0].order;
    let indices: Vec<u32> = scene.mesh.triangles_in_order(order).into_iter().flatten().collect();
    let scan = meshopt::build_meshlets_scan(&indices, scene.mesh.vertex_count(), 64, 124);
    let vertices: u32 = scan.meshlets.iter().map(|m| m.vertex_count).sum();
    let v = values("sphere:3000", "tipsify", &options(None));
    assert_eq!(v["meshlets"], scan.len() as f64);
    assert_eq!(v["meshlet_vertices_per_triangle"], f64::from(vertices) / scene.mesh.triangle_count() as f64);
}

#[test]
fn a_cache_order_makes_fewer_meshlets_that_cones_can_cull() {
    let o = options(Some("ico:42"));
    let (tipsify, random) = (values("sphere:3000", "tipsify", &o), values("sphere:3000", "random", &o));
    // Random meshlets gather triangles from all over the sphere: about three vertices each, and
    // normals in every direction, so no cone rejects one.
    assert!(random["meshlet_vertices_per_triangle"] > 2.5, "{random:?}");
    assert!(tipsify["meshlet_vertices_per_triangle"] < 1.0, "{tipsify:?}");
    assert!(tipsify["meshlets"] * 2.0 < random["meshlets"]);
    assert_eq!(random["meshlet_cone_culled"], 0.0);
    assert!(tipsify["meshlet_cone_culled"] > 0.1, "{tipsify:?}");
    // meshoptimizer's optimized builder regroups the triangles itself, whatever the order.
    let ratio = random["meshlets_optimized"] / tipsify["meshlets_optimized"];
    assert!((0.95..=1.05).contains(&ratio), "{ratio}");
}
