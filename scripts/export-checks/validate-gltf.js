// Validates glTF 2.0 files (.glb or .gltf) with the Khronos glTF-Validator and exits non-zero
// if any has an error. Usage: node validate-gltf.js FILE... (run where gltf-validator is
// installed, or with NODE_PATH pointing at its node_modules).
'use strict';
const fs = require('fs');
const path = require('path');
const validator = require('gltf-validator');

async function validate(file) {
  const bytes = new Uint8Array(fs.readFileSync(file));
  const options = {
    uri: path.basename(file),
    maxIssues: 50,
    // Every file impulse writes is self-contained (GLB BIN chunk or a data URI).
    externalResourceFunction: (uri) =>
      Promise.reject(new Error(`unexpected external resource ${uri}`)),
  };
  const report = file.endsWith('.gltf')
    ? await validator.validateString(new TextDecoder().decode(bytes), options)
    : await validator.validateBytes(bytes, options);
  const { numErrors, numWarnings, numInfos, numHints } = report.issues;
  console.log(
    `${file}: ${numErrors} errors, ${numWarnings} warnings, ${numInfos} infos, ` +
      `${numHints} hints (${report.info.drawCallCount} meshes drawn, ` +
      `${report.info.animationCount} animations)`,
  );
  for (const message of report.issues.messages) {
    if (message.severity <= 1) {
      console.log(`  ${['error', 'warning'][message.severity]} ${message.code} at ` +
        `${message.pointer ?? ''}: ${message.message}`);
    }
  }
  return numErrors;
}

(async () => {
  const files = process.argv.slice(2);
  if (files.length === 0) {
    console.error('usage: node validate-gltf.js FILE...');
    process.exit(2);
  }
  let errors = 0;
  for (const file of files) {
    errors += await validate(file);
  }
  process.exit(errors === 0 ? 0 : 1);
})().catch((e) => {
  console.error(e);
  process.exit(2);
});
