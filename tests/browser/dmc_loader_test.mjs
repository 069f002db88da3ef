// Headless check that web/DMCLoader.js plays a .dmc in three.js: serves dmc_loader.html for each
// FILE:MODE on the command line and checks in Debian's chromium (playwright-core) that the loader
// works in that mode, that what three.js draws at the first, middle and last frame is that frame
// as dmc.js decodes it (within 1e-6 of the mesh's size), and that the picture changes.
// Usage: node dmc_loader_test.mjs DIR FILE.dmc:MODE ... [example:FILE.dmc]   (files under DIR)
import { chromium } from 'playwright-core';
import { createServer } from 'node:http';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, extname } from 'node:path';

// A case example:FILE.dmc plays FILE with DIR/example/index.html instead.
const [root, ...items] = process.argv.slice(2);
const exampleStream = items.find((item) => item.startsWith('example:'))?.slice(8);
const cases = items.filter((item) => !item.startsWith('example:'));
const types = { '.html': 'text/html', '.js': 'text/javascript', '.wasm': 'application/wasm' };
const server = createServer((request, response) => {
  const name = decodeURIComponent(new URL(request.url, 'http://x').pathname).replace(/^\/+/, '');
  if (name.includes('..')) { response.writeHead(404); response.end(); return; }
  try {
    const body = readFileSync(join(root, name));
    response.writeHead(200, { 'Content-Type': types[extname(name)] ?? 'application/octet-stream' });
    response.end(body);
  } catch {
    response.writeHead(404);
    response.end();
  }
});
await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
const base = `http://127.0.0.1:${server.address().port}/`;
const userDataDir = mkdtempSync(join(tmpdir(), 'dmc-chromium-'));
let failed = false;
function check(condition, what) {
  console.log(`${condition ? 'ok' : 'FAILED'}: ${what}`);
  if (!condition) failed = true;
}
let context;
try {
  context = await chromium.launchPersistentContext(userDataDir, {
    executablePath: '/usr/bin/chromium',
    headless: true,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
           '--disable-background-networking', '--disable-component-update', '--disable-sync',
           '--enable-unsafe-swiftshader'],
  });
  for (const item of cases) {
    const [file, mode] = item.split(':');
    const page = await context.newPage();
    const problems = [];
    page.on('pageerror', (error) => problems.push(error.message));
    await page.goto(`${base}dmc_loader.html?dmc=${encodeURIComponent(file)}&mode=${mode}`);
    await page.waitForFunction(() => window.dmcLoader && (window.dmcLoader.ready || window.dmcLoader.error),
                               null, { timeout: 120000 });
    const state = await page.evaluate(() => window.dmcLoader);
    check(!state.error && problems.length === 0, `${file} (${mode}): DMCLoader loads it (${state.error ?? problems[0] ?? 'no error'})`);
    if (state.error) continue;
    check(state.mode === mode, `${file}: played as ${state.mode} (${state.info.vertexCount} V, ${state.info.frameCount} F, loaded in ${state.loadMs.toFixed(0)} ms)`);
    const errors = state.samples.map((sample) => sample.drawn.reduce((worst, v, i) =>
      Math.max(worst, Math.hypot(...v.map((x, c) => x - sample.expected[i][c]))), 0) / state.size);
    check(Math.max(...errors) <= 1e-6,
          `${file} (${mode}): drawn frames ${state.samples.map((s) => s.frame).join(', ')} within ` +
          `${errors.map((e) => e.toExponential(2)).join(', ')} of the mesh's size of the decoded ones`);
    const w = state.worker;
    check(!w.error && w.equal && w.frames === state.info.frameCount,
          `${file} (${mode}): a Web Worker decodes the same ${w.frames} frames in ${w.segments} segment(s)` +
          (w.error ? ` (${w.error})` : ''));
    const [start, middle] = state.samples;
    check(start.picture.lit > 0.001, `${file} (${mode}): the mesh is drawn (${(100 * start.picture.lit).toFixed(2)} % lit)`);
    check(start.picture.sum !== middle.picture.sum, `${file} (${mode}): the picture changes as the clip plays`);
    await page.close();
  }
  // The README's whole page (web/example/index.html), served beside three's build and the
  // package: it loads without an error and the animation moves on screen.
  if (exampleStream) {
    const page = await context.newPage();
    const problems = [];
    page.on('pageerror', (error) => problems.push(error.message));
    page.on('console', (message) => { if (message.type() === 'error') problems.push(message.text()); });
    await page.setViewportSize({ width: 480, height: 360 });
    await page.goto(`${base}example/index.html?src=${encodeURIComponent(exampleStream)}`);
    await page.waitForFunction(() => document.querySelector('canvas'), null, { timeout: 60000 });
    await page.waitForTimeout(300);
    const first = await page.screenshot();
    await page.waitForTimeout(400);
    const second = await page.screenshot({ path: join(root, 'example.png') });
    check(problems.length === 0, `web/example/index.html plays ${exampleStream} without an error (${problems[0] ?? 'none'})`);
    check(!first.equals(second), 'web/example/index.html: the picture changes as the clip plays');
    await page.close();
  }
} finally {
  await context?.close();
  server.close();
  rmSync(userDataDir, { recursive: true, force: true });
}
process.exit(failed ? 1 : 0);
