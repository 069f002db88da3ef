// A module Web Worker that decodes .dmc streams off the page's thread:
//   const worker = new Worker(new URL('./dmc_worker.js', import.meta.url), { type: 'module' });
//   worker.postMessage({ id: 1, bytes });            // bytes: ArrayBuffer (transferred) or view
//   worker.onmessage = ({ data }) => { ... };
// It answers, per request id: { id, info, indices } first, then { id, segment, firstFrame,
// frameCount, positions } per segment in order (positions: a Float32Array whose buffer is
// transferred), then { id, done: true }; or { id, error: { code, message } } (DmcError's code, or
// "trap" for any other exception). After the module aborts (out of memory) the next request gets
// a new one.
import { createDecoder, DmcError } from './dmc.js';

let decoder = createDecoder();

self.onmessage = async ({ data }) => {
  const { id, bytes, limits } = data;
  let dmc = null;
  try {
    dmc = await decoder;
    const view = bytes instanceof ArrayBuffer ? new Uint8Array(bytes) : bytes;
    self.postMessage({ id, info: dmc.info(view, limits), indices: dmc.triangles(view, limits) });
    for (const s of dmc.segments(view, limits)) {
      self.postMessage({ id, segment: s.index, firstFrame: s.firstFrame, frameCount: s.frameCount,
                         positions: s.positions }, [s.positions.buffer]);
    }
    self.postMessage({ id, done: true });
  } catch (error) {
    if (dmc?.trapped) decoder = createDecoder();  // an aborted module is not used again
    const code = error instanceof DmcError ? error.code : 'trap';
    self.postMessage({ id, error: { code, message: String(error?.message ?? error) } });
  }
};
