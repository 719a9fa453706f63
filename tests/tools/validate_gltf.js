// Validates .glb/.gltf files with the Khronos glTF validator (npm
// gltf-validator). Prints one line per file: errors, warnings, infos; exits
// 1 when any file has an error or a warning.
// Usage: node validate_gltf.js FILE...
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

async function main() {
  let bad = 0;
  for (const file of process.argv.slice(2)) {
    const data = new Uint8Array(fs.readFileSync(file));
    const report = await validator.validateBytes(data, {
      uri: path.basename(file),
      externalResourceFunction: () => Promise.reject(new Error('no external resources')),
    });
    const i = report.issues;
    console.log(`${file}: ${i.numErrors} errors, ${i.numWarnings} warnings, ${i.numInfos} infos`);
    for (const m of i.messages.filter((m) => m.severity <= 1)) {
      console.log(`  ${m.severity === 0 ? 'error' : 'warning'} ${m.code}: ${m.message} (${m.pointer || ''})`);
    }
    if (i.numErrors || i.numWarnings) bad = 1;
  }
  process.exit(bad);
}
main().catch((e) => { console.error(e); process.exit(2); });
