// Runs the WebAssembly decoder over every conformance vector (conformance/README.md):
//  - valid: the manifest's counts and segment layout, and every coordinate within the spec's
//    tolerance (§12.3) of the reference positions; reports how many frames are bit-exact;
//  - invalid: a DmcError with the manifest's error code;
//  - damaged copies of valid streams (every truncation of the smallest ones, single-byte flips of
//    every stream): a DmcError or a decode, never another exception (a trap) or a hang.
// Usage: node conformance.mjs PACKAGE_DIR VECTORS_DIR     (exit 1 on any failure)
import { execFileSync } from 'node:child_process';
import { readFileSync, readdirSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const [packageDir, vectorsDir] = process.argv.slice(2).map((p) => resolve(p));
const { createDecoder, DmcError } = await import(pathToFileURL(join(packageDir, 'dmc.js')).href);
let decoder = await createDecoder();
// Conformance is defined without a caller's limit (conformance/kit/vector_kit.h).
const noLimit = { maxOutputBytes: 0 };
let failures = 0;
const fail = (what) => { ++failures; console.log(`FAILED: ${what}`); };
const manifests = (kind) => readdirSync(join(vectorsDir, kind)).filter((f) => f.endsWith('.json')).sort()
  .map((f) => ({ name: f.replace(/\.json$/, ''), ...JSON.parse(readFileSync(join(vectorsDir, kind, f), 'utf8')) }));

// A decode that must either work or fail with a DmcError from the decoder itself; a trap (which
// dmc.js reports as "resource-limit" and remembers in decoder.trapped) or any other exception is a
// failure, and the module is rebuilt after it.
async function decodeOrError(bytes) {
  try {
    decoder.decode(bytes, noLimit);
    return 'ok';
  } catch (error) {
    if (error instanceof DmcError && !decoder.trapped) return error.code;
    const what = decoder.trapped ?? error;
    decoder = await createDecoder();
    return `trap: ${what}`;
  }
}

let validCount = 0, frames = 0, exactFrames = 0, worstRatio = 0;
const valid = manifests('valid');
for (const m of valid) {
  const bytes = readFileSync(join(vectorsDir, 'valid', m.stream));
  let clip;
  try {
    clip = decoder.decode(bytes, noLimit);
  } catch (error) {
    fail(`${m.name}: ${error}`);
    continue;
  }
  const layout = clip.segments.map((s) => [s.firstFrame, s.frameCount, s.rank]);
  const expected = m.segments.map((s) => [s.first_frame, s.frame_count, s.rank]);
  if (clip.vertexCount !== m.vertex_count || clip.indices.length !== 3 * m.triangle_count ||
      clip.frameCount !== m.frame_count || JSON.stringify(layout) !== JSON.stringify(expected)) {
    fail(`${m.name}: counts or segments differ`);
    continue;
  }
  const reference = execFileSync('zstd', ['-dc', join(vectorsDir, 'valid', m.positions.file)],
                                 { maxBuffer: 1 << 30 });
  const r = new Float32Array(reference.buffer, reference.byteOffset, reference.length / 4);
  const size = 3 * clip.vertexCount;
  let within = true;
  for (let f = 0; f < clip.frameCount; ++f) {
    const x = clip.positions(f);
    let exact = true;
    for (let i = 0; i < size; ++i) {
      const ref = r[f * size + i];
      const error = Math.abs(x[i] - ref);
      const tolerance = 2 ** -20 * m.positions.diagonal + 2 ** -22 * Math.abs(ref);
      worstRatio = Math.max(worstRatio, error / tolerance);
      if (!(error <= tolerance)) within = false;
      if (x[i] !== ref) exact = false;
    }
    ++frames;
    if (exact) ++exactFrames;
  }
  if (!within) fail(`${m.name}: a coordinate beyond the tolerance`);
  else ++validCount;
  // Segment by segment, the same frames.
  let same = true;
  for (const s of decoder.segments(bytes, noLimit)) {
    const whole = new Float32Array(s.positions.length);
    for (let k = 0; k < s.frameCount; ++k) whole.set(clip.positions(s.firstFrame + k), k * size);
    if (s.positions.some((v, i) => v !== whole[i])) same = false;
  }
  if (!same) fail(`${m.name}: segment-by-segment decoding differs`);
}
console.log(`valid: ${validCount}/${valid.length} within the tolerance; ${exactFrames}/${frames} ` +
            `frames bit-exact; largest error ${worstRatio.toFixed(3)} of the tolerance`);

let invalidCount = 0;
const invalid = manifests('invalid');
for (const m of invalid) {
  const code = await decodeOrError(readFileSync(join(vectorsDir, 'invalid', m.stream)));
  if (code === m.error) ++invalidCount;
  else fail(`${m.name}: ${code}, expected ${m.error}`);
}
console.log(`invalid: ${invalidCount}/${invalid.length} with the expected error code`);

// Damaged streams: every truncation of the three smallest valid streams, and 64 single-byte flips
// (a fixed pseudo-random sequence) of every valid stream.
let damaged = 0, traps = 0, decoded = 0;
let seed = 12345;
const random = () => (seed = (seed * 1103515245 + 12345) >>> 0) / 2 ** 32;
const bySize = valid.map((m) => readFileSync(join(vectorsDir, 'valid', m.stream))).sort((a, b) => a.length - b.length);
const cases = [];
for (const bytes of bySize.slice(0, 3)) {
  for (let n = 0; n < bytes.length; ++n) cases.push(bytes.subarray(0, n));
}
for (const bytes of bySize) {
  for (let k = 0; k < 64; ++k) {
    const copy = Uint8Array.from(bytes);
    copy[Math.floor(random() * copy.length)] ^= 1 << Math.floor(random() * 8);
    cases.push(copy);
  }
}
const started = Date.now();
for (const bytes of cases) {
  const code = await decodeOrError(bytes);
  ++damaged;
  if (code === 'ok') ++decoded;
  if (code.startsWith('trap')) {
    ++traps;
    if (traps <= 5) fail(`a damaged stream of ${bytes.length} bytes: ${code}`);
  }
}
if (traps > 5) fail(`${traps} damaged streams trapped in all`);

// A trap (here injected: the module built without C++ exceptions aborts when its memory runs out)
// is a DmcError "resource-limit", and the aborted decoder refuses later calls with "internal".
{
  const faulty = await createDecoder();
  faulty.module._dmc_decode_segment = () => { throw new WebAssembly.RuntimeError('Aborted(OOM)'); };
  const codeOf = (body) => {
    try {
      body();
      return 'ok';
    } catch (error) {
      return error instanceof DmcError ? error.code : `not a DmcError: ${error}`;
    }
  };
  const first = codeOf(() => faulty.decode(bySize[0]));
  const later = codeOf(() => faulty.info(bySize[0]));
  const fresh = codeOf(() => decoder.decode(bySize[0]));
  if (first !== 'resource-limit' || later !== 'internal' || fresh !== 'ok') {
    fail(`an injected trap: ${first}, then ${later} (expected resource-limit, internal); another decoder: ${fresh}`);
  } else {
    console.log('trap: reported as resource-limit, the aborted decoder then refuses with internal');
  }
}
console.log(`damaged: ${damaged} streams, ${decoded} decoded, ${damaged - decoded - traps} refused ` +
            `with an error code, ${traps} traps, ${((Date.now() - started) / 1000).toFixed(1)} s`);
process.exit(failures > 0 ? 1 : 0);
