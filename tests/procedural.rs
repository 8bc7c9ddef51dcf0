//! The procedural meshes of `triorder::mesh::procedural`: counts, winding, manifoldness,
//! determinism and spec parsing.

use std::collections::{HashMap, HashSet};

use glam::Vec3;
use triorder::mesh::Mesh;
use triorder::mesh::procedural::{
    HELIX_PITCH, HELIX_RADIUS, HELIX_SEGMENTS_PER_TURN, HELIX_SIDES, HELIX_TUBE_RADIUS, generate,
};

fn make(spec: &str) -> Mesh {
    make_seeded(spec, 1)
}

fn make_seeded(spec: &str, seed: u64) -> Mesh {
    match generate(spec, seed) {
        Some(Ok(mesh)) => mesh,
        Some(Err(e)) => panic!("{spec}: unexpected error: {e}"),
        None => panic!("{spec}: not recognised as procedural"),
    }
}

fn corners(mesh: &Mesh, t: [u32; 3]) -> [Vec3; 3] {
    t.map(|v| mesh.positions[v as usize])
}

/// Unnormalised normal (twice the area) of a triangle, by its winding.
fn normal(mesh: &Mesh, t: [u32; 3]) -> Vec3 {
    let [a, b, c] = corners(mesh, t);
    (b - a).cross(c - a)
}

fn centroid(mesh: &Mesh, t: [u32; 3]) -> Vec3 {
    let [a, b, c] = corners(mesh, t);
    (a + b + c) / 3.0
}

/// Directed edge → number of triangles using it in that direction.
fn directed_edges(mesh: &Mesh) -> HashMap<(u32, u32), usize> {
    let mut edges = HashMap::new();
    for &[a, b, c] in &mesh.triangles {
        for e in [(a, b), (b, c), (c, a)] {
            *edges.entry(e).or_insert(0) += 1;
        }
    }
    edges
}

/// Every undirected edge is used exactly twice, once in each direction (closed, manifold,
/// consistently oriented); returns the number of undirected edges.
fn assert_closed(mesh: &Mesh) -> usize {
    let edges = directed_edges(mesh);
    for (&(a, b), &n) in &edges {
        assert_eq!(n, 1, "{}: edge {a}->{b} used {n} times in one direction", mesh.name);
        assert_eq!(edges.get(&(b, a)), Some(&1), "{}: edge {a}->{b} has no opposite", mesh.name);
    }
    edges.len() / 2
}

/// Euler characteristic V − E + F, counting only vertices some triangle uses.
fn euler(mesh: &Mesh) -> i64 {
    let used: HashSet<u32> = mesh.triangles.iter().flatten().copied().collect();
    let undirected: HashSet<(u32, u32)> = directed_edges(mesh).keys().map(|&(a, b)| (a.min(b), a.max(b))).collect();
    used.len() as i64 - undirected.len() as i64 + mesh.triangle_count() as i64
}

/// The boundary of an oriented manifold-with-boundary: each boundary edge used once, interior
/// edges once each way. Returns the number of boundary loops (boundary vertices have exactly one
/// outgoing boundary edge).
fn boundary_loops(mesh: &Mesh) -> usize {
    let edges = directed_edges(mesh);
    let mut next = HashMap::new();
    for (&(a, b), &n) in &edges {
        assert_eq!(n, 1, "{}: edge {a}->{b} used {n} times in one direction", mesh.name);
        if !edges.contains_key(&(b, a)) {
            assert!(next.insert(a, b).is_none(), "{}: vertex {a} has two outgoing boundary edges", mesh.name);
        }
    }
    let mut seen = HashSet::new();
    let mut loops = 0;
    for &start in next.keys() {
        if seen.contains(&start) {
            continue;
        }
        loops += 1;
        let mut v = start;
        while seen.insert(v) {
            v = next[&v];
        }
        assert_eq!(v, start, "{}: boundary walk did not close", mesh.name);
    }
    loops
}

fn vertex_degrees(mesh: &Mesh) -> Vec<usize> {
    let mut neighbours = vec![HashSet::new(); mesh.vertex_count()];
    for &[a, b, c] in &mesh.triangles {
        for (x, y) in [(a, b), (b, c), (c, a)] {
            neighbours[x as usize].insert(y);
            neighbours[y as usize].insert(x);
        }
    }
    neighbours.iter().map(HashSet::len).collect()
}

fn assert_faces_up(mesh: &Mesh) {
    for (i, &t) in mesh.triangles.iter().enumerate() {
        assert!(normal(mesh, t).z > 0.0, "{}: triangle {i} {t:?} does not face +z", mesh.name);
    }
}

/// Six times the signed volume enclosed by a closed mesh: positive when wound outward.
fn signed_volume6(mesh: &Mesh) -> f64 {
    mesh.triangles
        .iter()
        .map(|&t| {
            let [a, b, c] = corners(mesh, t).map(|p| p.as_dvec3());
            a.dot(b.cross(c))
        })
        .sum()
}

#[test]
fn grid_counts_numbering_and_winding() {
    let mesh = make("grid:16x8");
    assert_eq!(mesh.name, "grid:16x8");
    assert_eq!(mesh.triangle_count(), 2 * 16 * 8);
    assert_eq!(mesh.vertex_count(), 17 * 9);
    for y in 0..=8u32 {
        for x in 0..=16u32 {
            assert_eq!(mesh.positions[(y * 17 + x) as usize], Vec3::new(x as f32, y as f32, 0.0));
        }
    }
    // Square (x, y) = (3, 2): s = 2*16 + 3; lower-right [a, b, c] then upper-left [a, c, d].
    let s = 2 * 16 + 3;
    let v = |x: u32, y: u32| y * 17 + x;
    assert_eq!(mesh.triangles[2 * s], [v(3, 2), v(4, 2), v(4, 3)]);
    assert_eq!(mesh.triangles[2 * s + 1], [v(3, 2), v(4, 3), v(3, 3)]);
    assert_faces_up(&mesh);
    assert_eq!(euler(&mesh), 1);
    assert_eq!(boundary_loops(&mesh), 1);
    let degrees = vertex_degrees(&mesh);
    for y in 1..8u32 {
        for x in 1..16u32 {
            assert_eq!(degrees[v(x, y) as usize], 6, "interior vertex ({x}, {y})");
        }
    }
}

#[test]
fn grid_of_one_square() {
    let mesh = make("grid:1x1");
    assert_eq!(mesh.triangles, vec![[0, 1, 3], [0, 3, 2]]);
    assert_faces_up(&mesh);
}

#[test]
fn disk_950_is_like_bogomjakov_gotsman_fig4() {
    let mesh = make("disk:950");
    let n = mesh.triangle_count() as f64;
    assert!((n - 950.0).abs() <= 0.03 * 950.0, "{n} triangles");
    assert_eq!(mesh.triangle_count(), 950);
    assert_eq!(mesh.vertex_count(), 509);
    assert_faces_up(&mesh);
    assert_eq!(euler(&mesh), 1);
    assert_eq!(boundary_loops(&mesh), 1);
    for p in &mesh.positions {
        assert!(p.z == 0.0 && p.truncate().length() <= 1.0 + 1e-6, "{p} outside the unit disk");
    }
    // Irregular: interior vertex degrees spread around 6 (4–8 in the paper's figure).
    let degrees = vertex_degrees(&mesh);
    let interior = &degrees[66..];
    let (lo, hi) = (interior.iter().min().unwrap(), interior.iter().max().unwrap());
    assert!(*lo >= 3 && *lo < 6 && *hi > 6 && *hi <= 10, "interior degrees {lo}..={hi}");
    // No sliver close to degenerate: every triangle has a reasonable area.
    let smallest = mesh.triangles.iter().map(|&t| normal(&mesh, t).z).fold(f32::INFINITY, f32::min);
    assert!(smallest > 1e-5, "smallest doubled area {smallest}");
}

#[test]
fn disk_counts_across_sizes() {
    for n in [1u64, 2, 3, 4, 5, 7, 10, 31, 100, 333, 1000, 5001, 20000] {
        let spec = format!("disk:{n}");
        let mesh = make(&spec);
        let got = mesh.triangle_count() as f64;
        assert!((got - n as f64).abs() <= 0.03 * n as f64, "{spec}: {got} triangles");
        assert_faces_up(&mesh);
        assert_eq!(euler(&mesh), 1, "{spec}");
        assert_eq!(boundary_loops(&mesh), 1, "{spec}");
    }
}

#[test]
fn disk_is_deterministic_per_seed() {
    let a = make_seeded("disk:950", 7);
    let b = make_seeded("disk:950", 7);
    assert_eq!(a, b);
    assert_eq!(
        a.positions.iter().map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>(),
        b.positions.iter().map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>()
    );
    let c = make_seeded("disk:950", 8);
    assert_ne!(a.positions, c.positions);
}

#[test]
fn other_generators_ignore_the_seed() {
    for spec in ["grid:5x3", "sphere:320", "helix:2", "layers:3"] {
        assert_eq!(make_seeded(spec, 1), make_seeded(spec, 99), "{spec}");
        assert_eq!(make(spec), make(spec), "{spec}");
    }
}

#[test]
fn sphere_counts_and_outward_winding() {
    for (spec, f) in [("sphere:1", 1u32), ("sphere:20", 1), ("sphere:80", 2), ("sphere:500", 5), ("sphere:20480", 32)] {
        let mesh = make(spec);
        assert_eq!(mesh.triangle_count() as u32, 20 * f * f, "{spec}");
        assert_eq!(mesh.vertex_count() as u32, 10 * f * f + 2, "{spec}");
        for p in &mesh.positions {
            assert!((p.length() - 1.0).abs() < 1e-5, "{spec}: {p} off the unit sphere");
        }
        for (i, &t) in mesh.triangles.iter().enumerate() {
            assert!(normal(&mesh, t).dot(centroid(&mesh, t)) > 0.0, "{spec}: triangle {i} faces inward");
        }
        let edges = assert_closed(&mesh);
        assert_eq!(edges as u32, 30 * f * f, "{spec}");
        assert_eq!(euler(&mesh), 2, "{spec}");
        assert!(signed_volume6(&mesh) > 0.0);
    }
}

#[test]
fn helix_counts_closed_and_outward() {
    let (segments, sides) = (HELIX_SEGMENTS_PER_TURN, HELIX_SIDES);
    for turns in [1u32, 3] {
        let spec = format!("helix:{turns}");
        let mesh = make(&spec);
        let rings = segments * turns + 1;
        assert_eq!(mesh.vertex_count() as u32, sides * rings + 2, "{spec}");
        assert_eq!(mesh.triangle_count() as u32, 2 * sides * segments * turns + 2 * sides, "{spec}");
        assert_closed(&mesh);
        assert_eq!(euler(&mesh), 2, "{spec}");
        assert!(signed_volume6(&mesh) > 0.0, "{spec}");
        // Tube walls face away from the centre line c(θ) = (R cos θ, R sin θ, Pθ/2π): compare each
        // wall triangle's normal with the direction from the nearest point of a finely sampled
        // centre line (caps are the last 2·sides triangles).
        let centre_line: Vec<Vec3> = (0..=turns * segments * 16)
            .map(|i| {
                let theta = std::f32::consts::TAU * i as f32 / (segments * 16) as f32;
                Vec3::new(
                    HELIX_RADIUS * theta.cos(),
                    HELIX_RADIUS * theta.sin(),
                    HELIX_PITCH * theta / std::f32::consts::TAU,
                )
            })
            .collect();
        let walls = mesh.triangle_count() - 2 * sides as usize;
        for (i, &t) in mesh.triangles[..walls].iter().enumerate() {
            let c = centroid(&mesh, t);
            let nearest = centre_line
                .iter()
                .copied()
                .min_by(|a, b| a.distance_squared(c).total_cmp(&b.distance_squared(c)))
                .unwrap();
            assert!(c.distance(nearest) < HELIX_TUBE_RADIUS * 1.01, "{spec}: triangle {i} far from the tube");
            assert!(normal(&mesh, t).dot(c - nearest) > 0.0, "{spec}: triangle {i} faces inward");
        }
        // Caps: the first faces back along the tangent at θ = 0, the second forward at the end.
        let tangent = |theta: f32| {
            Vec3::new(-HELIX_RADIUS * theta.sin(), HELIX_RADIUS * theta.cos(), HELIX_PITCH / std::f32::consts::TAU)
        };
        let end = std::f32::consts::TAU * turns as f32;
        for (j, &t) in mesh.triangles[walls..].iter().enumerate() {
            let expected = if j < sides as usize { -tangent(0.0) } else { tangent(end) };
            assert!(normal(&mesh, t).dot(expected) > 0.0, "{spec}: cap triangle {j} faces inward");
        }
    }
}

#[test]
fn helix_turns_overlap_from_the_side_without_touching() {
    // Consecutive turns are separated by the pitch along z; the tube is thinner than that …
    const { assert!(2.0 * HELIX_TUBE_RADIUS < HELIX_PITCH) };
    // … but thick enough that, seen along y, the front half-turn covers the middle of the gap to
    // the back half-turns above and below it (their centres are P/2 apart at x = 0).
    const { assert!(2.0 * HELIX_TUBE_RADIUS > HELIX_PITCH / 2.0) };
    let mesh = make("helix:4");
    // Rays along ±y near x = 0 at the height where turn 1 ends and turn 2 begins: from −y the
    // first surface hit is turn 1's front and the last is turn 2's back; from +y it is the other
    // way round, so each turn occludes the other from some view (Nehab et al. 2006, Fig. 5).
    let turn_of = |t: usize| t / (2 * (HELIX_SIDES * HELIX_SEGMENTS_PER_TURN) as usize);
    let z = 2.0 * HELIX_PITCH;
    for (origin, direction, first, last) in
        [(Vec3::new(0.013, -10.0, z), Vec3::Y, 1, 2), (Vec3::new(0.013, 10.0, z), -Vec3::Y, 2, 1)]
    {
        let mut hits: Vec<(f32, usize)> = (0..mesh.triangle_count())
            .filter_map(|t| ray_hit(origin, direction, corners(&mesh, mesh.triangles[t])).map(|d| (d, t)))
            .collect();
        hits.sort_by(|a, b| a.0.total_cmp(&b.0));
        assert_eq!(hits.len(), 4, "the ray should cross two tube sections: {hits:?}");
        assert_eq!((turn_of(hits[0].1), turn_of(hits[3].1)), (first, last), "from {origin}");
    }
    let (lo, hi) = mesh.bounds();
    assert!((lo.z - -HELIX_TUBE_RADIUS).abs() < 0.05 && (hi.z - (4.0 * HELIX_PITCH + HELIX_TUBE_RADIUS)).abs() < 0.05);
}

/// Distance along `direction` (unit) from `origin` to the triangle, if the ray hits it
/// (Möller–Trumbore).
fn ray_hit(origin: Vec3, direction: Vec3, [a, b, c]: [Vec3; 3]) -> Option<f32> {
    let (e1, e2) = (b - a, c - a);
    let p = direction.cross(e2);
    let det = e1.dot(p);
    if det.abs() < 1e-12 {
        return None;
    }
    let s = origin - a;
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = direction.dot(q) / det;
    let t = e2.dot(q) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0).then_some(t)
}

#[test]
fn layers_stack_back_to_front() {
    let mesh = make("layers:5");
    assert_eq!(mesh.triangle_count(), 10);
    assert_eq!(mesh.vertex_count(), 20);
    assert_faces_up(&mesh);
    for (i, &t) in mesh.triangles.iter().enumerate() {
        let layer = (i / 2) as f32;
        for p in corners(&mesh, t) {
            assert_eq!(p.z, layer);
            assert!((0.0..=1.0).contains(&p.x) && (0.0..=1.0).contains(&p.y));
        }
    }
    assert_eq!(mesh.triangles[2], [4, 5, 6]);
    assert_eq!(mesh.triangles[3], [4, 6, 7]);
}

#[test]
fn malformed_specs_are_errors_naming_the_spec() {
    for spec in [
        "grid:0x8",
        "grid:16",
        "grid:16x8x2",
        "grid:x8",
        "grid:16x",
        "grid:",
        "grid:16 x8",
        "grid:+16x8",
        "disk:abc",
        "disk:",
        "disk:0",
        "disk:9.5",
        "sphere:-3",
        "sphere:99999999999999999999999",
        "helix:0",
        "helix:1x1",
        "layers:0",
        "layers:-1",
        "grid:100000x100000",
        "sphere:1000000000",
        "helix:1000000",
        "layers:99999999999",
    ] {
        match generate(spec, 0) {
            Some(Err(e)) => assert!(e.to_string().contains(spec), "{spec}: error {e} does not name the spec"),
            Some(Ok(_)) => panic!("{spec}: accepted"),
            None => panic!("{spec}: treated as a path"),
        }
    }
    let e = generate("grid:0x8", 0).unwrap().unwrap_err().to_string();
    assert!(e.contains("grid:16x8"), "{e}");
}

#[test]
fn other_names_are_paths() {
    for spec in
        ["models/bunny.ply", "foo:bar", "grid", "Grid:16x8", "C:\\meshes\\grid.obj", "", ":", "sphere", "gridx:1"]
    {
        assert!(generate(spec, 0).is_none(), "{spec}");
    }
}
