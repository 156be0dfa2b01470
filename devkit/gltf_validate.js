// Validate one glTF file with the Khronos glTF validator (npm "gltf-validator"); print its report as JSON.
// Usage: node gltf_validate.js MODULE_DIR FILE   (devkit/gltf_validator.py installs the module and runs this)
const validator = require(process.argv[2]);
const fs = require("fs");
const path = process.argv[3];
validator.validateBytes(new Uint8Array(fs.readFileSync(path)), {maxIssues: 200})
  .then((report) => console.log(JSON.stringify(report.issues)))
  .catch((error) => { console.error(String(error)); process.exit(2); });
