// Compiled (never run) by `tests/browser/run.sh types` with tsc --strict against the package's
// declarations (dmc.d.ts, DMCLoader.d.ts) and @types/three: the README's uses type-check, and each
// expected error below proves the declarations are precise rather than `any`.
import { AnimationMixer, Scene } from 'three';
import { createDecoder, DmcError, DmcErrorCode, StreamInfo, WorkerReply } from './dmc.js';
import { DMCLoader, DMCResult } from './DMCLoader.js';

export async function decodeAll(bytes: Uint8Array): Promise<number> {
  const decoder = await createDecoder();
  const info: StreamInfo = decoder.info(bytes, { maxOutputBytes: 1 << 30 });
  const clip = decoder.decode(bytes);
  const first: Float32Array = clip.positions(0);
  const triangles: Uint32Array = clip.indices;
  let coordinates = first.length + triangles.length + info.segments[0].rank;
  for (const segment of decoder.segments(bytes)) coordinates += segment.positions.length;
  // @ts-expect-error: positions are a Float32Array
  const wrong: string = clip.positions(0);
  // @ts-expect-error: limits are numbers of bytes
  decoder.info(bytes, { maxOutputBytes: 'lots' });
  return coordinates + info.frameRate + wrong.length;
}

export function describe(error: unknown): DmcErrorCode | 'other' {
  if (error instanceof DmcError) {
    // @ts-expect-error: not one of the spec's codes
    const invented: DmcErrorCode = 'stream-on-fire';
    return invented && error.code;
  }
  return 'other';
}

export function onWorkerReply(reply: WorkerReply): number {
  if ('error' in reply) return reply.error.code === 'trap' ? -1 : 0;
  if ('segment' in reply) return reply.positions.length;
  if ('info' in reply) return reply.info.vertexCount;
  return 0;
}

export async function play(scene: Scene, url: string): Promise<AnimationMixer> {
  const loader = new DMCLoader().setMode('auto').setLimits({ maxMatrixBytes: 1 << 30 });
  const { mesh, clip, mode }: DMCResult = await loader.loadAsync(url);
  scene.add(mesh);
  const mixer = new AnimationMixer(mesh);
  mixer.clipAction(clip).play();
  // @ts-expect-error: 'auto' is resolved in the result
  const unresolved: typeof mode = 'auto';
  // @ts-expect-error: no such mode
  loader.setMode('skinned');
  return unresolved ? mixer : mixer;
}
