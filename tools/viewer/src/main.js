// dmc viewer: the original and the decoded animation side by side, in sync, the decoded mesh
// coloured by per-vertex error. Data comes from the page's server (dmc view): data/metrics.json,
// data/decoded.glb and, when an original was given, data/original.glb. The GLBs are dmc exports
// (asset.extras.dmc.layout "morph" or "frames"); frames are read back from the file's buffers and
// shown directly, so both sides always show the same frame index. Under the views: frame stepping,
// wireframe, the colour scale (largest error, a percentile, or a fixed value) and the per-frame
// KG/STED timeline.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { extractFrames, vertexErrors, errorColour, errorScale } from './frames.js';
import { Timeline } from './timeline.js';

const status = document.getElementById('status');
const slider = document.getElementById('slider');
const playButton = document.getElementById('play');
const frameLabel = document.getElementById('frame-label');
const stats = document.getElementById('stats');
const wireframeBox = document.getElementById('wireframe');
const scaleMode = document.getElementById('scale-mode');
const scaleValue = document.getElementById('scale-value');

// State the browser test reads (window.dmcViewer) as well as the page.
const viewer = {
  ready: false, frame: 0, frames: 0, renderedFrame: -1, playing: true, wireframe: false,
  scaleMode: scaleMode.value, scale: 0, // the colour scale, as a fraction of the diagonal
};
window.dmcViewer = viewer;

// The stream decoded in the page by the WebAssembly decoder (web/, served under wasm/ by dmc view).
async function loadStream(url) {
  const module = new URL('wasm/dmc.js', location.href).href;  // not bundled: loaded as served
  const { createDecoder } = await import(module);
  const response = await fetch(url);
  if (!response.ok) throw new Error(`${url}: HTTP ${response.status}`);
  const clip = (await createDecoder()).decode(new Uint8Array(await response.arrayBuffer()));
  const positions = [];
  for (let f = 0; f < clip.frameCount; ++f) positions.push(Float32Array.from(clip.positions(f)));
  return { vertexCount: clip.vertexCount, index: clip.indices, positions };
}

async function loadGlb(url) {
  const response = await fetch(url);
  if (!response.ok) throw new Error(`${url}: HTTP ${response.status}`);
  const gltf = await new GLTFLoader().parseAsync(await response.arrayBuffer(), '');
  return extractFrames(gltf);
}

function makeView(canvas, frames, colours) {
  const renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
  renderer.setPixelRatio(window.devicePixelRatio);
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x303338);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x404050, 2.2));
  const light = new THREE.DirectionalLight(0xffffff, 1.5);
  light.position.set(1, 2, 3);
  scene.add(light);
  const geometry = new THREE.BufferGeometry();
  geometry.setIndex(new THREE.BufferAttribute(frames.index, 1));
  geometry.setAttribute('position', new THREE.BufferAttribute(frames.positions[0].slice(), 3));
  if (colours) {
    geometry.setAttribute('color', new THREE.BufferAttribute(new Float32Array(frames.vertexCount * 3), 3));
  }
  const material = new THREE.MeshStandardMaterial({
    color: colours ? 0xffffff : 0xc8c8d0, vertexColors: !!colours, side: THREE.DoubleSide,
    roughness: 0.7, metalness: 0.0,
  });
  scene.add(new THREE.Mesh(geometry, material));
  const camera = new THREE.PerspectiveCamera(40, 1, 0.001, 1000);
  const controls = new OrbitControls(camera, canvas);
  return { renderer, scene, geometry, material, camera, controls, canvas, frames };
}

function frameCamera(view, box) {
  const centre = box.getCenter(new THREE.Vector3());
  const radius = Math.max(box.getSize(new THREE.Vector3()).length() / 2, 1e-6);
  view.camera.near = radius / 100;
  view.camera.far = radius * 100;
  view.camera.position.copy(centre).add(new THREE.Vector3(0, radius * 0.3, radius * 2.8));
  view.controls.target.copy(centre);
  view.camera.updateProjectionMatrix();
  view.controls.update();
}

function resize(view) {
  const width = view.canvas.clientWidth, height = view.canvas.clientHeight;
  if (view.canvas.width !== Math.floor(width * window.devicePixelRatio) ||
      view.canvas.height !== Math.floor(height * window.devicePixelRatio)) {
    view.renderer.setSize(width, height, false);
    view.camera.aspect = width / Math.max(height, 1);
    view.camera.updateProjectionMatrix();
  }
}

async function main() {
  const metrics = await (await fetch('data/metrics.json')).json();
  const started = performance.now();
  const decoded = metrics.stream ? await loadStream(metrics.stream) : await loadGlb('data/decoded.glb');
  viewer.source = metrics.stream ? 'wasm' : 'glb';
  viewer.decodeMs = performance.now() - started;
  const original = metrics.original ? await loadGlb('data/original.glb') : null;
  if (original && (original.vertexCount !== decoded.vertexCount ||
                   original.positions.length !== decoded.positions.length)) {
    throw new Error('original and decoded differ in vertex or frame count');
  }
  const frameCount = decoded.positions.length;
  const errors = original ? vertexErrors(original, decoded) : null;

  const views = [];
  const originalCanvas = document.getElementById('original');
  if (original) views.push(makeView(originalCanvas, original, null));
  else originalCanvas.parentElement.querySelector('.label').textContent = 'original: not given';
  const decodedView = makeView(document.getElementById('decoded'), decoded, errors);
  views.push(decodedView);

  const box = new THREE.Box3().setFromArray(decoded.positions[0]);
  for (const view of views) frameCamera(view, box);
  // One camera motion drives both views.
  for (const view of views) {
    view.controls.addEventListener('change', () => {
      for (const other of views) {
        if (other === view) continue;
        other.camera.position.copy(view.camera.position);
        other.camera.quaternion.copy(view.camera.quaternion);
        other.controls.target.copy(view.controls.target);
      }
    });
  }

  viewer.frames = frameCount;
  slider.max = String(frameCount - 1);
  document.getElementById('title').textContent =
    `${metrics.input}: ${metrics.frames} frames × ${metrics.vertices} vertices`;
  const legend = document.getElementById('legend-max');
  const timeline = new Timeline(document.getElementById('timeline'), metrics.distortion?.frames ?? null,
                                frameCount);
  // The colour scale from the chosen mode; a fixed value is in % of the diagonal.
  const applyScale = () => {
    viewer.scaleMode = scaleMode.value;
    scaleValue.disabled = !errors;  // it shows the scale in use; typing in it fixes the scale
    if (!errors) {
      legend.textContent = '(no original)';
      return;
    }
    if (scaleMode.value === 'manual') {
      const percent = Number(scaleValue.value);
      if (!(percent > 0)) return;  // keep the last scale until the field holds a positive number
      viewer.scale = percent / 100;
    } else {
      viewer.scale = errorScale(errors, scaleMode.value);
      scaleValue.value = (100 * viewer.scale).toPrecision(3);
    }
    const clipped = viewer.scale < errors.scale ? ` (largest ${(100 * errors.scale).toPrecision(3)}%)` : '';
    legend.textContent = `${(100 * viewer.scale).toPrecision(3)}% of the bounding-box diagonal${clipped}`;
  };
  if (!errors) scaleMode.disabled = true;
  applyScale();

  const showFrame = (f) => {
    viewer.frame = f;
    slider.value = String(f);
    frameLabel.textContent = `frame ${f} / ${frameCount - 1}`;
    document.body.dataset.frame = String(f);
    for (const view of views) {
      const position = view.geometry.getAttribute('position');
      position.array.set(view.frames.positions[f]);
      position.needsUpdate = true;
      view.geometry.computeVertexNormals();
      view.geometry.computeBoundingSphere();
    }
    if (errors) {
      const colour = decodedView.geometry.getAttribute('color');
      errorColour(errors.perFrame[f], viewer.scale, colour.array);
      colour.needsUpdate = true;
    }
    timeline.draw(f);
    const lines = [`file: ${metrics.bytes} bytes, ${metrics.bpfv.toFixed(3)} bpfv`];
    const distortion = metrics.distortion;
    if (distortion) {
      const frame = distortion.frames[f];
      lines.push(`frame ${f}: KG contribution ${frame.kg.toPrecision(4)}  STED_s ${frame.sted_s.toPrecision(4)}`);
      lines.push(`sequence: KG ${distortion.kg.toPrecision(4)}  STED ${distortion.sted.toPrecision(4)}` +
                 `  (STED_s ${distortion.sted_s.toPrecision(4)}, STED_t ${distortion.sted_t.toPrecision(4)})`);
    }
    stats.textContent = lines.join('\n');
  };

  slider.addEventListener('input', () => { showFrame(Number(slider.value)); });
  const setPlaying = (playing) => {
    viewer.playing = playing;
    playButton.textContent = playing ? 'pause' : 'play';
  };
  playButton.addEventListener('click', () => setPlaying(!viewer.playing));
  // Stepping pauses, and wraps around at either end.
  const step = (delta) => {
    setPlaying(false);
    showFrame((viewer.frame + delta + frameCount) % frameCount);
  };
  document.getElementById('previous').addEventListener('click', () => step(-1));
  document.getElementById('next').addEventListener('click', () => step(1));
  const setWireframe = (on) => {
    viewer.wireframe = on;
    wireframeBox.checked = on;
    for (const view of views) {
      view.material.wireframe = on;
      view.material.needsUpdate = true;
    }
  };
  wireframeBox.addEventListener('change', () => setWireframe(wireframeBox.checked));
  const recolour = () => {
    applyScale();
    showFrame(viewer.frame);
  };
  scaleMode.addEventListener('change', recolour);
  scaleValue.addEventListener('input', () => {
    scaleMode.value = 'manual';
    recolour();
  });
  document.addEventListener('keydown', (event) => {
    const target = event.target;
    // Fields keep their own keys (typing a scale, the slider's arrows, space on the checkbox).
    if (target instanceof HTMLInputElement && (target.type !== 'checkbox' || event.key === ' ')) return;
    if (target instanceof HTMLSelectElement) return;
    if (target instanceof HTMLButtonElement && (event.key === ' ' || event.key === 'Enter')) return;
    if (event.key === 'ArrowLeft') step(-1);
    else if (event.key === 'ArrowRight') step(1);
    else if (event.key === ' ') setPlaying(!viewer.playing);
    else if (event.key === 'w') setWireframe(!viewer.wireframe);
    else return;
    event.preventDefault();
  });
  window.addEventListener('resize', () => timeline.draw(viewer.frame));
  // Clicking or dragging on the timeline goes to that frame.
  const timelineCanvas = document.getElementById('timeline');
  const seek = (event) => {
    setPlaying(false);
    showFrame(timeline.frameAt(event.clientX));
  };
  timelineCanvas.addEventListener('pointerdown', (event) => {
    timelineCanvas.setPointerCapture(event.pointerId);
    seek(event);
  });
  timelineCanvas.addEventListener('pointermove', (event) => {
    if (timelineCanvas.hasPointerCapture(event.pointerId)) seek(event);
  });

  const frameRate = metrics.frame_rate > 0 ? metrics.frame_rate : 30;
  let clockStart = performance.now();
  let startFrame = 0;
  showFrame(0);
  const loop = (now) => {
    if (viewer.playing && frameCount > 1) {
      // requestAnimationFrame's timestamp may precede the performance.now() taken at start.
      const elapsed = Math.max(0, now - clockStart) / 1000;
      const f = (startFrame + Math.floor(elapsed * frameRate)) % frameCount;
      if (f !== viewer.frame) showFrame(f);
    } else {
      clockStart = now;
      startFrame = viewer.frame;
    }
    for (const view of views) {
      resize(view);
      view.controls.update();
      view.renderer.render(view.scene, view.camera);
    }
    viewer.renderedFrame = viewer.frame;
    if (!viewer.ready) {
      viewer.ready = true;
      status.textContent = '';
    }
    requestAnimationFrame(loop);
  };
  requestAnimationFrame(loop);
}

main().catch((error) => {
  status.textContent = `error: ${error.message}`;
  viewer.error = String(error.message);
  console.error(error);
});
