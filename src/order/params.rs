//! Method specs on the command line: `name:key=value,key=value`.
//!
//! Every ordering declares its parameters (name, default, range, help) in a static schema. A spec
//! is checked against it once, so an unknown method, an unknown parameter or an out-of-range
//! value is a clear usage error before any work starts, and the ordering itself can read typed
//! values without re-validating. The *canonical* spec lists every parameter with its value: it is
//! what results record, so a row can be reproduced exactly.

use std::fmt::Write as _;

use crate::error::{Error, Result};

/// The type and admissible values of one parameter.
#[derive(Debug, Clone, Copy)]
pub enum ParamKind {
    /// An integer in `min..=max`.
    Int { min: i64, max: i64 },
    /// A finite float in `min..=max`.
    Float { min: f64, max: f64 },
    /// One of a fixed set of words.
    Choice(&'static [&'static str]),
    /// A random seed (u64). Its default is the run's `--seed`, not the schema's `default`.
    Seed,
}

/// One declared parameter of a method. Declare each as a `const` and read it with
/// `params.int(&CONST)` (or `float`, `word`): a misspelt name is then a compile error, and reading
/// a parameter the schema does not list panics when the method is built, which the conformance
/// tests do for every registered method.
#[derive(Debug, Clone, Copy)]
pub struct ParamInfo {
    pub name: &'static str,
    /// The default as it would be written in a spec (ignored for [`ParamKind::Seed`]).
    pub default: &'static str,
    pub kind: ParamKind,
    pub help: &'static str,
}

/// A method name with the parameters the user wrote, not yet checked.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MethodSpec {
    pub name: String,
    pub params: Vec<(String, String)>,
}

impl MethodSpec {
    /// Splits `name[:k=v[,k=v]...]`. Only syntax is checked here; meaning is checked by [`Params::resolve`].
    pub fn parse(spec: &str) -> Result<MethodSpec> {
        let spec = spec.trim();
        let (name, rest) = spec.split_once(':').unwrap_or((spec, ""));
        if name.is_empty() {
            return Err(Error::usage(format!("method spec `{spec}` has no method name")));
        }
        let mut params = Vec::new();
        for pair in rest.split(',').filter(|p| !p.trim().is_empty()) {
            let Some((k, v)) = pair.split_once('=') else {
                return Err(Error::usage(format!("method spec `{spec}`: `{pair}` is not of the form key=value")));
            };
            let (k, v) = (k.trim(), v.trim());
            if params.iter().any(|(seen, _): &(String, String)| seen == k) {
                return Err(Error::usage(format!("method spec `{spec}`: parameter `{k}` given twice")));
            }
            params.push((k.to_string(), v.to_string()));
        }
        Ok(MethodSpec { name: name.to_string(), params })
    }
}

/// A parsed, validated value.
#[derive(Debug, Clone, PartialEq)]
enum Value {
    Int(i64),
    Float(f64),
    Word(String),
    Seed(u64),
}

/// Every parameter of a method with a checked value (defaults filled in).
#[derive(Debug, Clone, PartialEq)]
pub struct Params {
    method: &'static str,
    values: Vec<(&'static str, Value)>,
}

impl Params {
    /// Checks `spec` against `schema` and fills defaults (`seed` defaults to `run_seed`).
    pub fn resolve(method: &'static str, schema: &[ParamInfo], spec: &MethodSpec, run_seed: u64) -> Result<Params> {
        if let Some((unknown, _)) = spec.params.iter().find(|(k, _)| !schema.iter().any(|p| p.name == k)) {
            let known: Vec<_> = schema.iter().map(|p| p.name).collect();
            let known = if known.is_empty() { "none".to_string() } else { known.join(", ") };
            return Err(Error::usage(format!(
                "method `{method}` has no parameter `{unknown}` (its parameters: {known}; see `triorder methods`)"
            )));
        }
        let values = schema
            .iter()
            .map(|info| {
                let given = spec.params.iter().find(|(k, _)| k == info.name).map(|(_, v)| v.as_str());
                let value = match (given, info.kind) {
                    (None, ParamKind::Seed) => Value::Seed(run_seed),
                    (None, _) => parse_value(info, info.default).expect("schema defaults are valid"),
                    (Some(text), _) => parse_value(info, text).map_err(|why| {
                        Error::usage(format!("method `{method}`: parameter `{}`={text} {why}", info.name))
                    })?,
                };
                Ok((info.name, value))
            })
            .collect::<Result<_>>()?;
        Ok(Params { method, values })
    }

    fn get(&self, param: &ParamInfo) -> &Value {
        self.values.iter().find(|(k, _)| *k == param.name).map(|(_, v)| v).unwrap_or_else(|| {
            panic!("method `{}` reads `{}`, which its schema does not declare", self.method, param.name)
        })
    }

    pub fn int(&self, param: &ParamInfo) -> i64 {
        match self.get(param) {
            Value::Int(v) => *v,
            other => panic!("parameter `{}` of `{}` is {other:?}, not an integer", param.name, self.method),
        }
    }

    pub fn float(&self, param: &ParamInfo) -> f64 {
        match self.get(param) {
            Value::Float(v) => *v,
            other => panic!("parameter `{}` of `{}` is {other:?}, not a float", param.name, self.method),
        }
    }

    pub fn word(&self, param: &ParamInfo) -> &str {
        match self.get(param) {
            Value::Word(v) => v,
            other => panic!("parameter `{}` of `{}` is {other:?}, not a word", param.name, self.method),
        }
    }

    /// The value of the method's [`ParamKind::Seed`] parameter.
    pub fn seed(&self) -> u64 {
        self.values
            .iter()
            .find_map(|(_, v)| if let Value::Seed(seed) = v { Some(*seed) } else { None })
            .unwrap_or_else(|| panic!("method `{}` reads a seed but declares none", self.method))
    }

    /// `name:k=v,...` with every parameter, in schema order: the spec results record.
    pub fn canonical(&self) -> String {
        let mut out = self.method.to_string();
        for (i, (k, v)) in self.values.iter().enumerate() {
            out.push(if i == 0 { ':' } else { ',' });
            let _ = match v {
                Value::Int(x) => write!(out, "{k}={x}"),
                Value::Float(x) => write!(out, "{k}={x}"),
                Value::Word(x) => write!(out, "{k}={x}"),
                Value::Seed(x) => write!(out, "{k}={x}"),
            };
        }
        out
    }
}

fn parse_value(info: &ParamInfo, text: &str) -> std::result::Result<Value, String> {
    match info.kind {
        ParamKind::Int { min, max } => match text.parse::<i64>() {
            Ok(v) if (min..=max).contains(&v) => Ok(Value::Int(v)),
            _ => Err(format!("is not an integer in {min}..={max}")),
        },
        ParamKind::Float { min, max } => match text.parse::<f64>() {
            Ok(v) if v.is_finite() && (min..=max).contains(&v) => Ok(Value::Float(v)),
            _ => Err(format!("is not a number in {min}..={max}")),
        },
        ParamKind::Choice(words) => match words.iter().find(|w| **w == text) {
            Some(w) => Ok(Value::Word(w.to_string())),
            None => Err(format!("is not one of {}", words.join(", "))),
        },
        ParamKind::Seed => text.parse::<u64>().map(Value::Seed).map_err(|_| "is not a seed (an integer ≥ 0)".into()),
    }
}

/// A readable description of a parameter's admissible values, for `triorder methods`.
pub fn describe_kind(kind: ParamKind) -> String {
    match kind {
        ParamKind::Int { min, max } => format!("integer {min}..={max}"),
        ParamKind::Float { min, max } => format!("number {min}..={max}"),
        ParamKind::Choice(words) => words.join("|"),
        ParamKind::Seed => "integer ≥ 0 (default: --seed)".into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CACHE: ParamInfo =
        ParamInfo { name: "cache", default: "16", kind: ParamKind::Int { min: 3, max: 64 }, help: "" };
    const LAMBDA: ParamInfo =
        ParamInfo { name: "lambda", default: "0.85", kind: ParamKind::Float { min: 0.0, max: 3.0 }, help: "" };
    const INNER: ParamInfo =
        ParamInfo { name: "inner", default: "hoppe", kind: ParamKind::Choice(&["hoppe", "tipsify"]), help: "" };
    const SCHEMA: &[ParamInfo] =
        &[CACHE, LAMBDA, INNER, ParamInfo { name: "seed", default: "", kind: ParamKind::Seed, help: "" }];

    fn resolve(spec: &str) -> Result<Params> {
        Params::resolve("m", SCHEMA, &MethodSpec::parse(spec)?, 5)
    }

    #[test]
    fn defaults_and_canonical_form() {
        assert_eq!(resolve("m").unwrap().canonical(), "m:cache=16,lambda=0.85,inner=hoppe,seed=5");
        let p = resolve("m:lambda=3,cache=32,seed=9").unwrap();
        assert_eq!((p.int(&CACHE), p.float(&LAMBDA), p.word(&INNER), p.seed()), (32, 3.0, "hoppe", 9));
    }

    #[test]
    fn bad_specs_are_named() {
        let err = |s: &str| resolve(s).unwrap_err().to_string();
        assert!(err("m:cache=2").contains("`cache`=2 is not an integer in 3..=64"));
        assert!(err("m:lambda=nan").contains("not a number"));
        assert!(err("m:inner=foo").contains("not one of hoppe, tipsify"));
        assert!(err("m:size=3").contains("has no parameter `size`"));
        assert!(err("m:cache").contains("not of the form key=value"));
        assert!(err("m:cache=3,cache=4").contains("given twice"));
        assert!(err("m:seed=-1").contains("not a seed"));
    }
}
