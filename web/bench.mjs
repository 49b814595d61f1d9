// One Web Worker against the native binary on one thread, same scene and settings, in
// alternating rounds; prints the medians and their ratio. `npm run bench` (after `npm run
// build` and `cargo build --release -p glint`); ROUNDS, WIDTH, HEIGHT, SPP and SCENE (a file
// under web/scenes/, also an example of the page) change the defaults.
import { spawnSync } from 'node:child_process';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { serve } from './serve.mjs';

const web = path.dirname(fileURLToPath(import.meta.url));
const repo = path.dirname(web);
const glint = path.join(process.env.CARGO_TARGET_DIR ?? path.join(repo, 'target'), 'release', 'glint');
const rounds = Number(process.env.ROUNDS ?? 5);
const settings = {
  width: Number(process.env.WIDTH ?? 400),
  height: Number(process.env.HEIGHT ?? 300),
  spp: Number(process.env.SPP ?? 16),
};
const examples = { 'three_spheres.xml': 0, 'textured/textured.xml': 1 };
const scene = process.env.SCENE ?? 'three_spheres.xml';

function nativeSeconds(output) {
  const run = spawnSync(glint, ['render', path.join(web, 'scenes', scene), '-o', output,
    '-w', String(settings.width), '-h', String(settings.height), '-r', String(settings.spp), '-n', '1'],
  { encoding: 'utf8' });
  const match = run.stderr.match(/ in ([0-9.]+) s:/);
  if (run.status !== 0 || !match) throw new Error(`glint failed: ${run.stderr}`);
  return Number(match[1]);
}

async function pageSeconds(page) {
  await page.click('#render');
  await page.waitForSelector('#status[data-state="done"]', { timeout: 600_000 });
  return {
    seconds: Number(await page.getAttribute('#elapsed', 'data-seconds')),
    firstPixelMs: Number(await page.getAttribute('#first-pixel', 'data-ms')),
  };
}

const median = (values) => [...values].sort((a, b) => a - b)[Math.floor(values.length / 2)];

const server = await serve(0);
const browser = await chromium.launch({
  executablePath: process.env.CHROMIUM ?? '/usr/bin/chromium',
  headless: true,
  args: ['--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync'],
});
try {
  const page = await browser.newPage();
  await page.goto(`http://127.0.0.1:${server.address().port}/?workers=1`);
  await page.waitForSelector('#status[data-state="idle"]');
  await page.selectOption('#example', String(examples[scene]));
  await page.waitForSelector('#diagnostics[data-state="ok"]');
  await page.fill('#width', String(settings.width));
  await page.fill('#height', String(settings.height));
  await page.fill('#spp', String(settings.spp));
  await page.uncheck('#features'); // the CLI computes feature layers only for an EXR
  const output = path.join(web, 'test-output', 'bench.png');
  const times = { wasm: [], native: [], firstPixelMs: [] };
  for (let round = 0; round < rounds; round += 1) {
    const web1 = await pageSeconds(page);
    times.wasm.push(web1.seconds);
    times.firstPixelMs.push(web1.firstPixelMs);
    times.native.push(nativeSeconds(output));
  }
  const wasm = median(times.wasm);
  const nativeMedian = median(times.native);
  console.log(JSON.stringify({ scene, ...settings, rounds, ...times }));
  console.log(`${scene} ${settings.width}x${settings.height} ${settings.spp} rpp: one worker `
    + `${wasm.toFixed(3)} s, native one thread ${nativeMedian.toFixed(3)} s (medians of ${rounds}), `
    + `wasm/native ${(wasm / nativeMedian).toFixed(2)}x; first pixel ${median(times.firstPixelMs).toFixed(0)} ms`);
} finally {
  await browser.close();
  server.close();
}
