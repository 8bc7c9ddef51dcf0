//! How wrong a draw order is for translucent rendering, over a view set: the first measurement of
//! the static sorts of seed 003 ("Update on Sorting Translucent Triangles"), which judged them by
//! eye.
//!
//! An engine draws a translucent mesh with alpha blending and no depth writes, in its index
//! order: at each pixel the fragments blend in draw order, `c ← c·(1 − α) + colour·α`. The exact
//! image blends each pixel's fragments from the farthest to the nearest (an A-buffer: every
//! fragment kept and sorted per pixel). Both come from the same fragments of the CPU reference
//! rasterizer, under the overdraw metric's rules and cameras (back faces culled, one sample at
//! each pixel centre), with a constant α of 0.5 on a black background and a colour per triangle
//! (a hash of its id, so the colour follows the triangle whatever the order).
//!
//! Per view, over the pixels the mesh covers:
//! - `translucency_wrong_pixels`: the share whose blended colour differs from the exact one by
//!   more than 1/255 in some channel (what a viewer could see on an 8-bit display);
//! - `translucency_rmse`: the root mean square of the colour differences (channels in 0..1);
//! - `translucency_pairs`: fragment pairs blended in the wrong order (the nearer drawn first),
//!   per pixel: a normalised count of inversions, which does not depend on the colours.
//!
//! The set's values are the means over the views that see something; `_view` values give each
//! view. Fragments at equal depth are in order whichever comes first.

use rayon::prelude::*;

use super::{Draws, MeasureOptions, Metric, Name, Value};
use crate::error::Result;
use crate::raster::cpu::{self, Fragment};
use crate::raster::layers;
use crate::raster::naming_mesh;

/// The blending weight of every fragment.
pub const ALPHA: f32 = 0.5;

/// A colour difference a viewer can see on an 8-bit display.
const VISIBLE: f32 = 1.0 / 255.0;

/// What one view's fragments give.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ViewError {
    /// Pixels with at least one fragment.
    pub covered: u64,
    /// Pixels whose blended colour differs visibly from the exact one.
    pub wrong: u64,
    /// Σ over covered pixels and the three channels of the squared colour difference.
    pub squared: f64,
    /// Fragment pairs blended nearer first.
    pub pairs: u64,
}

impl ViewError {
    fn wrong_share(&self) -> Option<f64> {
        (self.covered > 0).then(|| self.wrong as f64 / self.covered as f64)
    }

    fn rmse(&self) -> Option<f64> {
        (self.covered > 0).then(|| (self.squared / (3 * self.covered) as f64).sqrt())
    }

    fn pairs_per_pixel(&self) -> Option<f64> {
        (self.covered > 0).then(|| self.pairs as f64 / self.covered as f64)
    }
}

/// The colour of triangle `id`: three well-spread channels from a hash of the id.
pub fn colour(id: u32) -> [f32; 3] {
    let mut x = u64::from(id).wrapping_add(0x9E37_79B9_7F4A_7C15);
    x = (x ^ (x >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    x = (x ^ (x >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    x ^= x >> 31;
    [0, 21, 42].map(|shift| ((x >> shift) & 0x1F_FFFF) as f32 / 0x1F_FFFF as f32)
}

/// Visits every pixel the `fragments` cover (one view's, of a `res`² image) with its colour
/// blended in draw order, its exact colour (blended back to front) and its fragment pairs
/// blended nearer first. A fragment's `triangle` is drawn `drawn(triangle)`-th and coloured as
/// triangle id `id(triangle)`: the fragments may come in any order.
fn blend_pixels(
    fragments: &[Fragment],
    res: u32,
    drawn: impl Fn(u32) -> u32,
    id: impl Fn(u32) -> u32,
    mut visit: impl FnMut(usize, [f32; 3], [f32; 3], u64),
) {
    // The fragments grouped by pixel (a counting sort, stable), then each pixel's in draw order.
    let pixels = (res as usize) * (res as usize);
    let mut start = vec![0u32; pixels + 1];
    for f in fragments {
        start[f.pixel as usize + 1] += 1;
    }
    for p in 0..pixels {
        start[p + 1] += start[p];
    }
    let mut next = start.clone();
    let mut grouped = vec![0u32; fragments.len()];
    for (i, f) in fragments.iter().enumerate() {
        grouped[next[f.pixel as usize] as usize] = i as u32;
        next[f.pixel as usize] += 1;
    }
    let blend = |order: &[u32]| {
        order.iter().fold([0f32; 3], |c, &i| {
            let own = colour(id(fragments[i as usize].triangle));
            [0, 1, 2].map(|k| c[k] * (1.0 - ALPHA) + own[k] * ALPHA)
        })
    };
    let mut far_first: Vec<u32> = Vec::new();
    for p in 0..pixels {
        let here = &mut grouped[start[p] as usize..start[p + 1] as usize];
        if here.is_empty() {
            continue;
        }
        if here.len() == 1 {
            let only = blend(here);
            visit(p, only, only, 0);
            continue;
        }
        here.sort_by_key(|&i| drawn(fragments[i as usize].triangle));
        let here = &*here;
        let depth = |i: u32| fragments[i as usize].depth;
        let pairs = here.iter().enumerate().map(|(a, &i)| here[a + 1..].iter().filter(|&&j| depth(i) < depth(j)).count() as u64).sum();
        far_first.clear();
        far_first.extend_from_slice(here);
        far_first.sort_by(|&i, &j| depth(j).total_cmp(&depth(i)));
        visit(p, blend(here), blend(&far_first), pairs);
    }
}

/// The error of drawing `fragments` (one view's, in draw order; `ids[t]` the triangle id of drawn
/// triangle `t`) blended in draw order, against the exact back-to-front blend, on a `res`² image.
pub fn view_error(fragments: &[Fragment], ids: &[u32], res: u32) -> ViewError {
    error_of(fragments, res, |t| t, |t| ids[t as usize])
}

/// The error of drawing triangle t `rank[t]`-th, from `fragments` of the triangles in any order
/// whose `triangle` is the triangle's id: [`view_error`] of that order, from fragments that every
/// order of the same triangles shares.
pub fn view_error_of_order(fragments: &[Fragment], rank: &[u32], res: u32) -> ViewError {
    error_of(fragments, res, |t| rank[t as usize], |t| t)
}

fn error_of(fragments: &[Fragment], res: u32, drawn: impl Fn(u32) -> u32, id: impl Fn(u32) -> u32) -> ViewError {
    let mut error = ViewError::default();
    blend_pixels(fragments, res, drawn, id, |_, drawn, exact, pairs| {
        let differences = [0, 1, 2].map(|k| drawn[k] - exact[k]);
        error.covered += 1;
        error.pairs += pairs;
        error.squared += differences.iter().map(|d| f64::from(*d) * f64::from(*d)).sum::<f64>();
        error.wrong += u64::from(differences.iter().any(|d| d.abs() > VISIBLE));
    });
    error
}

/// Where the errors fall, per pixel of a `res`² image (row 0 at the bottom): 0 where nothing is
/// drawn, 1 where the blend is right (within 1/255), and 2 to 255 where it is visibly wrong, by
/// the largest channel difference in 1/255 steps (saturating). What a figure of the errors draws.
pub fn error_picture(fragments: &[Fragment], ids: &[u32], res: u32) -> Vec<u32> {
    let mut picture = vec![0u32; (res as usize) * (res as usize)];
    blend_pixels(fragments, res, |t| t, |t| ids[t as usize], |p, drawn, exact, _| {
        let worst = (0..3).map(|k| (drawn[k] - exact[k]).abs()).fold(0.0f32, f32::max);
        picture[p] = if worst > VISIBLE { 1 + ((worst * 255.0).round() as u32).clamp(1, 254) } else { 1 };
    });
    picture
}

/// The translucency error over the view set.
pub struct Translucency;

pub static METRIC: Translucency = Translucency;

const NEEDS: &str = "`views` and `translucency`";

static NAMES: &[Name] = &[
    Name { name: "translucency_wrong_pixels", label: "wrong-pixel share", needs: NEEDS, optimum: None },
    Name { name: "translucency_rmse", label: "blend colour RMSE", needs: NEEDS, optimum: None },
    Name { name: "translucency_pairs", label: "inverted pairs/px", needs: NEEDS, optimum: None },
    Name { name: "translucency_wrong_pixels_view", label: "share of pixels blended visibly wrong, per view", needs: NEEDS, optimum: None },
    Name { name: "translucency_rmse_view", label: "colour RMSE, per view", needs: NEEDS, optimum: None },
    Name { name: "translucency_pairs_view", label: "wrongly blended pairs per pixel, per view", needs: NEEDS, optimum: None },
];

impl Metric for Translucency {
    fn names(&self) -> &'static [Name] {
        NAMES
    }

    fn reported(&self, options: &MeasureOptions) -> Vec<&'static str> {
        if options.translucency && options.views.is_some() { NAMES.iter().map(|n| n.name).collect() } else { Vec::new() }
    }

    fn measure(&self, draws: &Draws) -> Result<Vec<Value>> {
        Ok(self.measure_many(std::slice::from_ref(draws))?.pop().expect("one draws, one list"))
    }

    /// Every frame from every view, the views in parallel, each rasterized once into its
    /// fragments, which every order measured shares: each order's error is blended from them in
    /// that order (the buffer its lookup picks for the frame and view).
    fn measure_many(&self, many: &[Draws]) -> Result<Vec<Vec<Value>>> {
        let Some(draws) = many.first() else { return Ok(Vec::new()) };
        let (res, views) = (draws.options.res, draws.cameras.len());
        // Every buffer's ranks, per order measured.
        let ranks: Vec<Vec<Vec<u32>>> =
            many.iter().map(|d| d.orders.buffers.iter().map(|b| layers::ranks(&b.order)).collect()).collect();
        let jobs: Vec<(usize, usize)> = draws.frames.clone().flat_map(|f| (0..views).map(move |v| (f, v))).collect();
        let errors: Vec<Vec<ViewError>> = jobs
            .par_iter()
            .map_init(Vec::new, |fragments, &(f, v)| {
                let triangles = draws.scene.frames.triangles(f, &draws.scene.mesh);
                cpu::fragments(draws.positions(f), &triangles, &draws.cameras[v], res, fragments)
                    .map_err(|e| naming_mesh(&draws.scene.mesh.name, e))?;
                Ok(many.iter().zip(&ranks).map(|(d, r)| view_error_of_order(fragments, &r[d.pick(f, v)], res)).collect())
            })
            .collect::<Result<_>>()?;
        Ok((0..many.len()).map(|d| values(draws, &jobs, errors.iter().map(|e| e[d]))).collect())
    }

    fn columns(&self, values: &[&Value]) -> Vec<(String, String)> {
        let find = |metric: &str| values.iter().find(|v| v.metric == metric).map(|v| v.value);
        let cell = match (find("translucency_wrong_pixels"), find("translucency_rmse"), find("translucency_pairs")) {
            (Some(wrong), Some(rmse), Some(pairs)) => format!("{:.2}%/{rmse:.4}/{pairs:.3}", wrong * 100.0),
            _ => "no visible faces".into(),
        };
        vec![("translucency wrong/RMSE/pairs".to_string(), cell)]
    }
}

/// One order's values: the means over the views that see something, then each view's.
fn values(draws: &Draws, jobs: &[(usize, usize)], errors: impl Iterator<Item = ViewError> + Clone) -> Vec<Value> {
    let at = |metric: &'static str, value: f64| Value { views: draws.views(), ..Value::new(metric, value) };
    let mut values = Vec::new();
    type Of = fn(&ViewError) -> Option<f64>;
    let kinds: [(&'static str, &'static str, Of); 3] = [
        ("translucency_wrong_pixels", "translucency_wrong_pixels_view", ViewError::wrong_share),
        ("translucency_rmse", "translucency_rmse_view", ViewError::rmse),
        ("translucency_pairs", "translucency_pairs_view", ViewError::pairs_per_pixel),
    ];
    let views = draws.cameras.len();
    for (summary, per_view, of) in kinds {
        let seen: Vec<f64> = errors.clone().filter_map(|e| of(&e)).collect();
        if !seen.is_empty() {
            values.push(at(summary, seen.iter().sum::<f64>() / seen.len() as f64));
        }
        for (&(f, v), e) in jobs.iter().zip(errors.clone()) {
            if let Some(value) = of(&e) {
                values.push(Value { view: Some((f - draws.frames.start) * views + v), ..at(per_view, value) });
            }
        }
    }
    values
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fragment(pixel: u32, triangle: u32, depth: f32) -> Fragment {
        Fragment { pixel, triangle, depth, passed: true }
    }

    #[test]
    fn back_to_front_is_exact_and_front_to_back_is_wrong() {
        // Two triangles over pixel 0; triangle 0 is farther (depth 0.8).
        let ids = [7, 9];
        let right = [fragment(0, 0, 0.8), fragment(0, 1, 0.2), fragment(1, 1, 0.2)];
        let e = view_error(&right, &ids, 2);
        assert_eq!((e.covered, e.wrong, e.pairs), (2, 0, 0));
        assert_eq!(e.squared, 0.0);
        // Drawn nearer first: one inverted pair, one wrong pixel of two.
        let wrong = [fragment(0, 0, 0.2), fragment(0, 1, 0.8), fragment(1, 1, 0.2)];
        let e = view_error(&wrong, &ids, 2);
        assert_eq!((e.covered, e.wrong, e.pairs), (2, 1, 1));
        // By hand: blended a then b gives b/2 + a/4, the exact b-then-a gives a/2 + b/4.
        let (a, b) = (colour(7), colour(9));
        let expected: f64 = (0..3).map(|k| f64::from((b[k] / 2.0 + a[k] / 4.0) - (a[k] / 2.0 + b[k] / 4.0)).powi(2)).sum();
        assert!((e.squared - expected).abs() < 1e-9, "{} vs {expected}", e.squared);
        assert_eq!(e.wrong_share(), Some(0.5));
    }

    #[test]
    fn three_fragments_count_every_inverted_pair() {
        // Drawn nearest first: all three pairs are inverted.
        let fragments = [fragment(3, 0, 0.1), fragment(3, 1, 0.5), fragment(3, 2, 0.9)];
        let e = view_error(&fragments, &[0, 1, 2], 2);
        assert_eq!((e.covered, e.pairs), (1, 3));
        // Equal depths are never inverted.
        let tied = [fragment(0, 0, 0.5), fragment(0, 1, 0.5)];
        assert_eq!(view_error(&tied, &[0, 1], 1).pairs, 0);
    }
}
