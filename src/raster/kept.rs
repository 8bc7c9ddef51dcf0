//! Views' [`DepthLayers`] kept from one spec of a run for a later spec that measures the same
//! triangles from the same views: `reproduce` measures Soldier's 91 keyframes from 300 random
//! views at 256² in six specs (each with its own orders), and rasterizing those 27,300 views was
//! most of each spec's measuring. With the layers kept, a later spec only replays its orders'
//! depth tests on them ([`super::cpu::Replay`]): the counts are those of rasterizing again, which
//! is what the layers are (their triangles and views are checked equal, not trusted to a key).

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use glam::Vec3;
use rayon::prelude::*;

use super::cpu::{CpuRaster, Replay, depth_layers};
use super::layers::DepthLayers;
use super::{Camera, OrderPicks, RasterBackend, ViewCounts, count_each_order};
use crate::error::Result;

/// Most bytes of layers a [`LayerMemo`] holds: Soldier's 27,300 views take about 1.8 GB; beyond
/// the budget, layers are not kept (and are counted as the CPU backend counts them).
pub const BUDGET: usize = 4 << 30;

/// Layers kept under a tag (what the runner names a model's measurement by), each with the
/// drawing it is of.
#[derive(Default)]
pub struct LayerMemo {
    state: Mutex<State>,
}

#[derive(Default)]
struct State {
    kept: HashMap<String, Vec<Kept>>,
    bytes: usize,
}

/// One drawing's layers: of `triangles` at `positions` from `cameras` at `res`².
struct Kept {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    cameras: Vec<Camera>,
    res: u32,
    layers: Arc<Vec<DepthLayers>>,
}

impl Kept {
    fn is_of(&self, positions: &[Vec3], triangles: &[[u32; 3]], cameras: &[Camera], res: u32) -> bool {
        self.res == res && self.positions == positions && self.triangles == triangles && self.cameras == cameras
    }
}

impl LayerMemo {
    /// The layers of `triangles` at `positions` from `cameras`, kept under `tag` or rasterized;
    /// kept when `keep` says a later spec asks for `tag` and the budget has room.
    fn layers(
        &self,
        tag: &str,
        keep: bool,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        cameras: &[Camera],
        res: u32,
    ) -> Result<Arc<Vec<DepthLayers>>> {
        let found = {
            let state = self.state.lock().expect("no thread panics holding the memo");
            state
                .kept
                .get(tag)
                .and_then(|k| k.iter().find(|k| k.is_of(positions, triangles, cameras, res)))
                .map(|k| k.layers.clone())
        };
        if let Some(layers) = found {
            return Ok(layers);
        }
        let layers = Arc::new(depth_layers(positions, triangles, cameras, res)?);
        let bytes: usize = layers.iter().map(DepthLayers::bytes).sum();
        let mut state = self.state.lock().expect("no thread panics holding the memo");
        if keep && state.bytes + bytes <= BUDGET {
            state.bytes += bytes;
            let kept = Kept {
                positions: positions.to_vec(),
                triangles: triangles.to_vec(),
                cameras: cameras.to_vec(),
                res,
                layers: layers.clone(),
            };
            state.kept.entry(tag.to_string()).or_default().push(kept);
        }
        Ok(layers)
    }

    /// Drops every tag `still_wanted` refuses.
    pub fn retain(&self, still_wanted: impl Fn(&str) -> bool) {
        let mut state = self.state.lock().expect("no thread panics holding the memo");
        state.kept.retain(|tag, _| still_wanted(tag));
        state.bytes = state.kept.values().flatten().flat_map(|k| k.layers.iter()).map(DepthLayers::bytes).sum();
    }

    /// The bytes of layers held.
    pub fn bytes(&self) -> usize {
        self.state.lock().expect("no thread panics holding the memo").bytes
    }
}

/// The CPU backend with its views' layers taken from, or kept in, a [`LayerMemo`] under one tag.
pub struct KeptLayers<'a> {
    pub memo: &'a LayerMemo,
    pub tag: String,
    /// Whether a later spec asks for the tag, so that new layers are worth keeping.
    pub keep: bool,
}

impl RasterBackend for KeptLayers<'_> {
    fn name(&self) -> &'static str {
        CpuRaster.name()
    }

    fn count(
        &self,
        positions: &[Vec3],
        triangles: &[[u32; 3]],
        cameras: &[Camera],
        res: u32,
    ) -> Result<Vec<ViewCounts>> {
        CpuRaster.count(positions, triangles, cameras, res)
    }

    fn count_orders(
        &self,
        positions: &[Vec3],
        cameras: &[Camera],
        draws: &OrderPicks,
        res: u32,
    ) -> Result<Vec<Vec<ViewCounts>>> {
        let Some(replay) = Replay::new(draws) else {
            return count_each_order(self, positions, cameras, draws, res);
        };
        let layers = self.memo.layers(&self.tag, self.keep, positions, draws.triangles, cameras, res)?;
        Ok(layers.par_iter().zip(draws.picks).map(|(view, picks)| replay.counts(view, picks)).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Framing;
    use crate::mesh::procedural;
    use crate::raster::ViewSet;

    /// Counts from kept layers are the CPU backend's, on the first measurement (kept) and on a
    /// later one (taken from the memo); another drawing under the same tag is not mistaken for
    /// the kept one; what is not to be kept is not; dropping the tag frees the bytes.
    #[test]
    fn kept_layers_count_as_the_cpu_backend() {
        let mesh = procedural::generate("sphere:2000", 0).unwrap().unwrap();
        let cameras = ViewSet::Random(12).cameras(Framing::of(&mesh.positions), 0);
        let n = mesh.triangles.len() as u32;
        let forward: Vec<u32> = (0..n).collect();
        let backward: Vec<u32> = (0..n).rev().collect();
        let orders: Vec<&[u32]> = vec![&forward, &backward];
        let picks: Vec<Vec<usize>> =
            (0..cameras.len()).map(|v| if v % 2 == 0 { vec![0, 1] } else { vec![1] }).collect();
        let draws = OrderPicks { triangles: &mesh.triangles, orders: &orders, picks: &picks };
        let expected = CpuRaster.count_orders(&mesh.positions, &cameras, &draws, 64).unwrap();
        let memo = LayerMemo::default();
        let kept = KeptLayers { memo: &memo, tag: "sphere".into(), keep: true };
        assert_eq!(kept.count_orders(&mesh.positions, &cameras, &draws, 64).unwrap(), expected);
        let held = memo.bytes();
        assert!(held > 0);
        assert_eq!(kept.count_orders(&mesh.positions, &cameras, &draws, 64).unwrap(), expected);
        assert_eq!(memo.bytes(), held, "the second measurement reads the kept layers");
        let moved: Vec<Vec3> = mesh.positions.iter().map(|p| *p * Vec3::new(1.0, 0.5, 1.0)).collect();
        let elsewhere = CpuRaster.count_orders(&moved, &cameras, &draws, 64).unwrap();
        assert_ne!(elsewhere, expected);
        assert_eq!(kept.count_orders(&moved, &cameras, &draws, 64).unwrap(), elsewhere);
        let two = memo.bytes();
        assert!(two > held, "the other drawing is kept beside the first");
        let passing = KeptLayers { keep: false, ..kept };
        let at_32 = CpuRaster.count_orders(&moved, &cameras, &draws, 32).unwrap();
        assert_eq!(passing.count_orders(&moved, &cameras, &draws, 32).unwrap(), at_32);
        assert_eq!(memo.bytes(), two, "layers not to be kept are not");
        memo.retain(|_| true);
        assert_eq!(memo.bytes(), two);
        memo.retain(|tag| tag != "sphere");
        assert_eq!(memo.bytes(), 0);
    }
}
