//! Loop subdivision of animated meshes (`triorder::mesh::subdivide`): counts and order, closed
//! and flat surfaces, hand-computed stencils, influences and morphs carried so that posing
//! commutes with subdivision, seams welded, and odd topology that must not panic.

use std::collections::HashMap;

use glam::{Mat4, Quat, Vec3};
use triorder::mesh::animated::{Animated, Clip, Pose};
use triorder::mesh::procedural::generate;
use triorder::mesh::subdivide::loop_subdivide;
use triorder::mesh::topology::Topology;
use triorder::mesh::{Mesh, VertexAttributes};

fn make(spec: &str) -> Mesh {
    generate(spec, 0).expect("a procedural spec").expect("a valid spec")
}

fn mesh(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Mesh {
    let positions = positions.iter().map(|&p| Vec3::from(p)).collect();
    Mesh::new("test", positions, triangles.to_vec(), VertexAttributes::default()).unwrap()
}

fn pose(joints: Vec<Mat4>, morph_weights: Vec<f32>) -> Pose {
    Pose { time: 0.0, joints, morph_weights }
}

/// `mesh` with the given influences, no morph targets, and one clip of one rest pose.
fn animated(mesh: Mesh, influences: Vec<Vec<(u32, f32)>>, joint_count: usize) -> Animated {
    let rest = pose(vec![Mat4::IDENTITY; joint_count], vec![]);
    let clips = vec![Clip { name: "rest".into(), frames: vec![rest] }];
    Animated { mesh, influences, morph_targets: vec![], joint_count, clips }
}

/// Every vertex bound wholly to `joint` of `joint_count`.
fn rigid(mesh: Mesh, joint: u32, joint_count: usize) -> Animated {
    let influences = vec![vec![(joint, 1.0)]; mesh.vertex_count()];
    animated(mesh, influences, joint_count)
}

fn subdivide(animated: &Animated, levels: u32) -> Animated {
    loop_subdivide(animated, levels).unwrap()
}

fn assert_near(actual: Vec3, expected: Vec3, what: &str) {
    assert!((actual - expected).length() <= 1e-5 * expected.length().max(1.0), "{what}: {actual} != {expected}");
}

/// Undirected edges used by exactly one triangle.
fn boundary_edges(mesh: &Mesh) -> Vec<[u32; 2]> {
    let mut uses: HashMap<[u32; 2], usize> = HashMap::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *uses.entry([a.min(b), a.max(b)]).or_default() += 1;
        }
    }
    uses.into_iter().filter(|&(_, n)| n == 1).map(|(e, _)| e).collect()
}

#[test]
fn triangles_quadruple_per_level_in_consecutive_children() {
    let sphere = rigid(make("sphere:80"), 0, 1);
    for levels in 0..=3 {
        assert_eq!(subdivide(&sphere, levels).mesh.triangle_count(), 80 << (2 * levels));
    }
    // Triangle t's children are 4t..4t+4, the corner one at vertex k being 4t + k, winding kept.
    let fine = subdivide(&sphere, 1).mesh;
    for (t, tri) in sphere.mesh.triangles.iter().enumerate() {
        for (k, &v) in tri.iter().enumerate() {
            assert_eq!(fine.triangles[4 * t + k][k], v, "triangle {t}, corner {k}");
        }
        for child in &fine.triangles[4 * t..4 * t + 4] {
            let [a, b, c] = child.map(|v| fine.positions[v as usize]);
            assert!((b - a).cross(c - a).dot(a + b + c) > 0.0, "child of {t} faces inwards");
        }
    }
}

#[test]
fn closed_sphere_stays_closed() {
    let sphere = rigid(make("sphere:2000"), 0, 1);
    let fine = subdivide(&sphere, 2).mesh;
    assert_eq!(fine.triangle_count(), 2000 * 16);
    let topology = Topology::new(&fine);
    assert_eq!((topology.boundary_edges, topology.non_manifold_edges, topology.inconsistent_edges), (0, 0, 0));
    assert_eq!(topology.component_count, 1);
    // Closed and manifold: V − E + F = 2 with every triangle's vertices distinct and in use.
    assert_eq!(fine.vertex_count() + fine.triangle_count() - topology.edge_count, 2);
    // Loop smooths inwards a little, never outwards (weights are a convex combination).
    assert!(fine.positions.iter().all(|p| (0.99..=1.0 + 1e-6).contains(&p.length())));
}

#[test]
fn flat_grid_stays_flat_with_its_boundary_on_the_boundary_lines() {
    let grid = rigid(make("grid:8x8"), 0, 1);
    let fine = subdivide(&grid, 2).mesh;
    assert!(fine.positions.iter().all(|p| p.z == 0.0));
    assert!(fine.positions.iter().all(|p| (0.0..=8.0).contains(&p.x) && (0.0..=8.0).contains(&p.y)));
    let boundary = boundary_edges(&fine);
    assert_eq!(boundary.len(), 4 * 8 * 4, "each boundary edge splits in two per level");
    let on_line = |p: Vec3| p.x == 0.0 || p.x == 8.0 || p.y == 0.0 || p.y == 8.0;
    for &v in boundary.iter().flatten() {
        assert!(on_line(fine.positions[v as usize]), "boundary vertex {v} at {}", fine.positions[v as usize]);
    }
    // The grid's corners stay put: (8, 0) and (0, 8) are corners of single triangles, (0, 0) and
    // (8, 8) turn the boundary by 90°.
    for corner in [[0., 0.], [8., 0.], [0., 8.], [8., 8.]] {
        assert!(fine.positions.contains(&Vec3::new(corner[0], corner[1], 0.0)), "corner {corner:?} moved");
    }
}

#[test]
fn regular_interior_vertex_of_a_flat_grid_keeps_its_position() {
    let grid = rigid(make("grid:8x8"), 0, 1);
    // Old vertices come first at every level, so vertex 4·9 + 4 = (4, 4) keeps its index.
    for levels in 1..=2 {
        assert_eq!(subdivide(&grid, levels).mesh.positions[40], Vec3::new(4.0, 4.0, 0.0));
    }
}

#[test]
fn influence_weights_are_positive_sorted_and_sum_to_one() {
    let sphere = make("sphere:500");
    let influences = sphere
        .positions
        .iter()
        .map(|p| {
            let w = (0.5 + 0.4 * p.z).clamp(0.1, 0.9);
            if p.x > 0.0 { vec![(0, w), (1, 1.0 - w)] } else { vec![(1, 1.0 - w), (2, w)] }
        })
        .collect();
    let fine = subdivide(&animated(sphere, influences, 3), 2);
    assert_eq!(fine.influences.len(), fine.mesh.vertex_count());
    for (v, list) in fine.influences.iter().enumerate() {
        let total: f32 = list.iter().map(|&(_, w)| w).sum();
        assert!((total - 1.0).abs() <= 1e-5, "vertex {v}: weights sum to {total}");
        assert!(list.iter().all(|&(j, w)| w > 0.0 && j < 3), "vertex {v}: {list:?}");
        assert!(list.windows(2).all(|p| p[0].0 < p[1].0), "vertex {v}: joints not merged: {list:?}");
    }
    // A vertex where joints 0, 1 and 2 all reach has all three.
    assert!(fine.influences.iter().any(|l| l.len() == 3));
}

#[test]
fn skinning_and_morphs_commute_with_subdivision_on_a_single_joint() {
    let sphere = make("sphere:320");
    let delta: Vec<Vec3> = sphere.positions.iter().map(|p| Vec3::new(0.3 * p.y, p.x * p.z, 0.1)).collect();
    let mut coarse = rigid(sphere.clone(), 2, 4);
    coarse.morph_targets = vec![delta.clone()];
    let fine = subdivide(&coarse, 2);
    assert!(fine.influences.iter().all(|l| *l == [(2, 1.0)]));

    let m = Mat4::from_scale_rotation_translation(
        Vec3::new(1.5, 0.5, 2.0),
        Quat::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.7),
        Vec3::new(3.0, -1.0, 0.5),
    );
    let posed = fine.positions(&pose(vec![Mat4::IDENTITY, Mat4::IDENTITY, m, Mat4::IDENTITY], vec![0.6]));
    for (v, &p) in posed.iter().enumerate() {
        let rest = fine.mesh.positions[v] + 0.6 * fine.morph_targets[0][v];
        assert_near(p, m.transform_point3(rest), &format!("vertex {v}"));
    }

    // Morph deltas go by the same stencils as positions: subdividing the morphed mesh gives the
    // subdivided rest positions plus the subdivided deltas.
    let morphed_positions = sphere.positions.iter().zip(&delta).map(|(&p, &d)| p + d).collect();
    let morphed = Mesh { positions: morphed_positions, ..sphere };
    let fine_morphed = subdivide(&rigid(morphed, 0, 1), 2).mesh;
    for (v, &p) in fine_morphed.positions.iter().enumerate() {
        assert_near(p, fine.mesh.positions[v] + fine.morph_targets[0][v], &format!("morphed vertex {v}"));
    }
}

#[test]
fn single_triangle_by_hand() {
    // Boundary rules only, and each corner is a single triangle's corner: the corners stay, the
    // new vertices are the edge midpoints, listed by edge (0,1), (0,2), (1,2).
    let triangle = mesh(&[[0., 0., 0.], [4., 0., 0.], [0., 8., 2.]], &[[0, 1, 2]]);
    let influences = vec![vec![(0, 1.0)], vec![(1, 1.0)], vec![(0, 0.5), (1, 0.5)]];
    let fine = subdivide(&animated(triangle, influences, 2), 1);
    let expected = [[0., 0., 0.], [4., 0., 0.], [0., 8., 2.], [2., 0., 0.], [0., 4., 1.], [2., 4., 1.]];
    assert_eq!(fine.mesh.positions, expected.map(Vec3::from));
    assert_eq!(fine.mesh.triangles, [[0, 3, 4], [3, 1, 5], [4, 5, 2], [3, 5, 4]]);
    let expected_influences: [&[(u32, f32)]; 6] = [
        &[(0, 1.0)],
        &[(1, 1.0)],
        &[(0, 0.5), (1, 0.5)],
        &[(0, 0.5), (1, 0.5)],
        &[(0, 0.75), (1, 0.25)],
        &[(0, 0.25), (1, 0.75)],
    ];
    assert_eq!(fine.influences, expected_influences.map(<[_]>::to_vec));
    let bend = Mat4::from_rotation_z(1.0) * Mat4::from_translation(Vec3::new(0.0, 2.0, -1.0));
    assert!(fine.positions(&pose(vec![Mat4::IDENTITY, bend], vec![])).iter().all(|p| p.is_finite()));
}

#[test]
fn two_triangles_by_hand() {
    // A rhombus split along its short diagonal (0,2), which is interior: 3/8, 3/8, 1/8, 1/8.
    // Vertices 0 and 2 are on two boundary edges meeting at about 150°: 3/4, 1/8, 1/8 along the
    // boundary. Vertices 1 and 3 are corners of single triangles and stay.
    let rhombus = mesh(&[[0., -4., 0.], [16., 0., 8.], [0., 4., 0.], [-16., 0., 0.]], &[[0, 1, 2], [0, 2, 3]]);
    let fine = subdivide(&rigid(rhombus, 0, 1), 1).mesh;
    let expected = [
        [0., -3., 1.],
        [16., 0., 8.],
        [0., 3., 1.],
        [-16., 0., 0.],
        [8., -2., 4.],  // (0,1)
        [0., 0., 1.],   // (0,2)
        [-8., -2., 0.], // (0,3)
        [8., 2., 4.],   // (1,2)
        [-8., 2., 0.],  // (2,3)
    ];
    assert_eq!(fine.positions, expected.map(Vec3::from));

    // Bent to a right angle at vertex 0, the boundary keeps that corner.
    let bent = mesh(&[[0., 0., 0.], [16., 0., 8.], [8., 8., 0.], [0., 16., 0.]], &[[0, 1, 2], [0, 2, 3]]);
    assert_eq!(subdivide(&rigid(bent, 0, 1), 2).mesh.positions[0], Vec3::ZERO);
}

#[test]
fn tetrahedron_by_hand() {
    // Every vertex is interior with valence 3: Loop's β(3) = (5/8 − (3/8 − 1/8)²)/3 = 3/16.
    let tetrahedron = mesh(
        &[[0., 0., 0.], [16., 0., 0.], [0., 16., 0.], [0., 0., 16.]],
        &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]],
    );
    let fine = subdivide(&rigid(tetrahedron, 0, 1), 1).mesh;
    assert_near(fine.positions[0], Vec3::new(3., 3., 3.), "vertex 0: 7/16 itself + 3/16 each other");
    assert_near(fine.positions[1], Vec3::new(7., 3., 3.), "vertex 1");
    assert_near(fine.positions[4], Vec3::new(6., 2., 2.), "edge (0,1): 3/8, 3/8, 1/8, 1/8");
}

#[test]
fn zero_levels_return_the_input_unchanged() {
    let mut grid = make("grid:3x2");
    grid.attributes.uvs = Some(grid.positions.iter().map(|p| [p.x, p.y]).collect());
    let input = rigid(grid, 0, 1);
    assert_eq!(subdivide(&input, 0), input);
}

#[test]
fn seams_are_welded_and_attributes_dropped() {
    // grid:4x4 with the column x = 2 duplicated for the triangles right of it, each copy with its
    // own UV: the same surface, so the same subdivision, with no crack along the seam.
    let grid = make("grid:4x4");
    let mut positions = grid.positions.clone();
    let mut copy_of = HashMap::new();
    let mut triangles = grid.triangles.clone();
    for t in triangles.iter_mut() {
        if t.iter().any(|&v| grid.positions[v as usize].x > 2.0) {
            for v in t.iter_mut().filter(|v| grid.positions[**v as usize].x == 2.0) {
                *v = *copy_of.entry(*v).or_insert_with(|| {
                    positions.push(grid.positions[*v as usize]);
                    positions.len() as u32 - 1
                });
            }
        }
    }
    let uvs = (0..positions.len()).map(|v| [v as f32, 0.0]).collect();
    let attributes = VertexAttributes { uvs: Some(uvs), ..VertexAttributes::default() };
    let seamed = Mesh::new("seamed", positions, triangles, attributes).unwrap();
    assert_eq!(Topology::new(&seamed).boundary_edges, 16, "welded, the seam is no boundary");

    let plain = subdivide(&rigid(grid, 0, 1), 2).mesh;
    let welded = subdivide(&rigid(seamed, 0, 1), 2).mesh;
    assert_eq!(welded.positions, plain.positions);
    assert_eq!(welded.triangles, plain.triangles);
    assert_eq!(welded.attributes, VertexAttributes::default());
    assert_eq!(boundary_edges(&welded).len(), 16 * 4);
}

#[test]
fn non_manifold_edges_and_vertices_subdivide_without_panicking() {
    // Three triangles on the edge (0,1): a crease, so its new vertex is its midpoint, and each end
    // is on four crease edges, so a corner.
    let fin = mesh(
        &[[0., 0., 0.], [2., 0., 0.], [1., 1., 0.], [1., -1., 0.], [1., 0., 1.]],
        &[[0, 1, 2], [1, 0, 3], [0, 1, 4]],
    );
    let fine = subdivide(&rigid(fin, 0, 1), 2);
    assert_eq!(fine.mesh.triangle_count(), 3 * 16);
    assert!(fine.mesh.positions.iter().all(|p| p.is_finite()));
    assert_eq!(fine.mesh.positions[..2], [Vec3::ZERO, Vec3::new(2., 0., 0.)]);
    assert!(fine.mesh.positions.contains(&Vec3::new(1., 0., 0.)));

    // Two closed tetrahedra sharing vertex 0: two fans around it, so it is a corner.
    let bowtie = mesh(
        &[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [0., 0., 1.], [-1., 0., 0.], [0., -1., 0.], [0., 0., -1.]],
        &[[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2], [0, 5, 4], [0, 4, 6], [4, 5, 6], [0, 6, 5]],
    );
    let fine = subdivide(&rigid(bowtie, 0, 1), 1).mesh;
    assert_eq!(fine.triangle_count(), 32);
    assert_eq!(fine.positions[0], Vec3::ZERO);

    // A degenerate triangle is kept, as four degenerate children.
    let degenerate = mesh(&[[0., 0., 0.], [1., 0., 0.], [0., 1., 0.]], &[[0, 1, 2], [0, 0, 1]]);
    let fine = subdivide(&rigid(degenerate, 0, 1), 2).mesh;
    assert_eq!(fine.triangle_count(), 32);
    assert!(fine.positions.iter().all(|p| p.is_finite()));
}

#[test]
fn mismatched_inputs_and_huge_results_are_errors() {
    let grid = make("grid:2x2");
    let short = animated(grid.clone(), vec![vec![(0, 1.0)]; 3], 1);
    assert!(loop_subdivide(&short, 1).unwrap_err().to_string().contains("3 influence lists for 9 vertices"));
    let mut bad_morph = rigid(grid.clone(), 0, 1);
    bad_morph.morph_targets = vec![vec![Vec3::ZERO; 2]];
    assert!(loop_subdivide(&bad_morph, 1).is_err());
    assert!(loop_subdivide(&rigid(grid, 0, 1), 40).unwrap_err().to_string().contains("more than"));
}
