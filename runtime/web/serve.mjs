// A static file server for the web viewer: /web/ = this folder, /three/ = three from node_modules,
// /scene/ = the folder of the glTF to show, /ref/ = the folder of a reference image. Local only.
import http from 'node:http';
import fs from 'node:fs';
import path from 'node:path';

const types = { '.html': 'text/html', '.js': 'text/javascript', '.mjs': 'text/javascript', '.json': 'application/json',
                '.gltf': 'model/gltf+json', '.glb': 'model/gltf-binary', '.bin': 'application/octet-stream',
                '.png': 'image/png', '.jpg': 'image/jpeg', '.jpeg': 'image/jpeg' };

export function serve(roots) {
  const server = http.createServer((req, res) => {
    const url = decodeURIComponent(new URL(req.url, 'http://localhost').pathname);
    const [, mount, ...rest] = url.split('/');
    const root = roots[mount];
    const file = root && path.resolve(root, rest.join('/'));
    if (!file || !file.startsWith(path.resolve(root)) || !fs.existsSync(file) || !fs.statSync(file).isFile()) {
      res.writeHead(404).end(`not found: ${url}`);
      return;
    }
    res.writeHead(200, { 'Content-Type': types[path.extname(file).toLowerCase()] ?? 'application/octet-stream' });
    fs.createReadStream(file).pipe(res);
  });
  return new Promise(resolve => server.listen(0, '127.0.0.1', () => resolve(server)));
}

// Headless Chromium with WebGL on SwiftShader (no GPU), one tab of width × height whose console and page errors
// are collected in `log`. puppeteer: the caller's puppeteer-core (it lives in the build's node_modules).
export async function openTab(puppeteer, { chromium, width, height }) {
  const browser = await puppeteer.launch({
    executablePath: chromium ?? '/usr/bin/chromium',
    headless: true,
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader', '--ignore-gpu-blocklist',
           '--force-color-profile=srgb', `--window-size=${width},${height}`],
  });
  const tab = await browser.newPage();
  const log = [];
  tab.on('console', m => log.push(`${m.type()}: ${m.text()}`));
  tab.on('pageerror', e => log.push(`pageerror: ${e.message}`));
  await tab.setViewport({ width, height, deviceScaleFactor: 1 });
  return { browser, tab, log };
}

// Run directly to look at a bake in a browser:
//   node runtime/web/serve.mjs --modules build/web --scene out/scene.gltf [--port 8080]
// then open the printed URL (camera 0; add &camera=N&width=W&height=H).
import { fileURLToPath } from 'node:url';
if (process.argv[1] && path.resolve(process.argv[1]) === fileURLToPath(import.meta.url)) {
  const args = Object.fromEntries(process.argv.slice(2).reduce((a, v, i, all) => (v.startsWith('--') ? [...a, [v.slice(2), all[i + 1]]] : a), []));
  if (!args.modules || !args.scene || !fs.existsSync(args.scene)) {
    console.error('usage: node serve.mjs --modules BUILD/web --scene SCENE.gltf|.glb [--port N]');
    process.exit(2);
  }
  const server = await serve({
    web: path.dirname(fileURLToPath(import.meta.url)),
    three: path.join(path.resolve(args.modules), 'node_modules', 'three'),
    scene: path.dirname(path.resolve(args.scene)),
  });
  if (args.port) { server.close(); server.listen(Number(args.port), '127.0.0.1'); await new Promise(r => server.once('listening', r)); }
  const port = server.address().port;
  console.log(`http://127.0.0.1:${port}/web/index.html?scene=/scene/${encodeURIComponent(path.basename(args.scene))}`);
}
