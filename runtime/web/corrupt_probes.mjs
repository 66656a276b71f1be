// Writes broken copies of a baked glTF's IRBAKE_light_probes beside it, for the refusal tests:
//   NAME_probe_counts.gltf: counts[0] one larger (the accessors are then too short for the grid)
//   NAME_probe_zero.gltf:   counts[1] = 0
//   NAME_probe_nan.gltf:    the first coefficient NaN (in a copy of the buffer, NAME_probe_nan.bin)
// and, when the grid has a sun level (`sun`):
//   NAME_sun_nan.gltf:        the sun's first SH coefficient NaN (in NAME_sun_nan.bin)
//   NAME_sun_cells.gltf:      the refined cells' first two swapped (or the only one past the grid)
//   NAME_sun_irradiance.gltf: the sun's irradiance negative
// and, when it has exact emitters (`emitters`):
//   NAME_emitter_positions.gltf:  the first emitter's positions pointing at the validity (FLOAT SCALAR)
//   NAME_emitter_radiance.gltf:   its radiance [1, 1e39, 1] (not a finite float: JSON has no NaN)
//   NAME_emitter_visibility.gltf: its visibility pointing at a copy of its accessor one element short
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

const sun = ext.sun;
if (sun) {
  const dark = structuredClone(doc);
  dark.extensions.IRBAKE_light_probes.sun.irradiance = [1, -1, 1];
  fs.writeFileSync(path.join(dir, `${stem}_sun_irradiance.gltf`), JSON.stringify(dark));
}
if (sun?.cells !== undefined) {
  const at = index => {
    const a = doc.accessors[index], v = doc.bufferViews[a.bufferView];
    return [(v.byteOffset ?? 0) + (a.byteOffset ?? 0), a.count, v.buffer];
  };
  const [sh, , shBuffer] = at(sun.sh);
  const shBytes = fs.readFileSync(path.join(dir, doc.buffers[shBuffer].uri));
  shBytes.writeFloatLE(NaN, sh);
  const badSh = structuredClone(doc);
  badSh.buffers[shBuffer].uri = `${stem}_sun_nan.bin`;
  fs.writeFileSync(path.join(dir, `${stem}_sun_nan.bin`), shBytes);
  fs.writeFileSync(path.join(dir, `${stem}_sun_nan.gltf`), JSON.stringify(badSh));
  const [cells, count, cellBuffer] = at(sun.cells);
  const cellBytes = fs.readFileSync(path.join(dir, doc.buffers[cellBuffer].uri));
  if (count > 1) {
    const first = cellBytes.readUInt32LE(cells);
    cellBytes.writeUInt32LE(cellBytes.readUInt32LE(cells + 4), cells);
    cellBytes.writeUInt32LE(first, cells + 4);
  } else {
    cellBytes.writeUInt32LE(ext.counts[0] * ext.counts[1] * ext.counts[2], cells);
  }
  const badCells = structuredClone(doc);
  badCells.buffers[cellBuffer].uri = `${stem}_sun_cells.bin`;
  fs.writeFileSync(path.join(dir, `${stem}_sun_cells.bin`), cellBytes);
  fs.writeFileSync(path.join(dir, `${stem}_sun_cells.gltf`), JSON.stringify(badCells));
}

if (ext.emitters?.length) {
  const write = (name, mutate) => {
    const d = structuredClone(doc);
    mutate(d, d.extensions.IRBAKE_light_probes.emitters[0]);
    fs.writeFileSync(path.join(dir, `${stem}_${name}.gltf`), JSON.stringify(d));
  };
  write('emitter_positions', (d, e) => { e.positions = ext.valid; });
  write('emitter_radiance', (d, e) => { e.radiance = [1, 1e39, 1]; });
  // An UNSIGNED_INT SCALAR accessor of the wrong count: a copy of the visibility's with one element fewer.
  write('emitter_visibility', (d, e) => {
    d.accessors.push({ ...d.accessors[e.visibility], count: d.accessors[e.visibility].count - 1 });
    e.visibility = d.accessors.length - 1;
  });
}
