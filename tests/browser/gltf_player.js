// A page script for the GLB playback test: three.js's GLTFLoader (with meshoptimizer's decoder, as
// a three.js user sets it up for EXT_meshopt_compression) loads data/<glb>, an AnimationMixer
// plays each clip, and window.dmcPlayer reports the clips, a morphed vertex and a picture checksum
// at the start, middle and end of the first clip. Bundled with three.js by tests/browser/run.sh.
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { MeshoptDecoder } from 'three/addons/libs/meshopt_decoder.module.js';
import { RoomEnvironment } from 'three/addons/environments/RoomEnvironment.js';

const state = { ready: false };
window.dmcPlayer = state;

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
  const url = new URLSearchParams(location.search).get('glb');
  const gltf = await new GLTFLoader().setMeshoptDecoder(MeshoptDecoder).loadAsync(url);
  const canvas = document.getElementById('view');
  const renderer = new THREE.WebGLRenderer({ canvas, preserveDrawingBuffer: true });
  const scene = new THREE.Scene();
  scene.background = new THREE.Color(0x000000);
  scene.add(new THREE.HemisphereLight(0xffffff, 0x404040, 3));
  // glTF's default material is fully metallic: without an environment it would draw black.
  scene.environment = new THREE.PMREMGenerator(renderer).fromScene(new RoomEnvironment()).texture;
  scene.add(gltf.scene);
  // Both faces, so that a sheet seen from behind still shows.
  gltf.scene.traverse((object) => {
    if (object.isMesh) object.material.side = THREE.DoubleSide;
  });
  const mixer = new THREE.AnimationMixer(gltf.scene);
  const clips = gltf.animations;
  state.clips = clips.map((clip) => ({ name: clip.name, duration: clip.duration }));
  let morphed = null;
  gltf.scene.traverse((object) => {
    if (!morphed && object.isMesh && object.morphTargetInfluences?.length) morphed = object;
  });
  state.morphTargets = morphed ? morphed.morphTargetInfluences.length : 0;
  if (clips.length > 0) mixer.clipAction(clips[0]).play();
  // The camera frames the scene as it stands at the start of the first clip.
  mixer.setTime(0);
  gltf.scene.updateMatrixWorld(true);
  const box = new THREE.Box3().setFromObject(gltf.scene, true);
  const centre = box.getCenter(new THREE.Vector3());
  const size = box.getSize(new THREE.Vector3()).length() || 1;
  const camera = new THREE.PerspectiveCamera(45, canvas.width / canvas.height, size / 100, size * 10);
  // From the front, above and to the side: a sheet lying in any axis plane shows.
  camera.position.copy(centre).add(new THREE.Vector3(0.6, 0.7, 1.2).multiplyScalar(size));
  camera.lookAt(centre);
  const duration = clips.length > 0 ? clips[0].duration : 0;
  state.samples = [0, 0.5 * duration, duration].map((time) => {
    mixer.setTime(time);
    gltf.scene.updateMatrixWorld(true);
    renderer.render(scene, camera);
    let vertex = null;
    const vertices = [];
    if (morphed) {
      // What three.js draws: a vertex with its morph targets applied, in world space.
      const at = (i) => morphed.localToWorld(morphed.getVertexPosition(i, new THREE.Vector3())).toArray();
      vertex = at(0);
      const count = morphed.geometry.attributes.position.count;
      for (let i = 0; i < count; i += Math.max(1, Math.floor(count / 64))) vertices.push(at(i));
    }
    return { time, vertex, vertices, picture: checksum(canvas) };
  });
  state.size = size;
  state.ready = true;
}

main().catch((error) => { state.error = String(error?.stack ?? error); });
