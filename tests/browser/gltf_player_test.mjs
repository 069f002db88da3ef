// Headless check that three.js plays dmc's GLB output: serves gltf_player.html with each GLB named
// on the command line, and checks in Debian's chromium (via playwright-core) that GLTFLoader loads
// it without error, that it has the expected clips, that the first clip's morph targets move a
// vertex and change the picture between its start and its middle, and, for NAME.glb:CLIPS:REF.glb,
// that what three.js draws of NAME (sampled vertices at the first clip's start, middle and end)
// is within 1e-4 of the scene's size of what it draws of REF (the same stream in float32).
// Usage: node gltf_player_test.mjs DIR NAME.glb:CLIPS[:REF.glb] ...   (files under DIR)
import { chromium } from 'playwright-core';
import { createServer } from 'node:http';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, extname } from 'node:path';

const [root, ...cases] = process.argv.slice(2);
const types = { '.html': 'text/html', '.js': 'text/javascript', '.glb': 'model/gltf-binary' };
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
  const states = new Map();
  for (const item of cases) {
    const [file, clips] = item.split(':');
    const page = await context.newPage();
    const problems = [];
    page.on('pageerror', (error) => problems.push(error.message));
    await page.goto(`${base}gltf_player.html?glb=${encodeURIComponent(file)}`);
    await page.waitForFunction(() => window.dmcPlayer && (window.dmcPlayer.ready || window.dmcPlayer.error),
                               null, { timeout: 120000 });
    const state = await page.evaluate(() => window.dmcPlayer);
    check(!state.error && problems.length === 0,
          `${file}: GLTFLoader loads it (${state.error ?? problems[0] ?? 'no error'})`);
    if (state.error) continue;
    check(state.clips.length === Number(clips),
          `${file}: ${state.clips.length} clip(s) (${state.clips.map((c) => c.name).join(', ')}), expected ${clips}`);
    check(state.morphTargets > 0, `${file}: a mesh with ${state.morphTargets} morph targets`);
    const [start, middle] = state.samples;
    const moved = start.vertex && middle.vertex &&
                  Math.hypot(...start.vertex.map((x, i) => x - middle.vertex[i])) > 0;
    check(moved, `${file}: the first clip moves vertex 0 (${JSON.stringify(start.vertex)} -> ${JSON.stringify(middle.vertex)})`);
    check(start.picture.lit > 0.001, `${file}: the mesh is drawn (${(100 * start.picture.lit).toFixed(2)} % lit)`);
    check(start.picture.sum !== middle.picture.sum, `${file}: the picture changes as the clip plays`);
    states.set(file, state);
    await page.close();
  }
  for (const item of cases) {
    const [file, , reference] = item.split(':');
    if (!reference) continue;
    const a = states.get(file), b = states.get(reference);
    if (!a || !b) {
      check(false, `${file} against ${reference}: both loaded`);
      continue;
    }
    let worst = 0;
    a.samples.forEach((sample, s) => sample.vertices.forEach((v, i) => {
      worst = Math.max(worst, Math.hypot(...v.map((x, c) => x - b.samples[s].vertices[i][c])));
    }));
    check(a.samples[0].vertices.length > 0 && worst <= 1e-4 * b.size,
          `${file} against ${reference}: drawn vertices within ${(worst / b.size).toExponential(2)} of the scene's size`);
  }
} finally {
  await context?.close();
  server.close();
  rmSync(userDataDir, { recursive: true, force: true });
}
process.exit(failed ? 1 : 0);
