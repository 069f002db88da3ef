// Headless check of the dmc viewer served by `dmc view`: Debian's chromium driven by
// playwright-core loads the page, waits for the first rendered frame, checks that both canvases
// show something other than the background, that the slider changes the frame (and the picture),
// that stepping, wireframe, the colour scale and the timeline work, and saves a screenshot.
// Usage: node viewer_test.mjs URL SCREENSHOT.png
import { chromium } from 'playwright-core';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';

const [url, screenshot] = process.argv.slice(2);
if (!url || !screenshot) {
  console.error('usage: node viewer_test.mjs URL SCREENSHOT.png');
  process.exit(2);
}
const userDataDir = mkdtempSync(join(tmpdir(), 'dmc-chromium-'));

function check(condition, what) {
  if (!condition) throw new Error(`check failed: ${what}`);
  console.log(`ok: ${what}`);
}

let context;
try {
  context = await chromium.launchPersistentContext(userDataDir, {
    executablePath: '/usr/bin/chromium',
    headless: true,
    viewport: { width: 1280, height: 800 },
    args: [
      '--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync',
      // WebGL without a GPU: recent Chromium only falls back to SwiftShader when told to.
      '--enable-unsafe-swiftshader',
    ],
  });
  const page = context.pages()[0] ?? await context.newPage();
  const problems = [];
  page.on('pageerror', (error) => problems.push(`page error: ${error.message}`));
  page.on('console', (message) => {
    if (message.type() === 'error') problems.push(`console error: ${message.text()}`);
  });
  await page.goto(url);
  await page.waitForFunction(() => window.dmcViewer && (window.dmcViewer.ready || window.dmcViewer.error),
                             null, { timeout: 60000 });
  const error = await page.evaluate(() => window.dmcViewer.error ?? null);
  check(error === null, `viewer loaded without error (${error ?? 'none'})`);

  // Fraction of a canvas's pixels that differ from the background colour (48, 51, 56), and a
  // checksum of the picture.
  const inspect = (id) => page.evaluate((canvasId) => {
    const canvas = document.getElementById(canvasId);
    const copy = document.createElement('canvas');
    copy.width = canvas.width;
    copy.height = canvas.height;
    const context2d = copy.getContext('2d');
    context2d.drawImage(canvas, 0, 0);
    const { data } = context2d.getImageData(0, 0, copy.width, copy.height);
    let differing = 0, painted = 0, checksum = 0;
    for (let i = 0; i < data.length; i += 4) {
      if (data[i + 3] > 0) ++painted;
      const distance = Math.abs(data[i] - 48) + Math.abs(data[i + 1] - 51) + Math.abs(data[i + 2] - 56);
      if (distance > 24) ++differing;
      checksum = (checksum * 31 + data[i] + 7 * data[i + 1] + 13 * data[i + 2]) >>> 0;
    }
    const pixels = data.length / 4;
    return { width: canvas.width, height: canvas.height, covered: differing / pixels, painted: painted / pixels, checksum };
  }, id);

  // Pause, go to frame 0, let it render.
  await page.click('#play');
  const setFrame = async (f) => {
    await page.evaluate((frame) => {
      const slider = document.getElementById('slider');
      slider.value = String(frame);
      slider.dispatchEvent(new Event('input'));
    }, f);
    await page.waitForFunction((frame) => window.dmcViewer.renderedFrame === frame, f);
    await page.evaluate(() => new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve))));
  };
  await setFrame(0);
  const source = await page.evaluate(() => ({ source: window.dmcViewer.source, ms: window.dmcViewer.decodeMs }));
  if (process.env.DMC_EXPECT_WASM === '1') {
    check(source.source === 'wasm', `the page decoded the stream with the WebAssembly decoder (${source.source}, ${source.ms?.toFixed(0)} ms)`);
  }
  const frames = await page.evaluate(() => window.dmcViewer.frames);
  check(frames > 1, `the sequence has ${frames} frames`);
  const original0 = await inspect('original');
  const decoded0 = await inspect('decoded');
  check(original0.width > 0 && original0.covered > 0.005,
        `original canvas is not empty (${(100 * original0.covered).toFixed(2)}% covered)`);
  check(decoded0.width > 0 && decoded0.covered > 0.005,
        `decoded canvas is not empty (${(100 * decoded0.covered).toFixed(2)}% covered)`);

  const last = frames - 1;
  await setFrame(last);
  const shown = await page.evaluate(() => ({ frame: window.dmcViewer.frame, label: document.getElementById('frame-label').textContent, body: document.body.dataset.frame }));
  check(shown.frame === last && shown.body === String(last), `the slider moved to frame ${last} (${shown.label})`);
  const decodedLast = await inspect('decoded');
  const originalLast = await inspect('original');
  check(decodedLast.checksum !== decoded0.checksum && originalLast.checksum !== original0.checksum,
        'both pictures changed with the frame');
  const statsText = await page.evaluate(() => document.getElementById('stats').textContent);
  check(/bpfv/.test(statsText) && /KG contribution/.test(statsText) && /STED/.test(statsText),
        'frame KG/STED and bpfv are shown');

  // Single-frame stepping: the buttons and the arrow keys, wrapping at the ends.
  const frameShown = async (f) => {
    await page.waitForFunction((frame) => window.dmcViewer.renderedFrame === frame, f, { timeout: 10000 });
    return page.evaluate(() => window.dmcViewer.frame);
  };
  await page.click('#next');
  check(await frameShown(0) === 0, 'next on the last frame wraps to frame 0');
  await page.click('#next');
  check(await frameShown(1) === 1, 'next steps to frame 1');
  await page.click('#previous');
  check(await frameShown(0) === 0, 'previous steps back to frame 0');
  await page.focus('#slider');
  await page.evaluate(() => document.activeElement.blur());
  await page.keyboard.press('ArrowRight');
  check(await frameShown(1) === 1, 'the right arrow key steps to frame 1');
  await page.keyboard.press('ArrowLeft');
  check(await frameShown(0) === 0, 'the left arrow key steps back to frame 0');
  check(await page.evaluate(() => window.dmcViewer.playing) === false, 'stepping keeps playback paused');
  await page.evaluate(() => new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve))));
  const stepped0 = await inspect('decoded');

  // Wireframe: the picture changes, and comes back when it is switched off.
  await page.click('#wireframe');
  await page.evaluate(() => new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve))));
  const wire = await inspect('decoded');
  check(await page.evaluate(() => window.dmcViewer.wireframe) && wire.checksum !== stepped0.checksum,
        `wireframe changes the picture (${(100 * wire.covered).toFixed(2)}% covered)`);
  await page.click('#wireframe');
  await page.evaluate(() => new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve))));
  check((await inspect('decoded')).checksum === stepped0.checksum, 'switching wireframe off restores the picture');

  // Colour scale: a percentile is at most the largest error, and each mode recolours the mesh.
  const scaleOf = () => page.evaluate(() => ({ mode: window.dmcViewer.scaleMode, scale: window.dmcViewer.scale,
                                                legend: document.getElementById('legend-max').textContent }));
  const p99 = await scaleOf();
  check(p99.mode === '99' && p99.scale > 0, `the default scale is the 99th percentile (${p99.legend})`);
  await page.selectOption('#scale-mode', 'max');
  await page.evaluate(() => new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve))));
  const largest = await scaleOf();
  const maxPicture = await inspect('decoded');
  check(largest.scale >= p99.scale && maxPicture.checksum !== stepped0.checksum,
        `the largest-error scale (${largest.legend}) is at least the 99th percentile and recolours the mesh`);
  await page.fill('#scale-value', '0.05');
  await page.evaluate(() => new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve))));
  const manual = await scaleOf();
  check(manual.mode === 'manual' && Math.abs(manual.scale - 0.0005) < 1e-12 && /^0\.0500%/.test(manual.legend),
        `a typed value fixes the scale (${manual.legend})`);
  await page.selectOption('#scale-mode', '99');
  await page.evaluate(() => new Promise((resolve) => requestAnimationFrame(() => requestAnimationFrame(resolve))));
  check((await inspect('decoded')).checksum === stepped0.checksum, 'back to the 99th percentile gives the first picture');

  // Timeline: drawn, and a click at three quarters of its width goes to that frame.
  const timeline = await inspect('timeline');
  // Its 2D canvas is transparent where nothing is drawn: curves, labels and cursor paint a little.
  check(timeline.width > 0 && timeline.painted > 0.005 && timeline.painted < 0.5,
        `the timeline is drawn (${(100 * timeline.painted).toFixed(2)}% painted)`);
  const box = await page.locator('#timeline').boundingBox();
  await page.mouse.click(box.x + 0.75 * box.width, box.y + box.height / 2);
  const expected = Math.round(0.75 * (frames - 1));
  const seeked = await page.evaluate(() => window.dmcViewer.frame);
  check(Math.abs(seeked - expected) <= 1, `a click on the timeline goes to frame ${seeked} (expected about ${expected})`);
  await frameShown(seeked);

  await page.screenshot({ path: screenshot });
  console.log(`screenshot: ${screenshot}`);
  check(problems.length === 0, `no page errors${problems.length ? ': ' + problems.join('; ') : ''}`);
} catch (error) {
  console.error(error.message ?? error);
  process.exitCode = 1;
} finally {
  if (context) await context.close();
  rmSync(userDataDir, { recursive: true, force: true });
}
