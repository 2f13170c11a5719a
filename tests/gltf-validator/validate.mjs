// usage: node validate.mjs FILE.glb|FILE.gltf
// Prints the validator's issue counts as JSON; exits 1 when there are errors, 2 on usage/IO problems.
import { readFileSync } from 'node:fs';
import validator from 'gltf-validator';

const path = process.argv[2];
if (!path) { console.error('usage: node validate.mjs FILE'); process.exit(2); }
let bytes;
try { bytes = new Uint8Array(readFileSync(path)); } catch (e) { console.error(String(e)); process.exit(2); }
try {
  // No external resources: meshwork output embeds everything, and we refuse to resolve any uri.
  const report = await validator.validateBytes(bytes, { externalResourceFunction: () => Promise.reject('external resources are not allowed') });
  const { numErrors, numWarnings, numInfos, messages } = report.issues;
  console.log(JSON.stringify({ numErrors, numWarnings, numInfos, messages: messages.slice(0, 20) }));
  process.exit(numErrors > 0 ? 1 : 0);
} catch (e) {
  console.error('validator failed: ' + e);
  process.exit(2);
}
