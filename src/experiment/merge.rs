//! `triorder merge SPEC`: the shard files of a sharded run ([`super::shard`]) joined into the
//! results CSV an unsharded run writes, rows in canonical order.
//!
//! Everything is checked before anything is written: every shard of the cut is present, was run
//! for this spec, these models and this version of triorder, and the shards together did every
//! unit exactly once. A missing or stale shard is an error that names its file and the command
//! that remakes it. The shard files are left in place (a merge can be repeated).

use std::path::{Path, PathBuf};

use super::run::{Plan, RunOptions};
use super::shard::{self, Header, Shard};
use super::spec::Spec;
use crate::atomic;
use crate::error::{Error, Result};
use crate::results::{COLUMNS, ORDER_COLUMNS};

/// What [`merge`] wrote.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Merged {
    /// The results CSV.
    pub csv: PathBuf,
    /// How many shards it was joined from, and how many rows it has.
    pub shards: usize,
    pub rows: usize,
}

/// Merges the shards of the spec at `spec` into its results CSV (and orders file, for a drawing).
/// `count` says which cut to merge when the results directory holds shards of several.
pub fn merge(spec: &Path, opts: &RunOptions, count: Option<usize>) -> Result<Merged> {
    let spec = Spec::load(spec)?;
    let plan = Plan::new(&spec, opts)?;
    let csv = spec.csv_path(&opts.out_dir, opts.quick);
    let rerun = |shard: Shard| {
        let quick = if opts.quick { " --quick" } else { "" };
        format!("`triorder run {}{quick} --shard {shard}`", spec.path.display())
    };
    let count = match (count, &shard::counts_present(&csv)[..]) {
        (Some(n), _) => n,
        (None, [n]) => *n,
        (None, []) => {
            return Err(Error::input(
                spec.path.display(),
                format!(
                    "no shard files of `{}` in {}: run the shards first (`triorder run {} --shard K/N`, K = 1..N)",
                    spec.id,
                    csv.parent().map_or(String::new(), |d| d.display().to_string()),
                    spec.path.display()
                ),
            ));
        }
        (None, several) => {
            let cuts = several.iter().map(|n| n.to_string()).collect::<Vec<_>>().join(", ");
            return Err(Error::input(
                spec.path.display(),
                format!("results hold shards of `{}` cut {cuts} ways: say which with --shards N", spec.id),
            ));
        }
    };
    let shards: Vec<Shard> = (1..=count).map(|index| Shard { index, count }).collect();
    let missing: Vec<String> = shards
        .iter()
        .filter(|&&s| !shard::path(&csv, s).exists())
        .map(|&s| format!("{} (run {})", shard::path(&csv, s).display(), rerun(s)))
        .collect();
    if !missing.is_empty() {
        return Err(Error::input(spec.path.display(), format!("missing shards: {}", missing.join("; "))));
    }

    let draws = spec.figure.kind.draws_meshes();
    let orders_csv = spec.orders_path(&opts.out_dir, opts.quick);
    let mut done_by: Vec<Option<usize>> = vec![None; plan.units.len()];
    let mut rows = Vec::new();
    let mut orders = Vec::new();
    for &s in &shards {
        let path = shard::path(&csv, s);
        let header = Header::read(&path)?.ok_or_else(|| Error::input(path.display(), "no such file"))?;
        check(&header, &path, &spec, &plan.fingerprint, plan.units.len(), s)
            .map_err(|problem| Error::input(path.display(), format!("{problem}: rerun it with {}", rerun(s))))?;
        for &unit in &header.mine {
            match done_by[unit] {
                Some(other) => {
                    return Err(Error::input(
                        path.display(),
                        format!(
                            "did unit {unit}, which shard {other}/{count} did too: the shards were cut differently; rerun them all"
                        ),
                    ));
                }
                None => done_by[unit] = Some(s.index),
            }
        }
        rows.extend(shard::read(&path, COLUMNS)?.1);
        if draws {
            let path = shard::path(&orders_csv, s);
            let (orders_header, shard_orders) = shard::read(&path, ORDER_COLUMNS)?;
            if orders_header != header {
                return Err(Error::input(
                    path.display(),
                    format!("is not from the same run as its results shard: rerun it with {}", rerun(s)),
                ));
            }
            orders.extend(shard_orders);
        }
    }
    let undone: Vec<usize> = (0..plan.units.len()).filter(|&u| done_by[u].is_none()).collect();
    if !undone.is_empty() {
        return Err(Error::input(
            spec.path.display(),
            format!(
                "{} of {} units are in no shard (first: unit {}): the shards were cut from different estimates (did the models change between shard runs?); rerun them all",
                undone.len(),
                plan.units.len(),
                undone[0]
            ),
        ));
    }
    if draws {
        write(&orders_csv, ORDER_COLUMNS, orders)?;
    }
    let merged = rows.len();
    write(&csv, COLUMNS, rows)?;
    Ok(Merged { csv, shards: count, rows: merged })
}

/// Why the shard whose file has `header` cannot be merged into a run of `spec`, if it cannot.
fn check(
    header: &Header,
    path: &Path,
    spec: &Spec,
    fingerprint: &str,
    units: usize,
    shard: Shard,
) -> Result<(), String> {
    let version = env!("CARGO_PKG_VERSION");
    if header.shard != shard || header.spec != spec.id {
        return Err(format!("says it is shard {} of `{}`, not {shard} of `{}`", header.shard, header.spec, spec.id));
    }
    if header.version != version {
        return Err(format!("was written by triorder {}, not this {version}", header.version));
    }
    if header.fingerprint != fingerprint || header.units != units {
        return Err(format!(
            "is stale: it was run for another version of {} or of its models (fingerprint {}, now {fingerprint})",
            spec.path.display(),
            header.fingerprint
        ));
    }
    if let Some(&bad) = header.mine.iter().find(|&&u| u >= units) {
        return Err(format!("names unit {bad}, but the run has {units} ({})", path.display()));
    }
    Ok(())
}

/// Writes `rows` (with their units) to `path` atomically in canonical order: by unit, and within
/// a unit in the order the shard wrote them, which is the unsharded run's.
fn write(path: &Path, columns: &[&str], mut rows: Vec<(usize, csv::StringRecord)>) -> Result<()> {
    rows.sort_by_key(|(unit, _)| *unit);
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| Error::output(path, e))?;
    }
    atomic::write_with(path, |out| {
        let mut writer = csv::Writer::from_writer(out);
        writer.write_record(columns)?;
        for (_, record) in &rows {
            writer.write_record(record)?;
        }
        writer.flush()
    })
}
