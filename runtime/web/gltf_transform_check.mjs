// Checks for gltf_transform_irbake.mjs (run by web_pipeline_test.sh):
//   survives --modules DIR --input BAKE.gltf --output OPT.glb [--directional] [--probes]
//     every material of the bake that has MOZ_lightmap (and IRBAKE_lightmap_directional) has it in the output
//     with the same numbers and texCoord 1 on an existing texture; every light-mapped primitive has TEXCOORD_1
//     with POSITION's vertex count; the light-mapped triangles are as many as in the bake; with --probes,
//     IRBAKE_light_probes keeps its fields and every accessor value (its sun level's and exact emitters' included).
//   refusals --modules DIR --input BAKE.gltf   (a --directional bake)
//     read → write keeps both extensions' JSON exactly (and IRBAKE_light_probes' fields); bad input (missing texture, texCoord ≠ 1, negative or
//     non-numeric intensity or one not finite as a 32-bit float, incomplete directional extension, a probe grid or sun level that
//     does not fit its accessors or whose spacing or origin is not finite, or the spacing 0, as 32-bit floats; a grid no
//     bake writes: a spacing of 0.005 or 2e9 m, an origin of 2e9 m, a far corner beyond 1e9 m, a probe moved 2 spacings,
//     with irview's message) and bad output (no TEXCOORD_1, fewer triangles) throw an Error naming the material, mesh or
//     field; a probe moved exactly one spacing (the limit) reads.
//   shadowmask --modules DIR --input BAKE.gltf   (a bake with --light-mode ...=shadowmask)
//     prune + dedup keep every IRBAKE_shadowmask (texCoord 1 on a texture with an image, its exr) and the root's
//     light → channel map exactly; a missing texture, texCoord ≠ 1, a channel outside 0..3 and a material mask
//     without the root map are refused with an Error naming the material.
//   scenarios --modules DIR --input BAKE.gltf --output OPT.glb   (a bake with --light-group)
//     IRBAKE_lightmap_scenarios survives optimize: the same layers (names, lights, intensities, EXR names, sun
//     irradiance), scenarios and default; its pages are the materials' MOZ_lightmap textures and each layer's textures
//     the same images as in the bake; its probe and sun SH accessors' values bit for bit; a layer texture the file lacks
//     and a negative intensity are refused naming the field.
// Exit 0 when every check passes, 1 with the failures listed.
import fs from 'node:fs';
import path from 'node:path';
import { countLightmappedTriangles, defineIrbakeExtensions, importPackage, IRBAKE_LIGHT_PROBES, IRBAKE_LIGHTMAP_DIRECTIONAL,
  EMITTER_ACCESSORS, IRBAKE_LIGHTMAP_SCENARIOS, IRBAKE_SHADOWMASK, MOZ_LIGHTMAP, PROBE_ACCESSORS, probeFields, SUN_ACCESSORS }
  from './gltf_transform_irbake.mjs';

const [mode, ...rest] = process.argv.slice(2);
// --name value, or --name alone (a flag: true).
const args = Object.fromEntries(rest.reduce((a, v, i, all) =>
  (v.startsWith('--') ? [...a, [v.slice(2), all[i + 1] === undefined || all[i + 1].startsWith('--') ? true : all[i + 1]]] : a), []));
if (!['survives', 'refusals', 'shadowmask', 'scenarios'].includes(mode) || !args.modules || !args.input) {
  console.error('usage: gltf_transform_check.mjs survives|refusals|shadowmask|scenarios --modules DIR --input FILE [--output FILE] [--directional]');
  process.exit(2);
}
const modules = path.resolve(args.modules);
const core = await importPackage(modules, '@gltf-transform/core');
const { ALL_EXTENSIONS } = await importPackage(modules, '@gltf-transform/extensions');
const functions = await importPackage(modules, '@gltf-transform/functions');
const { MeshoptDecoder } = await importPackage(modules, 'meshoptimizer');
await MeshoptDecoder.ready;
const { MozLightmap, IrbakeLightmapDirectional, IrbakeShadowmask, IrbakeLightProbes, IrbakeLightmapScenarios } = defineIrbakeExtensions(core);
const io = new core.NodeIO().registerExtensions([...ALL_EXTENSIONS, MozLightmap, IrbakeLightmapDirectional, IrbakeShadowmask, IrbakeLightProbes,
                                                 IrbakeLightmapScenarios])
  .registerDependencies({ 'meshopt.decoder': MeshoptDecoder });
io.setLogger(new core.Logger(core.Logger.Verbosity.ERROR));

const failures = [];
const check = (ok, message) => { if (!ok) failures.push(message); };
// Equal JSON values, whatever the order of object keys.
const canonical = v => (Array.isArray(v) ? v.map(canonical) : v !== null && typeof v === 'object'
  ? Object.fromEntries(Object.keys(v).sort().map(k => [k, canonical(v[k])])) : v);
const same = (a, b) => JSON.stringify(canonical(a)) === JSON.stringify(canonical(b));

// The JSON of a .gltf or .glb.
function jsonOf(file) {
  const bytes = fs.readFileSync(file);
  if (bytes.readUInt32LE(0) !== 0x46546c67) return JSON.parse(bytes.toString('utf8'));
  return JSON.parse(bytes.subarray(20, 20 + bytes.readUInt32LE(12)).toString('utf8'));
}

// A texture info that names an existing texture with an image (core or EXT_texture_webp / KHR_texture_basisu).
function hasImage(json, info) {
  const t = json.textures?.[info?.index];
  const source = t?.source ?? Object.values(t?.extensions ?? {}).find(e => Number.isInteger(e?.source))?.source;
  return t !== undefined && json.images?.[source] !== undefined;
}

function survives() {
  const input = jsonOf(args.input), output = jsonOf(args.output);
  const byName = new Map((output.materials ?? []).map(m => [m.name, m]));
  let materials = 0, directional = 0, primitives = 0;
  for (const inMat of input.materials ?? []) {
    const inMoz = inMat.extensions?.[MOZ_LIGHTMAP];
    if (!inMoz) continue;
    ++materials;
    const outMat = byName.get(inMat.name), outMoz = outMat?.extensions?.[MOZ_LIGHTMAP];
    check(outMoz, `material '${inMat.name}': ${MOZ_LIGHTMAP} lost`);
    if (!outMoz) continue;
    check(outMoz.texCoord === 1, `material '${inMat.name}': texCoord ${outMoz.texCoord}`);
    check(outMoz.intensity === inMoz.intensity, `material '${inMat.name}': intensity ${outMoz.intensity}, bake ${inMoz.intensity}`);
    check(same(outMoz.extras, inMoz.extras), `material '${inMat.name}': extras ${JSON.stringify(outMoz.extras)}`);
    check(hasImage(output, outMoz), `material '${inMat.name}': light-map texture ${outMoz.index} has no image`);
    if (args.directional) {
      const inDir = inMat.extensions[IRBAKE_LIGHTMAP_DIRECTIONAL], outDir = outMat.extensions[IRBAKE_LIGHTMAP_DIRECTIONAL];
      check(inDir, `material '${inMat.name}': the bake has no ${IRBAKE_LIGHTMAP_DIRECTIONAL}`);
      check(outDir, `material '${inMat.name}': ${IRBAKE_LIGHTMAP_DIRECTIONAL} lost`);
      if (!inDir || !outDir) continue;
      ++directional;
      check(same(outDir.exr, inDir.exr), `material '${inMat.name}': exr ${JSON.stringify(outDir.exr)}`);
      check(outDir.l1?.length === 3, `material '${inMat.name}': l1 has ${outDir.l1?.length} entries`);
      (outDir.l1 ?? []).forEach((e, k) => {
        check(e.texCoord === 1 && e.scale === inDir.l1[k].scale, `material '${inMat.name}': l1[${k}] ${JSON.stringify(e)}`);
        check(hasImage(output, e), `material '${inMat.name}': l1[${k}] texture ${e.index} has no image`);
      });
    }
  }
  check(materials > 0, `${args.input}: no material with ${MOZ_LIGHTMAP}`);
  (output.meshes ?? []).forEach((mesh, m) => mesh.primitives.forEach((prim, p) => {
    if (!output.materials?.[prim.material]?.extensions?.[MOZ_LIGHTMAP]) return;
    ++primitives;
    const uv = output.accessors[prim.attributes.TEXCOORD_1], position = output.accessors[prim.attributes.POSITION];
    check(uv, `mesh ${m} ('${mesh.name}') primitive ${p}: TEXCOORD_1 lost`);
    check(!uv || uv.count === position.count, `mesh ${m} primitive ${p}: TEXCOORD_1 count ${uv?.count}, POSITION ${position.count}`);
  }));
  return Promise.all([io.read(args.input), io.read(args.output)]).then(([a, b]) => {
    const total = d => [...countLightmappedTriangles(d).values()].reduce((x, y) => x + y, 0);
    const before = total(a), after = total(b);
    check(before === after && before > 0, `light-mapped triangles ${before} → ${after}`);
    const probes = args.probes ? probesSurvive(a, b, input, output) : 0;
    console.log(JSON.stringify({ output: args.output, materials, directional, primitives, triangles: after, probes }));
  });
}

// IRBAKE_light_probes: the same grid fields in the output's JSON, and its accessors' values (as glTF-Transform
// decodes them, meshopt or not) equal to the bake's, bit for bit. Returns the probe count.
function probesSurvive(inDoc, outDoc, inJson, outJson) {
  const inDef = inJson.extensions?.[IRBAKE_LIGHT_PROBES], outDef = outJson.extensions?.[IRBAKE_LIGHT_PROBES];
  check(inDef, `${args.input}: no ${IRBAKE_LIGHT_PROBES}`);
  check(outDef, `${args.output}: ${IRBAKE_LIGHT_PROBES} lost`);
  check((outJson.extensionsUsed ?? []).includes(IRBAKE_LIGHT_PROBES), `${args.output}: ${IRBAKE_LIGHT_PROBES} not in extensionsUsed`);
  check(!(outJson.extensionsRequired ?? []).includes(IRBAKE_LIGHT_PROBES), `${args.output}: ${IRBAKE_LIGHT_PROBES} required`);
  if (!inDef || !outDef) return 0;
  check(same(probeFields(inDef), probeFields(outDef)), `${IRBAKE_LIGHT_PROBES}: fields ${JSON.stringify(probeFields(outDef))}`);
  const gridA = inDoc.getRoot().getExtension(IRBAKE_LIGHT_PROBES), gridB = outDoc.getRoot().getExtension(IRBAKE_LIGHT_PROBES);
  const keys = [...Object.keys(PROBE_ACCESSORS),
                ...(inDef.sun ? Object.keys(SUN_ACCESSORS).filter(k => k in inDef.sun).map(k => `sun_${k}`) : []),
                ...(inDef.emitters ?? []).flatMap((_, i) => Object.keys(EMITTER_ACCESSORS).map(k => `emitters_${i}_${k}`))];
  for (const key of keys) {
    const a = gridA?.getAccessor(key)?.getArray(), b = gridB?.getAccessor(key)?.getArray();
    check(a && b && a.length === b.length && a.every((v, i) => Object.is(v, b[i])),
          `${IRBAKE_LIGHT_PROBES}.${key}: ${a?.length} values in, ${b?.length} out${a && b && a.length === b.length ? ', some differ' : ''}`);
  }
  return inDef.counts.reduce((x, y) => x * y, 1);
}

// Runs fn and requires an Error whose message has every one of the texts.
let refused = 0;
async function throws(label, fn, ...texts) {
  ++refused;
  try {
    await fn();
    failures.push(`${label}: accepted`);
  } catch (e) {
    const missing = texts.filter(t => !String(e.message).includes(t));
    check(missing.length === 0, `${label}: error "${e.message}" lacks ${JSON.stringify(missing)}`);
  }
}

async function refusals() {
  const original = await io.readAsJSON(args.input);
  const clone = () => ({ json: structuredClone(original.json), resources: original.resources });
  // The extensions of each material with texture indices replaced by image URIs: index-free comparison.
  const normalised = json => (json.materials ?? []).map(m => {
    const ext = structuredClone({ moz: m.extensions?.[MOZ_LIGHTMAP], dir: m.extensions?.[IRBAKE_LIGHTMAP_DIRECTIONAL] });
    for (const info of [ext.moz, ...(ext.dir?.l1 ?? [])].filter(Boolean)) info.index = json.images[json.textures[info.index].source].uri;
    return ext;
  });
  const written = await io.writeJSON(await io.readJSON(clone()));
  check(original.json.materials.some(m => m.extensions?.[IRBAKE_LIGHTMAP_DIRECTIONAL]), `${args.input}: not a --directional bake`);
  check(same(normalised(written.json), normalised(original.json)),
        `read → write changed the extensions:\n  ${JSON.stringify(canonical(normalised(written.json)))}\n  ` +
        JSON.stringify(canonical(normalised(original.json))));

  // Bad input: material 0 with one field changed.
  const name = original.json.materials[0].name;
  const label = `material 0 ('${name}')`;
  const bad = (mutate) => () => { const doc = clone(); mutate(doc.json.materials[0].extensions); return io.readJSON(doc); };
  await throws('missing texture', bad(e => { e[MOZ_LIGHTMAP].index = 99; }), label, 'texture 99 does not exist');
  await throws('no texture index', bad(e => { delete e[MOZ_LIGHTMAP].index; }), label, 'no texture index');
  await throws('texCoord 0', bad(e => { e[MOZ_LIGHTMAP].texCoord = 0; }), label, 'texCoord 0');
  await throws('texCoord 2', bad(e => { e[MOZ_LIGHTMAP].texCoord = 2; }), label, 'texCoord 2');
  await throws('negative intensity', bad(e => { e[MOZ_LIGHTMAP].intensity = -1; }), label, 'intensity -1');
  await throws('NaN intensity', bad(e => { e[MOZ_LIGHTMAP].intensity = 'NaN'; }), label, 'intensity "NaN"');
  await throws('null intensity', bad(e => { e[MOZ_LIGHTMAP].intensity = null; }), label, 'intensity null');
  await throws('float-overflow intensity', bad(e => { e[MOZ_LIGHTMAP].intensity = 1e39; }), label, 'intensity 1e+39');
  await throws('two L1 pages', bad(e => { e[IRBAKE_LIGHTMAP_DIRECTIONAL].l1.pop(); }), label, 'l1 needs 3 entries');
  await throws('L1 texCoord 0', bad(e => { e[IRBAKE_LIGHTMAP_DIRECTIONAL].l1[2].texCoord = 0; }), label, 'l1[2]', 'texCoord 0');
  await throws('L1 missing texture', bad(e => { e[IRBAKE_LIGHTMAP_DIRECTIONAL].l1[1].index = 42; }), label, 'texture 42 does not exist');
  await throws('L1 negative scale', bad(e => { e[IRBAKE_LIGHTMAP_DIRECTIONAL].l1[0].scale = -2; }), label, 'scale -2');

  // IRBAKE_light_probes: read → write keeps its fields; a grid that does not fit its accessors is refused.
  if (original.json.extensions?.[IRBAKE_LIGHT_PROBES]) {
    const fields = probeFields;
    check(same(fields(written.json.extensions[IRBAKE_LIGHT_PROBES]), fields(original.json.extensions[IRBAKE_LIGHT_PROBES])),
          `read → write changed ${IRBAKE_LIGHT_PROBES}`);
    const badGrid = mutate => () => { const doc = clone(); mutate(doc.json.extensions[IRBAKE_LIGHT_PROBES]); return io.readJSON(doc); };
    await throws('probe counts', badGrid(e => { e.counts[0] += 1; }), `${IRBAKE_LIGHT_PROBES}.coefficients`, 'the grid needs');
    await throws('probe spacing', badGrid(e => { e.spacing = -1; }), `${IRBAKE_LIGHT_PROBES}.spacing -1`);
    await throws('probe spacing 0 as a float', badGrid(e => { e.spacing = 1e-50; }), `${IRBAKE_LIGHT_PROBES}.spacing 1e-50`);
    await throws('probe spacing Infinity as a float', badGrid(e => { e.spacing = 1e39; }), `${IRBAKE_LIGHT_PROBES}.spacing 1e+39`);
    await throws('probe origin Infinity as a float', badGrid(e => { e.origin[1] = 1e39; }), `${IRBAKE_LIGHT_PROBES}.origin`);
    await throws('probe accessor', badGrid(e => { e.valid = 9999; }), `${IRBAKE_LIGHT_PROBES}.valid`, 'does not exist');
    await throws('probe counts type', badGrid(e => { e.counts = [2, 2]; }), `${IRBAKE_LIGHT_PROBES}.counts`);
    // A grid no bake writes, with irview's message (probe_grid_rules.js).
    const outside = 'm is outside the 0.01 … 1e9 m a bake writes';
    await throws('probe spacing below a bake\'s', badGrid(e => { e.spacing = 0.005; }), `${IRBAKE_LIGHT_PROBES}.spacing: 0.005 ${outside}`);
    await throws('probe spacing above a bake\'s', badGrid(e => { e.spacing = 2e9; }), `${IRBAKE_LIGHT_PROBES}.spacing: 2e+09 ${outside}`);
    await throws('probe origin beyond 1e9 m', badGrid(e => { e.origin[1] = 2e9; }),
                 `${IRBAKE_LIGHT_PROBES}.origin: 2e+09 m is beyond the supported 1e9 m`);
    const grid = original.json.extensions[IRBAKE_LIGHT_PROBES], axis = grid.counts.findIndex(c => c >= 3);
    check(axis >= 0 && grid.counts[axis] <= 90, `${args.input}: needs a probe axis of 3 to 90 probes (counts ${grid.counts})`);
    // On the first axis of 3 or more probes, 9e8 + 1e8 × (counts − 1) ≥ 1.1e9 m, exact as floats.
    const far = 9e8 + 1e8 * (grid.counts[axis] - 1);
    await throws('probe far corner beyond 1e9 m', badGrid(e => { e.origin[axis] = 9e8; e.spacing = 1e8; }),
                 `${IRBAKE_LIGHT_PROBES}.counts: the grid reaches ${Number((far / 1e9).toPrecision(3))}e+09 m, beyond the supported 1e9 m`);
    // The middle probe's x offset set to `spacings` spacings, in a copy of its buffer.
    const probe = Math.floor(grid.counts.reduce((x, y) => x * y, 1) / 2);
    const moved = spacings => Math.fround(spacings * Math.fround(grid.spacing));
    const movedProbe = spacings => () => {
      const doc = clone(), accessor = doc.json.accessors[grid.offsets], view = doc.json.bufferViews[accessor.bufferView];
      const uri = doc.json.buffers[view.buffer].uri, bytes = original.resources[uri].slice();
      new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength)
        .setFloat32((view.byteOffset ?? 0) + (accessor.byteOffset ?? 0) + 12 * probe, moved(spacings), true);
      doc.resources = { ...original.resources, [uri]: bytes };
      return io.readJSON(doc);
    };
    await throws('probe moved 2 spacings', movedProbe(2),
                 `${IRBAKE_LIGHT_PROBES}.offsets: probe ${probe} is moved ${Number(moved(2).toPrecision(3))} m from its grid point, more than a spacing`);
    try {
      await movedProbe(1)();
    } catch (e) {
      failures.push(`probe moved 1 spacing (the limit): refused: ${e.message}`);
    }
    if (original.json.extensions[IRBAKE_LIGHT_PROBES].sun?.cells !== undefined) {
      await throws('sun fine', badGrid(e => { e.sun.fine = e.sun.cells; }), `${IRBAKE_LIGHT_PROBES}.sun.fine`, 'the grid needs');
      await throws('sun subdivisions', badGrid(e => { e.sun.subdivisions = 0; }), `${IRBAKE_LIGHT_PROBES}.sun.subdivisions`);
    }
    if (original.json.extensions[IRBAKE_LIGHT_PROBES].emitters) {
      await throws('emitter visibility', badGrid(e => { e.emitters[0].visibility = e.valid; }),
                   `${IRBAKE_LIGHT_PROBES}.emitters[0].visibility`, 'the grid needs');
      await throws('emitter radiance', badGrid(e => { e.emitters[0].radiance = [1, null, 1]; }), `${IRBAKE_LIGHT_PROBES}.emitters[0].radiance`);
    }
  } else {
    failures.push(`${args.input}: no ${IRBAKE_LIGHT_PROBES} (baked with --probes off?)`);
  }

  // Bad output: a light-mapped primitive without TEXCOORD_1; one triangle fewer (what simplification does).
  const lightmapped = doc => doc.getRoot().listMeshes().flatMap(m => m.listPrimitives().map(p => [m, p]))
    .find(([, p]) => p.getMaterial()?.getExtension(MOZ_LIGHTMAP) && p.getIndices());
  {
    const doc = await io.readJSON(clone());
    const [mesh, prim] = lightmapped(doc);
    prim.setAttribute('TEXCOORD_1', null);
    await throws('no TEXCOORD_1', () => io.writeJSON(doc), `('${mesh.getName()}')`, `('${prim.getMaterial().getName()}')`,
                 'needs TEXCOORD_1');
  }
  {
    const doc = await io.readJSON(clone());
    const [, prim] = lightmapped(doc);
    const indices = prim.getIndices();
    indices.setArray(indices.getArray().slice(0, indices.getCount() - 3));
    await throws('one triangle fewer', () => io.writeJSON(doc), `material '${prim.getMaterial().getName()}'`, 'simplified');
  }
  {
    const doc = await io.readJSON(clone());
    const lightmap = doc.getRoot().listMaterials()[0].getExtension(MOZ_LIGHTMAP);
    await throws('setIntensity(NaN)', () => lightmap.setIntensity(NaN), 'intensity null');
  }
  // prune moves a material's only UV set to TEXCOORD_0; the written file has the light map on TEXCOORD_1 again.
  {
    const doc = await io.readJSON(clone());
    await doc.transform(functions.prune());
    const shifted = doc.getRoot().listMaterials().filter(m => m.getExtension(MOZ_LIGHTMAP)?.getTextureInfo().getTexCoord() === 0);
    const json = (await io.writeJSON(doc)).json;
    const bad = json.meshes.flatMap(m => m.primitives).filter(p => json.materials[p.material].extensions?.[MOZ_LIGHTMAP] &&
      (p.attributes.TEXCOORD_1 === undefined || json.materials[p.material].extensions[MOZ_LIGHTMAP].texCoord !== 1));
    check(bad.length === 0, `after prune: ${bad.length} light-mapped primitives without the map on TEXCOORD_1`);
    console.log(JSON.stringify({ roundTrip: 'exact', refusalsChecked: refused, pruneShiftedMaterials: shifted.length }));
  }
}

async function shadowmask() {
  const original = await io.readAsJSON(args.input);
  const clone = () => ({ json: structuredClone(original.json), resources: original.resources });
  const masked = (original.json.materials ?? []).filter(m => m.extensions?.[IRBAKE_SHADOWMASK]);
  check(masked.length > 0 && original.json.extensions?.[IRBAKE_SHADOWMASK], `${args.input}: no ${IRBAKE_SHADOWMASK}`);
  const doc = await io.readJSON(clone());
  await doc.transform(functions.prune(), functions.dedup());
  const json = (await io.writeJSON(doc)).json;
  check(same(json.extensions?.[IRBAKE_SHADOWMASK], original.json.extensions[IRBAKE_SHADOWMASK]),
        `root ${IRBAKE_SHADOWMASK}: ${JSON.stringify(json.extensions?.[IRBAKE_SHADOWMASK])}`);
  const byName = new Map((json.materials ?? []).map(m => [m.name, m]));
  for (const inMat of masked) {
    const a = inMat.extensions[IRBAKE_SHADOWMASK], b = byName.get(inMat.name)?.extensions?.[IRBAKE_SHADOWMASK];
    check(b && b.texCoord === 1 && b.exr === a.exr && hasImage(json, b), `material '${inMat.name}': mask ${JSON.stringify(b)}`);
    const image = b && json.images[json.textures[b.index].source];
    check(!b || image.name === original.json.images[original.json.textures[a.index].source].name,
          `material '${inMat.name}': the mask's texture is now image '${image?.name}'`);
  }
  const name = masked[0].name;
  const edited = edit => { const c = clone(); edit(c.json); return () => io.readJSON(c); };
  const firstMask = j => j.materials.find(m => m.name === name).extensions[IRBAKE_SHADOWMASK];
  await throws('mask texture 999', edited(j => { firstMask(j).index = 999; }), `('${name}')`, 'texture 999 does not exist');
  await throws('mask texCoord 0', edited(j => { firstMask(j).texCoord = 0; }), `('${name}')`, 'texCoord 0');
  await throws('channel 5', edited(j => { j.extensions[IRBAKE_SHADOWMASK].lights[0].channel = 5; }), 'channel 0..3');
  await throws('no root map', edited(j => { delete j.extensions[IRBAKE_SHADOWMASK]; }), `('${name}')`, 'without the root');
  console.log(JSON.stringify({ maskedMaterials: masked.length, refusalsChecked: refused }));
}

async function scenarios() {
  const input = jsonOf(args.input), output = jsonOf(args.output);
  const a = input.extensions?.[IRBAKE_LIGHTMAP_SCENARIOS], b = output.extensions?.[IRBAKE_LIGHTMAP_SCENARIOS];
  check(a, `${args.input}: no ${IRBAKE_LIGHTMAP_SCENARIOS}`);
  check(b, `${args.output}: ${IRBAKE_LIGHTMAP_SCENARIOS} lost`);
  check((output.extensionsUsed ?? []).includes(IRBAKE_LIGHTMAP_SCENARIOS) && !(output.extensionsRequired ?? []).includes(IRBAKE_LIGHTMAP_SCENARIOS),
        `${args.output}: ${IRBAKE_LIGHTMAP_SCENARIOS} not (only) in extensionsUsed`);
  if (!a || !b) return;
  // Everything but texture and accessor indices.
  const fields = d => ({ ...d, pages: d.pages.length,
                         layers: d.layers.map(l => ({ ...l, textures: l.textures.length, probes: l.probes !== undefined,
                                                       sun: l.sun && { ...l.sun, sh: l.sun.sh !== undefined } })) });
  check(same(fields(a), fields(b)), `${IRBAKE_LIGHTMAP_SCENARIOS}: fields ${JSON.stringify(fields(b))}`);
  const mozTextures = new Set((output.materials ?? []).map(m => m.extensions?.[MOZ_LIGHTMAP]?.index).filter(i => i !== undefined));
  check([...mozTextures].every(t => b.pages.includes(t)), `pages ${JSON.stringify(b.pages)}, MOZ_lightmap textures ${JSON.stringify([...mozTextures])}`);
  const imageName = (json, t) => json.images?.[json.textures?.[t]?.source ?? Object.values(json.textures?.[t]?.extensions ?? {})[0]?.source]?.name;
  // The same image as in the bake, or one dedup merged it with (the same bytes in the bake: a layer without light
  // in view can equal another's PNG).
  const inBytes = name => { const i = input.images.find(x => x.name === name); return i?.uri && fs.readFileSync(path.join(path.dirname(args.input), i.uri)); };
  a.layers.forEach((layer, l) => layer.textures.forEach((t, p) => {
    const info = { index: b.layers[l]?.textures?.[p] }, was = imageName(input, t), now = imageName(output, info.index);
    check(hasImage(output, info) && (now === was || (inBytes(now) && inBytes(was)?.equals(inBytes(now)))),
          `layer '${layer.name}' page ${p}: texture ${info.index} is image '${now}', the bake's '${was}'`);
  }));
  const [docA, docB] = await Promise.all([io.read(args.input), io.read(args.output)]);
  const extA = docA.getRoot().getExtension(IRBAKE_LIGHTMAP_SCENARIOS), extB = docB.getRoot().getExtension(IRBAKE_LIGHTMAP_SCENARIOS);
  let accessors = 0;
  for (const key of a.layers.flatMap((l, i) => [l.probes !== undefined && `layer_${i}_probes`, l.sun && `layer_${i}_sun_sh`]).filter(Boolean)) {
    const x = extA.getAccessor(key)?.getArray(), y = extB.getAccessor(key)?.getArray();
    check(x && y && x.length === y.length && x.every((v, i) => Object.is(v, y[i])), `${IRBAKE_LIGHTMAP_SCENARIOS} ${key}: values differ`);
    ++accessors;
  }
  const original = await io.readAsJSON(args.input);
  const edited = edit => () => { const c = { json: structuredClone(original.json), resources: original.resources }; edit(c.json); return io.readJSON(c); };
  await throws('layer texture 999', edited(j => { j.extensions[IRBAKE_LIGHTMAP_SCENARIOS].layers[0].textures[0] = 999; }),
               `${IRBAKE_LIGHTMAP_SCENARIOS}.layers[0].textures[0]`, 'texture 999 does not exist');
  await throws('layer intensity -1', edited(j => { j.extensions[IRBAKE_LIGHTMAP_SCENARIOS].layers[0].intensity[0] = -1; }),
               `${IRBAKE_LIGHTMAP_SCENARIOS}.layers[0]`, 'intensity -1');
  console.log(JSON.stringify({ output: args.output, layers: b.layers.length, pages: b.pages.length, accessors, refusalsChecked: refused }));
}

await (mode === 'survives' ? survives() : mode === 'refusals' ? refusals() : mode === 'scenarios' ? scenarios() : shadowmask());
if (failures.length) {
  console.error(`gltf_transform_check ${mode}:\n  ${failures.join('\n  ')}`);
  process.exit(1);
}
