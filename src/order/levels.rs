//! Rendering sequences kept under vertex removal: Bogomjakov & Gotsman 2002, §3, the simple and
//! the smart update.
//!
//! A progressive mesh ([`History`]) is drawn at a level by replaying its first removals. The
//! paper keeps one rendering sequence through them: the triangles a removal leaves alone never
//! move, and the n − 2 triangles that fill its hole take n − 2 of the n positions the removed
//! triangles free.
//! - **Simple** gives them the first n − 2 freed positions, in sequence order.
//! - **Smart** follows the paper's pseudo-code: first each new triangle takes the position of a
//!   removed one with which it shares exactly two vertices; then, repeatedly, the new triangle
//!   with the fewest removed neighbours still free (sharing at least one vertex) takes the first
//!   of them; then what is left takes what is left. The pseudo-code's first loop overwrites an
//!   earlier match and may hand out a position already taken; we take, for each new triangle in
//!   turn, the first removed triangle (in sequence order) with two common vertices whose position
//!   is still free, which is what the loop is meant to do.
//!
//! The two positions a removal leaves unused stay empty: a renderer draws the sequence with its
//! holes skipped (compacted, the relative order kept), which is what [`Sequence::order`] returns.

use std::time::Instant;

use crate::error::Result;
use crate::mesh::frames::Levels;
use crate::mesh::progressive::{History, Record, Update};
use crate::mesh::{Mesh, Scene};

use super::{Clustered, Lookup, Order, Orders, Resolved, needs_one_order};

/// The orders of `resolved` for every level of `scene` (whose frames are `levels`): its sequence
/// of the full mesh kept through the removals by the simple or smart update, or, for
/// [`Update::Reorder`], the method run anew on each level's mesh. Buffer f draws level f; each is
/// an order of that level's triangles (indices into its list).
pub fn run(resolved: &Resolved, scene: &Scene, levels: &Levels) -> Result<Orders> {
    if resolved.method.per_node {
        return Err(needs_one_order(resolved.method.name, "a progressive mesh cannot keep its sequence"));
    }
    let one = |scene: &Scene| -> Result<Order> {
        let orders = resolved.ordering.order(scene)?;
        let buffer =
            orders.single().ok_or_else(|| needs_one_order(resolved.method.name, "it has no sequence to keep"))?;
        Ok(buffer.order.clone())
    };
    let start = Instant::now();
    let mut reused = 0.0;
    let (buffers, phases) = match levels.update {
        Update::Reorder => {
            let buffers = (0..levels.alive.len())
                .map(|f| one(&Scene::still(Mesh { triangles: levels.triangles(f), ..scene.mesh.clone() })))
                .collect::<Result<Vec<_>>>()?;
            (buffers, vec![("order every level", start.elapsed().as_secs_f64())])
        }
        update => {
            // A static method orders `scene.mesh`, the full-resolution mesh, whatever the frames.
            // That order is the same for the simple and the smart update, so it is made once a
            // scene (its shared work) and each reuse is charged at what making it cost.
            let key = format!("the full mesh ordered by {}", resolved.canonical());
            let (order, made) = scene.shared.get_or_compute(&key, || one(scene))?;
            reused = made.unwrap_or(0.0);
            let ordered = start.elapsed().as_secs_f64();
            let sequences = self::levels(&levels.history, &order, update == Update::Smart, &levels.records);
            let buffers = sequences
                .iter()
                .zip(&levels.alive)
                .map(|(sequence, alive)| {
                    sequence
                        .iter()
                        .map(|t| alive.binary_search(t).expect("a level draws its own triangles") as u32)
                        .collect()
                })
                .collect();
            (buffers, vec![("order", ordered + reused), ("update", start.elapsed().as_secs_f64() - ordered)])
        }
    };
    let per_level: Vec<u16> = (0..buffers.len() as u16).collect();
    Ok(Orders {
        buffers: buffers.into_iter().map(Clustered::single).collect(),
        lookup: Lookup::per_frame(&per_level),
        iterations: None,
        converged: true,
        phases,
        reused,
    })
}

/// Marks an empty position.
const EMPTY: u32 = u32::MAX;

/// A rendering sequence over the triangles of a [`History`]: positions holding triangle ids, some
/// empty.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Sequence {
    slots: Vec<u32>,
    /// Triangle id → its position, for alive triangles.
    position: Vec<u32>,
}

impl Sequence {
    /// The full-resolution sequence: `order` (a permutation of the mesh's triangles) in place.
    pub fn new(history: &History, order: &[u32]) -> Sequence {
        let mut position = vec![EMPTY; history.triangles.len()];
        for (p, &t) in order.iter().enumerate() {
            position[t as usize] = p as u32;
        }
        Sequence { slots: order.to_vec(), position }
    }

    /// Applies one removal, by the smart update or else the simple one.
    pub fn apply(&mut self, history: &History, record: &Record, smart_update: bool) {
        let mut freed: Vec<(u32, u32)> = record.before.iter().map(|&t| (self.position[t as usize], t)).collect();
        freed.sort_unstable();
        for &(p, t) in &freed {
            self.slots[p as usize] = EMPTY;
            self.position[t as usize] = EMPTY;
        }
        let new: Vec<u32> = record.after.clone().collect();
        let chosen = if smart_update { smart(history, &freed, &new) } else { (0..new.len()).collect() };
        for (&t, &j) in new.iter().zip(&chosen) {
            let p = freed[j].0;
            self.slots[p as usize] = t;
            self.position[t as usize] = p;
        }
    }

    /// The triangles in drawing order, empty positions skipped.
    pub fn order(&self) -> Vec<u32> {
        self.slots.iter().copied().filter(|&t| t != EMPTY).collect()
    }
}

/// For each new triangle, the index into `freed` (removed triangles in sequence order) whose
/// position it takes, by the smart rule.
fn smart(history: &History, freed: &[(u32, u32)], new: &[u32]) -> Vec<usize> {
    let corners = |t: u32| history.triangles[t as usize];
    let common = |a: u32, b: u32| {
        let (a, b) = (corners(a), corners(b));
        a.iter().filter(|v| b.contains(v)).count()
    };
    let mut free = vec![true; freed.len()];
    let mut chosen: Vec<Option<usize>> = vec![None; new.len()];
    // Two common vertices: the removed triangle this one most nearly replaces.
    for (i, &t) in new.iter().enumerate() {
        if let Some(j) = (0..freed.len()).find(|&j| free[j] && common(t, freed[j].1) == 2) {
            chosen[i] = Some(j);
            free[j] = false;
        }
    }
    // One common vertex: the most constrained new triangle first.
    let mut lists: Vec<Vec<usize>> = new
        .iter()
        .enumerate()
        .map(|(i, &t)| {
            if chosen[i].is_some() {
                Vec::new()
            } else {
                (0..freed.len()).filter(|&j| free[j] && common(t, freed[j].1) >= 1).collect()
            }
        })
        .collect();
    while let Some(i) = (0..lists.len()).filter(|&i| !lists[i].is_empty()).min_by_key(|&i| (lists[i].len(), i)) {
        let j = lists[i][0];
        chosen[i] = Some(j);
        free[j] = false;
        lists[i].clear();
        lists.iter_mut().for_each(|l| l.retain(|&k| k != j));
    }
    // Whatever is left takes whatever is left, in order.
    let mut rest = (0..freed.len()).filter(|&j| free[j]);
    chosen
        .into_iter()
        .map(|c| c.unwrap_or_else(|| rest.next().expect("n − 2 new triangles for n freed positions")))
        .collect()
}

/// The sequence of each level, each level given as a number of removals (ascending), from
/// `order` at full resolution kept by the smart update (or else the simple one): per level, the
/// triangle ids in drawing order.
pub fn levels(history: &History, order: &[u32], smart_update: bool, levels: &[usize]) -> Vec<Order> {
    let mut sequence = Sequence::new(history, order);
    let mut applied = 0;
    let mut out = Vec::with_capacity(levels.len());
    for &records in levels {
        for record in &history.records[applied..records] {
            sequence.apply(history, record, smart_update);
        }
        applied = applied.max(records);
        out.push(sequence.order());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::cache::{CacheModel, simulate};
    use crate::mesh::{Topology, procedural};

    #[test]
    fn updates_keep_unaffected_triangles_in_place_and_give_each_level_its_triangles() {
        let mesh = procedural::generate("sphere:2000", 1).unwrap().unwrap();
        let history = History::build(&mesh, &Topology::new(&mesh), 200);
        let order: Vec<u32> = (0..mesh.triangle_count() as u32).rev().collect();
        for update in [false, true] {
            let mut sequence = Sequence::new(&history, &order);
            for (i, record) in history.records.iter().enumerate() {
                let before = sequence.clone();
                sequence.apply(&history, record, update);
                // Every triangle the removal did not touch keeps its position.
                for (p, &t) in before.slots.iter().enumerate() {
                    if t != EMPTY && !record.before.contains(&t) {
                        assert_eq!(sequence.slots[p], t, "smart {update} record {i} moved triangle {t}");
                    }
                }
                // New triangles sit only where removed ones were.
                for t in record.after.clone() {
                    let p = sequence.position[t as usize] as usize;
                    assert!(record.before.contains(&before.slots[p]), "smart {update} record {i}");
                }
            }
            let mut drawn = sequence.order();
            drawn.sort_unstable();
            assert_eq!(drawn, history.level(history.records.len()), "smart {update}");
        }
    }

    #[test]
    fn smart_prefers_the_triangle_a_new_one_replaces() {
        // A vertex of valence 6 in a flat hexagon, removed onto neighbour 1: each new triangle is a
        // removed one with vertex 1 for vertex 0, sharing two vertices with it.
        let mesh = procedural::generate("disk:200", 3).unwrap().unwrap();
        let history = History::build(&mesh, &Topology::new(&mesh), 150);
        let record = &history.records[0];
        let freed: Vec<(u32, u32)> = record.before.iter().enumerate().map(|(p, &t)| (p as u32, t)).collect();
        let new: Vec<u32> = record.after.clone().collect();
        let chosen = smart(&history, &freed, &new);
        for (&t, &j) in new.iter().zip(&chosen) {
            let origin =
                history.triangles[freed[j].1 as usize].map(|v| if v == record.removed { record.kept } else { v });
            let shared = history.triangles[t as usize].iter().filter(|v| origin.contains(v)).count();
            assert!(shared >= 2, "new triangle {t} took the slot of an unrelated triangle");
        }
        let mut sorted = chosen.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), chosen.len(), "two new triangles in one slot");
    }

    /// The simple and the smart update of one scene start from one order of the full mesh, made
    /// once: the second run reuses it, is charged what it cost, and gives the levels a scene
    /// that orders anew gives.
    #[test]
    fn the_updates_of_a_scene_share_the_full_meshs_order() {
        let resolved = crate::order::resolve("mla", 0).unwrap();
        let open = || {
            let mesh = procedural::generate("sphere:3000", 1).unwrap().unwrap();
            Scene::still(mesh).with_levels(&[1.0, 0.6, 0.3], Update::Simple).unwrap()
        };
        let buffers = |orders: &Orders| orders.buffers.iter().map(|b| b.order.clone()).collect::<Vec<_>>();
        let mut scene = open();
        let simple = crate::order::run(&resolved, &scene).unwrap();
        assert_eq!(simple.reused, 0.0, "the first update orders the mesh");
        scene.set_update(Update::Smart);
        let smart = crate::order::run(&resolved, &scene).unwrap();
        assert!(smart.reused > 0.0, "the second update reuses the order and is charged for it");
        let mut fresh = open();
        fresh.set_update(Update::Smart);
        let anew = crate::order::run(&resolved, &fresh).unwrap();
        assert_eq!(anew.reused, 0.0);
        assert_eq!(buffers(&smart), buffers(&anew));
        assert_ne!(buffers(&smart), buffers(&simple), "the two updates differ, so the test tells them apart");
    }

    #[test]
    fn smart_degrades_less_than_simple_on_a_sphere() {
        let mesh = procedural::generate("sphere:5000", 1).unwrap().unwrap();
        let history = History::build(&mesh, &Topology::new(&mesh), 500);
        let topology = Topology::new(&mesh);
        let order = crate::order::tipsify::tipsify(&mesh.triangles, &topology.vertex_triangles, 16).0;
        let last = history.records.len();
        let acmr = |update| {
            let drawn = &levels(&history, &order, update, &[last])[0];
            let triangles: Vec<[u32; 3]> = drawn.iter().map(|&t| history.triangles[t as usize]).collect();
            simulate(CacheModel::Fifo(16), &triangles, mesh.vertex_count()).acmr()
        };
        let (simple, smart) = (acmr(false), acmr(true));
        assert!(smart <= simple * 1.01, "smart {smart} against simple {simple}");
    }
}
