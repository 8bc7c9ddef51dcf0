//! Overdraw ratio statistics over a view set.
//!
//! Per view, OVR = fragments passing the depth test ÷ pixels covered (Nehab, Barczak & Sander
//! 2006 §6; 1.0 = perfect front-to-back). Over a set we report the mean of the per-view ratios,
//! the worst (max) view, and the population variance, as Nehab 2006 Fig. 8 and §6 do. Views from
//! which nothing is visible (a flat mesh seen edge-on or from behind) have no ratio; they are
//! left out of the statistics and counted in `empty_views`, never silently read as 1.0. The
//! ratio of sums (Tootle's "mean") is also given, since papers differ on which they report.

use super::{Draws, MeasureOptions, Metric, Name, Value};
use crate::error::Result;
use crate::raster::{OrderPicks, ViewCounts, naming_mesh};

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OverdrawSummary {
    /// Views with a ratio (covered > 0).
    pub views: usize,
    pub empty_views: usize,
    pub mean: f64,
    pub max: f64,
    pub min: f64,
    pub variance: f64,
    /// Σ passed ÷ Σ covered over all views.
    pub ratio_of_sums: f64,
}

impl OverdrawSummary {
    /// Summarises per-view counts; `None` if no view sees anything.
    pub fn of(counts: &[ViewCounts]) -> Option<OverdrawSummary> {
        let ratios: Vec<f64> = counts.iter().filter_map(ViewCounts::ovr).collect();
        if ratios.is_empty() {
            return None;
        }
        let n = ratios.len() as f64;
        let mean = ratios.iter().sum::<f64>() / n;
        let variance = ratios.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / n;
        let (passed, covered) = counts.iter().fold((0, 0), |(p, c), v| (p + v.passed, c + v.covered));
        Some(OverdrawSummary {
            views: ratios.len(),
            empty_views: counts.len() - ratios.len(),
            mean,
            max: ratios.iter().copied().fold(f64::MIN, f64::max),
            min: ratios.iter().copied().fold(f64::MAX, f64::min),
            variance,
            ratio_of_sums: passed as f64 / covered as f64,
        })
    }
}

/// Overdraw over the view set: every frame drawn from every view, each draw with its buffer.
pub struct Overdraw;

pub static METRIC: Overdraw = Overdraw;

static NAMES: &[Name] = &[
    Name { name: "ovr", label: "overdraw ratio (shaded ÷ covered pixels)", needs: "`views`", optimum: Some(1.0) },
    Name { name: "ovr_mean", label: "mean overdraw ratio over views", needs: "`views`", optimum: Some(1.0) },
    Name { name: "ovr_max", label: "worst-view overdraw ratio", needs: "`views`", optimum: Some(1.0) },
    Name { name: "ovr_min", label: "best-view overdraw ratio", needs: "`views`", optimum: Some(1.0) },
    Name { name: "ovr_var", label: "variance of the overdraw ratio over views", needs: "`views`", optimum: None },
    Name { name: "ovr_sum", label: "overdraw ratio (Σ shaded ÷ Σ covered)", needs: "`views`", optimum: Some(1.0) },
    Name { name: "ovr_empty", label: "views that see nothing", needs: "`views`", optimum: None },
];

impl Metric for Overdraw {
    fn names(&self) -> &'static [Name] {
        NAMES
    }

    fn reported(&self, options: &MeasureOptions) -> Vec<&'static str> {
        if options.views.is_some() { NAMES.iter().map(|n| n.name).collect() } else { Vec::new() }
    }

    fn measure(&self, draws: &Draws) -> Result<Vec<Value>> {
        Ok(self.measure_many(std::slice::from_ref(draws))?.pop().expect("one draws, one list"))
    }

    /// Per frame, every view's draws (one per order measured) are counted in one call of the
    /// backend, which the CPU backend answers from one rasterization per view
    /// ([`crate::raster::RasterBackend::count_orders`]). Summaries come for all frames
    /// (`ovr_empty` first; the statistics only when some view sees a front face), then for each
    /// clip of an animation with several, each with the per-view ratios (`ovr`) of the views
    /// that see something.
    fn measure_many(&self, many: &[Draws]) -> Result<Vec<Vec<Value>>> {
        let Some(draws) = many.first() else { return Ok(Vec::new()) };
        let views = draws.cameras.len();
        let first = draws.frames.start;
        let mut per_view = vec![vec![ViewCounts::default(); draws.frames.len() * views]; many.len()];
        for f in draws.frames.clone() {
            // The distinct buffers drawn at this frame, and per view the one each order's lookup picks.
            let mut orders: Vec<(usize, usize)> = Vec::new();
            let picks: Vec<Vec<usize>> = (0..views)
                .map(|v| {
                    let index = |d: usize| {
                        let key = (d, many[d].pick(f, v));
                        orders.iter().position(|&o| o == key).unwrap_or_else(|| {
                            orders.push(key);
                            orders.len() - 1
                        })
                    };
                    (0..many.len()).map(index).collect()
                })
                .collect();
            let slices: Vec<&[u32]> = orders.iter().map(|&(d, b)| &many[d].orders.buffers[b].order[..]).collect();
            let triangles = draws.scene.frames.triangles(f, &draws.scene.mesh);
            let counts = draws
                .raster
                .count_orders(
                    draws.positions(f),
                    &draws.cameras,
                    &OrderPicks { triangles: &triangles, orders: &slices, picks: &picks },
                    draws.options.res,
                )
                .map_err(|e| naming_mesh(&draws.scene.mesh.name, e))?;
            for (v, counts) in counts.into_iter().enumerate() {
                for (d, c) in counts.into_iter().enumerate() {
                    per_view[d][(f - first) * views + v] = c;
                }
            }
        }
        Ok(per_view.iter().map(|counts| summaries(draws, counts)).collect())
    }

    fn columns(&self, values: &[&Value]) -> Vec<(String, String)> {
        let Some((views, res)) = values.first().and_then(|v| v.views) else { return Vec::new() };
        let find = |metric: &str| values.iter().find(|v| v.metric == metric).map(|v| v.value);
        let cell = match (find("ovr_mean"), find("ovr_max"), find("ovr_var")) {
            (Some(mean), Some(max), Some(var)) => format!("{mean:.4}/{max:.4}/{var:.5}"),
            _ => "no visible faces".into(),
        };
        vec![(format!("OVR mean/max/var {views}@{res}"), cell)]
    }
}

/// The values of one order's per-view counts (frame-major over `draws`' frames): for all frames,
/// then per clip.
fn summaries(draws: &Draws, per_view: &[ViewCounts]) -> Vec<Value> {
    let views = draws.cameras.len();
    let first = draws.frames.start;
    let all = std::iter::once((None, draws.frames.clone()));
    let clips = draws.clips().iter().map(|(name, frames)| (Some(name.clone()), frames.clone()));
    let mut values = Vec::new();
    for (clip, frames) in all.chain(clips) {
        let counts = &per_view[(frames.start - first) * views..(frames.end - first) * views];
        let at = |metric: &'static str, value: f64| Value { views: draws.views(), clip: clip.clone(), ..Value::new(metric, value) };
        values.push(at("ovr_empty", counts.iter().filter(|v| v.ovr().is_none()).count() as f64));
        if let Some(s) = OverdrawSummary::of(counts) {
            for (metric, value) in [
                ("ovr_mean", s.mean),
                ("ovr_max", s.max),
                ("ovr_min", s.min),
                ("ovr_var", s.variance),
                ("ovr_sum", s.ratio_of_sums),
            ] {
                values.push(at(metric, value));
            }
        }
        for (i, ratio) in counts.iter().enumerate().filter_map(|(i, c)| Some((i, c.ovr()?))) {
            values.push(Value { view: Some(i), ..at("ovr", ratio) });
        }
    }
    values
}
