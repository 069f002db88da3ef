// What the Draco baseline of the web benchmarks does with draco3d's modules, shared by the Node
// (bench_draco.mjs) and Chromium (bench_browser.mjs) runs; no Node imports, so a page can load it.

// Every frame as its own Draco mesh, encoded as `dmc sweep`'s draco baseline does: edgebreaker,
// speed 0, positions quantised to `bits`.
export function encodeDracoFrames(encoderModule, frames, indices, bits) {
  const vertexCount = frames[0].length / 3;
  return frames.map((positions) => {
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
}

// Decodes every frame to positions and triangles, copied out as a page would use them.
export function decodeDracoFrames(decoderModule, buffers) {
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
    const triangleData = decoderModule._malloc(triangles * 4);
    decoderObject.GetTrianglesUInt32Array(mesh, triangles * 4, triangleData);
    new Uint32Array(decoderModule.HEAPU32.buffer, triangleData, triangles).slice();
    decoderModule._free(triangleData);
    decoderModule.destroy(mesh);
    decoderModule.destroy(decoderObject);
  }
}

// The fastest of `runs` runs, in ms.
export function best(runs, body) {
  let fastest = Infinity;
  for (let k = 0; k < runs; ++k) {
    const start = performance.now();
    body();
    fastest = Math.min(fastest, performance.now() - start);
  }
  return fastest;
}

// A PC2 point cache's frames (Float32Array of x y z per vertex each) and an OBJ's triangles.
export function readPc2Frames(bytes) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const vertexCount = view.getInt32(16, true), frameCount = view.getInt32(28, true);
  const frames = [];
  for (let f = 0; f < frameCount; ++f) {
    const start = bytes.byteOffset + 32 + f * vertexCount * 12;
    frames.push(new Float32Array(bytes.buffer.slice(start, start + vertexCount * 12)));
  }
  return frames;
}

export function readObjTriangles(text) {
  const faces = [];
  for (const line of text.split('\n')) {
    if (line.startsWith('f ')) faces.push(...line.split(/\s+/).slice(1, 4).map((t) => parseInt(t, 10) - 1));
  }
  return Uint32Array.from(faces);
}
