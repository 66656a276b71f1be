// Writes two broken copies of a baked glTF's IRBAKE_light_probes beside it, for the refusal tests:
//   NAME_probe_counts.gltf: counts[0] one larger (the accessors are then too short for the grid)
//   NAME_probe_zero.gltf:   counts[1] = 0
//   NAME_probe_nan.gltf:    the first coefficient NaN (in a copy of the buffer, NAME_probe_nan.bin)
// Usage: node corrupt_probes.mjs SCENE.gltf
import fs from 'node:fs';
import path from 'node:path';

const file = process.argv[2];
const dir = path.dirname(file), stem = path.basename(file, '.gltf');
const doc = JSON.parse(fs.readFileSync(file, 'utf8'));
const ext = doc.extensions?.IRBAKE_light_probes;
if (!ext) { console.error(`corrupt_probes: ${file}: no IRBAKE_light_probes`); process.exit(2); }

const counts = structuredClone(doc);
counts.extensions.IRBAKE_light_probes.counts[0] += 1;
fs.writeFileSync(path.join(dir, `${stem}_probe_counts.gltf`), JSON.stringify(counts));
const zero = structuredClone(doc);
zero.extensions.IRBAKE_light_probes.counts[1] = 0;
fs.writeFileSync(path.join(dir, `${stem}_probe_zero.gltf`), JSON.stringify(zero));

const accessor = doc.accessors[ext.coefficients];
const view = doc.bufferViews[accessor.bufferView];
const buffer = doc.buffers[view.buffer];
const bytes = fs.readFileSync(path.join(dir, buffer.uri));
bytes.writeFloatLE(NaN, (view.byteOffset ?? 0) + (accessor.byteOffset ?? 0));
const nan = structuredClone(doc);
nan.buffers[view.buffer].uri = `${stem}_probe_nan.bin`;
fs.writeFileSync(path.join(dir, `${stem}_probe_nan.bin`), bytes);
fs.writeFileSync(path.join(dir, `${stem}_probe_nan.gltf`), JSON.stringify(nan));
