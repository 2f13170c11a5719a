// usage: node validate.mjs FILE.glb|FILE.gltf [FILE ...]
// Prints one JSON line per file with the validator's issue counts and first messages; exits 1 when
// any file has errors, 2 on usage/IO problems. Several files per run: node starts once.
import { readFileSync } from 'node:fs';
import validator from 'gltf-validator';

const paths = process.argv.slice(2);
if (paths.length === 0) { console.error('usage: node validate.mjs FILE [FILE ...]'); process.exit(2); }
let worst = 0;
for (const path of paths) {
  let bytes;
  try { bytes = new Uint8Array(readFileSync(path)); } catch (e) { console.error(String(e)); process.exit(2); }
  try {
    // No external resources: meshwork output embeds everything, and we refuse to resolve any uri.
    const report = await validator.validateBytes(bytes, { externalResourceFunction: () => Promise.reject('external resources are not allowed') });
    const { numErrors, numWarnings, numInfos, messages } = report.issues;
    console.log(JSON.stringify({ file: path, numErrors, numWarnings, numInfos, messages: messages.slice(0, 20) }));
    if (numErrors > 0) worst = 1;
  } catch (e) {
    console.error(`validator failed on ${path}: ${e}`);
    process.exit(2);
  }
}
process.exit(worst);
