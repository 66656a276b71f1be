// Writes a variant of irbake's Cornell box sample for the mixed-lighting web test: the emissive quad under the
// ceiling is switched off (emission 0) and a KHR_lights_punctual point light takes its place 5 cm below it,
// with the quad's colour and the on-axis intensity of the quad (Le·A: 17 × 0.01365 ≈ 0.232 W/sr in red, so
// the room is about as bright), optionally with extras.irbake.mode and a range (metres). The buffers stay where
// they are (the variant is written beside the sample). Pure node, no dependencies.
// Usage: node make_mixed_cornell.mjs SAMPLE.gltf OUT.gltf [--mode baked|indirect|shadowmask] [--range R]
import fs from 'node:fs';
import path from 'node:path';

const [input, output] = process.argv.slice(2);
const modeAt = process.argv.indexOf('--mode');
const mode = modeAt > 0 ? process.argv[modeAt + 1] : undefined;
const rangeAt = process.argv.indexOf('--range');
const range = rangeAt > 0 ? Number(process.argv[rangeAt + 1]) : undefined;
if (!input || !output || (mode !== undefined && !['baked', 'indirect', 'shadowmask'].includes(mode)) ||
    (range !== undefined && !(range > 0))) {
  console.error('usage: node make_mixed_cornell.mjs SAMPLE.gltf OUT.gltf [--mode baked|indirect|shadowmask] [--range R > 0]');
  process.exit(2);
}
if (path.resolve(path.dirname(input)) !== path.resolve(path.dirname(output))) {
  console.error('make_mixed_cornell: OUT.gltf must be beside SAMPLE.gltf (it shares its buffers)');
  process.exit(2);
}
const gltf = JSON.parse(fs.readFileSync(input, 'utf8'));
const light = (gltf.materials ?? []).find(m => m.name === 'light');
if (!light?.emissiveFactor) { console.error(`${input}: no emissive material 'light' (not the Cornell box sample?)`); process.exit(1); }
const le = light.emissiveFactor.map(v => v * (light.extensions?.KHR_materials_emissive_strength?.emissiveStrength ?? 1));
light.emissiveFactor = [0, 0, 0];
delete light.extensions?.KHR_materials_emissive_strength;
const area = 0.130 * 0.105;
const peak = Math.max(...le);
const def = { name: 'lamp', type: 'point', color: le.map(v => v / peak), intensity: peak * area };
if (mode) def.extras = { irbake: { mode } };
if (range !== undefined) def.range = range;
gltf.extensions = { ...(gltf.extensions ?? {}), KHR_lights_punctual: { lights: [def] } };
gltf.extensionsUsed = [...new Set([...(gltf.extensionsUsed ?? []), 'KHR_lights_punctual'])];
// The quad is 0.5 mm below the 548.8 mm ceiling, centred at (278, ·, 279.5) mm.
gltf.nodes.push({ name: 'lamp', translation: [0.278, 0.4988, 0.2795], extensions: { KHR_lights_punctual: { light: 0 } } });
gltf.scenes[gltf.scene ?? 0].nodes.push(gltf.nodes.length - 1);
fs.writeFileSync(output, JSON.stringify(gltf, null, 1));
console.log(JSON.stringify({ output, light: def }));
