// Benchmark (not a test): the WebAssembly dmc decoder against Draco's (the draco3d npm package)
// decoding the same sequence frame by frame, in the same Node process. Each frame is Draco-encoded
// here as `dmc sweep`'s draco baseline does (edgebreaker, speed 0, positions quantised to BITS),
// and decoded to positions and triangles as a page would use them. Prints bytes, best-of-5 decode
// time and the ratio. bench_browser.mjs runs the same in Chromium.
// Usage: node bench_draco.mjs PACKAGE_DIR DRACO3D_DIR STREAM.dmc CACHE.pc2 MESH.obj BITS[,BITS...]
import { readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { createRequire } from 'node:module';
import { pathToFileURL } from 'node:url';
import { best, decodeDracoFrames, encodeDracoFrames, readObjTriangles, readPc2Frames } from './draco_frames.mjs';

const [packageDir, dracoDir, dmcPath, pc2Path, objPath, bitsList] = process.argv.slice(2);
const { createDecoder } = await import(pathToFileURL(join(resolve(packageDir), 'dmc.js')).href);
const draco3d = createRequire(import.meta.url)(resolve(dracoDir));

const frames = readPc2Frames(readFileSync(pc2Path));
const indices = readObjTriangles(readFileSync(objPath, 'utf8'));
const vertexCount = frames[0].length / 3, frameCount = frames.length;
const rate = (ms) => `${(vertexCount * frameCount / ms / 1000).toFixed(2)} M vertex-frames/s`;

const dmcBytes = readFileSync(dmcPath);
const decoder = await createDecoder();
const info = decoder.info(dmcBytes);
const dmcMs = best(5, () => decoder.decode(dmcBytes));
console.log(`dmc: ${dmcBytes.length} bytes, ${info.vertexCount} V x ${info.frameCount} F, ranks ` +
            `${info.segments.map((s) => s.rank).join(',')}: ${dmcMs.toFixed(0)} ms, ${rate(dmcMs)}`);

const encoderModule = await draco3d.createEncoderModule({});
const decoderModule = await draco3d.createDecoderModule({});
for (const bits of bitsList.split(',').map(Number)) {
  const buffers = encodeDracoFrames(encoderModule, frames, indices, bits);
  const total = buffers.reduce((sum, b) => sum + b.length, 0);
  const dracoMs = best(5, () => decodeDracoFrames(decoderModule, buffers));
  console.log(`draco ${bits} bits: ${total} bytes: ${dracoMs.toFixed(0)} ms, ${rate(dracoMs)}; ` +
              `dmc ${(dracoMs / dmcMs).toFixed(2)}x faster`);
}
