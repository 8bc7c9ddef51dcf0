//! Experiments: a TOML spec per paper figure ([`spec`]) is run into a tidy results CSV
//! ([`row`]), which [`crate::figure`] draws. `triorder run`, `plot` and `reproduce` are thin
//! wrappers around [`run`], [`crate::figure::plot`] and [`reproduce`].

pub mod provenance;
pub mod row;
mod run;
pub mod spec;

pub use run::{RunOptions, reproduce, run};
pub use spec::Spec;
