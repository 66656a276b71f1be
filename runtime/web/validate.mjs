// Runs the Khronos glTF-Validator (npm gltf-validator, validateBytes) on an export and, when given,
// on its input. Passes (exit 0) when the export has 0 errors, no warning the input did not already
// have (compared by code and count), and no UNUSED_OBJECT for a mesh or an accessor (but the accessors
// IRBAKE_light_probes and its `sun` and `emitters` name, and those of IRBAKE_lightmap_scenarios's layers: the
// validator does not know the extensions). Prints the counts.
// Usage: node validate.mjs --modules DIR --output OUT.gltf|.glb [--input IN.gltf|.glb]
import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';

const args = Object.fromEntries(process.argv.slice(2).reduce((a, v, i, all) => (v.startsWith('--') ? [...a, [v.slice(2), all[i + 1]]] : a), []));
const fail = msg => { console.error(`validate: ${msg}`); process.exit(2); };
if (!args.modules || !args.output) fail('--modules and --output are required');
const require = createRequire(path.join(path.resolve(args.modules), 'package.json'));
const validator = require('gltf-validator');

// The JSON of a .gltf or .glb.
function jsonOf(file) {
  const bytes = fs.readFileSync(file);
  if (bytes.readUInt32LE(0) !== 0x46546c67) return JSON.parse(bytes.toString('utf8'));
  return JSON.parse(bytes.subarray(20, 20 + bytes.readUInt32LE(12)).toString('utf8'));
}

async function validate(file) {
  if (!fs.existsSync(file)) fail(`${file}: no such file`);
  const folder = path.dirname(file);
  const report = await validator.validateBytes(new Uint8Array(fs.readFileSync(file)), {
    uri: path.basename(file),
    maxIssues: 0,
    externalResourceFunction: uri => new Promise((resolve, reject) => {
      try { resolve(new Uint8Array(fs.readFileSync(path.join(folder, decodeURIComponent(uri))))); } catch (e) { reject(String(e)); }
    }),
  });
  const byCode = severity => {
    const counts = {};
    for (const m of report.issues.messages) if (m.severity === severity) counts[m.code] = (counts[m.code] ?? 0) + 1;
    return counts;
  };
  return { report, errors: report.issues.numErrors, warnings: report.issues.numWarnings, infos: report.issues.numInfos,
           warningCodes: byCode(1), infoCodes: byCode(2) };
}

const out = await validate(args.output);
const input = args.input ? await validate(args.input) : null;
const problems = [];
if (out.errors > 0)
  for (const m of out.report.issues.messages.filter(m => m.severity === 0)) problems.push(`error ${m.code} at ${m.pointer}: ${m.message}`);
for (const [code, n] of Object.entries(out.warningCodes)) {
  const before = input ? (input.warningCodes[code] ?? 0) : 0;
  if (n > before) problems.push(`warning ${code}: ${n} (input: ${before})`);
}
// IRBAKE_light_probes names its accessors from the root's extensions, which the validator does not read.
// Its optional `sun` object names four more, and each of its optional `emitters` two.
const probeExt = jsonOf(args.output).extensions?.IRBAKE_light_probes ?? {};
const probeAccessors = new Set([
  ...Object.entries(probeExt).filter(([k]) => ['coefficients', 'offsets', 'valid'].includes(k)),
  ...Object.entries(probeExt.sun ?? {}).filter(([k]) => ['sh', 'visibility', 'cells', 'fine'].includes(k)),
  ...(Array.isArray(probeExt.emitters) ? probeExt.emitters : []).flatMap(e => Object.entries(e ?? {}))
    .filter(([k]) => ['positions', 'visibility'].includes(k)),
].map(([, v]) => `/accessors/${v}`));
// IRBAKE_lightmap_scenarios names each layer's probe coefficients and the sun layer's SH the same way (its
// textures show as UNUSED_OBJECT infos, which pass).
for (const layer of jsonOf(args.output).extensions?.IRBAKE_lightmap_scenarios?.layers ?? [])
  for (const v of [layer?.probes, layer?.sun?.sh]) if (Number.isInteger(v)) probeAccessors.add(`/accessors/${v}`);
for (const m of out.report.issues.messages)
  if (m.code === 'UNUSED_OBJECT' && /^\/(meshes|accessors)\/\d+$/.test(m.pointer ?? '') && !probeAccessors.has(m.pointer))
    problems.push(`unused ${m.pointer}`);
const summary = { file: args.output, errors: out.errors, warnings: out.warnings, infos: out.infos, warningCodes: out.warningCodes,
                  infoCodes: out.infoCodes };
if (input) summary.input = { errors: input.errors, warnings: input.warnings, infos: input.infos, warningCodes: input.warningCodes };
console.log(JSON.stringify(summary));
if (problems.length) {
  console.error(`validate: ${args.output}:\n  ${problems.join('\n  ')}`);
  process.exit(1);
}
