// Validate a .glb/.gltf with the Khronos glTF-Validator and print a JSON summary:
// {"errors": N, "warnings": N, "infos": N, "messages": [...]} (exit 2 when it cannot run).
// Used by tests/export_gltf.rs; installed by `make deps` (npm ci in tools/npm).
const fs = require('fs');
const validator = require('gltf-validator');
const file = process.argv[2];
validator
  .validateBytes(new Uint8Array(fs.readFileSync(file)), { maxIssues: 100 })
  .then((r) => {
    const m = r.issues.messages.map((x) => `${x.severity} ${x.code} ${x.pointer || ''}: ${x.message}`);
    console.log(JSON.stringify({
      errors: r.issues.numErrors,
      warnings: r.issues.numWarnings,
      infos: r.issues.numInfos,
      messages: m,
    }));
  })
  .catch((e) => {
    console.error(`gltf-validator failed: ${e}`);
    process.exit(2);
  });
