// Compares a glTF input with dmc's GLB of it (encode, then decode): what the scene chunk must keep.
// Node names, material names, texture and image counts, the primitives that have TEXCOORD_0 and
// COLOR_0, the clips (names and durations within a frame) and asset.copyright.
// Usage: node compare_scene.mjs ORIGINAL.glb DECODED.glb FPS    (exits 1 on a difference)
import { readFileSync } from 'node:fs';

function json(path) {
  const bytes = readFileSync(path);
  const length = bytes.readUInt32LE(12);
  return JSON.parse(bytes.subarray(20, 20 + length).toString('utf8'));
}
const [originalPath, decodedPath, fps] = process.argv.slice(2);
const original = json(originalPath), decoded = json(decodedPath);
let failed = false;
function same(what, a, b) {
  const equal = JSON.stringify(a) === JSON.stringify(b);
  console.log(`${equal ? 'ok' : 'DIFFERS'}: ${what}${equal ? '' : `: ${JSON.stringify(a)} vs ${JSON.stringify(b)}`}`);
  if (!equal) failed = true;
}
const names = (list) => [...new Set((list ?? []).map((x) => x.name ?? ''))].sort();
const withAttribute = (doc, name) => (doc.meshes ?? []).flatMap((m) => m.primitives)
  .filter((p) => name in p.attributes && p.mode !== 0 && p.mode !== 1 && p.mode !== 3).length;
// The duration of an animation: the span of its samplers' inputs (accessor min/max).
const durations = (doc) => (doc.animations ?? []).map((a) => {
  const times = a.samplers.map((s) => doc.accessors[s.input]);
  const start = Math.min(...times.map((t) => t.min[0])), end = Math.max(...times.map((t) => t.max[0]));
  return { name: a.name ?? '', duration: end - start };
});

same('node names', names(original.nodes), names(decoded.nodes).filter((n) => names(original.nodes).includes(n)));
same('material names', names(original.materials), names(decoded.materials));
same('textures', (original.textures ?? []).length, (decoded.textures ?? []).length);
same('images', (original.images ?? []).length, (decoded.images ?? []).length);
// Samplers with the spec's defaults written out (wrapS, wrapT: 10497 REPEAT) are the same.
const samplers = (doc) => (doc.samplers ?? []).map((x) => ({ wrapS: 10497, wrapT: 10497, ...x }));
same('samplers', samplers(original), samplers(decoded));
same('primitives with TEXCOORD_0', withAttribute(original, 'TEXCOORD_0'), withAttribute(decoded, 'TEXCOORD_0'));
same('primitives with COLOR_0', withAttribute(original, 'COLOR_0'), withAttribute(decoded, 'COLOR_0'));
same('asset.copyright', original.asset.copyright ?? null, decoded.asset.copyright ?? null);
const a = durations(original), b = durations(decoded);
same('clip names', a.map((c) => c.name), b.map((c) => c.name));
for (let i = 0; i < Math.min(a.length, b.length); ++i) {
  // The decoded clip ends at its last whole frame: up to one frame period short.
  const close = a[i].duration - b[i].duration >= -1e-4 && a[i].duration - b[i].duration <= 1 / fps + 1e-4;
  console.log(`${close ? 'ok' : 'DIFFERS'}: clip '${a[i].name}' lasts ${b[i].duration.toFixed(4)} s (input ${a[i].duration.toFixed(4)} s)`);
  if (!close) failed = true;
}
process.exit(failed ? 1 : 0);
