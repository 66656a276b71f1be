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
//          [--region-a A.png --region-b B.png [--region-min 8] [--min-region-pixels N]: the mean over the pixels
//           where A and B (beside the reference) differ by at least region-min in some channel, and fail unless
//           there are N of them]
//          [--weights 'a=0.5;b=1,0.8,0.5', --scenario NAME: a bake with light groups blended at run time with these
//           layer weights over that stored scenario (irbake_lightmap_scenarios.js); --scenarios off: its own maps,
//           unblended; --min-blended N: fail unless N materials were blended]
//          [--exposure EV: the three.js viewer's display exposure, as irview --exposure]
//          [--image X.png: compare that image (beside the reference, irview's own screenshot) instead of a render;
//           --scene is then not read]
import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';
import { openTab, serve } from './serve.mjs';

const args = Object.fromEntries(process.argv.slice(2).reduce((a, v, i, all) => (v.startsWith('--') ? [...a, [v.slice(2), all[i + 1]]] : a), []));
const fail = msg => { console.error(`render_compare: ${msg}`); process.exit(2); };
const image = args.image;
for (const k of ['modules', ...(image ? [] : ['scene']), 'reference', 'out']) if (!args[k]) fail(`--${k} is required`);
const width = Number(args.width ?? 256), height = Number(args.height ?? 256), camera = args.camera;
const maxMeanAbs = Number(args['max-mean-abs'] ?? 2);
const client = args.client ?? 'three';
const pages = { three: { html: 'index.html', module: '/web/viewer.js' },
                babylon: { html: 'babylon.html', module: '/web/babylon_viewer.js' },
                spec: { html: 'spec_reader.html', module: '/web/spec_moz_lightmap.js' } };
if (!pages[client]) fail(`--client ${client}: three, babylon or spec`);
const page = pages[client];
if (!image && !fs.existsSync(args.scene)) fail(`${args.scene}: no such file`);
if (image && (!fs.existsSync(image) || path.resolve(path.dirname(image)) !== path.resolve(path.dirname(args.reference))))
  fail(`--image ${image}: no such file beside --reference`);
if (!fs.existsSync(args.reference)) fail(`${args.reference}: no such file`);
const region = args['region-a'] !== undefined || args['region-b'] !== undefined;
for (const k of region ? ['region-a', 'region-b'] : []) {
  if (!args[k] || !fs.existsSync(args[k])) fail(`--${k} ${args[k]}: no such file`);
  if (path.resolve(path.dirname(args[k])) !== path.resolve(path.dirname(args.reference))) fail(`--${k} must be beside --reference`);
}
const regionMin = Number(args['region-min'] ?? 8);

const require = createRequire(path.join(path.resolve(args.modules), 'package.json'));
const puppeteer = require('puppeteer-core');
const here = path.dirname(fileURLToPath(import.meta.url));
const nodeModules = path.join(path.resolve(args.modules), 'node_modules');
const server = await serve({
  web: here,
  three: path.join(nodeModules, 'three'),
  'babylon-core': path.join(nodeModules, '@babylonjs', 'core'),
  'babylon-loaders': path.join(nodeModules, '@babylonjs', 'loaders'),
  scene: path.dirname(path.resolve(args.scene ?? args.reference)),
  ref: path.dirname(path.resolve(args.reference)),
});
const port = server.address().port;
const { browser, tab, log } = await openTab(puppeteer, { chromium: args.chromium, width, height });
let code = 0;
try {
  const q = new URLSearchParams({ scene: `/scene/${encodeURIComponent(path.basename(args.scene ?? ''))}`, width, height,
                                  lightmap: args.lightmap ?? 'sh', plugin: args.plugin ?? 'moz', standard: args.standard ?? '1' });
  if (camera !== undefined) q.set('camera', camera);  // none: the viewer's default (camera 0, or the overview)
  for (const k of ['weights', 'scenario', 'scenarios', 'exposure']) if (args[k] !== undefined) q.set(k, args[k]);
  const imageUrl = image ? `/ref/${encodeURIComponent(path.basename(image))}` : null;
  let ready = {};
  if (image) {
    await tab.goto(`http://127.0.0.1:${port}${imageUrl}`);  // a page of the server's origin, for its fetches
  } else {
    await tab.goto(`http://127.0.0.1:${port}/web/${page.html}?${q}`);
    await tab.waitForFunction('window.viewerReady || window.viewerError', { timeout: 120000 });
    const error = await tab.evaluate('window.viewerError');
    if (error) throw new Error(`viewer: ${error}\n${log.join('\n')}`);
    ready = await tab.evaluate('window.viewerReady');
  }
  const result = await tab.evaluate(async (refUrl, module, regionUrls, regionMin, imageUrl) => {
    const decode = async url => {
      const blob = await (await fetch(url)).blob();
      const bitmap = await createImageBitmap(blob, { colorSpaceConversion: 'none', premultiplyAlpha: 'none' });
      const c = new OffscreenCanvas(bitmap.width, bitmap.height);
      const ctx = c.getContext('2d');
      ctx.drawImage(bitmap, 0, 0);
      return { width: bitmap.width, height: bitmap.height, data: ctx.getImageData(0, 0, bitmap.width, bitmap.height).data };
    };
    let web, w, h, png = null;
    if (imageUrl) {
      ({ width: w, height: h, data: web } = await decode(imageUrl));
    } else {
      const { canvasPixels } = await import(module);
      web = canvasPixels();
      w = document.querySelector('canvas').width;
      h = document.querySelector('canvas').height;
      png = document.querySelector('canvas').toDataURL('image/png');
    }
    const read = async url => {
      const img = await decode(url);
      return img.width === w && img.height === h ? img.data : `${url} is ${img.width}×${img.height}, render ${w}×${h}`;
    };
    const ref = await read(refUrl);
    if (typeof ref === 'string') return { error: ref };
    let inRegion = () => true;
    if (regionUrls) {
      const [a, b] = [await read(regionUrls[0]), await read(regionUrls[1])];
      for (const img of [a, b]) if (typeof img === 'string') return { error: img };
      inRegion = i => [0, 1, 2].some(ch => Math.abs(a[4 * i + ch] - b[4 * i + ch]) >= regionMin);
    }
    let sum = 0, worst = 0, over8 = 0, webSum = 0, refSum = 0, pixels = 0;
    for (let i = 0; i < w * h; ++i) {
      if (!inRegion(i)) continue;
      ++pixels;
      for (let ch = 0; ch < 3; ++ch) {
        const d = Math.abs(web[4 * i + ch] - ref[4 * i + ch]);
        sum += d;
        worst = Math.max(worst, d);
        if (d > 8) ++over8;
        webSum += web[4 * i + ch];
        refSum += ref[4 * i + ch];
      }
    }
    const n = Math.max(pixels, 1) * 3;
    return { meanAbs: sum / n, max: worst, fractionOver8: over8 / n, webMean: webSum / n, refMean: refSum / n, pixels, png };
  }, `/ref/${encodeURIComponent(path.basename(args.reference))}`, page.module,
  region ? ['region-a', 'region-b'].map(k => `/ref/${encodeURIComponent(path.basename(args[k]))}`) : null, regionMin, imageUrl);
  if (result.error) throw new Error(result.error);
  if (result.png) fs.writeFileSync(args.out, Buffer.from(result.png.split(',')[1], 'base64'));
  else fs.copyFileSync(image, args.out);
  delete result.png;
  result.client = image ? 'image' : client;
  Object.assign(result, ready);
  for (const k of ['width', 'height']) delete result[k];
  console.log(JSON.stringify(result));
  if (!(result.meanAbs <= maxMeanAbs)) {
    console.error(`render_compare: mean absolute difference ${result.meanAbs.toFixed(3)} > ${maxMeanAbs} (web ${args.out}, irview ${args.reference})`);
    code = 1;
  }
  for (const [option, field] of [['min-runtime-lights', 'runtimeLights'], ['min-masked', 'maskedMaterials'],
                                 ['min-region-pixels', 'pixels'], ['min-probe-lit', 'probeLit'], ['min-blended', 'blendedMaterials']])
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
