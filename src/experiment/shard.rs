//! Sharded runs: a spec's work cut into units, a deterministic share of them run per shard (one
//! task of a Slurm job array), each shard's rows written to a file of its own, and the shards
//! merged back into exactly the CSV an unsharded run writes.
//!
//! A **unit** is one (model, update, method) of a spec: the model ordered by the method, the
//! sequence kept by the update (progressive levels only), and every measurement of that pair.
//! Units are enumerated in the order an unsharded run works through them (models in the spec's
//! order, then updates, then methods), which is also the order of its CSV rows, so merging is a
//! stable sort by unit.
//!
//! Shards are balanced by **estimated cost**, not round robin: a corpus mixes meshes of a hundred
//! and of a million triangles, and methods differ by a thousandfold per triangle. Each unit's
//! cost is its model's triangles (counted for procedural meshes, estimated from the file's size
//! for files, which the loaders store at roughly 35 bytes per triangle whatever the format) times
//! the method's [`Cost`] class plus what its measurements cost per triangle and per pixel. Every
//! shard that has a unit of a model must load it, so a model's units stay on one shard unless the
//! model is too big for one ([`assign`]): spreading the units alone, four shards of the 14-model
//! `universal-acmr-vs-cache` loaded the models 46 times instead of 14, 9% more CPU time than one
//! run.
//!
//! A shard file is the results CSV with a `unit` column in front and one line before the header,
//! `# triorder-shard shard=K/N spec=ID fingerprint=HEX triorder=VERSION units=U mine=RANGES`:
//! the fingerprint hashes the spec file, the run's options that change results and the list of
//! models (a corpus directory that changed between shards changes it), so the merge can refuse a
//! stale shard, and `mine` lists the units the shard did, so the merge can check that the shards
//! cover every unit exactly once.

use std::collections::BTreeMap;
use std::fmt;
use std::hash::Hasher;
use std::io::BufRead;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use crate::atomic;
use crate::error::{Error, Result};
use crate::measure::MeasureOptions;
use crate::mesh::Source;
use crate::order::Cost;

/// Most shards a run may be cut into.
pub const MAX_SHARDS: usize = 100_000;

/// Bytes per triangle of a mesh file, roughly, over the shared models (OBJ, ASCII and binary PLY
/// alike lie between 25 and 75): turns a file's size into an estimate of its triangles.
const BYTES_PER_TRIANGLE: u64 = 35;

/// Shard `index` (from 1) of `count`, as `--shard K/N` writes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    pub index: usize,
    pub count: usize,
}

impl FromStr for Shard {
    type Err = Error;

    fn from_str(text: &str) -> Result<Shard> {
        let bad = |why: &str| Error::usage(format!("--shard `{text}`: {why}"));
        let (k, n) = text.split_once('/').ok_or_else(|| bad("expected K/N, as in 2/8 (shard 2 of 8)"))?;
        let parse = |s: &str| s.trim().parse::<usize>().ok();
        let (Some(index), Some(count)) = (parse(k), parse(n)) else {
            return Err(bad("K and N must be whole numbers, as in 2/8"));
        };
        if count == 0 || count > MAX_SHARDS {
            return Err(bad(&format!("N must be in 1..={MAX_SHARDS}")));
        }
        if index == 0 || index > count {
            return Err(bad(&format!("K must be in 1..={count} (shards count from 1, as Slurm array ids can)")));
        }
        Ok(Shard { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// One unit of a spec's work: indices into the run's models, updates and methods.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Unit {
    pub model: usize,
    pub update: usize,
    pub method: usize,
}

/// Every unit of a run, in canonical order: models, then updates, then methods.
pub fn units(models: usize, updates: usize, methods: usize) -> Vec<Unit> {
    (0..models)
        .flat_map(|model| {
            (0..updates).flat_map(move |update| (0..methods).map(move |method| Unit { model, update, method }))
        })
        .collect()
}

/// An estimate of a model's triangles without loading it: counted for a procedural mesh and a
/// simplified one, estimated from the file's size otherwise (a missing file counts as small: it
/// fails at once). An animation is measured at each keyframe, so its triangles count once per
/// frame it asks for (eight when it leaves that to the file) and four times per subdivision.
pub fn estimated_triangles(source: &Source, data: Option<&Path>) -> f64 {
    let file = |path: &str| {
        let found = Path::new(path).metadata().ok().or_else(|| data.and_then(|d| d.join(path).metadata().ok()));
        found.map_or(1.0, |m| (m.len() / BYTES_PER_TRIANGLE).max(1) as f64)
    };
    match source {
        Source::Procedural(spec) => crate::mesh::procedural::triangle_count(spec).unwrap_or(1) as f64,
        Source::File(path) => file(path),
        Source::Simplified { target, .. } => *target as f64,
        Source::Animation(a) => {
            let frames = a.selection.frames.unwrap_or(8) as f64;
            file(&a.path) * frames * 4f64.powi(a.subdiv as i32)
        }
    }
}

/// The estimated cost of measuring one (model, method) pair of `triangles`, in microseconds: the
/// ordering (its [`Cost`] class), each cache model's pass over the index buffer, and each view's
/// rasterization (its triangles and its pixels). The constants are this machine's (AMD EPYC)
/// orders of magnitude; only their ratios matter.
pub fn unit_cost(triangles: f64, cost: Cost, measure: &MeasureOptions, levels: usize) -> f64 {
    let caches = measure.caches.len() as f64 * 0.01;
    let views = measure.views.map_or(0.0, |v| v.len() as f64);
    let pixels = f64::from(measure.res) * f64::from(measure.res);
    let per_level = triangles * (cost.micros_per_triangle() + caches + views * 0.05) + views * pixels * 0.002;
    per_level * levels.max(1) as f64
}

/// The estimated cost of opening a model of `triangles` in a shard, in microseconds: loading it
/// and checking its topology (about 1.3 µs per triangle here), or simplifying it into levels
/// (about 10 µs per triangle). Every shard that has a unit of the model pays it.
pub fn setup_cost(triangles: f64, levels: usize) -> f64 {
    triangles * if levels > 0 { 10.0 } else { 1.3 }
}

/// Which shard (from 0) does each unit. Every shard that has a unit of a model pays to open it,
/// so a model's units stay together unless the model alone costs more than a shard's fair share
/// (the total over the shards); such a model is cut into as many pieces of about that share as
/// it needs, by longest processing time first (LPT: the costliest unit to the least loaded
/// piece). The pieces, and the whole models, then go to shards by LPT too. Ties fall to canonical
/// order and the lowest shard, so the assignment depends on the estimates alone.
pub fn assign(units: &[Unit], costs: &[f64], setup: &[f64], shards: usize) -> Vec<usize> {
    let models = setup.len();
    let mut of_model: Vec<Vec<usize>> = vec![Vec::new(); models];
    for (u, unit) in units.iter().enumerate() {
        of_model[unit.model].push(u);
    }
    let cost_of = |m: usize| setup[m] + of_model[m].iter().map(|&u| costs[u]).sum::<f64>();
    let share = (0..models).map(cost_of).sum::<f64>() / shards as f64;
    // Pieces: (cost, units), a whole model or a part of one.
    let mut pieces: Vec<(f64, Vec<usize>)> = Vec::new();
    for (m, units) in of_model.iter().enumerate().filter(|(_, u)| !u.is_empty()) {
        let parts = if share > 0.0 { ((cost_of(m) / share).ceil() as usize).clamp(1, units.len()) } else { 1 };
        let part_of = lpt(units.iter().map(|&u| costs[u]), parts);
        for part in 0..parts {
            let mine: Vec<usize> = units.iter().zip(&part_of).filter(|(_, p)| **p == part).map(|(&u, _)| u).collect();
            if !mine.is_empty() {
                pieces.push((setup[m] + mine.iter().map(|&u| costs[u]).sum::<f64>(), mine));
            }
        }
    }
    let shard_of_piece = lpt(pieces.iter().map(|(cost, _)| *cost), shards);
    let mut shard_of = vec![0; costs.len()];
    for ((_, units), &shard) in pieces.iter().zip(&shard_of_piece) {
        for &u in units {
            shard_of[u] = shard;
        }
    }
    shard_of
}

/// Longest processing time first: each item, costliest first (ties in order), to the least
/// loaded of `bins` (ties to the lowest); the bin of each item.
fn lpt(costs: impl Iterator<Item = f64>, bins: usize) -> Vec<usize> {
    let costs: Vec<f64> = costs.collect();
    let mut by_cost: Vec<usize> = (0..costs.len()).collect();
    by_cost.sort_by(|&a, &b| costs[b].total_cmp(&costs[a]).then(a.cmp(&b)));
    let mut load = vec![0.0f64; bins];
    let mut bin_of = vec![0; costs.len()];
    for item in by_cost {
        let least = (0..bins).min_by(|&a, &b| load[a].total_cmp(&load[b]).then(a.cmp(&b))).unwrap_or(0);
        load[least] += costs[item];
        bin_of[item] = least;
    }
    bin_of
}

/// A hash of everything a shard's rows depend on besides the code: the spec's text, whether the
/// run is quick, the backend override, and the models after corpus expansion.
pub fn fingerprint(spec_text: &str, quick: bool, backend: Option<&str>, models: &[String]) -> String {
    let mut hasher = fnv::FnvHasher::default();
    hasher.write(spec_text.as_bytes());
    hasher.write_u8(u8::from(quick));
    hasher.write(backend.unwrap_or("").as_bytes());
    for model in models {
        hasher.write(model.as_bytes());
        hasher.write_u8(b'\n');
    }
    format!("{:016x}", hasher.finish())
}

/// The first line of a shard file: what it is a shard of, and which units it holds.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Header {
    pub shard: Shard,
    pub spec: String,
    pub fingerprint: String,
    pub version: String,
    /// Units in the whole run.
    pub units: usize,
    /// The units this shard did, ascending.
    pub mine: Vec<usize>,
}

const MARK: &str = "# triorder-shard";

impl Header {
    fn line(&self) -> String {
        format!(
            "{MARK} shard={} spec={} fingerprint={} triorder={} units={} mine={}\n",
            self.shard,
            self.spec,
            self.fingerprint,
            self.version,
            self.units,
            ranges(&self.mine)
        )
    }

    fn parse(line: &str, path: &Path) -> Result<Header> {
        let bad = || Error::input(path.display(), format!("is not a shard file (its first line is not `{MARK} …`)"));
        let rest = line.trim_end().strip_prefix(MARK).ok_or_else(bad)?;
        let fields: BTreeMap<&str, &str> = rest.split_whitespace().filter_map(|f| f.split_once('=')).collect();
        let get = |key: &str| fields.get(key).copied().ok_or_else(bad);
        Ok(Header {
            shard: get("shard")?.parse().map_err(|_| bad())?,
            spec: get("spec")?.to_string(),
            fingerprint: get("fingerprint")?.to_string(),
            version: get("triorder")?.to_string(),
            units: get("units")?.parse().map_err(|_| bad())?,
            mine: parse_ranges(get("mine")?).ok_or_else(bad)?,
        })
    }

    /// Reads the header of the shard file at `path`; `None` when there is no such file.
    pub fn read(path: &Path) -> Result<Option<Header>> {
        let file = match std::fs::File::open(path) {
            Ok(file) => file,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(Error::input(path.display(), e)),
        };
        let mut line = String::new();
        std::io::BufReader::new(file).read_line(&mut line).map_err(|e| Error::input(path.display(), e))?;
        Header::parse(&line, path).map(Some)
    }
}

/// `0-3,7,9-10` for `[0, 1, 2, 3, 7, 9, 10]` (ascending).
fn ranges(ids: &[usize]) -> String {
    let mut out: Vec<String> = Vec::new();
    let mut i = 0;
    while i < ids.len() {
        let mut j = i;
        while j + 1 < ids.len() && ids[j + 1] == ids[j] + 1 {
            j += 1;
        }
        out.push(if i == j { ids[i].to_string() } else { format!("{}-{}", ids[i], ids[j]) });
        i = j + 1;
    }
    out.join(",")
}

fn parse_ranges(text: &str) -> Option<Vec<usize>> {
    let mut ids = Vec::new();
    for part in text.split(',').filter(|p| !p.is_empty()) {
        match part.split_once('-') {
            Some((lo, hi)) => ids.extend(lo.parse::<usize>().ok()?..=hi.parse::<usize>().ok()?),
            None => ids.push(part.parse().ok()?),
        }
    }
    Some(ids)
}

/// `DIR/NAME.shard-K-of-N.csv` for the results file `DIR/NAME.csv`.
pub fn path(csv: &Path, shard: Shard) -> PathBuf {
    let stem = csv.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    csv.with_file_name(format!("{stem}.shard-{}-of-{}.csv", shard.index, shard.count))
}

/// The shard counts of the shard files of `csv` in its directory (several after a run was
/// re-cut), ascending.
pub fn counts_present(csv: &Path) -> Vec<usize> {
    let stem = csv.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let prefix = format!("{stem}.shard-");
    let Some(dir) = csv.parent().and_then(|d| std::fs::read_dir(d).ok()) else { return Vec::new() };
    let mut counts: Vec<usize> = dir
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            let (_, n) = name.strip_prefix(&prefix)?.strip_suffix(".csv")?.split_once("-of-")?;
            n.parse().ok()
        })
        .collect();
    counts.sort_unstable();
    counts.dedup();
    counts
}

/// Writes a shard file atomically: the header line, then `rows` as CSV with their unit in front
/// (the header row is `unit` and `columns`).
pub fn write<T: serde::Serialize>(path: &Path, header: &Header, columns: &[&str], rows: &[(usize, T)]) -> Result<()> {
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| Error::output(path, e))?;
    }
    atomic::write_with(path, |out| {
        out.write_all(header.line().as_bytes())?;
        let mut writer = csv::WriterBuilder::new().has_headers(false).from_writer(out);
        writer.write_record(std::iter::once("unit").chain(columns.iter().copied()))?;
        for (unit, row) in rows {
            writer.serialize((unit, row)).map_err(std::io::Error::other)?;
        }
        writer.flush()
    })
}

/// The rows of the shard file at `path`, each with its unit, and its header; the column header
/// must be `unit` and `columns`.
pub fn read(path: &Path, columns: &[&str]) -> Result<(Header, Vec<(usize, csv::StringRecord)>)> {
    let header = Header::read(path)?.ok_or_else(|| Error::input(path.display(), "no such file"))?;
    let text = std::fs::read_to_string(path).map_err(|e| Error::input(path.display(), e))?;
    let body = text.split_once('\n').map_or("", |(_, body)| body);
    let mut reader = csv::Reader::from_reader(body.as_bytes());
    let found = reader.headers().map_err(|e| Error::input(path.display(), e))?.clone();
    if !found.iter().eq(std::iter::once("unit").chain(columns.iter().copied())) {
        return Err(Error::input(
            path.display(),
            "its columns are not this version's results columns: rerun the shard".to_string(),
        ));
    }
    let mut rows = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| Error::input(path.display(), e))?;
        let unit = record[0].parse::<usize>().map_err(|_| Error::input(path.display(), "a row has no unit"))?;
        if !header.mine.contains(&unit) {
            return Err(Error::input(
                path.display(),
                format!("a row of unit {unit}, which the shard says it did not do"),
            ));
        }
        rows.push((unit, record.iter().skip(1).collect()));
    }
    Ok((header, rows))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shard_specs_parse_and_refuse_nonsense() {
        assert_eq!("2/8".parse::<Shard>().unwrap(), Shard { index: 2, count: 8 });
        for bad in ["0/8", "9/8", "1/0", "a/2", "3", "1/2/3", ""] {
            assert!(bad.parse::<Shard>().is_err(), "{bad}");
        }
    }

    #[test]
    fn ranges_round_trip() {
        for ids in [vec![], vec![0], vec![0, 1, 2, 3, 7, 9, 10], vec![5, 6]] {
            assert_eq!(parse_ranges(&ranges(&ids)).unwrap(), ids);
        }
        assert_eq!(ranges(&[0, 1, 2, 3, 7, 9, 10]), "0-3,7,9-10");
    }

    #[test]
    fn longest_first_balances_and_covers_every_unit() {
        // One heavy unit and many light ones: the heavy one gets a shard nearly to itself.
        let costs: Vec<f64> = std::iter::once(50.0).chain((0..100).map(|i| 1.0 + (i % 7) as f64)).collect();
        let each = |n: usize| units(n, 1, 1);
        let shard_of = assign(&each(101), &costs, &[0.0; 101], 4);
        let mut load = [0.0; 4];
        for (unit, &s) in shard_of.iter().enumerate() {
            load[s] += costs[unit];
        }
        let mean = costs.iter().sum::<f64>() / 4.0;
        let max = load.iter().cloned().fold(0.0, f64::max);
        assert!(max <= mean * 1.05, "loads {load:?}, mean {mean}");
        // Deterministic: the same costs give the same cut.
        assert_eq!(assign(&each(101), &costs, &[0.0; 101], 4), shard_of);
        // More shards than units: some are empty, none has two.
        let few = assign(&each(3), &[3.0, 2.0, 1.0], &[0.0; 3], 5);
        assert_eq!(few, [0, 1, 2]);
    }

    #[test]
    fn a_models_units_stay_together_unless_it_is_too_big() {
        // Two models of four equal units each: two shards take one model each rather than both
        // opening both.
        let shard_of = assign(&units(2, 1, 4), &[1.0; 8], &[2.0, 2.0], 2);
        assert_eq!(shard_of[..4], [shard_of[0]; 4]);
        assert_eq!(shard_of[4..], [shard_of[4]; 4]);
        assert_ne!(shard_of[0], shard_of[4]);
        // One model of eight units and four shards: it is cut in four.
        let shard_of = assign(&units(1, 1, 8), &[1.0; 8], &[0.5], 4);
        for s in 0..4 {
            assert_eq!(shard_of.iter().filter(|&&x| x == s).count(), 2);
        }
    }
}
