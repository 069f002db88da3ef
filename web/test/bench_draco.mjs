// Benchmark (not a test): the WebAssembly dmc decoder against Draco's (the draco3d npm package)
// decoding the same sequence frame by frame, in the same Node process. Each frame is Draco-encoded
// here as `dmc sweep`'s draco baseline does (edgebreaker, speed 0, positions quantised to BITS),
// and decoded to positions and triangles as a page would use them. Prints bytes, best-of-5 decode
// time and the ratio.
// Usage: node bench_draco.mjs PACKAGE_DIR DRACO3D_DIR STREAM.dmc CACHE.pc2 MESH.obj BITS[,BITS...]
import { readFileSync } from 'node:fs';
import { join, resolve } from 'node:path';
import { createRequire } from 'node:module';
import { pathToFileURL } from 'node:url';

const [packageDir, dracoDir, dmcPath, pc2Path, objPath, bitsList] = process.argv.slice(2);
const { createDecoder } = await import(pathToFileURL(join(resolve(packageDir), 'dmc.js')).href);
const draco3d = createRequire(import.meta.url)(resolve(dracoDir));

const pc2 = readFileSync(pc2Path);
const vertexCount = pc2.readInt32LE(16), frameCount = pc2.readInt32LE(28);
const frames = [];
for (let f = 0; f < frameCount; ++f) {
  frames.push(new Float32Array(pc2.buffer.slice(pc2.byteOffset + 32 + f * vertexCount * 12,
                                                pc2.byteOffset + 32 + (f + 1) * vertexCount * 12)));
}
const faces = [];
for (const line of readFileSync(objPath, 'utf8').split('\n')) {
  if (line.startsWith('f ')) faces.push(...line.split(/\s+/).slice(1, 4).map((t) => parseInt(t, 10) - 1));
}
const indices = Uint32Array.from(faces);

const best = (runs, body) => {
  let fastest = Infinity;
  for (let k = 0; k < runs; ++k) {
    const start = performance.now();
    body();
    fastest = Math.min(fastest, performance.now() - start);
  }
  return fastest;
};
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
  const buffers = frames.map((positions) => {
    const encoder = new encoderModule.Encoder();
    const builder = new encoderModule.MeshBuilder();
    const mesh = new encoderModule.Mesh();
    builder.AddFacesToMesh(mesh, indices.length / 3, indices);
    builder.AddFloatAttributeToMesh(mesh, encoderModule.POSITION, vertexCount, 3, positions);
    encoder.SetSpeedOptions(0, 0);
    encoder.SetAttributeQuantization(encoderModule.POSITION, bits);
    encoder.SetEncodingMethod(encoderModule.MESH_EDGEBREAKER_ENCODING);
    const out = new encoderModule.DracoInt8Array();
    const length = encoder.EncodeMeshToDracoBuffer(mesh, out);
    const bytes = new Int8Array(length);
    for (let i = 0; i < length; ++i) bytes[i] = out.GetValue(i);
    [out, mesh, builder, encoder].forEach((o) => encoderModule.destroy(o));
    return bytes;
  });
  const total = buffers.reduce((sum, b) => sum + b.length, 0);
  const dracoMs = best(5, () => {
    for (const bytes of buffers) {
      const decoderObject = new decoderModule.Decoder();
      const mesh = new decoderModule.Mesh();
      const status = decoderObject.DecodeArrayToMesh(bytes, bytes.length, mesh);
      if (!status.ok()) throw new Error(status.error_msg());
      const attribute = decoderObject.GetAttribute(mesh, decoderObject.GetAttributeId(mesh, decoderModule.POSITION));
      const values = mesh.num_points() * 3;
      const pointer = decoderModule._malloc(values * 4);
      decoderObject.GetAttributeDataArrayForAllPoints(mesh, attribute, decoderModule.DT_FLOAT32, values * 4, pointer);
      new Float32Array(decoderModule.HEAPF32.buffer, pointer, values).slice();
      decoderModule._free(pointer);
      const triangles = mesh.num_faces() * 3;
      const tri = decoderModule._malloc(triangles * 4);
      decoderObject.GetTrianglesUInt32Array(mesh, triangles * 4, tri);
      new Uint32Array(decoderModule.HEAPU32.buffer, tri, triangles).slice();
      decoderModule._free(tri);
      decoderModule.destroy(mesh);
      decoderModule.destroy(decoderObject);
    }
  });
  console.log(`draco ${bits} bits: ${total} bytes: ${dracoMs.toFixed(0)} ms, ${rate(dracoMs)}; ` +
              `dmc ${(dracoMs / dmcMs).toFixed(2)}x faster`);
}
