// A page script for the DMCLoader test: web/DMCLoader.js loads ?dmc=<file> in ?mode=<mode>, an
// AnimationMixer plays its clip, and window.dmcLoader reports, at the clip's first, middle and last
// frame, sampled vertices as three.js draws them (morph targets applied) beside the same frames
// decoded by dmc.js directly, and a picture checksum. Bundled with three.js by run.sh.
import * as THREE from 'three';
import { DMCLoader } from './package/DMCLoader.js';
import { createDecoder } from './package/dmc.js';

const state = { ready: false };
window.dmcLoader = state;

function checksum(canvas) {
  const copy = document.createElement('canvas');
  copy.width = canvas.width;
  copy.height = canvas.height;
  const context = copy.getContext('2d');
  context.drawImage(canvas, 0, 0);
  const { data } = context.getImageData(0, 0, copy.width, copy.height);
  let sum = 0, lit = 0;
  for (let i = 0; i < data.length; i += 4) {
    sum = (sum * 31 + data[i] + 7 * data[i + 1] + 13 * data[i + 2]) >>> 0;
    if (data[i] + data[i + 1] + data[i + 2] > 60) ++lit;
  }
  return { sum, lit: lit / (data.length / 4) };
}

async function main() {
  const params = new URLSearchParams(location.search);
  const url = params.get('dmc');
  const started = performance.now();
  const { mesh, clip, mode, info } = await new DMCLoader().setMode(params.get('mode') ?? 'auto').loadAsync(url);
  state.loadMs = performance.now() - started;
  state.mode = mode;
  state.info = info;
  const bytes = new Uint8Array(await (await fetch(url)).arrayBuffer());
  const decoded = (await createDecoder()).decode(bytes);
  const canvas = document.getElementById('view');
  const renderer = new THREE.WebGLRenderer({ canvas, preserveDrawingBuffer: true });
  const scene = new THREE.Scene();
  scene.add(new THREE.HemisphereLight(0xffffff, 0x404040, 3));
  mesh.material.side = THREE.DoubleSide;
  mesh.frustumCulled = false;
  scene.add(mesh);
  const mixer = new THREE.AnimationMixer(mesh);
  // Once, held at the end: a repeating action would wrap its last frame's time to the first.
  const action = mixer.clipAction(clip);
  action.setLoop(THREE.LoopOnce);
  action.clampWhenFinished = true;
  action.play();
  mixer.setTime(0);
  // Framed on the first frame as decoded (a morph geometry's box spans every target).
  const box = new THREE.Box3().setFromBufferAttribute(new THREE.BufferAttribute(decoded.positions(0), 3));
  const centre = box.getCenter(new THREE.Vector3());
  const size = box.getSize(new THREE.Vector3()).length() || 1;
  state.size = size;
  const camera = new THREE.PerspectiveCamera(45, 1, size / 100, size * 10);
  camera.position.copy(centre).add(new THREE.Vector3(0.6, 0.7, 1.2).multiplyScalar(size));
  camera.lookAt(centre);
  const last = info.frameCount - 1;
  const step = Math.max(1, Math.floor(info.vertexCount / 64));
  state.samples = [0, Math.floor(last / 2), last].map((frame) => {
    mixer.setTime(frame / info.frameRate);
    renderer.render(scene, camera);
    const drawn = [], expected = [];
    const reference = decoded.positions(frame);
    for (let v = 0; v < info.vertexCount; v += step) {
      drawn.push(mesh.getVertexPosition(v, new THREE.Vector3()).toArray());
      expected.push([reference[3 * v], reference[3 * v + 1], reference[3 * v + 2]]);
    }
    return { frame, drawn, expected, picture: checksum(canvas) };
  });
  // The same stream decoded in a module Web Worker (web/dmc_worker.js), segment by segment.
  state.worker = await new Promise((resolve) => {
    const worker = new Worker('./package/dmc_worker.js', { type: 'module' });
    const result = { segments: 0, equal: true, frames: 0 };
    worker.onerror = (event) => resolve({ error: String(event.message ?? event) });
    worker.onmessage = ({ data }) => {
      if (data.error) resolve({ error: `${data.error.code}: ${data.error.message}` });
      else if (data.info) result.triangles = data.indices.length / 3;
      else if (data.done) { worker.terminate(); resolve(result); }
      else {
        ++result.segments;
        const size = 3 * info.vertexCount;
        for (let k = 0; k < data.frameCount; ++k) {
          const expected = decoded.positions(data.firstFrame + k);
          for (let i = 0; i < size; ++i) if (data.positions[k * size + i] !== expected[i]) result.equal = false;
          ++result.frames;
        }
      }
    };
    worker.postMessage({ id: 1, bytes: bytes.slice().buffer }, []);
  });
  state.ready = true;
}

main().catch((error) => { state.error = String(error?.stack ?? error); });
