// A three.js loader for .dmc streams, in the manner of DRACOLoader: decodes in the page with the
// WebAssembly decoder (dmc.js) and returns a Mesh whose animation an AnimationClip carries, so that
// an AnimationMixer plays it.
//
//   import { DMCLoader } from 'dmc-decoder/DMCLoader.js';
//   const { mesh, clip } = await new DMCLoader().loadAsync('walk.dmc');
//   scene.add(mesh);
//   const mixer = new THREE.AnimationMixer(mesh);
//   mixer.clipAction(clip).play();              // then mixer.update(dt) per frame
//
// Two ways to animate (setMode):
//  - 'morph': frame 0 as the geometry, one morph target per later frame (positions and normals,
//    relative to frame 0), played by a '.morphTargetInfluences' track; the GPU blends frames.
//  - 'buffer': the geometry's position (and normal) attribute rewritten on every change of the
//    mesh's `dmcFrame` property, which a '.dmcFrame' track drives, blending the two nearest frames;
//    memory for the decoded frames only, whatever their count.
//  - 'auto' (the default): morph up to 128 frames, buffer beyond.
import {
  AnimationClip, BufferAttribute, BufferGeometry, FileLoader, Loader, Mesh, MeshStandardMaterial,
  NumberKeyframeTrack,
} from 'three';
import { createDecoder } from './dmc.js';

let sharedDecoder = null;

// Area-weighted vertex normals of one frame (x, y, z per vertex).
function vertexNormals(positions, indices) {
  const normals = new Float32Array(positions.length);
  for (let t = 0; t < indices.length; t += 3) {
    const a = 3 * indices[t], b = 3 * indices[t + 1], c = 3 * indices[t + 2];
    const ux = positions[b] - positions[a], uy = positions[b + 1] - positions[a + 1], uz = positions[b + 2] - positions[a + 2];
    const vx = positions[c] - positions[a], vy = positions[c + 1] - positions[a + 1], vz = positions[c + 2] - positions[a + 2];
    const nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
    for (const v of [a, b, c]) {
      normals[v] += nx; normals[v + 1] += ny; normals[v + 2] += nz;
    }
  }
  for (let v = 0; v < normals.length; v += 3) {
    const length = Math.hypot(normals[v], normals[v + 1], normals[v + 2]);
    if (length > 0) {
      normals[v] /= length; normals[v + 1] /= length; normals[v + 2] /= length;
    } else {
      normals[v + 2] = 1;
    }
  }
  return normals;
}

export class DMCLoader extends Loader {
  constructor(manager) {
    super(manager);
    this.mode = 'auto';
    this.limits = undefined;
  }

  setMode(mode) {
    if (!['auto', 'morph', 'buffer'].includes(mode)) throw new Error(`DMCLoader: unknown mode ${mode}`);
    this.mode = mode;
    return this;
  }

  // { maxOutputBytes, maxMatrixBytes }: the decoder's limits (dmc.js).
  setLimits(limits) {
    this.limits = limits;
    return this;
  }

  load(url, onLoad, onProgress, onError) {
    const loader = new FileLoader(this.manager);
    loader.setPath(this.path);
    loader.setResponseType('arraybuffer');
    loader.setRequestHeader(this.requestHeader);
    loader.setWithCredentials(this.withCredentials);
    loader.load(url, (buffer) => {
      this.parse(buffer).then(onLoad).catch((error) => {
        if (onError) onError(error); else console.error(error);
        this.manager.itemError(url);
      });
    }, onProgress, onError);
  }

  // Resolves to { mesh, clip, info }.
  async parse(buffer) {
    sharedDecoder ??= createDecoder();
    const decoder = await sharedDecoder;
    const decoded = decoder.decode(new Uint8Array(buffer), this.limits);
    const { vertexCount, frameCount, indices, name } = decoded;
    const frameRate = decoded.frameRate > 0 ? decoded.frameRate : 30;
    const mode = this.mode === 'auto' ? (frameCount <= 128 ? 'morph' : 'buffer') : this.mode;
    const geometry = new BufferGeometry();
    geometry.setIndex(new BufferAttribute(indices, 1));
    const first = Float32Array.from(decoded.positions(0));
    geometry.setAttribute('position', new BufferAttribute(first, 3));
    geometry.setAttribute('normal', new BufferAttribute(vertexNormals(first, indices), 3));
    const mesh = new Mesh(geometry, new MeshStandardMaterial({ color: 0xb0b8c8, roughness: 0.7 }));
    mesh.name = name || 'dmc';
    const times = Float32Array.from({ length: frameCount }, (_, f) => f / frameRate);
    let track;
    if (mode === 'morph') {
      const positions = [], normals = [];
      const firstNormals = geometry.attributes.normal.array;
      for (let f = 1; f < frameCount; ++f) {
        const frame = decoded.positions(f);
        const delta = new Float32Array(frame.length), normalDelta = vertexNormals(frame, indices);
        for (let i = 0; i < frame.length; ++i) {
          delta[i] = frame[i] - first[i];
          normalDelta[i] -= firstNormals[i];
        }
        positions.push(new BufferAttribute(delta, 3));
        normals.push(new BufferAttribute(normalDelta, 3));
      }
      geometry.morphAttributes.position = positions;
      geometry.morphAttributes.normal = normals;
      geometry.morphTargetsRelative = true;
      mesh.updateMorphTargets();
      // One key per frame, one-hot: LINEAR interpolation blends the two neighbouring frames.
      const values = new Float32Array(frameCount * (frameCount - 1));
      for (let f = 1; f < frameCount; ++f) values[f * (frameCount - 1) + (f - 1)] = 1;
      track = new NumberKeyframeTrack('.morphTargetInfluences', times, values);
    } else {
      const all = [];
      for (let f = 0; f < frameCount; ++f) all.push(decoded.positions(f));
      let current = 0;
      Object.defineProperty(mesh, 'dmcFrame', {
        get: () => current,
        set: (value) => {
          const frame = Math.min(Math.max(value, 0), frameCount - 1);
          if (frame === current) return;
          current = frame;
          const lower = Math.floor(frame), upper = Math.min(lower + 1, frameCount - 1), w = frame - lower;
          const a = all[lower], b = all[upper], out = geometry.attributes.position.array;
          for (let i = 0; i < out.length; ++i) out[i] = a[i] + w * (b[i] - a[i]);
          geometry.attributes.normal.array.set(vertexNormals(out, indices));
          geometry.attributes.position.needsUpdate = true;
          geometry.attributes.normal.needsUpdate = true;
          geometry.computeBoundingSphere();
        },
      });
      track = new NumberKeyframeTrack('.dmcFrame', times, Float32Array.from(times, (_, f) => f));
    }
    const duration = frameCount > 1 ? (frameCount - 1) / frameRate : 0;
    const clip = new AnimationClip(mesh.name, duration, [track]);
    return { mesh, clip, mode, info: { vertexCount, frameCount, frameRate, segments: decoded.segments } };
  }
}
