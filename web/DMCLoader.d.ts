// Types of DMCLoader.js, the three.js loader of .dmc streams.
import { AnimationClip, Loader, LoadingManager, Mesh } from 'three';
import { DecoderLimits, SegmentInfo } from './dmc.js';

export type DMCLoaderMode = 'auto' | 'morph' | 'buffer';

export interface DMCResult {
  /** In 'buffer' mode it also has a numeric `dmcFrame` property, which the clip's track drives. */
  mesh: Mesh;
  clip: AnimationClip;
  /** The mode used ('auto' resolved). */
  mode: 'morph' | 'buffer';
  info: { vertexCount: number; frameCount: number; frameRate: number; segments: SegmentInfo[] };
}

export class DMCLoader extends Loader<DMCResult> {
  constructor(manager?: LoadingManager);
  mode: DMCLoaderMode;
  limits: DecoderLimits | undefined;
  setMode(mode: DMCLoaderMode): this;
  setLimits(limits: DecoderLimits | undefined): this;
  load(url: string, onLoad: (result: DMCResult) => void, onProgress?: (event: ProgressEvent) => void,
       onError?: (error: unknown) => void): void;
  parse(buffer: ArrayBuffer): Promise<DMCResult>;
}
