//! The gallery's generated tables are what their CSVs give (issue 16: numbers quoted in
//! paper-figures/README.md had gone stale against the CSVs beside them). Every table between
//! `<!-- generated from … -->` and `<!-- end generated -->` is rebuilt from its CSV here; a
//! rerun that moves a number fails this test until `triorder gallery` rewrites the table.

use std::path::Path;

#[test]
fn every_generated_table_matches_its_csv() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let file = root.join("paper-figures/README.md");
    let text = std::fs::read_to_string(&file).expect("the gallery exists");
    let (fresh, sources) = triorder::figure::gallery::refresh(&text, root, &file).expect("every recipe reads its CSV");
    assert!(sources.len() >= 10, "expected the gallery's tables to be generated, found {}", sources.len());
    if fresh != text {
        let stale: Vec<String> = text
            .lines()
            .zip(fresh.lines())
            .enumerate()
            .filter(|(_, (a, b))| a != b)
            .take(5)
            .map(|(i, (a, b))| format!("line {}:\n  typed: {a}\n  CSV:   {b}", i + 1))
            .collect();
        panic!("generated tables differ from their CSVs; run `triorder gallery`:\n{}", stale.join("\n"));
    }
}
