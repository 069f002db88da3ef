// Types of dmc.js, the WebAssembly decoder's ES module (see the comments there for behaviour).

/** The spec's error code names (bitstream-spec/dmc-format.md §11.1). */
export type DmcErrorCode =
  | 'invalid-argument' | 'io-error' | 'parse-error' | 'invalid-sequence' | 'mismatch'
  | 'unsupported' | 'corrupt-stream' | 'truncated-stream' | 'numerical-failure' | 'not-found'
  | 'internal' | 'resource-limit' | 'unknown';

/** Every refusal of a stream; `message` starts with the code. */
export class DmcError extends Error {
  constructor(code: DmcErrorCode, message: string);
  readonly name: 'DmcError';
  readonly code: DmcErrorCode;
}

/** The decoder's resource limits, as the native DecoderOptions: bytes, 0 for none, default 4 GiB. */
export interface DecoderLimits {
  maxOutputBytes?: number;
  maxMatrixBytes?: number;
}

export interface SegmentInfo {
  firstFrame: number;
  frameCount: number;
  rank: number;
  /** The Laplace operator's registry name, e.g. "ddl". */
  operator: string;
}

export interface StreamInfo {
  /** "major.minor" of the format. */
  version: string;
  vertexCount: number;
  triangleCount: number;
  frameCount: number;
  /** Frames per second; 0 when the stream does not say. */
  frameRate: number;
  name: string;
  bytes: number;
  /** Bytes of the embedded glTF scene (0 without one). */
  sceneBytes: number;
  segments: SegmentInfo[];
}

export interface DecodedSegment {
  index: number;
  firstFrame: number;
  frameCount: number;
  /** frameCount × vertexCount × 3 coordinates, frame by frame, vertex by vertex. */
  positions: Float32Array;
}

export interface DecodedSequence {
  vertexCount: number;
  frameCount: number;
  frameRate: number;
  name: string;
  segments: SegmentInfo[];
  /** Three vertex indices per triangle. */
  indices: Uint32Array;
  /** One frame's vertexCount × 3 coordinates (a view, not a copy); RangeError outside the sequence. */
  positions(frame: number): Float32Array;
}

export type StreamBytes = Uint8Array | ArrayBuffer | ArrayBufferView;

/**
 * A trap of the WebAssembly module (out of its memory) is thrown as DmcError "resource-limit";
 * the decoder then refuses every call with "internal" and `trapped` holds the abort's message.
 */
export class Decoder {
  readonly trapped: string | null;
  info(bytes: StreamBytes, limits?: DecoderLimits): StreamInfo;
  triangles(bytes: StreamBytes, limits?: DecoderLimits): Uint32Array;
  /** Segment by segment: the first frames are there before the last segment is decoded. */
  segments(bytes: StreamBytes, limits?: DecoderLimits): Generator<DecodedSegment, void, undefined>;
  decode(bytes: StreamBytes, limits?: DecoderLimits): DecodedSequence;
}

/** Emscripten module options, e.g. `{ wasmBinary }` or `{ locateFile }`. */
export interface ModuleOptions {
  wasmBinary?: ArrayBuffer | Uint8Array;
  locateFile?: (path: string, prefix: string) => string;
  [option: string]: unknown;
}

export function createDecoder(moduleOptions?: ModuleOptions): Promise<Decoder>;

/** What dmc_worker.js posts back for a request `{ id, bytes, limits? }`. */
export type WorkerReply =
  | { id: unknown; info: StreamInfo; indices: Uint32Array }
  | { id: unknown; segment: number; firstFrame: number; frameCount: number; positions: Float32Array }
  | { id: unknown; done: true }
  | { id: unknown; error: { code: DmcErrorCode | 'trap'; message: string } };
