// Reading dmc GLB exports back into per-frame position arrays, and the error colouring. Kept free
// of WebGL so it can be reasoned about (and tested) on its own.

// { vertexCount, index: Uint32Array, positions: [Float32Array per frame] } from a GLTFLoader result.
export function extractFrames(gltf) {
  const extras = gltf.parser.json.asset?.extras?.dmc;
  const meshes = [];
  gltf.scene.traverse((object) => { if (object.isMesh) meshes.push(object); });
  if (meshes.length === 0) throw new Error('the GLB holds no mesh');
  const layout = extras?.layout ?? (meshes.length > 1 ? 'frames' : 'morph');
  const first = meshes[0].geometry;
  const vertexCount = first.getAttribute('position').count;
  const index = first.index ? Uint32Array.from(first.index.array)
                            : Uint32Array.from({ length: vertexCount }, (_, i) => i);
  const positions = [];
  if (layout === 'frames') {
    // One mesh per frame, in node order (frame_0, frame_1, ...).
    for (const mesh of meshes) positions.push(Float32Array.from(mesh.geometry.getAttribute('position').array));
  } else {
    const base = first.getAttribute('position').array;
    positions.push(Float32Array.from(base));
    const targets = first.morphAttributes.position ?? [];
    const relative = first.morphTargetsRelative;
    for (const target of targets) {
      const frame = Float32Array.from(target.array);
      if (relative) for (let i = 0; i < frame.length; ++i) frame[i] += base[i];
      positions.push(frame);
    }
  }
  return { vertexCount, index, positions };
}

// Per-frame, per-vertex Euclidean error relative to the original's bounding-box diagonal, and the
// colour scale (the largest error over the sequence, so colours compare across frames).
export function vertexErrors(original, decoded) {
  let min = [Infinity, Infinity, Infinity], max = [-Infinity, -Infinity, -Infinity];
  for (const frame of original.positions) {
    for (let i = 0; i < frame.length; ++i) {
      const axis = i % 3;
      if (frame[i] < min[axis]) min[axis] = frame[i];
      if (frame[i] > max[axis]) max[axis] = frame[i];
    }
  }
  const diagonal = Math.hypot(max[0] - min[0], max[1] - min[1], max[2] - min[2]) || 1;
  let scale = 0;
  const perFrame = original.positions.map((a, f) => {
    const b = decoded.positions[f];
    const errors = new Float32Array(original.vertexCount);
    for (let v = 0; v < original.vertexCount; ++v) {
      const e = Math.hypot(a[3 * v] - b[3 * v], a[3 * v + 1] - b[3 * v + 1], a[3 * v + 2] - b[3 * v + 2]) / diagonal;
      errors[v] = e;
      if (e > scale) scale = e;
    }
    return errors;
  });
  return { perFrame, scale: scale > 0 ? scale : 1e-9 };
}

// Blue (no error) through green and yellow to red (the scale), written as RGB into `out`.
const STOPS = [[0.19, 0.31, 1.0], [0.13, 0.82, 0.63], [1.0, 0.88, 0.25], [1.0, 0.19, 0.13]];
export function errorColour(errors, scale, out) {
  for (let v = 0; v < errors.length; ++v) {
    const t = Math.min(errors[v] / scale, 1) * (STOPS.length - 1);
    const k = Math.min(Math.floor(t), STOPS.length - 2), s = t - k;
    for (let c = 0; c < 3; ++c) out[3 * v + c] = STOPS[k][c] + s * (STOPS[k + 1][c] - STOPS[k][c]);
  }
}

// The colour scale of a mode: 'max' is the largest error of the sequence; a number p (e.g. 99)
// the p-th percentile of every vertex's error in every frame, so that a few outliers do not turn
// the rest of the mesh blue. Sequences of more than 4M vertex-frames are sampled evenly.
export function errorScale(errors, mode) {
  if (mode === 'max') return errors.scale;
  const p = Number(mode);
  if (!(p > 0 && p <= 100)) throw new Error(`colour scale ${mode}: not 'max' or a percentile`);
  const total = errors.perFrame.reduce((sum, frame) => sum + frame.length, 0);
  const stride = Math.max(1, Math.ceil(total / 4e6));
  const values = new Float32Array(Math.ceil(total / stride));
  let n = 0, k = 0;
  for (const frame of errors.perFrame) {
    for (let v = 0; v < frame.length; ++v, ++k) if (k % stride === 0) values[n++] = frame[v];
  }
  const sample = values.subarray(0, n).sort();
  const value = sample[Math.min(n - 1, Math.max(0, Math.ceil((p / 100) * n) - 1))];
  return value > 0 ? value : errors.scale;
}
