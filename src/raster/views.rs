//! Cameras and the view sets every overdraw experiment is parameterised by.
//!
//! - `axis6`: orthographic along ±X, ±Y, ±Z.
//! - `ico:N` (N = 10·4^m + 2: 12, 42, 162, 642, 2562): orthographic along the vertices of a
//!   subdivided icosahedron (Nehab, Barczak & Sander 2006, §4 and Fig. 4), coarser sets first so
//!   the sets nest.
//! - `random:N`: N perspective cameras at 3× the bounding radius looking at the centre, uniformly
//!   distributed directions from a seeded generator (Han & Sander 2017, §5).
//!
//! Framing is the same everywhere: the centre is the bounding-box centre and the radius r is the
//! largest distance of any vertex from it. An orthographic view is a square of half-width r
//! around the centre; a perspective camera has the vertical field of view 2·asin(1/3) ≈ 38.9°,
//! which just fits the bounding sphere from distance 3r. Depth maps to 0..1 (the Vulkan/wgpu
//! convention) with the near and far planes outside the bounding sphere, so no triangle is ever
//! clipped (glam's right-handed view with `directx` projections: NDC y up, z in 0..1, as wgpu).
//! The image's "up" is world +Y, or +Z when the view direction is within ~8° of ±Y.
//!
//! A camera sees the model in its *unit frame* ([`Framing::to_unit`]: centred and divided by r,
//! in f64): its matrix is built for the unit sphere at the origin, and every rasterizer maps the
//! positions into the unit frame before the matrix. So the counts depend on the shape alone: a
//! mesh at 1e-30 or 1e25 scale, or far from the origin, is drawn as it would be at unit size
//! around the origin. Built from world coordinates in f32 instead, a 1e-30 mesh squared its
//! radius to zero (and was drawn as a point: "no visible faces"), a 1e25 one to infinity (and
//! was refused as needing clipping), and one far off-centre lost its size to the rounding of
//! the translation.

use std::fmt;
use std::str::FromStr;

use glam::camera::rh::{proj::directx, view::look_at_mat4};
use glam::{Mat4, Vec3, Vec4};
use rand::{Rng, SeedableRng};

use crate::error::{Error, Result};
use crate::mesh::Framing;

/// One view: where the model is framed, a unit frame → clip transform (depth 0..1, y up) and
/// where the eye is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Unit frame → clip: applied to positions after `framing` has mapped them into the unit
    /// frame ([`Camera::clip`]).
    pub view_proj: Mat4,
    /// The framing the camera was made for: world positions → unit frame, in f64.
    pub framing: Framing,
    /// The viewpoint in world coordinates, rounded to f32 (for orthographic views: a point on
    /// the axis, outside the bounding sphere).
    pub eye: Vec3,
    /// Unit vector from the eye toward the model centre.
    pub forward: Vec3,
    pub perspective: bool,
}

impl Camera {
    /// The clip coordinates of the world position `p`: mapped into the unit frame in f64, then
    /// through [`Camera::view_proj`] in f32, as every rasterizer does.
    pub fn clip(&self, p: Vec3) -> Vec4 {
        self.view_proj * self.framing.to_unit(p).extend(1.0)
    }

    /// The eye in the unit frame: its direction from the centre, at the camera's distance (2 for
    /// orthographic views, 3 for perspective ones).
    pub fn unit_eye(&self) -> Vec3 {
        -self.forward * if self.perspective { 3.0 } else { 2.0 }
    }

    /// Unit vector from the model centre toward the eye: exact, whatever the scale and place of
    /// the model (`eye − centre` in f32 is not, far from the origin).
    pub fn direction(&self) -> Vec3 {
        -self.forward
    }

    /// True when the sphere `sphere` (world coordinates) lies inside this camera's depth range
    /// and projects well within the area the rasterizers accept (|NDC x|, |NDC y| ≤ 14), so no
    /// vertex inside it can need clipping. The sphere is taken into the unit frame in f64; each
    /// condition is a plane a·(p, 1) ≥ 0 made from rows of the matrix.
    pub fn frames_sphere(&self, sphere: Framing) -> bool {
        let center = ((sphere.center - self.framing.center) / self.framing.radius).as_vec3();
        let radius = (sphere.radius / self.framing.radius) as f32;
        if !(center.is_finite() && radius.is_finite()) {
            return false;
        }
        let m = self.view_proj;
        let (x, y, z, w) = (m.row(0), m.row(1), m.row(2), m.row(3));
        [z, w - z, 14.0 * w - x, 14.0 * w + x, 14.0 * w - y, 14.0 * w + y].iter().all(|plane| {
            let normal = plane.truncate();
            normal.dot(center) + plane.w >= radius * normal.length() * 1.0001 + f32::EPSILON
        })
    }
}

/// The image side at which drawings of a mesh are rasterized (and the measurements they show,
/// such as the overdraw picture, are saved by the run): about 1.4 image pixels per figure pixel
/// for a mesh filling a panel.
pub const DRAWING_RES: u32 = 1024;

/// The camera a drawing sees `positions` with: orthographic along `view` (centre → eye), the
/// model framed as for measurements.
pub fn drawing_camera(positions: &[Vec3], view: [f32; 3], up: Option<[f32; 3]>) -> Camera {
    let direction = Vec3::from(view).normalize();
    match up {
        Some(up) => orthographic_up(Framing::of(positions), direction, Vec3::from(up)),
        None => orthographic(Framing::of(positions), direction),
    }
}

/// A named set of views.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ViewSet {
    Axis6,
    Ico(u32),
    Random(u32),
}

impl fmt::Display for ViewSet {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ViewSet::Axis6 => write!(f, "axis6"),
            ViewSet::Ico(n) => write!(f, "ico:{n}"),
            ViewSet::Random(n) => write!(f, "random:{n}"),
        }
    }
}

/// The icosahedron subdivision counts we generate: 10·4^m + 2 for m = 0..=4.
const ICO_COUNTS: [u32; 5] = [12, 42, 162, 642, 2562];

impl FromStr for ViewSet {
    type Err = Error;

    fn from_str(text: &str) -> Result<ViewSet> {
        let bad = |why: String| {
            Error::usage(format!(
                "view set `{text}` {why} (expected axis6, ico:N with N in 12, 42, 162, 642, 2562, or random:N)"
            ))
        };
        match text.split_once(':') {
            None if text == "axis6" => Ok(ViewSet::Axis6),
            Some(("ico", n)) => match n.parse::<u32>() {
                Ok(n) if ICO_COUNTS.contains(&n) => Ok(ViewSet::Ico(n)),
                _ => Err(bad("is not an icosahedron subdivision count".into())),
            },
            Some(("random", n)) => match n.parse::<u32>() {
                Ok(n) if (1..=100_000).contains(&n) => Ok(ViewSet::Random(n)),
                _ => Err(bad("needs a count in 1..=100000".into())),
            },
            _ => Err(bad("is not a known view set".into())),
        }
    }
}

impl ViewSet {
    pub fn len(&self) -> usize {
        match *self {
            ViewSet::Axis6 => 6,
            ViewSet::Ico(n) | ViewSet::Random(n) => n as usize,
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The cameras of this set framing `framing`; `seed` drives `random:N` only.
    pub fn cameras(&self, framing: Framing, seed: u64) -> Vec<Camera> {
        match *self {
            ViewSet::Axis6 => [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z]
                .into_iter()
                .map(|d| orthographic(framing, d))
                .collect(),
            ViewSet::Ico(n) => icosphere_directions(n).into_iter().map(|d| orthographic(framing, d)).collect(),
            ViewSet::Random(n) => {
                let mut rng = rand_pcg::Pcg64Mcg::seed_from_u64(seed);
                (0..n).map(|_| perspective(framing, random_direction(&mut rng))).collect()
            }
        }
    }
}

fn up_for(direction: Vec3) -> Vec3 {
    if direction.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y }
}

/// Orthographic camera looking at the centre from `direction` (unit vector centre → eye), at
/// twice the radius: built in the unit frame ([`Camera`]).
pub fn orthographic(framing: Framing, direction: Vec3) -> Camera {
    orthographic_up(framing, direction, up_for(direction))
}

/// [`orthographic`] with the image's up given: a model whose up axis is not +Y (the GaTech
/// horse stands along Z) is drawn standing.
pub fn orthographic_up(framing: Framing, direction: Vec3, up: Vec3) -> Camera {
    let view = look_at_mat4(direction * 2.0, Vec3::ZERO, up);
    let proj = directx::orthographic(-1.0, 1.0, -1.0, 1.0, 0.5, 3.5);
    camera(framing, direction, 2.0, proj * view, false)
}

/// Perspective camera at 3r from the centre along `direction`, fitting the bounding sphere.
pub fn perspective(framing: Framing, direction: Vec3) -> Camera {
    let view = look_at_mat4(direction * 3.0, Vec3::ZERO, up_for(direction));
    let fov_y = 2.0 * (1.0f32 / 3.0).asin();
    let proj = directx::perspective(fov_y, 1.0, 1.0, 5.0);
    camera(framing, direction, 3.0, proj * view, true)
}

/// A camera of `framing` at `distance` radii along `direction`, seeing the unit frame through
/// `view_proj`.
fn camera(framing: Framing, direction: Vec3, distance: f64, view_proj: Mat4, perspective: bool) -> Camera {
    let eye = framing.to_world(direction.as_dvec3() * distance);
    Camera { view_proj, framing, eye, forward: -direction, perspective }
}

/// Uniform direction on the unit sphere (z uniform in [-1, 1], azimuth uniform).
fn random_direction(rng: &mut impl Rng) -> Vec3 {
    let z: f32 = rng.random_range(-1.0..=1.0);
    let phi: f32 = rng.random_range(0.0..std::f32::consts::TAU);
    let s = (1.0 - z * z).max(0.0).sqrt();
    Vec3::new(s * phi.cos(), s * phi.sin(), z)
}

/// Unit directions of the icosahedron subdivided until it has `n` vertices, coarser levels first
/// (each level keeps the previous level's vertices in place and appends the edge midpoints).
pub fn icosphere_directions(n: u32) -> Vec<Vec3> {
    let phi = (1.0 + 5.0f32.sqrt()) / 2.0;
    let mut points: Vec<Vec3> = [
        (-1.0, phi, 0.0),
        (1.0, phi, 0.0),
        (-1.0, -phi, 0.0),
        (1.0, -phi, 0.0),
        (0.0, -1.0, phi),
        (0.0, 1.0, phi),
        (0.0, -1.0, -phi),
        (0.0, 1.0, -phi),
        (phi, 0.0, -1.0),
        (phi, 0.0, 1.0),
        (-phi, 0.0, -1.0),
        (-phi, 0.0, 1.0),
    ]
    .into_iter()
    .map(|(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let mut faces: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    while points.len() < n as usize {
        let mut midpoint = std::collections::HashMap::new();
        let mut split = |a: usize, b: usize, points: &mut Vec<Vec3>| {
            *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                points.push((points[a] + points[b]).normalize());
                points.len() - 1
            })
        };
        faces = faces
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (split(a, b, &mut points), split(b, c, &mut points), split(c, a, &mut points));
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    points
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn icosphere_counts_nest_and_are_unit() {
        for n in ICO_COUNTS {
            let d = icosphere_directions(n);
            assert_eq!(d.len(), n as usize);
            assert!(d.iter().all(|v| (v.length() - 1.0).abs() < 1e-5));
        }
        assert_eq!(icosphere_directions(42)[..12], icosphere_directions(12)[..]);
        // Neighbouring directions of ico:162 are ~17° apart: no duplicates.
        let d = icosphere_directions(162);
        let min_angle = (0..d.len())
            .flat_map(|i| (i + 1..d.len()).map(move |j| (i, j)))
            .map(|(i, j)| d[i].angle_between(d[j]))
            .fold(f32::MAX, f32::min);
        assert!(min_angle > 0.25, "{min_angle}");
    }

    #[test]
    fn cameras_frame_the_bounding_sphere() {
        let framing = Framing { center: DVec3::new(1.0, 2.0, 3.0), radius: 2.0 };
        for set in ["axis6", "ico:42", "random:50"] {
            for cam in set.parse::<ViewSet>().unwrap().cameras(framing, 7) {
                // Sphere points project inside the unit square and strictly inside the depth range.
                for d in icosphere_directions(162) {
                    let clip = cam.clip(framing.to_world(d.as_dvec3()));
                    let ndc = clip.truncate() / clip.w;
                    assert!(ndc.x.abs() <= 1.0001 && ndc.y.abs() <= 1.0001, "{set}: {ndc}");
                    assert!(ndc.z > 0.0 && ndc.z < 1.0, "{set}: {ndc}");
                }
            }
        }
    }

    #[test]
    fn framed_spheres_pass_and_clipped_ones_fail() {
        let framing = Framing { center: DVec3::new(1.0, 2.0, 3.0), radius: 2.0 };
        for set in ["axis6", "ico:42", "random:50"] {
            for cam in set.parse::<ViewSet>().unwrap().cameras(framing, 7) {
                assert!(cam.frames_sphere(framing), "{set}");
                // Reaching the eye crosses the near plane.
                assert!(!cam.frames_sphere(Framing { radius: 2.2 * framing.radius, ..framing }), "{set}");
            }
        }
    }

    #[test]
    fn random_views_are_seeded() {
        let f = Framing::UNIT;
        let a = ViewSet::Random(5).cameras(f, 1);
        assert_eq!(a, ViewSet::Random(5).cameras(f, 1));
        assert_ne!(a, ViewSet::Random(5).cameras(f, 2));
        assert!(a.iter().all(|c| (c.eye.length() - 3.0).abs() < 1e-5));
    }

    #[test]
    fn parse_errors() {
        for bad in ["ico:100", "random:0", "axis7", "ico", "sphere:4"] {
            assert!(bad.parse::<ViewSet>().unwrap_err().to_string().contains(bad));
        }
        assert_eq!("ico:642".parse::<ViewSet>().unwrap().to_string(), "ico:642");
    }
}
