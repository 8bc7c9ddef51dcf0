//! The parameters the pair-based sorts share: which viewpoints find the overlapping pairs.

use super::super::{ParamInfo, ParamKind, Params};

pub const VIEWS: ParamInfo = ParamInfo {
    name: "views",
    default: "42",
    kind: ParamKind::Choice(&["12", "42", "162", "642"]),
    help: "viewpoints that find the overlapping pairs: an icosphere of this many directions",
};

pub const RES: ParamInfo = ParamInfo {
    name: "res",
    default: "256",
    kind: ParamKind::Int { min: 16, max: 4096 },
    help: "image size for finding overlapping pairs (pixels per side)",
};

/// `(views, res)` of `params`.
pub fn read(params: &Params) -> (u32, u32) {
    (params.word(&VIEWS).parse().expect("the schema lists only numbers"), params.int(&RES) as u32)
}
