//! Render time on the GPU (`--render pixel|vertex`, a spec's `render`): every frame drawn from
//! every view with its buffer, timed with a pixel-bound or a vertex-bound shader; reported per
//! shader as the mean over draws of the median frame time and of its spread (90th − 10th
//! percentile), and the median of each draw.

use super::{Draws, MeasureOptions, Metric, Name, Value};
use crate::error::{Error, Result};
use crate::gpu::render_time::{self, Shading};

pub struct RenderTime;

pub static METRIC: RenderTime = RenderTime;

const PIXEL: &str = "render = [\"pixel\"] and `views`";
const VERTEX: &str = "render = [\"vertex\"] and `views`";

static NAMES: &[Name] = &[
    Name { name: "render_ms_pixel", label: "frame time, pixel-bound shader (ms, mean over views)", needs: PIXEL, optimum: None },
    Name { name: "render_ms_vertex", label: "frame time, vertex-bound shader (ms, mean over views)", needs: VERTEX, optimum: None },
    Name {
        name: "render_spread_pixel",
        label: "frame-time spread p90 − p10, pixel-bound (ms, mean over views)",
        needs: PIXEL,
        optimum: None,
    },
    Name {
        name: "render_spread_vertex",
        label: "frame-time spread p90 − p10, vertex-bound (ms, mean over views)",
        needs: VERTEX,
        optimum: None,
    },
    Name { name: "render_ms_pixel_view", label: "frame time, pixel-bound shader (ms)", needs: PIXEL, optimum: None },
    Name { name: "render_ms_vertex_view", label: "frame time, vertex-bound shader (ms)", needs: VERTEX, optimum: None },
];

/// The names of one shader's values: mean, spread, per view.
fn names(shading: Shading) -> [&'static str; 3] {
    match shading {
        Shading::Pixel => ["render_ms_pixel", "render_spread_pixel", "render_ms_pixel_view"],
        Shading::Vertex => ["render_ms_vertex", "render_spread_vertex", "render_ms_vertex_view"],
    }
}

impl Metric for RenderTime {
    fn names(&self) -> &'static [Name] {
        NAMES
    }

    fn reported(&self, options: &MeasureOptions) -> Vec<&'static str> {
        options.render.iter().flat_map(|&s| names(s)).collect()
    }

    fn needs_gpu(&self) -> bool {
        true
    }

    fn measure(&self, draws: &Draws) -> Result<Vec<Value>> {
        if draws.cameras.is_empty() {
            return Err(Error::usage("render timing needs a view set (--views)"));
        }
        let timer = render_time::shared()?;
        let device = Some(timer.device());
        let (res, frames) = (draws.options.res, draws.options.render_frames);
        let mut values = Vec::new();
        for &shading in &draws.options.render {
            let mut timings = Vec::new();
            for (f, positions) in draws.scene.frames.frames.iter().enumerate() {
                let mut per_view = vec![None; draws.cameras.len()];
                for (b, group) in draws.groups(f) {
                    let triangles = draws.triangles(b);
                    for v in group {
                        per_view[v] =
                            Some(timer.time(positions, &triangles, &draws.cameras[v], res, shading, frames)?);
                    }
                }
                timings.extend(per_view.into_iter().flatten());
            }
            let n = timings.len().max(1) as f64;
            let [mean, spread, per_view] = names(shading);
            let at = |metric: &'static str, value: f64| Value {
                views: draws.views(),
                device: device.clone(),
                ..Value::new(metric, value)
            };
            values.push(at(mean, timings.iter().map(|t| t.median_ms).sum::<f64>() / n));
            values.push(at(spread, timings.iter().map(|t| t.p90_ms - t.p10_ms).sum::<f64>() / n));
            values
                .extend(timings.iter().enumerate().map(|(i, t)| Value { view: Some(i), ..at(per_view, t.median_ms) }));
        }
        Ok(values)
    }

    fn columns(&self, values: &[&Value]) -> Vec<(String, String)> {
        values
            .iter()
            .filter(|v| v.metric.starts_with("render_ms_"))
            .map(|v| {
                let shading = v.metric.trim_start_matches("render_ms_");
                (format!("{shading} ms"), format!("{:.3}", v.value))
            })
            .collect()
    }
}
