// Benchmark (not a test): bench_draco.mjs in headless Chromium. Node encodes each frame with
// draco3d's encoder (as `dmc sweep`'s draco baseline does) and serves the streams; the page times
// the WebAssembly dmc decoder and draco3d's WebAssembly decoder (the same package's
// draco_decoder.wasm) on them, best of 5 each, in the same tab. Chromium is Debian's, driven by
// playwright-core from tests/browser's lock file (the ctest browser tests install it in
// BUILD/browser-tests).
// Usage: node bench_browser.mjs NPM_DIR PACKAGE_DIR DRACO3D_DIR STREAM.dmc CACHE.pc2 MESH.obj BITS[,BITS...]
//   e.g. node web/test/bench_browser.mjs build/browser-tests build/web/package \
//          build/browser-tests/node_modules/draco3d crane150.dmc crane150.pc2 crane150.obj 10,11
import { createServer } from 'node:http';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { createRequire } from 'node:module';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { encodeDracoFrames, readObjTriangles, readPc2Frames } from './draco_frames.mjs';

const [npmDir, packageDir, dracoDir, dmcPath, pc2Path, objPath, bitsList] = process.argv.slice(2);
if (!bitsList) {
  console.error('usage: node bench_browser.mjs NPM_DIR PACKAGE_DIR DRACO3D_DIR STREAM.dmc CACHE.pc2 MESH.obj BITS[,BITS...]');
  process.exit(2);
}
const requireFromNpm = createRequire(join(resolve(npmDir), 'package.json'));
const { chromium } = requireFromNpm('playwright-core');
const draco3d = createRequire(import.meta.url)(resolve(dracoDir));

const frames = readPc2Frames(readFileSync(pc2Path));
const indices = readObjTriangles(readFileSync(objPath, 'utf8'));
const encoderModule = await draco3d.createEncoderModule({});
const bits = bitsList.split(',').map(Number);
const draco = {};  // bits -> concatenated frames, and their lengths
for (const b of bits) {
  const buffers = encodeDracoFrames(encoderModule, frames, indices, b);
  draco[b] = { bytes: Buffer.concat(buffers.map((x) => Buffer.from(x.buffer))), lengths: buffers.map((x) => x.length) };
}

const here = dirname(fileURLToPath(import.meta.url));
const page = `<!doctype html><meta charset="utf-8"><title>dmc vs draco3d</title>
<script src="draco/draco_decoder_nodejs.js"></script>
<script type="module">
import { createDecoder } from './package/dmc.js';
import { best, decodeDracoFrames } from './bench/draco_frames.mjs';
const fetchBytes = async (url) => new Uint8Array(await (await fetch(url)).arrayBuffer());
try {
  const result = { userAgent: navigator.userAgent, draco: [] };
  const dmcBytes = await fetchBytes('data/stream.dmc');
  const decoder = await createDecoder();
  result.info = decoder.info(dmcBytes);
  result.dmcMs = best(5, () => decoder.decode(dmcBytes));
  const decoderModule = await DracoDecoderModule({ wasmBinary: await fetchBytes('draco/draco_decoder.wasm') });
  for (const bits of ${JSON.stringify(bits)}) {
    const all = await fetchBytes('data/draco-' + bits + '.bin');
    const lengths = await (await fetch('data/draco-' + bits + '.json')).json();
    const buffers = [];
    let offset = 0;
    for (const length of lengths) buffers.push(new Int8Array(all.buffer, (offset += length) - length, length));
    result.draco.push({ bits, bytes: all.length, ms: best(5, () => decodeDracoFrames(decoderModule, buffers)) });
  }
  window.benchResult = result;
} catch (error) {
  window.benchResult = { error: String(error?.stack ?? error) };
}
</script>`;

const files = {
  '/index.html': () => [page, 'text/html'],
  '/data/stream.dmc': () => [readFileSync(dmcPath), 'application/octet-stream'],
  '/bench/draco_frames.mjs': () => [readFileSync(join(here, 'draco_frames.mjs')), 'text/javascript'],
};
for (const b of bits) {
  files[`/data/draco-${b}.bin`] = () => [draco[b].bytes, 'application/octet-stream'];
  files[`/data/draco-${b}.json`] = () => [JSON.stringify(draco[b].lengths), 'application/json'];
}
const server = createServer((request, response) => {
  const path = decodeURIComponent(new URL(request.url, 'http://x').pathname);
  try {
    let body, type;
    if (files[path]) [body, type] = files[path]();
    else if (path.startsWith('/package/') && !path.includes('..')) {
      body = readFileSync(join(resolve(packageDir), path.slice(9)));
      type = path.endsWith('.wasm') ? 'application/wasm' : 'text/javascript';
    } else if (path.startsWith('/draco/') && !path.includes('..')) {
      body = readFileSync(join(resolve(dracoDir), path.slice(7)));
      type = path.endsWith('.wasm') ? 'application/wasm' : 'text/javascript';
    } else throw new Error('not found');
    response.writeHead(200, { 'content-type': type });
    response.end(body);
  } catch {
    response.writeHead(404);
    response.end();
  }
});
await new Promise((done) => server.listen(0, '127.0.0.1', done));

const userDataDir = mkdtempSync(join(tmpdir(), 'dmc-bench-chromium-'));
let context;
try {
  context = await chromium.launchPersistentContext(userDataDir, {
    executablePath: '/usr/bin/chromium', headless: true,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--no-first-run', '--disable-background-networking',
           '--disable-component-update', '--disable-sync'],
  });
  const tab = context.pages()[0] ?? await context.newPage();
  await tab.goto(`http://127.0.0.1:${server.address().port}/index.html`);
  await tab.waitForFunction(() => window.benchResult, null, { timeout: 300000 });
  const result = await tab.evaluate(() => window.benchResult);
  if (result.error) throw new Error(result.error);
  const { info } = result;
  const rate = (ms) => `${(info.vertexCount * info.frameCount / ms / 1000).toFixed(2)} M vertex-frames/s`;
  console.log(result.userAgent);
  console.log(`dmc: ${info.bytes} bytes, ${info.vertexCount} V x ${info.frameCount} F, ranks ` +
              `${info.segments.map((s) => s.rank).join(',')}: ${result.dmcMs.toFixed(0)} ms, ${rate(result.dmcMs)}`);
  for (const d of result.draco) {
    console.log(`draco ${d.bits} bits: ${d.bytes} bytes: ${d.ms.toFixed(0)} ms, ${rate(d.ms)}; ` +
                `dmc ${(d.ms / result.dmcMs).toFixed(2)}x faster`);
  }
} catch (error) {
  console.error(error.message ?? error);
  process.exitCode = 1;
} finally {
  if (context) await context.close();
  server.close();
  rmSync(userDataDir, { recursive: true, force: true });
}
