// Writes a small glTF for the directional-map web test: a 4 m × 4 m grey plane (ρ = 0.5) at y = 0,
// TEXCOORD_0 planar (u along +x, v along +z), a constant normal map tilted 35° from the normal towards
// +u and −v's opposite (the tangent-space normal has x and y components, so both the tangent and the
// bitangent's sign show), a point light of I candela 1 m above the centre (KHR_lights_punctual) and a camera
// looking down at the plane. Pure node (zlib for the PNG), no dependencies.
// With --tangent the primitive carries TANGENT = (+x, w = +1), the frame a client would generate (B = cross(N, T)·w = −z,
// where v decreases), so the given-tangent path shows the same image.
// With --mirror TEXCOORD_0's u is mirrored at x = 0 (u = 0.5 + |x|/4), the column of vertices there shared by both
// halves: generated tangents must split them (MikkTSpace) or that column's quads get a frame of neither half.
// Usage: node make_directional_scene.mjs OUT_DIR [--tangent | --mirror]   → OUT_DIR/plane.gltf, plane.bin, normal.png
import fs from 'node:fs';
import path from 'node:path';
import zlib from 'node:zlib';

const out = process.argv[2];
if (!out) { console.error('usage: node make_directional_scene.mjs OUT_DIR [--tangent | --mirror]'); process.exit(2); }
const withTangent = process.argv.includes('--tangent'), mirror = process.argv.includes('--mirror');
fs.mkdirSync(out, { recursive: true });

// Tangent-space normal (x towards +u, y towards −v, z out): 35° off the normal, 30° around it from +x.
const tilt = 35 * Math.PI / 180, around = 30 * Math.PI / 180;
export const tangentSpaceNormal = [Math.sin(tilt) * Math.cos(around), Math.sin(tilt) * Math.sin(around), Math.cos(tilt)];

const crcTable = Array.from({ length: 256 }, (_, n) => {
  let c = n;
  for (let k = 0; k < 8; ++k) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
  return c >>> 0;
});
function crc32(bytes) {
  let c = 0xffffffff;
  for (const b of bytes) c = crcTable[(c ^ b) & 0xff] ^ (c >>> 8);
  return (c ^ 0xffffffff) >>> 0;
}
function chunk(type, data) {
  const head = Buffer.alloc(8);
  head.writeUInt32BE(data.length, 0);
  head.write(type, 4, 'ascii');
  const crc = Buffer.alloc(4);
  crc.writeUInt32BE(crc32(Buffer.concat([head.subarray(4), data])), 0);
  return Buffer.concat([head, data, crc]);
}
// An 8-bit RGB PNG of one colour (codes 0..255).
function constantPng(size, rgb) {
  const ihdr = Buffer.alloc(13);
  ihdr.writeUInt32BE(size, 0);
  ihdr.writeUInt32BE(size, 4);
  ihdr.set([8, 2, 0, 0, 0], 8);  // bit depth 8, colour type RGB, deflate, filter 0, no interlace
  const row = Buffer.from([0, ...Array.from({ length: size }, () => rgb).flat()]);  // filter byte 0 + pixels
  const raw = Buffer.concat(Array.from({ length: size }, () => row));
  return Buffer.concat([Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a]), chunk('IHDR', ihdr),
                        chunk('IDAT', zlib.deflateSync(raw)), chunk('IEND', Buffer.alloc(0))]);
}

const codes = tangentSpaceNormal.map(c => Math.round((c * 0.5 + 0.5) * 255));
fs.writeFileSync(path.join(out, 'normal.png'), constantPng(4, codes));

// The plane as a 4 × 4 grid of quads (the light's falloff needs texels; the atlas is irbake's).
const cells = 4, half = 2;
const positions = [], normals = [], uvs = [], tangents = [], indices = [];
for (let j = 0; j <= cells; ++j)
  for (let i = 0; i <= cells; ++i) {
    const x = -half + 2 * half * i / cells, z = -half + 2 * half * j / cells;
    positions.push(x, 0, z);
    normals.push(0, 1, 0);
    tangents.push(1, 0, 0, 1);
    uvs.push(mirror ? 0.5 + Math.abs(x) / (2 * half) : (x + half) / (2 * half), (z + half) / (2 * half));
  }
for (let j = 0; j < cells; ++j)
  for (let i = 0; i < cells; ++i) {
    const a = j * (cells + 1) + i, b = a + 1, c = a + cells + 1, d = c + 1;
    indices.push(a, c, b, b, c, d);  // counter-clockwise seen from +y
  }
const bin = Buffer.concat([Buffer.from(new Float32Array(positions).buffer), Buffer.from(new Float32Array(normals).buffer),
                           Buffer.from(new Float32Array(uvs).buffer), Buffer.from(new Uint16Array(indices).buffer),
                           Buffer.from(new Float32Array(tangents).buffer)]);
fs.writeFileSync(path.join(out, 'plane.bin'), bin);
const n = positions.length / 3, f = 4 * 3 * n, t = 4 * 2 * n, ib = 2 * indices.length;
const gltf = {
  asset: { version: '2.0', generator: 'irbake runtime/web/make_directional_scene.mjs' },
  extensionsUsed: ['KHR_lights_punctual'],
  extensions: { KHR_lights_punctual: { lights: [{ type: 'point', intensity: 3, color: [1, 1, 1] }] } },
  scene: 0,
  scenes: [{ nodes: [0, 1, 2] }],
  nodes: [
    { mesh: 0 },
    { translation: [0, 1, 0], extensions: { KHR_lights_punctual: { light: 0 } } },
    // 2.6 m above and 1.2 m back (+z), looking at (0, 0, −0.2): rotation about +x by −atan2(2.6, 1.4).
    (() => {
      const angle = -Math.atan2(2.6, 1.4);
      return { camera: 0, translation: [0, 2.6, 1.2], rotation: [Math.sin(angle / 2), 0, 0, Math.cos(angle / 2)] };
    })(),
  ],
  cameras: [{ type: 'perspective', perspective: { yfov: 60 * Math.PI / 180, aspectRatio: 1, znear: 0.05, zfar: 50 } }],
  meshes: [{ primitives: [{ attributes: { POSITION: 0, NORMAL: 1, TEXCOORD_0: 2, ...(withTangent ? { TANGENT: 4 } : {}) }, indices: 3, material: 0 }] }],
  materials: [{ name: 'grey', pbrMetallicRoughness: { baseColorFactor: [0.5, 0.5, 0.5, 1], metallicFactor: 0, roughnessFactor: 1 },
                normalTexture: { index: 0 } }],
  textures: [{ source: 0, sampler: 0 }],
  images: [{ uri: 'normal.png' }],
  samplers: [{ magFilter: 9729, minFilter: 9729, wrapS: 33071, wrapT: 33071 }],
  buffers: [{ uri: 'plane.bin', byteLength: bin.length }],
  bufferViews: [
    { buffer: 0, byteOffset: 0, byteLength: f, target: 34962 },
    { buffer: 0, byteOffset: f, byteLength: f, target: 34962 },
    { buffer: 0, byteOffset: 2 * f, byteLength: t, target: 34962 },
    { buffer: 0, byteOffset: 2 * f + t, byteLength: ib, target: 34963 },
    { buffer: 0, byteOffset: 2 * f + t + ib, byteLength: 16 * n, target: 34962 },
  ],
  accessors: [
    { bufferView: 0, componentType: 5126, count: n, type: 'VEC3', min: [-half, 0, -half], max: [half, 0, half] },
    { bufferView: 1, componentType: 5126, count: n, type: 'VEC3' },
    { bufferView: 2, componentType: 5126, count: n, type: 'VEC2' },
    { bufferView: 3, componentType: 5123, count: indices.length, type: 'SCALAR' },
    { bufferView: 4, componentType: 5126, count: n, type: 'VEC4' },
  ],
};
fs.writeFileSync(path.join(out, 'plane.gltf'), JSON.stringify(gltf, null, 1));
console.log(`make_directional_scene: ${path.join(out, 'plane.gltf')} (normal map codes ${codes.join(', ')})`);
