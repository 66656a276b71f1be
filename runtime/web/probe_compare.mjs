// The probe-lit sphere in three.js against irview: renders a baked glTF with a white sphere (albedo 1) lit by
// IRBAKE_light_probes (irbake_light_probes.js) from a look-at camera in headless Chromium and compares the
// sphere's pixels with irview's PNG of the same view (irview --probe-object --eye --target --fov): prints the mean
// absolute difference over the sphere's pixels (RGB, 8-bit) and the whole image's, and exits 1 when the
// sphere's exceeds --max-mean-abs. The sphere's pixels are found from the camera itself: rays that pass within
// 0.95 r of the centre (the silhouette, where a tessellated sphere and irview's ray-cast one differ, is left out).
// With --expect-error TEXT nothing is compared: the page must refuse the scene with an error containing TEXT.
// Usage: node probe_compare.mjs --modules DIR --scene FILE.gltf --probe-object X,Y,Z,R --eye X,Y,Z --target X,Y,Z
//          --fov DEG --width W --height H (--reference IRVIEW.png --out WEB.png [--max-mean-abs 3] | --expect-error TEXT)
import fs from 'node:fs';
import path from 'node:path';
import { createRequire } from 'node:module';
import { fileURLToPath } from 'node:url';
import { openTab, serve } from './serve.mjs';

const args = Object.fromEntries(process.argv.slice(2).reduce((a, v, i, all) => (v.startsWith('--') ? [...a, [v.slice(2), all[i + 1]]] : a), []));
const fail = msg => { console.error(`probe_compare: ${msg}`); process.exit(2); };
const expectError = args['expect-error'];
for (const k of ['modules', 'scene', 'probe-object', 'eye', 'target', ...(expectError ? [] : ['reference', 'out'])])
  if (!args[k]) fail(`--${k} is required`);
const width = Number(args.width ?? 160), height = Number(args.height ?? 160), fov = Number(args.fov ?? 40);
const maxMeanAbs = Number(args['max-mean-abs'] ?? 3);
const xyz = s => s.split(',').map(Number);
const [eye, target, sphere] = [xyz(args.eye), xyz(args.target), xyz(args['probe-object'])];
if (!fs.existsSync(args.scene)) fail(`${args.scene}: no such file`);
if (!expectError && !fs.existsSync(args.reference)) fail(`${args.reference}: no such file`);

// Pixel i of the image is on the sphere (well inside its silhouette) when the ray through its centre passes
// within 0.95 r of the sphere's centre: the camera as three.js's PerspectiveCamera.lookAt and irview's lookAt
// build it (+Y up, vertical fov).
function sphereMask() {
  const sub = (a, b) => a.map((v, i) => v - b[i]);
  const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
  const norm = a => a.map(v => v / Math.sqrt(dot(a, a)));
  const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
  const f = norm(sub(target, eye)), r = norm(cross(f, [0, 1, 0])), u = cross(r, f);
  const tanHalf = Math.tan((fov * Math.PI) / 360), aspect = width / height;
  const oc = sub(sphere, eye), mask = new Uint8Array(width * height);
  for (let y = 0; y < height; ++y)
    for (let x = 0; x < width; ++x) {
      const sx = ((x + 0.5) / width * 2 - 1) * tanHalf * aspect, sy = (1 - (y + 0.5) / height * 2) * tanHalf;
      const d = norm([0, 1, 2].map(i => f[i] + sx * r[i] + sy * u[i]));
      const along = dot(oc, d);
      const miss = dot(oc, oc) - along * along;
      mask[y * width + x] = along > 0 && miss < (0.95 * sphere[3]) ** 2 ? 1 : 0;
    }
  return mask;
}

const require = createRequire(path.join(path.resolve(args.modules), 'package.json'));
const puppeteer = require('puppeteer-core');
const here = path.dirname(fileURLToPath(import.meta.url));
const server = await serve({
  web: here,
  three: path.join(path.resolve(args.modules), 'node_modules', 'three'),
  scene: path.dirname(path.resolve(args.scene)),
  ref: path.dirname(path.resolve(args.reference ?? args.scene)),
});
const { browser, tab, log } = await openTab(puppeteer, { chromium: args.chromium, width, height });
let code = 0;
try {
  const q = new URLSearchParams({ scene: `/scene/${encodeURIComponent(path.basename(args.scene))}`, width, height,
                                  probeObject: args['probe-object'], eye: args.eye, target: args.target, fov });
  await tab.goto(`http://127.0.0.1:${server.address().port}/web/index.html?${q}`);
  await tab.waitForFunction('window.viewerReady || window.viewerError', { timeout: 120000 });
  const error = await tab.evaluate('window.viewerError');
  if (expectError) {
    if (!error) throw new Error(`the page showed ${args.scene}; expected an error containing '${expectError}'`);
    if (!error.includes(expectError)) throw new Error(`error '${error.split('\n')[0]}' does not contain '${expectError}'`);
    console.log(JSON.stringify({ refused: error.split('\n')[0] }));
  } else {
    if (error) throw new Error(`viewer: ${error}\n${log.join('\n')}`);
    const ready = await tab.evaluate('window.viewerReady');
    const result = await tab.evaluate(async refUrl => {
      const { canvasPixels } = await import('/web/viewer.js');
      const web = Array.from(canvasPixels());
      const bitmap = await createImageBitmap(await (await fetch(refUrl)).blob(),
                                             { colorSpaceConversion: 'none', premultiplyAlpha: 'none' });
      const c = new OffscreenCanvas(bitmap.width, bitmap.height);
      c.getContext('2d').drawImage(bitmap, 0, 0);
      const ref = Array.from(c.getContext('2d').getImageData(0, 0, bitmap.width, bitmap.height).data);
      return { web, ref, refWidth: bitmap.width, refHeight: bitmap.height,
               png: document.querySelector('canvas').toDataURL('image/png') };
    }, `/ref/${encodeURIComponent(path.basename(args.reference))}`);
    if (result.refWidth !== width || result.refHeight !== height)
      throw new Error(`reference is ${result.refWidth}×${result.refHeight}, render ${width}×${height}`);
    fs.writeFileSync(args.out, Buffer.from(result.png.split(',')[1], 'base64'));
    const mask = sphereMask();
    let sphereSum = 0, spherePixels = 0, sphereMax = 0, allSum = 0, webMean = 0, refMean = 0;
    for (let i = 0; i < width * height; ++i)
      for (let ch = 0; ch < 3; ++ch) {
        const d = Math.abs(result.web[4 * i + ch] - result.ref[4 * i + ch]);
        allSum += d;
        if (!mask[i]) continue;
        sphereSum += d;
        sphereMax = Math.max(sphereMax, d);
        webMean += result.web[4 * i + ch];
        refMean += result.ref[4 * i + ch];
        if (ch === 0) ++spherePixels;
      }
    const n = 3 * spherePixels;
    const out = { spherePixels, sphereMeanAbs: sphereSum / n, sphereMax, sphereWebMean: webMean / n,
                  sphereIrviewMean: refMean / n, imageMeanAbs: allSum / (3 * width * height), probes: ready.probes };
    console.log(JSON.stringify(out));
    if (spherePixels < 100) { console.error(`probe_compare: only ${spherePixels} sphere pixels in view`); code = 1; }
    if (!(out.sphereMeanAbs <= maxMeanAbs)) {
      console.error(`probe_compare: sphere mean absolute difference ${out.sphereMeanAbs.toFixed(3)} > ${maxMeanAbs} (web ${args.out}, irview ${args.reference})`);
      code = 1;
    }
    if (!(out.sphereIrviewMean > 10)) { console.error('probe_compare: the irview sphere is black'); code = 1; }
  }
} catch (e) {
  console.error(`probe_compare: ${e.stack ?? e}`);
  code = expectError ? 1 : 2;
} finally {
  await browser.close();
  server.close();
}
process.exit(code);
