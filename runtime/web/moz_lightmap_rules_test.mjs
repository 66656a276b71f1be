// MOZ_lightmap's units in moz_lightmap_rules.js (docs/export.md): the irradiance factor is the intensity (the
// specification's E = intensity × sRGBToLinear(texel)) for every file but an older irbake's, whose generator starts
// with "irbake" and whose extension has no irradiance marker (intensity × π). Exits 1 naming the case that differs.
// Usage: node moz_lightmap_rules_test.mjs
import { checkMozLightmap } from './moz_lightmap_rules.js';

const marker = { colorSpace: 'srgb', irbake: { mozLightmap: 'irradiance' } };
const cases = [
  // [name, asset, MOZ_lightmap extras (undefined: none), expected irradiance factor for intensity 2]
  ['irbake, marked', { generator: 'irbake' }, marker, 2],
  ['irbake, unmarked (older bake)', { generator: 'irbake' }, { colorSpace: 'srgb' }, 2 * Math.PI],
  ['irbake from another source, unmarked', { generator: 'irbake (from Blender)' }, undefined, 2 * Math.PI],
  ['irbake, another marker value', { generator: 'irbake' }, { irbake: { mozLightmap: 'radiance' } }, 2 * Math.PI],
  ['another tool, unmarked', { generator: 'Khronos glTF Blender I/O' }, undefined, 2],
  ['another tool naming irbake later', { generator: 'THREE.GLTFExporter irbake' }, undefined, 2],
  ['another tool, marked', { generator: 'glTF-Transform' }, marker, 2],
  ['no generator, unmarked', {}, undefined, 2],
  ['no asset, unmarked', undefined, undefined, 2],
];
let failures = 0;
for (const [name, asset, extras, want] of cases) {
  const ext = { index: 0, texCoord: 1, intensity: 2, ...(extras ? { extras } : {}) };
  const json = { ...(asset ? { asset: { version: '2.0', ...asset } } : {}), textures: [{ source: 0 }],
                 materials: [{ extensions: { MOZ_lightmap: ext } }] };
  const got = checkMozLightmap(json, 0, ext).irradiance;
  if (Math.abs(got - want) > 1e-12) {
    console.error(`moz_lightmap_rules_test: ${name}: irradiance factor ${got}, expected ${want}`);
    failures++;
  }
}
if (failures) process.exit(1);
console.log(`moz_lightmap_rules_test: ${cases.length} cases`);
