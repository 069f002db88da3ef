// dmc's WebAssembly decoder for browsers, Web Workers and Node (ES module).
//
//   import { createDecoder } from 'dmc-decoder';
//   const decoder = await createDecoder();
//   const info = decoder.info(bytes);            // counts, frame rate, segments
//   const indices = decoder.triangles(bytes);    // Uint32Array, without decoding the frames
//   const clip = decoder.decode(bytes);          // { vertexCount, frameCount, frameRate, indices,
//                                                //   positions(frame) -> Float32Array, ... }
//   for (const s of decoder.segments(bytes)) {}  // segment by segment: { firstFrame, frameCount,
//                                                //   positions: Float32Array }
//
// Errors are DmcError exceptions whose `code` is the spec's error code name
// (bitstream-spec/dmc-format.md §11.1: "corrupt-stream", "truncated-stream", "unsupported", ...).
// The module is built without C++ exceptions, so running out of its 4 GB memory aborts it (a
// WebAssembly trap): that surfaces as DmcError "resource-limit", and the decoder, whose memory may
// be left inconsistent, refuses every later call with "internal" (create a new one). The decoder
// limits (below) refuse the streams that declare too much before anything is allocated.
// The module is single-threaded; decode in a Worker to keep a page responsive.
import createDmcModule from './dmc_decoder.js';

export class DmcError extends Error {
  constructor(code, message) {
    super(`${code}: ${message}`);
    this.name = 'DmcError';
    this.code = code;
  }
}

class Stream {
  constructor(module, bytes, limits = {}) {
    if (!(bytes instanceof Uint8Array)) {
      bytes = bytes instanceof ArrayBuffer ? new Uint8Array(bytes) : new Uint8Array(bytes.buffer);
    }
    this.module = module;
    const pointer = module._malloc(Math.max(1, bytes.length));
    module.HEAPU8.set(bytes, pointer);
    this.handle = module._dmc_open(pointer, bytes.length, limits.maxOutputBytes ?? -1,
                                   limits.maxMatrixBytes ?? -1);
    module._free(pointer);
    if (!this.handle) throw lastError(module);
    this.info = JSON.parse(module.UTF8ToString(module._dmc_info_json(this.handle)));
  }
  triangles() {
    const count = 3 * this.info.triangleCount;
    const at = this.module._dmc_triangles(this.handle) >>> 2;
    return Uint32Array.from(this.module.HEAP32.subarray(at, at + count));
  }
  // Segment `index`'s positions, copied out of the module's memory.
  segment(index) {
    const pointer = this.module._dmc_decode_segment(this.handle, index);
    if (!pointer) throw lastError(this.module);
    const { frameCount } = this.info.segments[index];
    const count = frameCount * this.info.vertexCount * 3;
    return this.module.HEAPF32.slice(pointer >>> 2, (pointer >>> 2) + count);
  }
  close() {
    if (this.handle) this.module._dmc_close(this.handle);
    this.handle = 0;
  }
}

function lastError(module) {
  return new DmcError(module.UTF8ToString(module._dmc_last_error_code()),
                      module.UTF8ToString(module._dmc_last_error_message()));
}

// Runs `body` on the decoder's module, turning a trap into a DmcError and retiring the module.
function guarded(decoder, body) {
  if (decoder.trapped) {
    throw new DmcError('internal', `this decoder aborted earlier (${decoder.trapped}); create a new one`);
  }
  try {
    return body();
  } catch (error) {
    if (error instanceof WebAssembly.RuntimeError) {
      decoder.trapped ??= String(error.message);
      throw new DmcError('resource-limit', `the WebAssembly decoder aborted (out of memory?): ${decoder.trapped}`);
    }
    if (error instanceof RangeError && /allocat|length/i.test(error.message)) {  // a typed array
      throw new DmcError('resource-limit', `out of JavaScript memory: ${error.message}`);
    }
    throw error;
  }
}

export class Decoder {
  constructor(module) {
    this.module = module;
    this.trapped = null;  // the abort's message once the module has trapped
  }

  // The stream's description without decoding its segments. `limits` (every method):
  // { maxOutputBytes, maxMatrixBytes }, as the native DecoderOptions (default 4 GiB each, 0: no
  // limit): a stream declaring more is refused with "resource-limit" before anything is built.
  info(bytes, limits) {
    return guarded(this, () => {
      const stream = new Stream(this.module, bytes, limits);
      try {
        return stream.info;
      } finally {
        stream.close();
      }
    });
  }

  // The triangles (three vertex indices each), without decoding the segments.
  triangles(bytes, limits) {
    return guarded(this, () => {
      const stream = new Stream(this.module, bytes, limits);
      try {
        return stream.triangles();
      } finally {
        stream.close();
      }
    });
  }

  // Every segment in turn (the first frames are there before the last segment is decoded).
  * segments(bytes, limits) {
    const stream = guarded(this, () => new Stream(this.module, bytes, limits));
    try {
      for (let s = 0; s < stream.info.segments.length; ++s) {
        const { firstFrame, frameCount } = stream.info.segments[s];
        yield { index: s, firstFrame, frameCount, positions: guarded(this, () => stream.segment(s)) };
      }
    } finally {
      if (!this.trapped) stream.close();  // an aborted module cannot free anything
    }
  }

  // The whole sequence.
  decode(bytes, limits) {
    return guarded(this, () => this.#decodeAll(bytes, limits));
  }

  #decodeAll(bytes, limits) {
    const stream = new Stream(this.module, bytes, limits);
    try {
      const { vertexCount, frameCount, frameRate, name, segments } = stream.info;
      const indices = stream.triangles();
      const all = new Float32Array(frameCount * vertexCount * 3);
      segments.forEach((segment, s) => all.set(stream.segment(s), segment.firstFrame * vertexCount * 3));
      const size = vertexCount * 3;
      return {
        vertexCount, frameCount, frameRate, name, segments, indices,
        positions(frame) {
          if (!(frame >= 0 && frame < frameCount)) throw new RangeError(`no frame ${frame}`);
          return all.subarray(frame * size, (frame + 1) * size);
        },
      };
    } finally {
      stream.close();
    }
  }
}

export async function createDecoder(moduleOptions = {}) {
  const options = { ...moduleOptions };
  if (!options.wasmBinary && typeof process === 'object' && process.versions?.node) {
    // Under Node the module cannot fetch its .wasm (see web/CMakeLists.txt): read it here.
    const { readFile } = await import('node:fs/promises');
    options.wasmBinary = await readFile(new URL('./dmc_decoder.wasm', import.meta.url));
  }
  return new Decoder(await createDmcModule(options));
}
