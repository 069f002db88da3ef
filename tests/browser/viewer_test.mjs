// Headless check of the dmc viewer served by `dmc view`: Debian's chromium driven by
// playwright-core loads the page, waits for the first rendered frame, checks that both canvases
// show something other than the background, that the slider changes the frame (and the picture),
// and saves a screenshot.
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
    let differing = 0, checksum = 0;
    for (let i = 0; i < data.length; i += 4) {
      const distance = Math.abs(data[i] - 48) + Math.abs(data[i + 1] - 51) + Math.abs(data[i + 2] - 56);
      if (distance > 24) ++differing;
      checksum = (checksum * 31 + data[i] + 7 * data[i + 1] + 13 * data[i + 2]) >>> 0;
    }
    return { width: canvas.width, height: canvas.height, covered: differing / (data.length / 4), checksum };
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
