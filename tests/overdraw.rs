//! The rasterizers against answers computed by hand: every count is asserted for the CPU
//! reference and, where a Vulkan adapter exists (always in CI), for the GPU backend too, which
//! must give exactly the same counts on these scenes.
//!
//! Scenes are placed directly in normalised device coordinates with an identity camera, so at
//! R = 512 one pixel is 1/256 NDC and every count below can be checked with a pencil.

mod common;

use glam::{Mat4, Vec3};
use triorder::measure::OverdrawSummary;
use triorder::mesh::Framing;
use triorder::mesh::{Mesh, VertexAttributes, procedural};
use triorder::raster::{Camera, OrderPicks, RasterBackend, ViewCounts, ViewSet};

/// Identity camera: world = unit frame = NDC (x, y in -1..1 map to the image, z in 0..1 is depth).
fn ndc_camera() -> Camera {
    Camera {
        view_proj: Mat4::IDENTITY,
        framing: Framing::UNIT,
        eye: Vec3::new(0.0, 0.0, -1.0),
        forward: Vec3::Z,
        perspective: false,
    }
}

/// A counter-clockwise quad in NDC from pixel (x0, y0) to (x1, y1) at R = 512, at depth z.
fn quad_px(x0: f32, y0: f32, x1: f32, y1: f32, z: f32, out: &mut Vec<Vec3>, tris: &mut Vec<[u32; 3]>) {
    let n = |px: f32| px / 256.0 - 1.0;
    let base = out.len() as u32;
    out.extend([
        Vec3::new(n(x0), n(y0), z),
        Vec3::new(n(x1), n(y0), z),
        Vec3::new(n(x1), n(y1), z),
        Vec3::new(n(x0), n(y1), z),
    ]);
    tris.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
}

/// Counts on every backend, which must agree; returns the (common) counts.
fn count_views(positions: &[Vec3], tris: &[[u32; 3]], cameras: &[Camera], res: u32) -> Vec<ViewCounts> {
    let backends = common::backends();
    let reference = backends[0].count(positions, tris, cameras, res).unwrap();
    for other in &backends[1..] {
        assert_eq!(other.count(positions, tris, cameras, res).unwrap(), reference, "{} vs cpu", other.name());
    }
    reference
}

fn count(positions: &[Vec3], tris: &[[u32; 3]]) -> ViewCounts {
    count_views(positions, tris, &[ndc_camera()], 512)[0]
}

#[test]
fn two_overlapping_quads_front_to_back_and_back_to_front() {
    // Two 256×256-pixel quads overlapping in a 128×128 square (the scene of ../shared/GPU.md).
    let (mut p, mut t) = (Vec::new(), Vec::new());
    quad_px(0.0, 0.0, 256.0, 256.0, 0.25, &mut p, &mut t); // near
    quad_px(128.0, 128.0, 384.0, 384.0, 0.75, &mut p, &mut t); // far
    let front_to_back = count(&p, &t);
    assert_eq!(front_to_back, ViewCounts { covered: 114_688, passed: 114_688 });
    let back_to_front = count(&p, &[t[2], t[3], t[0], t[1]]);
    assert_eq!(back_to_front, ViewCounts { covered: 114_688, passed: 131_072 });
    assert_eq!(back_to_front.ovr(), Some(131_072.0 / 114_688.0));
}

#[test]
fn top_left_rule_covers_shared_diagonal_pixels_once() {
    // The diagonal of this 256-pixel quad passes through 256 pixel centres exactly.
    let (mut p, mut t) = (Vec::new(), Vec::new());
    quad_px(0.0, 0.0, 256.0, 256.0, 0.5, &mut p, &mut t);
    let whole = count(&p, &t);
    assert_eq!(whole, ViewCounts { covered: 65_536, passed: 65_536 });
    // Lower-right triangle: its diagonal runs down-left, a left edge, so it owns the diagonal.
    assert_eq!(count(&p, &t[..1]).covered, 256 * 257 / 2);
    assert_eq!(count(&p, &t[1..]).covered, 256 * 255 / 2);
}

#[test]
fn back_faces_and_edge_on_faces_are_culled() {
    let (mut p, mut t) = (Vec::new(), Vec::new());
    quad_px(0.0, 0.0, 256.0, 256.0, 0.5, &mut p, &mut t);
    let reversed: Vec<[u32; 3]> = t.iter().map(|&[a, b, c]| [a, c, b]).collect();
    assert_eq!(count(&p, &reversed), ViewCounts::default());
    let flat = [Vec3::new(-0.5, 0.0, 0.2), Vec3::new(0.5, 0.0, 0.4), Vec3::new(0.0, 0.0, 0.6)];
    assert_eq!(count(&flat, &[[0, 1, 2]]), ViewCounts::default());
}

#[test]
fn equal_depth_fails_the_less_test() {
    let (mut p, mut t) = (Vec::new(), Vec::new());
    quad_px(0.0, 0.0, 64.0, 64.0, 0.5, &mut p, &mut t);
    quad_px(0.0, 0.0, 64.0, 64.0, 0.5, &mut p, &mut t);
    assert_eq!(count(&p, &t), ViewCounts { covered: 4096, passed: 4096 });
}

fn cube() -> Mesh {
    let positions: Vec<Vec3> = (0..8)
        .map(|i| Vec3::new((i & 1) as f32 * 2.0 - 1.0, (i >> 1 & 1) as f32 * 2.0 - 1.0, (i >> 2) as f32 * 2.0 - 1.0))
        .collect();
    // Outward counter-clockwise faces of the cube [-1, 1]^3, two triangles each.
    let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
    let triangles = quads.iter().flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]]).collect();
    Mesh::new("cube", positions, triangles, VertexAttributes::default()).unwrap()
}

fn summary(mesh: &Mesh, order: &[u32], views: &str, res: u32) -> (Vec<ViewCounts>, OverdrawSummary) {
    let cameras = views.parse::<ViewSet>().unwrap().cameras(Framing::of(&mesh.positions), 3);
    let counts = count_views(&mesh.positions, &mesh.triangles_in_order(order), &cameras, res);
    let s = OverdrawSummary::of(&counts).unwrap();
    (counts, s)
}

#[test]
fn closed_cube_has_no_overdraw_in_any_order() {
    let cube = cube();
    let orders: [Vec<u32>; 2] = [(0..12).collect(), (0..12).rev().collect()];
    for order in &orders {
        let (counts, s) = summary(&cube, order, "axis6", 512);
        // Along an axis only the facing square is visible: half-width √3 frames side 2, so the
        // square spans 512·2/(2√3) ≈ 295.6 pixels, i.e. 296 pixel centres per side.
        for c in &counts {
            assert_eq!((c.covered, c.passed), (296 * 296, 296 * 296));
        }
        assert_eq!((s.mean, s.max, s.variance), (1.0, 1.0, 0.0));
        let (_, s) = summary(&cube, order, "ico:162", 256);
        assert_eq!((s.max, s.views), (1.0, 162));
    }
}

#[test]
fn layers_drawn_back_to_front_have_overdraw_k() {
    for k in [1, 2, 5, 8] {
        let mesh = procedural::generate(&format!("layers:{k}"), 0).unwrap().unwrap();
        let order: Vec<u32> = (0..mesh.triangle_count() as u32).collect();
        let (counts, s) = summary(&mesh, &order, "axis6", 256);
        // Only the +Z view sees the layers' front faces; the others see them edge-on or from behind.
        assert_eq!((s.views, s.empty_views), (1, 5));
        assert_eq!(s.mean, k as f64);
        let plus_z = counts[4];
        assert_eq!(plus_z.passed, k * plus_z.covered);
        // Front to back instead: no overdraw.
        let reversed: Vec<u32> = order.iter().rev().copied().collect();
        assert_eq!(summary(&mesh, &reversed, "axis6", 256).1.mean, 1.0);
    }
}

#[test]
fn convex_sphere_has_no_overdraw_in_any_order() {
    let mesh = procedural::generate("sphere:5000", 0).unwrap().unwrap();
    let n = mesh.triangle_count() as u32;
    // A scrambled order (multiplicative stride) as well as the generator's.
    let stride: Vec<u32> = (0..n).map(|i| (i as u64 * 7919 % n as u64) as u32).collect();
    for order in [(0..n).collect::<Vec<_>>(), stride] {
        for views in ["ico:42", "random:20"] {
            let (counts, s) = summary(&mesh, &order, views, 256);
            // Snapping to 1/256 pixel can flip a silhouette sliver's orientation, which would add
            // a handful of fragments; demand at most 1 in 10,000.
            for c in &counts {
                assert!(c.passed >= c.covered);
                assert!((c.passed - c.covered) * 10_000 <= c.covered, "{views}: {c:?}");
            }
            assert!(s.max < 1.0001, "{views}: {s:?}");
        }
    }
}

/// Several orders counted at once (each view rasterized once on the CPU, the depth test
/// replayed per order) give exactly what drawing each order gives: on a helix, which overlaps
/// itself from most views, with coincident quads added so that fragments tie in depth, every
/// view picking its own orders (one repeated, one left out). On every backend.
#[test]
fn counting_many_orders_at_once_is_drawing_each() {
    let helix = procedural::generate("helix:3", 0).unwrap().unwrap();
    let (mut positions, mut triangles) = (helix.positions.clone(), helix.triangles.clone());
    // Two coincident quads inside the helix's frame: equal depths at every pixel they share.
    for _ in 0..2 {
        let base = positions.len() as u32;
        positions.extend([[-0.3, -0.3, 0.1], [0.3, -0.3, 0.1], [0.3, 0.3, 0.1], [-0.3, 0.3, 0.1]].map(Vec3::from));
        triangles.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    }
    let n = triangles.len() as u32;
    let mut orders: Vec<Vec<u32>> = vec![
        (0..n).collect(),
        (0..n).rev().collect(),
        (0..n).map(|i| (u64::from(i) * 7919 % u64::from(n)) as u32).collect(),
    ];
    // Rotations of the scrambled order: ten orders in all, more than are replayed side by side.
    let scrambled = orders[2].clone();
    orders.extend((1..8).map(|s| scrambled.iter().cycle().skip(s * 37).take(n as usize).copied().collect()));
    let slices: Vec<&[u32]> = orders.iter().map(|o| &o[..]).collect();
    let cameras = "ico:42".parse::<ViewSet>().unwrap().cameras(Framing::of(&positions), 0);
    // Each view its own orders, one of them drawn by all; then every view the same ten, one
    // twice (the backend may replay orders that every view draws side by side, eight at a time).
    let own: Vec<Vec<usize>> = (0..cameras.len()).map(|v| vec![v % 3, 2, (v + 1) % 3, 2, 3 + v % 7]).collect();
    let same = vec![vec![9, 0, 1, 2, 3, 4, 5, 6, 7, 8, 2]; cameras.len()];
    for (backend, picks) in common::backends().into_iter().flat_map(|b| [(b, &own), (b, &same)]) {
        let draws = OrderPicks { triangles: &triangles, orders: &slices, picks };
        let together = backend.count_orders(&positions, &cameras, &draws, 128).unwrap();
        let mut overdrawn = 0;
        for (v, camera) in cameras.iter().enumerate() {
            for (&o, &got) in picks[v].iter().zip(&together[v]) {
                let drawn: Vec<[u32; 3]> = orders[o].iter().map(|&t| triangles[t as usize]).collect();
                let want = backend.count(&positions, &drawn, &[*camera], 128).unwrap()[0];
                assert_eq!(got, want, "{}: view {v}, order {o}", backend.name());
                overdrawn += usize::from(want.passed > want.covered);
            }
        }
        // The scene must exercise the replay: most draws shade some pixel twice.
        assert!(overdrawn > cameras.len(), "{}: only {overdrawn} draws with overdraw", backend.name());
    }
}

/// A vertex the views cannot draw is named as the mesh numbers it, whether the views are drawn
/// in the given order or from depth layers (which draw the triangles renumbered for locality):
/// here the bad triangle comes first and its vertices are 0–2, but in space it lies last.
#[test]
fn a_bad_vertex_is_named_as_given_on_every_path() {
    let mut positions: Vec<Vec3> = [[1e4, 0.0, 0.0], [1e4, 1.0, 0.0], [1e4, 0.0, 1.0]].map(Vec3::from).to_vec();
    positions.extend([[-0.5, -0.5, 0.0], [0.5, -0.5, 0.0], [0.5, 0.5, 0.0], [-0.5, 0.5, 0.0]].map(Vec3::from));
    let triangles = vec![[0, 1, 2], [3, 4, 5], [3, 5, 6]];
    let cameras = "ico:12".parse::<ViewSet>().unwrap().cameras(Framing::of(&positions[3..]), 0);
    let order: Vec<u32> = vec![0, 1, 2];
    let picks = vec![vec![0]; cameras.len()];
    let draws = OrderPicks { triangles: &triangles, orders: &[&order], picks: &picks };
    let cpu = triorder::raster::cpu::CpuRaster;
    let errors = [
        cpu.count(&positions, &triangles, &cameras, 64).unwrap_err().to_string(),
        cpu.count_orders(&positions, &cameras, &draws, 64).unwrap_err().to_string(),
        triorder::raster::cpu::depth_layers(&positions, &triangles, &cameras, 64).unwrap_err().to_string(),
    ];
    for e in &errors {
        assert!(e.contains("vertex 0 "), "{e}");
    }
}
