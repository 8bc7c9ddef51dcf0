// Runs the Khronos glTF validator (the `gltf-validator` npm package) on each file named and
// prints one JSON line per file: {"file", "errors", "warnings", "infos", "codes": {CODE: count}}
// with the codes of errors and warnings. Exits 2 when the package is missing.
//
//   node scripts/validate-gltf.cjs FILE.glb [FILE.gltf ...]
//
// The package is looked up in $TRIORDER_GLTF_VALIDATOR (a folder holding node_modules/), else in
// target/gltf-validator (where .ci/run installs it: npm install --prefix target/gltf-validator
// gltf-validator), else wherever Node finds it. Tests call this through tests/common.
"use strict";
const fs = require("fs");
const path = require("path");

function load() {
  const roots = [process.env.TRIORDER_GLTF_VALIDATOR, path.join(__dirname, "..", "target", "gltf-validator")];
  for (const root of roots.filter(Boolean)) {
    try {
      return require(path.join(root, "node_modules", "gltf-validator"));
    } catch (_) {}
  }
  try {
    return require("gltf-validator");
  } catch (_) {
    console.error("gltf-validator is not installed: npm install --prefix target/gltf-validator gltf-validator");
    process.exit(2);
  }
}

async function main() {
  const validator = load();
  for (const file of process.argv.slice(2)) {
    const full = path.resolve(file);
    const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(full)), {
      uri: path.basename(full),
      maxIssues: 0,
      externalResourceFunction: (uri) =>
        new Promise((resolve, reject) =>
          fs.readFile(path.resolve(path.dirname(full), decodeURIComponent(uri)), (err, data) =>
            err ? reject(err.toString()) : resolve(new Uint8Array(data)),
          ),
        ),
    });
    const codes = {};
    for (const message of report.issues.messages) {
      if (message.severity <= 1) codes[message.code] = (codes[message.code] || 0) + 1;
    }
    console.log(JSON.stringify({
      file,
      errors: report.issues.numErrors,
      warnings: report.issues.numWarnings,
      infos: report.issues.numInfos,
      codes,
    }));
  }
}

main().catch((e) => {
  console.error(String(e));
  process.exit(1);
});
