// node validate.mjs FILE...: runs the Khronos glTF validator on each file and
// exits 1 if any report has an error (warnings and infos are printed, not
// fatal). CTest: haptics_gltf_validator_test (clients/haptics/gltf_validator).
import { readFile } from 'node:fs/promises';
import path from 'node:path';
import validator from 'gltf-validator';

let failed = false;
for (const file of process.argv.slice(2)) {
  const bytes = new Uint8Array(await readFile(file));
  const report = await validator.validateBytes(bytes, {
    uri: path.basename(file),
    maxIssues: 100,
    externalResourceFunction: () => Promise.reject(new Error('surfmap exports embed their buffers')),
  });
  const { numErrors, numWarnings, numInfos, numHints } = report.issues;
  console.log(`${file}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos, ${numHints} hints ` +
              `(${report.info?.totalVertexCount ?? '?'} vertices)`);
  for (const m of report.issues.messages) {
    console.log(`  [${['error', 'warning', 'info', 'hint'][m.severity]}] ${m.code} ${m.pointer ?? ''}: ${m.message}`);
  }
  if (numErrors > 0 || report.info === undefined) failed = true;
}
if (process.argv.length <= 2) {
  console.error('usage: node validate.mjs FILE...');
  failed = true;
}
process.exit(failed ? 1 : 0);
