//! Tables of targets met, generated from the results CSVs like the gallery's other tables
//! ([`super::gallery`]): one row per model, one column per target, each cell "yes" or "**no**"
//! with the margin it was met or missed by. An issue's targets ("FIFO-16 ACMR within 1% of
//! meshopt-vcache's", "within 2% of the best ordering under each vendor model", "within 3× its
//! time") are verdicts over two or three numbers; typed, they go stale the day a spec is rerun.
//!
//! ```text
//! <!-- generated from results/ID.csv: subject=cheap-cuts checks=acmr@cache=fifo:16<=meshopt-vcache+1%/ovr_mean<=meshopt-overdraw/acmr@cache=intel<=best+2%/seconds<=meshopt-overdraw*3 best_from=results/vendor-cache-models.csv tuned=bun_zipper.ply|horse.ply -->
//! ```
//!
//! - `subject`: the `method_name` whose rows are judged; each of its variants (`method`, the
//!   full spec: a parameter sweep) gets a row of its own, named by what tells it apart.
//! - `checks`: targets joined by `/`, each `METRIC[@COLUMN=VALUE…]<=REFERENCE[+P%|*F]`: the
//!   subject's value at most the reference's, plus P percent or times F. REFERENCE is a
//!   `method_name` run in one variant only, a full `method` spec (`meshopt-overdraw:threshold=1.05`:
//!   one variant of a sweep), or `best`: the lowest value of any ordering but `input` for that
//!   model (and conditions) in the first `best_from` CSV that has the model, else in this one.
//! - `best_from` (optional): the CSVs `best` is read from first, `|`-separated (a spec that runs
//!   every ordering; then, for a table of one method's sweep, the table whose targets it shares).
//! - `tuned` (optional): the model files a method's defaults were tuned on, `|`-separated; adds a
//!   `set` column (tuned or held out) and lists the tuned models first.

use std::fmt::Write as _;
use std::path::Path;

use super::data::{Table, display_names, metric_where, thousands};
use crate::error::{Error, Result};

/// One verdict table's recipe.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Verdicts {
    pub(super) csv: String,
    subject: String,
    checks: Vec<Check>,
    best_from: Vec<String>,
    tuned: Option<Vec<String>>,
}

/// One target: the subject's `metric` (where `conditions` hold) at most `against`'s, with `slack`.
#[derive(Debug, Clone, PartialEq)]
struct Check {
    metric: String,
    conditions: Vec<(String, String)>,
    against: Against,
    slack: Slack,
}

#[derive(Debug, Clone, PartialEq)]
enum Against {
    Method(String),
    /// The lowest of every ordering's values.
    Best,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Slack {
    /// At most the reference's value plus this percentage of it.
    Percent(f64),
    /// At most this many times the reference's value.
    Times(f64),
}

impl Verdicts {
    /// Whether a recipe's text asks for a verdict table rather than a table of numbers.
    pub(super) fn wanted(text: &str) -> bool {
        text.split_whitespace().any(|option| option.starts_with("checks="))
    }

    /// Parses the text between `<!-- generated from ` and ` -->`.
    pub(super) fn parse(text: &str) -> std::result::Result<Verdicts, String> {
        let (csv, options) = text.split_once(':').ok_or("expected `CSV: subject=… checks=…`")?;
        let mut recipe = Verdicts {
            csv: csv.trim().to_string(),
            subject: String::new(),
            checks: Vec::new(),
            best_from: Vec::new(),
            tuned: None,
        };
        for option in options.split_whitespace() {
            let (key, value) = option.split_once('=').ok_or_else(|| format!("`{option}` is not KEY=VALUE"))?;
            match key {
                "subject" => recipe.subject = value.to_string(),
                "checks" => {
                    recipe.checks = value.split('/').map(Check::parse).collect::<std::result::Result<_, _>>()?
                }
                "best_from" => recipe.best_from = value.split('|').map(str::to_string).collect(),
                "tuned" => recipe.tuned = Some(value.split('|').map(str::to_string).collect()),
                _ => {
                    return Err(format!(
                        "unknown option `{key}` in a verdict table (subject, checks, best_from, tuned)"
                    ));
                }
            }
        }
        if recipe.subject.is_empty() || recipe.checks.is_empty() {
            return Err("a verdict table needs subject= and checks=".into());
        }
        Ok(recipe)
    }

    /// The markdown table, from the CSVs under `root`.
    pub(super) fn table(&self, root: &Path) -> Result<String> {
        let table = Table::read(&root.join(&self.csv))?;
        let best_from = self.best_from.iter().map(|csv| Table::read(&root.join(csv))).collect::<Result<Vec<_>>>()?;
        let path = table.path().display().to_string();
        let file = |model: &str| model.rsplit('/').next().unwrap_or(model).to_string();
        let is_tuned = |model: &str| self.tuned.as_ref().is_some_and(|t| t.contains(&file(model)));
        // Models in the order they first appear, the tuned ones first.
        let judged = table.distinct(&["model", "method_name"]);
        let mut models: Vec<(String, String)> = table
            .distinct(&["model", "model_triangles"])
            .into_iter()
            .filter(|m| judged.contains(&vec![m[0].clone(), self.subject.clone()]))
            .map(|m| (m[0].clone(), m[1].clone()))
            .collect();
        models.dedup_by(|a, b| a.0 == b.0);
        models.sort_by_key(|(model, _)| !is_tuned(model));
        if models.is_empty() {
            return Err(Error::input(&path, format!("no rows of subject = {}", self.subject)));
        }
        // The subject's variants, named by what tells them apart; a column only if it has several.
        let variants: Vec<String> = table
            .distinct(&["method_name", "method"])
            .into_iter()
            .filter(|m| m[0] == self.subject)
            .map(|mut m| m.swap_remove(1))
            .collect();
        let names = display_names(&variants);
        let several = variants.len() > 1;
        let mut out = String::new();
        let set = if self.tuned.is_some() { " set |" } else { "" };
        let variant = if several { " variant |" } else { "" };
        let titles: Vec<String> = self.checks.iter().map(Check::title).collect();
        let _ = writeln!(out, "| model |{set}{variant} {} |", titles.join(" | "));
        let columns = titles.len() + usize::from(self.tuned.is_some()) + usize::from(several);
        let _ = writeln!(out, "|---|{}", "---|".repeat(columns));
        let run = table.distinct(&["model", "method"]);
        for (model, triangles) in &models {
            let set = match &self.tuned {
                Some(_) if is_tuned(model) => " tuned |",
                Some(_) => " held out |",
                None => "",
            };
            for (spec, name) in variants.iter().zip(&names) {
                if !run.contains(&vec![model.clone(), spec.clone()]) {
                    continue;
                }
                let mut cells = Vec::new();
                for check in &self.checks {
                    cells.push(check.verdict(&table, &best_from, spec, model)?);
                }
                let variant = if several { format!(" {name} |") } else { String::new() };
                let _ = writeln!(
                    out,
                    "| {} ({}) |{set}{variant} {} |",
                    file(model),
                    thousands(triangles),
                    cells.join(" | ")
                );
            }
        }
        Ok(out)
    }
}

impl Check {
    fn parse(text: &str) -> std::result::Result<Check, String> {
        let bad = || format!("check `{text}`: expected METRIC[@COLUMN=VALUE]<=REFERENCE[+P%|*F]");
        let (left, right) = text.split_once("<=").ok_or_else(bad)?;
        let (metric, conditions) = metric_where(left).map_err(|_| bad())?;
        let number = |s: &str| s.parse::<f64>().ok().filter(|v| v.is_finite() && *v >= 0.0).ok_or_else(bad);
        let (reference, slack) = if let Some((reference, percent)) = right.split_once('+') {
            (reference, Slack::Percent(number(percent.strip_suffix('%').ok_or_else(bad)?)?))
        } else if let Some((reference, times)) = right.split_once('*') {
            (reference, Slack::Times(number(times)?))
        } else {
            (right, Slack::Percent(0.0))
        };
        let against = if reference == "best" { Against::Best } else { Against::Method(reference.to_string()) };
        if metric.is_empty() || reference.is_empty() {
            return Err(bad());
        }
        Ok(Check { metric, conditions, against, slack })
    }

    /// The column heading: the target as written, `≤` for `<=`.
    fn title(&self) -> String {
        let reference = match &self.against {
            Against::Method(name) => name.as_str(),
            Against::Best => "best",
        };
        let limit = match self.slack {
            Slack::Percent(0.0) => reference.to_string(),
            Slack::Percent(p) => format!("{reference} + {p}%"),
            Slack::Times(f) => format!("{f}× {reference}"),
        };
        let conditions: String = self.conditions.iter().map(|(c, v)| format!(" {c}={v}")).collect();
        format!("{}{conditions} ≤ {limit}", self.metric)
    }

    /// `(method_name, method, value)` of every row of this check's metric and conditions for
    /// `model`.
    fn values(&self, table: &Table, model: &str) -> Result<Vec<(String, String, f64)>> {
        let mut columns = vec!["model", "method_name", "method"];
        columns.extend(self.conditions.iter().map(|(c, _)| c.as_str()));
        Ok(table
            .rows(&self.metric, &columns)?
            .into_iter()
            .filter(|(cells, _)| cells[0] == model && self.conditions.iter().zip(&cells[3..]).all(|((_, v), c)| v == c))
            .map(|(cells, value)| (cells[1].clone(), cells[2].clone(), value))
            .collect())
    }

    /// "yes" or "**no**", with the value of `subject` (a full method spec) against the
    /// reference's.
    fn verdict(&self, table: &Table, best_from: &[Table], subject: &str, model: &str) -> Result<String> {
        let here = self.values(table, model)?;
        let path = table.path().display().to_string();
        let missing = |what: &str| Error::input(&path, format!("no `{}` row of {what} on {model}", self.title()));
        let ours = here.iter().find(|(_, spec, _)| spec == subject).map(|r| r.2).ok_or_else(|| missing(subject))?;
        let (name, reference) = match &self.against {
            Against::Method(name) => {
                // A spec names one variant; a bare name must have only one on the model.
                let matching: Vec<&(String, String, f64)> = here
                    .iter()
                    .filter(|(n, spec, _)| if name.contains(':') { spec == name } else { n == name })
                    .collect();
                match matching.as_slice() {
                    [] => return Err(missing(name)),
                    [(n, _, v)] => (n.clone(), *v),
                    several => {
                        let specs: Vec<&str> = several.iter().map(|(_, spec, _)| spec.as_str()).collect();
                        return Err(Error::input(
                            &path,
                            format!(
                                "`{}`: {name} ran as {} on {model}; name one by its spec",
                                self.title(),
                                specs.join(", ")
                            ),
                        ));
                    }
                }
            }
            Against::Best => {
                let mut pool = here;
                for other in best_from {
                    let values = self.values(other, model)?;
                    if !values.is_empty() {
                        pool = values;
                        break;
                    }
                }
                pool.into_iter()
                    .filter(|(name, _, _)| name != "input")
                    .map(|(name, _, value)| (name, value))
                    .min_by(|a, b| a.1.total_cmp(&b.1).then_with(|| a.0.cmp(&b.0)))
                    .ok_or_else(|| missing("any ordering"))?
            }
        };
        let (met, margin) = match self.slack {
            Slack::Percent(p) => {
                let over = (ours / reference - 1.0) * 100.0;
                (ours <= reference * (1.0 + p / 100.0), format!("{over:+.1}% vs {name}"))
            }
            Slack::Times(f) => (ours <= reference * f, format!("{:.1}×", ours / reference)),
        };
        Ok(format!("{} ({margin})", if met { "yes" } else { "**no**" }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const CSV: &str = "model,model_triangles,method_name,method,metric,cache,value
models/a.ply,100,ours,ours,acmr,fifo:16,0.70
models/a.ply,100,peer,peer,acmr,fifo:16,0.695
models/a.ply,100,other,other,acmr,fifo:16,0.60
models/a.ply,100,input,input,acmr,fifo:16,0.50
models/a.ply,100,ours,ours,seconds,,0.4
models/a.ply,100,peer,peer,seconds,,0.1
models/b.ply,2000,ours,ours,acmr,fifo:16,0.80
models/b.ply,2000,peer,peer,acmr,fifo:16,0.70
models/b.ply,2000,ours,ours,seconds,,0.2
models/b.ply,2000,peer,peer,seconds,,0.1
";

    #[test]
    fn each_target_is_judged_with_its_margin() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("x.csv"), CSV).unwrap();
        let recipe =
            Verdicts::parse("x.csv: subject=ours checks=acmr@cache=fifo:16<=peer+1%/acmr@cache=fifo:16<=best+2%/seconds<=peer*3 tuned=b.ply")
                .unwrap();
        let table = recipe.table(dir.path()).unwrap();
        let want = "| model | set | acmr cache=fifo:16 ≤ peer + 1% | acmr cache=fifo:16 ≤ best + 2% | seconds ≤ 3× peer |\n\
|---|---|---|---|---|\n\
| b.ply (2,000) | tuned | **no** (+14.3% vs peer) | **no** (+14.3% vs peer) | yes (2.0×) |\n\
| a.ply (100) | held out | yes (+0.7% vs peer) | **no** (+16.7% vs other) | **no** (4.0×) |\n";
        assert_eq!(table, want);
    }

    #[test]
    fn the_best_comes_from_the_named_csv_where_it_has_the_model() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("x.csv"), CSV).unwrap();
        std::fs::write(
            dir.path().join("all.csv"),
            "model,model_triangles,method_name,method,metric,cache,value\nmodels/a.ply,100,wide,wide,acmr,fifo:16,0.69\n",
        )
        .unwrap();
        let recipe =
            Verdicts::parse("x.csv: subject=ours checks=acmr@cache=fifo:16<=best+2% best_from=all.csv").unwrap();
        let table = recipe.table(dir.path()).unwrap();
        assert!(table.contains("| a.ply (100) | yes (+1.4% vs wide) |"), "{table}");
        assert!(table.contains("| b.ply (2,000) | **no** (+14.3% vs peer) |"), "{table}");
        // Several CSVs: the first that has the model, here the second for b.ply.
        std::fs::write(
            dir.path().join("peers.csv"),
            "model,model_triangles,method_name,method,metric,cache,value
models/a.ply,100,far,far,acmr,fifo:16,0.10
models/b.ply,2000,near,near,acmr,fifo:16,0.79
",
        )
        .unwrap();
        let recipe =
            Verdicts::parse("x.csv: subject=ours checks=acmr@cache=fifo:16<=best+2% best_from=all.csv|peers.csv")
                .unwrap();
        let table = recipe.table(dir.path()).unwrap();
        assert!(table.contains("| a.ply (100) | yes (+1.4% vs wide) |"), "{table}");
        assert!(table.contains("| b.ply (2,000) | yes (+1.3% vs near) |"), "{table}");
    }

    /// A swept subject gets a row per variant, named by the parameter that differs; a swept
    /// reference must be named by its spec, as a bare name could mean any of its runs.
    #[test]
    fn each_variant_of_a_sweep_is_judged_and_a_swept_reference_is_named_by_spec() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("x.csv"),
            "model,model_triangles,method_name,method,metric,value\n\
models/a.ply,100,ours,ours:k=1,acmr,0.70\n\
models/a.ply,100,ours,ours:k=2,acmr,0.80\n\
models/a.ply,100,peer,peer:t=1,acmr,0.75\n\
models/a.ply,100,peer,peer:t=2,acmr,0.72\n",
        )
        .unwrap();
        let table = Verdicts::parse("x.csv: subject=ours checks=acmr<=peer:t=2").unwrap().table(dir.path()).unwrap();
        let want = "| model | variant | acmr ≤ peer:t=2 |\n|---|---|---|\n\
| a.ply (100) | ours k=1 | yes (-2.8% vs peer) |\n\
| a.ply (100) | ours k=2 | **no** (+11.1% vs peer) |\n";
        assert_eq!(table, want);
        let ambiguous = Verdicts::parse("x.csv: subject=ours checks=acmr<=peer").unwrap().table(dir.path());
        assert!(ambiguous.is_err_and(|e| e.to_string().contains("name one by its spec")));
    }

    #[test]
    fn bad_checks_say_what_is_expected() {
        for text in
            ["x.csv: subject=a checks=acmr<peer", "x.csv: subject=a checks=acmr<=peer+1", "x.csv: checks=acmr<=b"]
        {
            assert!(Verdicts::parse(text).is_err(), "{text}");
        }
    }
}
