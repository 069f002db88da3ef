// Runs the Khronos glTF validator (npm "gltf-validator") on every GLB named on the command line.
// Prints each file's issue counts and every error and warning; exits 1 when any file has an error.
import validator from 'gltf-validator';
import { readFileSync } from 'node:fs';

let failed = false;
for (const path of process.argv.slice(2)) {
  const report = await validator.validateBytes(new Uint8Array(readFileSync(path)), {
    maxIssues: 200,
    externalResourceFunction: () => Promise.reject(new Error('dmc exports are self-contained')),
  });
  const { numErrors, numWarnings, numInfos, messages } = report.issues;
  console.log(`${path}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos`);
  for (const message of messages) {
    if (message.severity <= 1) {
      console.log(`  ${message.severity === 0 ? 'ERROR' : 'warning'} ${message.code}` +
                  ` ${message.pointer ?? ''}: ${message.message}`);
    }
  }
  if (numErrors > 0) failed = true;
}
process.exit(failed ? 1 : 0);
