// The clients refuse what irview refuses: writes broken copies of a baked glTF beside it (a MOZ_lightmap intensity
// of -1, "NaN", null or 1e39, a texture index the file lacks, texCoord 0; an IRBAKE_light_probes spacing of 1e-50
// or 1e39, an origin of 1e39: not finite as 32-bit floats; a grid no bake writes: a spacing of 0.005 or 2e9 m, an
// origin of 2e9 m, a far corner beyond 1e9 m, a probe moved 2 spacings) and requires irview (exit 5), three.js
// (moz_lightmap.js, irbake_light_probes.js) and Babylon.js (babylon_moz_lightmap.js, MOZ_lightmap only) in headless
// Chromium to refuse each with the same message, naming the material or the field. The bake as written, and copies
// without texCoord or intensity (defaults 1), must load in all three, with their light maps; a probe moved exactly
// one spacing (the limit) in irview and three.js.
// Usage: node plugin_refusals.mjs --modules DIR --irview EXE --scene BAKE.gltf (a bake with probes)
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';
import { openTab, serve } from './serve.mjs';

const args = Object.fromEntries(process.argv.slice(2).reduce((a, v, i, all) => (v.startsWith('--') ? [...a, [v.slice(2), all[i + 1]]] : a), []));
const fail = msg => { console.error(`plugin_refusals: ${msg}`); process.exit(2); };
for (const k of ['modules', 'irview', 'scene']) if (!args[k]) fail(`--${k} is required`);
const doc = JSON.parse(fs.readFileSync(args.scene, 'utf8'));
const dir = path.dirname(path.resolve(args.scene)), stem = path.basename(args.scene, '.gltf');
const m = (doc.materials ?? []).findIndex(mat => mat.extensions?.MOZ_lightmap);
if (m < 0 || !doc.extensions?.IRBAKE_light_probes) fail(`${args.scene}: needs a MOZ_lightmap and IRBAKE_light_probes`);
const name = doc.materials[m].name;
const material = `material ${m}${name ? ` ('${name}')` : ''}: MOZ_lightmap`;

// name → [mutation of a copy, the message every client must give (null: it must load), clients]
const moz = f => d => f(d.materials[m].extensions.MOZ_lightmap);
const probes = f => d => f(d.extensions.IRBAKE_light_probes);
const all = ['irview', 'three', 'babylon'], threeAndIrview = ['irview', 'three'];
const grid = doc.extensions.IRBAKE_light_probes;
// The far corner: on the first axis of 3 or more probes (the axes before it have at most 2), an origin of 9e8 m
// and a spacing of 1e8 m, each within the limits, reach 9e8 + 1e8 × (counts − 1) ≥ 1.1e9 m (all exact as floats).
const axis = grid.counts.findIndex(c => c >= 3);
if (axis < 0 || grid.counts[axis] > 90) fail(`${args.scene}: needs a probe axis of 3 to 90 probes (counts ${grid.counts})`);
const far = 9e8 + 1e8 * (grid.counts[axis] - 1);
// A copy of the buffer that holds the probe offsets with the middle probe's x offset set to `spacings` spacings
// (as a 32-bit float), beside the bake; the mutation points the copy's buffer at it. Returns [mutation, metres].
const probe = Math.floor(grid.counts.reduce((x, y) => x * y, 1) / 2);
function movedProbe(spacings, file) {
  const accessor = doc.accessors[grid.offsets], view = doc.bufferViews[accessor.bufferView];
  const bytes = fs.readFileSync(path.join(dir, doc.buffers[view.buffer].uri));
  const moved = Math.fround(spacings * Math.fround(grid.spacing));
  bytes.writeFloatLE(moved, (view.byteOffset ?? 0) + (accessor.byteOffset ?? 0) + 12 * probe);
  fs.writeFileSync(path.join(dir, file), bytes);
  return [d => { d.buffers[view.buffer].uri = file; }, moved];
}
const [twoSpacings, twoSpacingsMetres] = movedProbe(2, `${stem}_offset_two_spacings.bin`);
// The expected text below writes it as printf's %.3g does in this range (no exponent).
if (!(twoSpacingsMetres >= 1e-4 && twoSpacingsMetres < 1e3)) fail(`${args.scene}: spacing ${grid.spacing} m out of the test's range`);
const [oneSpacing] = movedProbe(1, `${stem}_offset_one_spacing.bin`);
const outside = 'm is outside the 0.01 … 1e9 m a bake writes', beyond = 'm is beyond the supported 1e9 m';
const cases = {
  as_baked: [() => {}, null, all],
  no_texcoord: [moz(e => { delete e.texCoord; }), null, all],
  no_intensity: [moz(e => { delete e.intensity; }), null, all],
  intensity_negative: [moz(e => { e.intensity = -1; }), `${material} intensity -1 must be a finite number ≥ 0`, all],
  intensity_nan: [moz(e => { e.intensity = 'NaN'; }), `${material} intensity "NaN" must be a finite number ≥ 0`, all],
  intensity_null: [moz(e => { e.intensity = null; }), `${material} intensity null must be a finite number ≥ 0`, all],
  intensity_overflow: [moz(e => { e.intensity = 1e39; }), `${material} intensity 1e+39 must be a finite number ≥ 0`, all],
  texture_missing: [moz(e => { e.index = 99; }),
                    `${material} names texture 99, which does not exist (the file has ${doc.textures.length})`, all],
  texcoord_zero: [moz(e => { e.texCoord = 0; }), `${material} texCoord 0, but light maps use TEXCOORD_1`, all],
  spacing_tiny: [probes(e => { e.spacing = 1e-50; }), 'IRBAKE_light_probes.spacing: needs a positive finite number', threeAndIrview],
  spacing_huge: [probes(e => { e.spacing = 1e39; }), 'IRBAKE_light_probes.spacing: needs a positive finite number', threeAndIrview],
  origin_huge: [probes(e => { e.origin[1] = 1e39; }), 'IRBAKE_light_probes.origin: not finite', threeAndIrview],
  spacing_below_bakes: [probes(e => { e.spacing = 0.005; }), `IRBAKE_light_probes.spacing: 0.005 ${outside}`, threeAndIrview],
  spacing_above_bakes: [probes(e => { e.spacing = 2e9; }), `IRBAKE_light_probes.spacing: 2e+09 ${outside}`, threeAndIrview],
  origin_beyond_bakes: [probes(e => { e.origin[1] = 2e9; }), `IRBAKE_light_probes.origin: 2e+09 ${beyond}`, threeAndIrview],
  far_corner_beyond_bakes: [probes(e => { e.origin[axis] = 9e8; e.spacing = 1e8; }),
                            `IRBAKE_light_probes.counts: the grid reaches ${Number((far / 1e9).toPrecision(3))}e+09 m, ` +
                            'beyond the supported 1e9 m (origin + spacing × (counts − 1))', threeAndIrview],
  offset_two_spacings: [twoSpacings, `IRBAKE_light_probes.offsets: probe ${probe} is moved ` +
                        `${Number(twoSpacingsMetres.toPrecision(3))} m from its grid point, more than a spacing ` +
                        '(a bake moves it at most half)', threeAndIrview],
  offset_one_spacing: [oneSpacing, null, threeAndIrview],
};
// A probe-lit sphere makes irview read the probes; three.js reads them on every load.
const sphere = '0.2,0.4,0.2,0.08';
for (const [key, [mutate]] of Object.entries(cases)) {
  const copy = structuredClone(doc);
  mutate(copy);
  fs.writeFileSync(path.join(dir, `${stem}_${key}.gltf`), JSON.stringify(copy));
}

const require = createRequire(path.join(path.resolve(args.modules), 'package.json'));
const puppeteer = require('puppeteer-core');
const nodeModules = path.join(path.resolve(args.modules), 'node_modules');
const server = await serve({
  web: path.dirname(fileURLToPath(import.meta.url)),
  three: path.join(nodeModules, 'three'),
  'babylon-core': path.join(nodeModules, '@babylonjs', 'core'),
  'babylon-loaders': path.join(nodeModules, '@babylonjs', 'loaders'),
  scene: dir,
});
const size = 32;
const { browser, tab } = await openTab(puppeteer, { chromium: args.chromium, width: size, height: size });
const failures = [];
// What a client says about FILE: { error } or { ready } (the page's result).
async function load(client, file) {
  if (client === 'irview') {
    const shot = path.join(dir, `${stem}_refusal_shot.png`);
    try {
      execFileSync(args.irview, [file, '--probe-object', sphere, '--width', `${size}`, '--height', `${size}`,
                                 '--screenshot', shot], { stdio: 'pipe' });
      return { ready: { exit: 0 } };
    } catch (e) {
      return { error: `exit ${e.status}: ${e.stderr.toString()}${e.stdout.toString()}`, exit: e.status };
    }
  }
  const q = new URLSearchParams({ scene: `/scene/${encodeURIComponent(path.basename(file))}`, camera: 0, width: size,
                                  height: size, plugin: 'moz-only' });
  await tab.goto(`http://127.0.0.1:${server.address().port}/web/${client === 'babylon' ? 'babylon.html' : 'index.html'}?${q}`);
  await tab.waitForFunction('window.viewerReady || window.viewerError', { timeout: 120000 });
  return { error: await tab.evaluate('window.viewerError'), ready: await tab.evaluate('window.viewerReady') };
}
try {
  for (const [key, [, expected, clients]] of Object.entries(cases)) {
    const file = path.join(dir, `${stem}_${key}.gltf`);
    for (const client of clients) {
      const r = await load(client, file);
      const said = (r.error ?? '').split('\n').find(l => l.trim()) ?? '';
      if (expected === null) {
        const mapped = client === 'babylon' ? r.ready?.lightmappedMaterials > 0 : true;
        if (r.error || !mapped) failures.push(`${client} ${key}: expected it to load with its light maps, got ${said || JSON.stringify(r.ready)}`);
        else console.log(`${client} ${key}: loads`);
      } else if (!r.error) {
        failures.push(`${client} ${key}: accepted; expected '${expected}'`);
      } else if (!r.error.includes(expected) || (client === 'irview' && r.exit !== 5)) {
        failures.push(`${client} ${key}: said '${said.trim()}'; expected '${expected}'${client === 'irview' ? ' with exit 5' : ''}`);
      } else {
        console.log(`${client} ${key}: refused: ${expected}`);
      }
    }
  }
} finally {
  await browser.close();
  server.close();
}
for (const f of failures) console.error(`plugin_refusals: ${f}`);
process.exit(failures.length ? 1 : 0);
