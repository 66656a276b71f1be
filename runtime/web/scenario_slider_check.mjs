// The web viewer's light-group sliders (scenario_sliders.js) on a bake with IRBAKE_lightmap_scenarios, driven as a
// user drives them: loads index.html (sliders on) in headless Chromium, checks the panel has one slider per layer
// named in --layers and, with two layers, the "a ⇄ b" fade slider; then moves the sliders of --set NAME=W;... and
// then the fade slider to 1, each through an 'input' event, and checks the weights the sliders show after each
// move (the fade sets the layers' sliders from the viewer's weights).
// Writes the canvas after each move (--out-set, --out-fade: the render alone, the panel is HTML over it) and
// prints the mean absolute difference (8-bit RGB) of each against the canvas at load; exits 1 when a slider is
// missing, a weight is not the one set, or a move changes the canvas by less than --min-change.
// Usage: node scenario_slider_check.mjs --modules DIR --scene FILE.gltf|.glb [--camera N] --width W --height H
//          --layers a,b --set 'NAME=W;NAME=W' --out-set SET.png --out-fade FADE.png [--min-change 1]
//          [--exposure EV: as irview --exposure] [--chromium /usr/bin/chromium]
import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';
import { openTab, serve } from './serve.mjs';

const args = Object.fromEntries(process.argv.slice(2).reduce((a, v, i, all) => (v.startsWith('--') ? [...a, [v.slice(2), all[i + 1]]] : a), []));
const fail = msg => { console.error(`scenario_slider_check: ${msg}`); process.exit(2); };
for (const k of ['modules', 'scene', 'layers', 'set', 'out-set', 'out-fade']) if (!args[k]) fail(`--${k} is required`);
if (!fs.existsSync(args.scene)) fail(`${args.scene}: no such file`);
const width = Number(args.width ?? 320), height = Number(args.height ?? 200), minChange = Number(args['min-change'] ?? 1);
const layers = args.layers.split(',');
const set = Object.fromEntries(args.set.split(';').map(kv => [kv.split('=')[0], Number(kv.split('=')[1])]));
if (!Object.entries(set).every(([name, w]) => layers.includes(name) && w >= 0 && w <= 2))
  fail(`--set ${args.set}: NAME=W;... with each NAME in --layers, W from 0 to 2`);

const require = createRequire(path.join(path.resolve(args.modules), 'package.json'));
const puppeteer = require('puppeteer-core');
const here = path.dirname(fileURLToPath(import.meta.url));
const server = await serve({ web: here, three: path.join(path.resolve(args.modules), 'node_modules', 'three'),
                             scene: path.dirname(path.resolve(args.scene)) });
const { browser, tab, log } = await openTab(puppeteer, { chromium: args.chromium, width, height });
const problems = [];
try {
  const q = new URLSearchParams({ scene: `/scene/${encodeURIComponent(path.basename(args.scene))}`, width, height });
  for (const k of ['camera', 'exposure']) if (args[k] !== undefined) q.set(k, args[k]);
  await tab.goto(`http://127.0.0.1:${server.address().port}/web/index.html?${q}`);
  await tab.waitForFunction('window.viewerReady || window.viewerError', { timeout: 120000 });
  const error = await tab.evaluate('window.viewerError');
  if (error) throw new Error(`viewer: ${error}\n${log.join('\n')}`);
  const result = await tab.evaluate(async (layers, set) => {
    const { canvasPixels } = await import('/web/viewer.js');
    const canvas = document.querySelector('canvas');
    // The panel's sliders by their label (the text before the input).
    const sliders = {};
    for (const label of document.querySelectorAll('label')) {
      const input = label.querySelector('input[type=range]');
      if (input) sliders[label.firstChild.textContent.trim()] = input;
    }
    const fadeLabel = layers.length === 2 ? `${layers[0]} ⇄ ${layers[1]}` : null;
    const missing = [...layers, ...(fadeLabel ? [fadeLabel] : [])].filter(name => !sliders[name]);
    if (missing.length) return { error: `no slider for ${missing.join(', ')} (sliders: ${Object.keys(sliders).join(', ')})` };
    const before = canvasPixels();
    const meanAbs = (a, b) => { let s = 0; for (let i = 0; i < a.length; i += 4) s += Math.abs(a[i] - b[i]) + Math.abs(a[i + 1] - b[i + 1]) + Math.abs(a[i + 2] - b[i + 2]); return s / (a.length / 4 * 3); };
    // The weights the sliders show (slider value, one number per layer).
    const shown = () => Object.fromEntries(layers.map(name => [name, Number(sliders[name].value)]));
    const move = (input, value) => { input.value = value; input.dispatchEvent(new Event('input')); };
    const initial = shown();
    for (const [name, w] of Object.entries(set)) move(sliders[name], w);
    const afterSet = { weights: shown(), meanAbs: meanAbs(canvasPixels(), before), png: canvas.toDataURL('image/png') };
    move(sliders[fadeLabel ?? layers[0]], 1);
    const afterFade = { weights: shown(), meanAbs: meanAbs(canvasPixels(), before), png: canvas.toDataURL('image/png') };
    return { sliders: Object.keys(sliders), initial, afterSet, afterFade };
  }, layers, set);
  if (result.error) throw new Error(result.error);
  fs.writeFileSync(args['out-set'], Buffer.from(result.afterSet.png.split(',')[1], 'base64'));
  fs.writeFileSync(args['out-fade'], Buffer.from(result.afterFade.png.split(',')[1], 'base64'));
  delete result.afterSet.png;
  delete result.afterFade.png;
  console.log(JSON.stringify(result));
  const expectSet = { ...result.initial, ...set };
  const expectFade = layers.length === 2 ? { [layers[0]]: 0, [layers[1]]: 1 } : { ...expectSet, [layers[0]]: 1 };
  for (const [what, got, want] of [['--set', result.afterSet.weights, expectSet], ['the fade slider at 1', result.afterFade.weights, expectFade]]) {
    if (layers.some(name => Math.abs(got[name] - want[name]) > 1e-6))
      problems.push(`after ${what} the sliders show ${JSON.stringify(got)}, expected ${JSON.stringify(want)}`);
  }
  for (const [what, r] of [['--set', result.afterSet], ['the fade slider', result.afterFade]])
    if (!(r.meanAbs >= minChange)) problems.push(`${what} changed the canvas by ${r.meanAbs.toFixed(3)} < ${minChange}`);
} catch (e) {
  problems.push(String(e && e.stack || e));
} finally {
  await browser.close();
  server.close();
}
for (const p of problems) console.error(`scenario_slider_check: ${p}`);
process.exit(problems.length ? 1 : 0);
