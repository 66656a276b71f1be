// Renders a baked glTF in headless Chromium (three.js, the MOZ_lightmap plugin; or Babylon.js with
// --client babylon) from one of its cameras and compares it with a reference PNG (irview --camera N
// --screenshot): prints the mean absolute difference over RGB in 8-bit units and exits 1 when it exceeds
// --max-mean-abs.
// Usage: node render_compare.mjs --modules DIR --scene FILE.gltf [--camera N] --width W --height H
//          --reference REF.png --out WEB.png [--max-mean-abs 2] [--chromium /usr/bin/chromium]
//          [--lightmap sh|l0] [--min-directional N: fail unless N materials were shaded with directional maps]
//          [--plugin none: the client's glTF loader without our MOZ_lightmap plugin, as any viewer (the portable GLB);
//           moz-only: MOZ_lightmap without irbake_shadowmask.js's mixed lights]
//          [--min-runtime-lights N, --min-masked N: fail unless three.js shaded N lights in real time, N materials
//           with a shadow mask; --min-probe-lit N: unless N meshes were lit by the probes (probe-lit objects)]
//          [--client three|babylon|spec (default three; spec: three.js reading MOZ_lightmap from its specification
//           alone, spec_reader.html; --standard 0 shades it with Lambert instead of MeshStandardMaterial)]
import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';
import { openTab, serve } from './serve.mjs';

const args = Object.fromEntries(process.argv.slice(2).reduce((a, v, i, all) => (v.startsWith('--') ? [...a, [v.slice(2), all[i + 1]]] : a), []));
const fail = msg => { console.error(`render_compare: ${msg}`); process.exit(2); };
for (const k of ['modules', 'scene', 'reference', 'out']) if (!args[k]) fail(`--${k} is required`);
const width = Number(args.width ?? 256), height = Number(args.height ?? 256), camera = args.camera;
const maxMeanAbs = Number(args['max-mean-abs'] ?? 2);
const client = args.client ?? 'three';
const pages = { three: { html: 'index.html', module: '/web/viewer.js' },
                babylon: { html: 'babylon.html', module: '/web/babylon_viewer.js' },
                spec: { html: 'spec_reader.html', module: '/web/spec_moz_lightmap.js' } };
if (!pages[client]) fail(`--client ${client}: three, babylon or spec`);
const page = pages[client];
if (!fs.existsSync(args.scene)) fail(`${args.scene}: no such file`);
if (!fs.existsSync(args.reference)) fail(`${args.reference}: no such file`);

const require = createRequire(path.join(path.resolve(args.modules), 'package.json'));
const puppeteer = require('puppeteer-core');
const here = path.dirname(fileURLToPath(import.meta.url));
const nodeModules = path.join(path.resolve(args.modules), 'node_modules');
const server = await serve({
  web: here,
  three: path.join(nodeModules, 'three'),
  'babylon-core': path.join(nodeModules, '@babylonjs', 'core'),
  'babylon-loaders': path.join(nodeModules, '@babylonjs', 'loaders'),
  scene: path.dirname(path.resolve(args.scene)),
  ref: path.dirname(path.resolve(args.reference)),
});
const port = server.address().port;
const { browser, tab, log } = await openTab(puppeteer, { chromium: args.chromium, width, height });
let code = 0;
try {
  const q = new URLSearchParams({ scene: `/scene/${encodeURIComponent(path.basename(args.scene))}`, width, height,
                                  lightmap: args.lightmap ?? 'sh', plugin: args.plugin ?? 'moz', standard: args.standard ?? '1' });
  if (camera !== undefined) q.set('camera', camera);  // none: the viewer's default (camera 0, or the overview)
  await tab.goto(`http://127.0.0.1:${port}/web/${page.html}?${q}`);
  await tab.waitForFunction('window.viewerReady || window.viewerError', { timeout: 120000 });
  const error = await tab.evaluate('window.viewerError');
  if (error) throw new Error(`viewer: ${error}\n${log.join('\n')}`);
  const ready = await tab.evaluate('window.viewerReady');
  const result = await tab.evaluate(async (refUrl, module) => {
    const { canvasPixels } = await import(module);
    const web = canvasPixels();
    const blob = await (await fetch(refUrl)).blob();
    const bitmap = await createImageBitmap(blob, { colorSpaceConversion: 'none', premultiplyAlpha: 'none' });
    const c = new OffscreenCanvas(bitmap.width, bitmap.height);
    const ctx = c.getContext('2d');
    ctx.drawImage(bitmap, 0, 0);
    const ref = ctx.getImageData(0, 0, bitmap.width, bitmap.height).data;
    const w = document.querySelector('canvas').width, h = document.querySelector('canvas').height;
    if (bitmap.width !== w || bitmap.height !== h) return { error: `reference is ${bitmap.width}×${bitmap.height}, render ${w}×${h}` };
    let sum = 0, worst = 0, over8 = 0, webSum = 0, refSum = 0;
    for (let i = 0; i < w * h; ++i)
      for (let ch = 0; ch < 3; ++ch) {
        const d = Math.abs(web[4 * i + ch] - ref[4 * i + ch]);
        sum += d;
        worst = Math.max(worst, d);
        if (d > 8) ++over8;
        webSum += web[4 * i + ch];
        refSum += ref[4 * i + ch];
      }
    const n = w * h * 3;
    return { meanAbs: sum / n, max: worst, fractionOver8: over8 / n, webMean: webSum / n, refMean: refSum / n,
             png: document.querySelector('canvas').toDataURL('image/png') };
  }, `/ref/${encodeURIComponent(path.basename(args.reference))}`, page.module);
  if (result.error) throw new Error(result.error);
  fs.writeFileSync(args.out, Buffer.from(result.png.split(',')[1], 'base64'));
  delete result.png;
  result.client = client;
  Object.assign(result, ready);
  for (const k of ['width', 'height']) delete result[k];
  console.log(JSON.stringify(result));
  if (!(result.meanAbs <= maxMeanAbs)) {
    console.error(`render_compare: mean absolute difference ${result.meanAbs.toFixed(3)} > ${maxMeanAbs} (web ${args.out}, irview ${args.reference})`);
    code = 1;
  }
  for (const [option, field] of [['min-runtime-lights', 'runtimeLights'], ['min-masked', 'maskedMaterials'],
                                 ['min-probe-lit', 'probeLit']])
    if (args[option] !== undefined && !(result[field] >= Number(args[option]))) {
      console.error(`render_compare: ${field} ${result[field]}, expected at least ${args[option]}`);
      code = 1;
    }
  if (args['min-directional'] !== undefined && !(result.directionalMaterials >= Number(args['min-directional']))) {
    console.error(`render_compare: ${result.directionalMaterials} materials with directional maps, expected at least ${args['min-directional']}`);
    code = 1;
  }
} catch (e) {
  console.error(`render_compare: ${e.stack ?? e}`);
  code = 2;
} finally {
  await browser.close();
  server.close();
}
process.exit(code);
