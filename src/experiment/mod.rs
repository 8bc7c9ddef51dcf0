//! Experiments: a TOML spec per paper figure ([`spec`]) is run into a tidy results CSV (the
//! contract in [`crate::results`]), which [`crate::figure`] draws; [`crate::reproduce`] does both
//! for every spec. [`bench`] times our metrics and orderings against meshoptimizer.

pub mod bench;
pub mod corpus;
pub mod merge;
pub mod provenance;
pub mod run;
pub mod shard;
pub mod spec;

pub use merge::merge;
pub use run::{Failure, Outcome, RunOptions, run};
pub use spec::Spec;
