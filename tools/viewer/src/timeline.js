// The per-frame timeline under the views: each frame's KG contribution and spatial STED as two
// curves, each scaled to its own largest value (printed in the legend), and a cursor at the frame
// shown. Kept free of three.js; drawn on a 2D canvas.

const KG_COLOUR = '#ffb060', STED_COLOUR = '#60c0ff', CURSOR_COLOUR = '#f0f0f0';

export class Timeline {
  // frames: metrics.json's distortion.frames ([{ kg, sted_s }]), or null without an original.
  constructor(canvas, frames, frameCount) {
    this.canvas = canvas;
    this.frames = frames;
    this.frameCount = frameCount;
    this.kgMax = frames ? Math.max(...frames.map((f) => f.kg), 1e-30) : 0;
    this.stedMax = frames ? Math.max(...frames.map((f) => f.sted_s), 1e-30) : 0;
  }

  // The frame under a click at clientX.
  frameAt(clientX) {
    const box = this.canvas.getBoundingClientRect();
    const t = Math.min(Math.max((clientX - box.left) / Math.max(box.width, 1), 0), 1);
    return Math.round(t * (this.frameCount - 1));
  }

  draw(frame) {
    const { canvas } = this;
    const ratio = window.devicePixelRatio || 1;
    const width = Math.floor(canvas.clientWidth * ratio), height = Math.floor(canvas.clientHeight * ratio);
    if (canvas.width !== width || canvas.height !== height) {
      canvas.width = width;
      canvas.height = height;
    }
    const g = canvas.getContext('2d');
    g.clearRect(0, 0, width, height);
    const top = 16 * ratio, bottom = height - 4 * ratio;
    const x = (f) => (this.frameCount > 1 ? (f / (this.frameCount - 1)) * (width - 1) : width / 2);
    const y = (value, max) => bottom - (value / max) * (bottom - top);
    g.font = `${11 * ratio}px system-ui, sans-serif`;
    if (this.frames) {
      const curve = (key, max, colour) => {
        g.strokeStyle = colour;
        g.lineWidth = 1.5 * ratio;
        g.beginPath();
        this.frames.forEach((f, i) => (i === 0 ? g.moveTo(x(i), y(f[key], max)) : g.lineTo(x(i), y(f[key], max))));
        g.stroke();
      };
      curve('kg', this.kgMax, KG_COLOUR);
      curve('sted_s', this.stedMax, STED_COLOUR);
      g.fillStyle = KG_COLOUR;
      g.fillText(`KG contribution (max ${this.kgMax.toPrecision(3)})`, 4 * ratio, 12 * ratio);
      g.fillStyle = STED_COLOUR;
      g.fillText(`STED_s (max ${this.stedMax.toPrecision(3)})`, width / 2, 12 * ratio);
    } else {
      g.fillStyle = '#909090';
      g.fillText('no original: no per-frame distortion', 4 * ratio, 12 * ratio);
    }
    g.strokeStyle = CURSOR_COLOUR;
    g.lineWidth = 1 * ratio;
    g.beginPath();
    g.moveTo(x(frame), top - 2 * ratio);
    g.lineTo(x(frame), bottom);
    g.stroke();
  }
}
