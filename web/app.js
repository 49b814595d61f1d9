// The page: choose or drop a scene or a glTF model, check it with the renderer (diagnostics as
// the CLI prints them), render it in tiles on a pool of Web Workers (the path tracers in passes
// over the whole image, optionally to a time budget), and download the image encoded by the same
// Rust code as the CLI's. A render starts with a coarse preview of the whole image (1/8 of its
// width and height, one sample per pixel, drawn in 8x8 blocks) that its tiles then replace.
import init, { Files, Settings, load_bytes as loadBytes } from './pkg/glint_wasm.js';
import { makeSettings } from './settings.js';

const EXAMPLES = [
  { name: 'Three spheres', root: 'scenes/', scene: 'three_spheres.xml', assets: [] },
  {
    name: 'Textured sphere and OBJ pyramid',
    root: 'scenes/',
    scene: 'textured/textured.xml',
    assets: ['textured/images/checker.png', 'textured/objFiles/pyramid.obj'],
  },
];
const TILE = 32;
// The preview's pixels stand for PREVIEW x PREVIEW blocks of the image: 1/64 of its samples (at
// one sample per pixel), so it is on screen in a small share of a pass's time.
const PREVIEW = 8;
// No preview for images of at most this many tiles: they are on screen about as soon.
const PREVIEW_MIN_TILES = 4;
// Pixels in a strip of the preview (a quarter of a tile).
const PREVIEW_STRIP = (TILE * TILE) / 4;
// The longest time budget, as `glint render --time` takes: a year.
const MAX_TIME_BUDGET = 365 * 24 * 3600;
const SCENE_FILE = /\.(xml|json|gltf|glb)$/i;
// A GLB is binary: it is loaded from the dropped bytes and its text is not shown or edited.
const BINARY_SCENE = /\.glb$/i;

const $ = (id) => document.getElementById(id);
const ui = {
  example: $('example'), dropZone: $('drop-zone'), openFiles: $('open-files'),
  openFolder: $('open-folder'), sceneFile: $('scene-file'), sceneText: $('scene-text'),
  assetList: $('asset-list'), diagnostics: $('diagnostics'), width: $('width'),
  height: $('height'), spp: $('spp'), integrator: $('integrator'), maxDepth: $('max-depth'),
  seed: $('seed'), time: $('time'), background: $('background'), focus: $('focus'),
  aperture: $('aperture'), exposure: $('exposure'), tonemap: $('tonemap'), transfer: $('transfer'),
  features: $('features'), render: $('render'), cancel: $('cancel'),
  downloadPng: $('download-png'), downloadExr: $('download-exr'), status: $('status'),
  progress: $('progress'), tiles: $('tiles'), elapsed: $('elapsed'),
  raysPerSecond: $('rays-per-second'), firstPixel: $('first-pixel'), firstImage: $('first-image'),
  workers: $('workers'),
  canvas: $('canvas'),
};

// The files at hand, by path; the scene is one of them (or text typed into the page).
let files = new Map();
let scenePath = 'scene.xml';
let pool = [];
let render = null; // the render in progress or the last one finished
let jobCounter = 0;
// What the scene last asked of its render (JSON; '{}' for nothing, as course scenes ask).
let sceneAsked = '{}';

const workerCount = Number(new URLSearchParams(location.search).get('workers'))
  || navigator.hardwareConcurrency || 1;

function setStatus(state, text) {
  ui.status.dataset.state = state;
  ui.status.textContent = text;
}

// A render in passes also marks its status with the passes complete and the samples per pixel
// they reached (what the canvas and the downloads hold), for whoever watches it.
function markPass(passes, samples) {
  ui.status.dataset.pass = String(passes);
  ui.status.dataset.samples = String(samples);
}

function startPool() {
  pool = Array.from({ length: workerCount }, () => {
    const worker = new Worker('worker.js', { type: 'module' });
    worker.onmessage = ({ data }) => onWorkerMessage(worker, data);
    worker.onerror = (event) => failRender(`a worker failed: ${event.message}`);
    return worker;
  });
  ui.workers.textContent = String(workerCount);
}

function stopPool() {
  for (const worker of pool) worker.terminate();
  pool = [];
}

// ---- Choosing a scene ----

function setFiles(newFiles) {
  files = newFiles;
  const scenes = [...files.keys()].filter((path) => SCENE_FILE.test(path)).sort(
    (a, b) => a.split('/').length - b.split('/').length || a.localeCompare(b),
  );
  ui.sceneFile.replaceChildren(...scenes.map((path) => new Option(path, path)));
  const others = [...files.keys()].filter((path) => !SCENE_FILE.test(path));
  ui.assetList.textContent = others.length ? `assets: ${others.join(', ')}` : 'no assets';
  if (scenes.length) {
    showScene(scenes[0]);
  } else {
    ui.diagnostics.textContent =
      'error: no scene file (.xml, .json, .gltf or .glb) among the files given';
  }
}

function showScene(path) {
  scenePath = path;
  ui.sceneFile.value = path;
  const binary = BINARY_SCENE.test(path);
  ui.sceneText.readOnly = binary;
  ui.sceneText.value = binary
    ? `(binary glTF, ${files.get(path).length} bytes: rendered as dropped, not editable here)`
    : new TextDecoder().decode(files.get(path));
  checkScene();
}

// What the workers load: the dropped bytes of a GLB, else the (possibly edited) text. Both go
// through bytes, so one loader reads every format.
function sceneBytes() {
  return BINARY_SCENE.test(scenePath)
    ? files.get(scenePath)
    : new TextEncoder().encode(ui.sceneText.value);
}

async function chooseExample(index) {
  const example = EXAMPLES[index];
  // Until the example is in, the diagnostics are not its: whoever waits for them waits on.
  delete ui.diagnostics.dataset.state;
  const names = [example.scene, ...example.assets];
  const bytes = await Promise.all(names.map(async (name) => {
    const response = await fetch(example.root + name);
    if (!response.ok) throw new Error(`cannot fetch ${example.root + name}: ${response.status}`);
    return new Uint8Array(await response.arrayBuffer());
  }));
  setFiles(new Map(names.map((name, i) => [name, bytes[i]])));
}

// Files from a drop: folders walked with webkitGetAsEntry where the browser offers entries,
// else the plain file list.
async function droppedFiles(dataTransfer) {
  const entries = [...dataTransfer.items]
    .map((item) => item.webkitGetAsEntry?.())
    .filter(Boolean);
  const found = new Map();
  if (!entries.length) {
    for (const file of dataTransfer.files) {
      found.set(file.name, new Uint8Array(await file.arrayBuffer()));
    }
    return found;
  }
  const walk = async (entry) => {
    if (entry.isFile) {
      const file = await new Promise((resolve, reject) => entry.file(resolve, reject));
      found.set(entry.fullPath.replace(/^\//, ''), new Uint8Array(await file.arrayBuffer()));
    } else if (entry.isDirectory) {
      const reader = entry.createReader();
      for (;;) {
        const batch = await new Promise((resolve, reject) => reader.readEntries(resolve, reject));
        if (!batch.length) break;
        for (const child of batch) await walk(child);
      }
    }
  };
  for (const entry of entries) await walk(entry);
  return found;
}

async function inputFiles(input) {
  const found = new Map();
  for (const file of input.files) {
    found.set(file.webkitRelativePath || file.name, new Uint8Array(await file.arrayBuffer()));
  }
  return found;
}

// Loads the scene as the workers will, and shows its error or warnings as the CLI prints them.
function checkScene() {
  const assets = new Files();
  for (const [path, bytes] of files) assets.add(path, bytes);
  const loaded = loadBytes(sceneBytes(), scenePath, assets);
  assets.free();
  ui.diagnostics.textContent = loaded.messages.map((message) => message.text).join('\n');
  ui.diagnostics.dataset.state = loaded.ok ? 'ok' : 'error';
  const ok = loaded.ok;
  if (ok) followScene(loaded.scene_settings());
  loaded.free();
  return ok;
}

// The controls show what is rendered, so a scene's own settings (a Mitsuba scene's film size,
// sample count, integrator and depth) go into them, rather than being applied behind values the
// user sees. That happens only when what the scene asks changes (another scene, its film
// edited): a value typed into a control stays until then. Controls the scene leaves alone
// return to the page's defaults, so a course scene opened after a Mitsuba one renders as before.
function followScene(asked) {
  const wanted = {
    width: asked.width,
    height: asked.height,
    spp: asked.samples_per_pixel,
    integrator: asked.integrator,
    maxDepth: asked.max_depth,
  };
  asked.free();
  const key = JSON.stringify(wanted);
  if (key === sceneAsked) return;
  sceneAsked = key;
  const set = (input, value) => {
    input.value = value === undefined ? input.defaultValue : String(value);
  };
  set(ui.width, wanted.width);
  set(ui.height, wanted.height);
  set(ui.spp, wanted.spp);
  set(ui.maxDepth, wanted.maxDepth);
  const options = [...ui.integrator.options];
  ui.integrator.value = wanted.integrator
    ?? (options.find((option) => option.defaultSelected) ?? options[0]).value;
}

// ---- Rendering ----

function readSettings() {
  const integer = (input) => Math.max(Number(input.min || 0), Math.floor(Number(input.value)));
  return {
    width: integer(ui.width),
    height: integer(ui.height),
    spp: integer(ui.spp),
    integrator: ui.integrator.value,
    seed: integer(ui.seed),
    maxDepth: ui.maxDepth.value === '' ? undefined : integer(ui.maxDepth),
    features: ui.features.checked,
    // Seconds, or null for no budget; checked in startRender.
    time: ui.time.value.trim() === '' ? null : Number(ui.time.value),
    // As the CLI's flags: undefined where not given. Checked by glint-wasm (`makeSettings`).
    background: ui.background.value.trim(),
    focus: optionalNumber(ui.focus),
    aperture: optionalNumber(ui.aperture),
    exposure: optionalNumber(ui.exposure),
    tonemap: ui.tonemap.value || undefined,
    transfer: ui.transfer.value || undefined,
  };
}

// A number input's value, undefined when empty; NaN (refused by glint-wasm) when not a number.
function optionalNumber(input) {
  return input.value.trim() === '' ? undefined : Number(input.value);
}

// The preview's size: glint-wasm's `Settings.preview(PREVIEW)`, which the workers render.
function previewSize({ width, height }) {
  return { width: Math.ceil(width / PREVIEW), height: Math.ceil(height / PREVIEW) };
}

// Why these settings cannot render in passes (glint-render's rule, in its words, naming `what`),
// or null when they can. Throws what the workers would for settings that cannot render at all.
function progressiveRefusal(settings, what) {
  const renderSettings = makeSettings(Settings, settings);
  try {
    renderSettings.check_progressive(what);
    return null;
  } catch (error) {
    return String(error);
  } finally {
    renderSettings.free();
  }
}

function startRender() {
  if (render?.running) return;
  if (!BINARY_SCENE.test(scenePath) && ui.sceneText.value.trim() === '') {
    const what = 'no scene to render: choose an example, open a scene file or drop one here';
    ui.diagnostics.textContent = `error: ${what}`;
    ui.diagnostics.dataset.state = 'error';
    setStatus('error', what);
    return;
  }
  if (!checkScene()) {
    setStatus('error', 'the scene has an error: see below the scene text');
    return;
  }
  const settings = readSettings();
  let refusal;
  try {
    if (settings.time !== null && !(settings.time > 0 && settings.time <= MAX_TIME_BUDGET)) {
      throw new Error(`the time budget must be a number of seconds above 0 and at most ${MAX_TIME_BUDGET}`);
    }
    refusal = progressiveRefusal(settings, 'a time budget');
    if (refusal && settings.time !== null) throw new Error(refusal);
  } catch (error) {
    setStatus('error', `the render failed: ${error.message ?? error}`);
    return;
  }
  const { width, height } = settings;
  const tiles = [];
  for (let y0 = 0; y0 < height; y0 += TILE) {
    for (let x0 = 0; x0 < width; x0 += TILE) {
      tiles.push({
        index: tiles.length, x0, y0, x1: Math.min(x0 + TILE, width), y1: Math.min(y0 + TILE, height),
      });
    }
  }
  const pixelCount = width * height;
  // The preview, in strips of its rows ahead of the tiles in the shared queue: strips of about
  // PREVIEW_STRIP pixels, so that the first is on screen in a fraction of a tile's time.
  const preview = tiles.length > PREVIEW_MIN_TILES ? previewSize(settings) : null;
  const previewTiles = [];
  if (preview) {
    const rows = Math.max(1, Math.floor(PREVIEW_STRIP / preview.width));
    for (let y0 = 0; y0 < preview.height; y0 += rows) {
      previewTiles.push({
        preview: true, x0: 0, y0, x1: preview.width, y1: Math.min(y0 + rows, preview.height),
      });
    }
  }
  render = {
    job: ++jobCounter,
    running: true,
    settings,
    tiles,
    queue: [...previewTiles, ...tiles],
    total: tiles.length,
    preview,
    previewLeft: previewTiles.length,
    firstImage: null,
    done: 0,
    // In passes (the path tracers): the pass in flight, the samples per pixel it reaches, and
    // those of the last pass complete (what the image holds). Workers' own queues from pass 2.
    progressive: refusal === null,
    pass: 1,
    target: 1,
    taken: 0,
    passStart: null,
    queues: null,
    rays: 0,
    nonfinite: 0,
    start: performance.now(),
    firstPixel: null,
    pixels: new Float32Array(pixelCount * 3),
    albedo: settings.features ? new Float32Array(pixelCount * 3) : null,
    normal: settings.features ? new Float32Array(pixelCount * 3) : null,
    depth: settings.features ? new Float32Array(pixelCount) : null,
  };
  ui.canvas.width = width;
  ui.canvas.height = height;
  const context = ui.canvas.getContext('2d');
  context.clearRect(0, 0, width, height);
  ui.firstPixel.textContent = '–';
  ui.firstImage.textContent = '–';
  delete ui.firstPixel.dataset.ms;
  delete ui.firstImage.dataset.ms;
  // `pending` until the preview covers the canvas, then `done` (for whoever watches).
  if (preview) ui.canvas.dataset.preview = 'pending';
  else delete ui.canvas.dataset.preview;
  ui.render.disabled = true;
  ui.cancel.disabled = false;
  ui.downloadPng.disabled = true;
  ui.downloadExr.disabled = true;
  delete ui.status.dataset.pass;
  delete ui.status.dataset.samples;
  setStatus('rendering', render.progressive
    ? `rendering pass 1 (1 of ${settings.spp} samples per pixel)…`
    : 'rendering…');
  render.passStart = render.start;
  showProgress();
  const message = {
    type: 'job',
    job: render.job,
    bytes: sceneBytes(),
    path: scenePath,
    files: [...files],
    settings,
    preview: preview ? PREVIEW : null,
  };
  for (const worker of pool) worker.postMessage(message);
  render.timer = setInterval(showProgress, 250);
}

// Hands `worker` its next tile. In passes, pass 1 shares one queue (so the workers balance their
// load) and each tile stays with the worker that took it, which holds its running sums; later
// passes give each worker its own tiles.
function nextTile(worker) {
  const queue = render.queues ? render.queues.get(worker) : render.queue;
  const tile = queue?.shift();
  if (!tile) return;
  if (tile.preview) {
    worker.postMessage({ type: 'preview', job: render.job, tile });
    return;
  }
  if (!render.progressive) {
    worker.postMessage({ type: 'tile', job: render.job, tile });
    return;
  }
  tile.worker = worker;
  worker.postMessage({ type: 'tile', job: render.job, tile: tileBounds(tile), samples: render.target });
}

// A tile as a message carries it: its index and bounds (not its worker).
function tileBounds({ index, x0, y0, x1, y1 }) {
  return { index, x0, y0, x1, y1 };
}

function onWorkerMessage(worker, data) {
  if (!render?.running || data.job !== render.job) return;
  if (data.type === 'ready') {
    nextTile(worker);
  } else if (data.type === 'tile' && data.tile.preview) {
    drawPreview(data);
    nextTile(worker);
  } else if (data.type === 'tile') {
    storeTile(data);
    nextTile(worker);
    if (render.done === render.total) {
      if (render.progressive) passDone();
      else finishRender();
    }
  } else if (data.type === 'failed') {
    failRender(data.error);
  }
}

// A strip of the preview, scaled up to the blocks it stands for and drawn behind what the
// canvas holds ('destination-over'), so that it never covers a tile already rendered.
function drawPreview({ tile, rgb8, rays }) {
  const tileWidth = tile.x1 - tile.x0;
  const tileHeight = tile.y1 - tile.y0;
  const strip = new OffscreenCanvas(tileWidth, tileHeight);
  strip.getContext('2d').putImageData(rgbaImage(rgb8, tileWidth, tileHeight), 0, 0);
  const context = ui.canvas.getContext('2d');
  context.save();
  context.globalCompositeOperation = 'destination-over';
  context.imageSmoothingEnabled = false;
  context.drawImage(strip, tile.x0 * PREVIEW, tile.y0 * PREVIEW, tileWidth * PREVIEW, tileHeight * PREVIEW);
  context.restore();
  render.rays += rays;
  markFirstPixel();
  render.previewLeft -= 1;
  if (render.previewLeft === 0) {
    markFirstImage();
    ui.canvas.dataset.preview = 'done';
  }
}

function rgbaImage(rgb8, width, height) {
  const image = new ImageData(width, height);
  for (let i = 0; i < width * height; i += 1) {
    image.data[i * 4] = rgb8[i * 3];
    image.data[i * 4 + 1] = rgb8[i * 3 + 1];
    image.data[i * 4 + 2] = rgb8[i * 3 + 2];
    image.data[i * 4 + 3] = 255;
  }
  return image;
}

// The first thing on screen (a strip of the preview or a tile).
function markFirstPixel() {
  if (render.firstPixel !== null) return;
  render.firstPixel = performance.now() - render.start;
  ui.firstPixel.textContent = `${render.firstPixel.toFixed(0)} ms`;
  ui.firstPixel.dataset.ms = String(render.firstPixel);
}

// The whole canvas holds an image: the preview's, pass 1's, or the final one.
function markFirstImage() {
  if (render.firstImage !== null) return;
  render.firstImage = performance.now() - render.start;
  ui.firstImage.textContent = `${render.firstImage.toFixed(0)} ms`;
  ui.firstImage.dataset.ms = String(render.firstImage);
}

function storeTile({ tile, rgb8, pixels, albedo, normal, depth, rays, nonfinite }) {
  const { width } = render.settings;
  const tileWidth = tile.x1 - tile.x0;
  const tileHeight = tile.y1 - tile.y0;
  for (let row = 0; row < tileHeight; row += 1) {
    const start = ((tile.y0 + row) * width + tile.x0);
    const from = row * tileWidth;
    render.pixels.set(pixels.subarray(from * 3, (from + tileWidth) * 3), start * 3);
    if (render.albedo) {
      render.albedo.set(albedo.subarray(from * 3, (from + tileWidth) * 3), start * 3);
      render.normal.set(normal.subarray(from * 3, (from + tileWidth) * 3), start * 3);
      render.depth.set(depth.subarray(from, from + tileWidth), start);
    }
  }
  ui.canvas.getContext('2d').putImageData(rgbaImage(rgb8, tileWidth, tileHeight), tile.x0, tile.y0);
  markFirstPixel();
  render.done += 1;
  render.rays += rays;
  render.nonfinite += nonfinite;
}

// Every tile has the pass's samples: the image is whole at `render.target` samples per pixel.
// The next pass doubles the samples (capped at the spp control) unless that was the last, or
// the time budget is spent; with a budget, it also takes no more samples than the last pass's
// time per sample says fit in what is left (at least one), as `glint render --time` does.
function passDone() {
  const now = performance.now();
  const added = render.target - render.taken;
  const perSample = (now - render.passStart) / 1000 / added;
  render.taken = render.target;
  const { spp, time } = render.settings;
  markFirstImage();
  markPass(render.pass, render.taken);
  ui.downloadPng.disabled = false;
  ui.downloadExr.disabled = false;
  const seconds = (now - render.start) / 1000;
  if (render.taken >= spp || (time !== null && seconds >= time)) {
    finishRender();
    return;
  }
  let samples = Math.min(render.taken, spp - render.taken);
  if (time !== null) samples = Math.max(1, Math.min(samples, Math.floor((time - seconds) / perSample)));
  render.pass += 1;
  render.target = render.taken + samples;
  render.passStart = now;
  render.done = 0;
  render.queues = new Map(pool.map((worker) => [worker, []]));
  for (const tile of render.tiles) render.queues.get(tile.worker).push(tile);
  setStatus('rendering', `${passText()}; rendering pass ${render.pass} (${render.target} samples)…`);
  showProgress();
  for (const worker of pool) nextTile(worker);
}

// "pass 3: 4 of 64 samples per pixel": the last pass complete.
function passText() {
  const passes = render.target === render.taken ? render.pass : render.pass - 1;
  return `pass ${passes}: ${render.taken} of ${render.settings.spp} samples per pixel`;
}

function showProgress() {
  const seconds = (performance.now() - render.start) / 1000;
  // In passes, the share of the spp control's samples taken, the pass in flight's tiles included.
  ui.progress.value = render.progressive
    ? (render.taken + (render.target - render.taken) * (render.done / render.total)) / render.settings.spp
    : render.done / render.total;
  ui.tiles.textContent = `${render.done} / ${render.total}`;
  ui.elapsed.textContent = `${seconds.toFixed(2)} s`;
  ui.elapsed.dataset.seconds = String(seconds);
  ui.raysPerSecond.textContent = seconds > 0 ? siUnits(render.rays / seconds) : '–';
}

function siUnits(value) {
  if (value >= 1e9) return `${(value / 1e9).toFixed(2)} G`;
  if (value >= 1e6) return `${(value / 1e6).toFixed(2)} M`;
  if (value >= 1e3) return `${(value / 1e3).toFixed(1)} k`;
  return value.toFixed(0);
}

function endRender() {
  render.running = false;
  clearInterval(render.timer);
  showProgress();
  ui.render.disabled = false;
  ui.cancel.disabled = true;
}

function finishRender() {
  markFirstImage();
  endRender();
  ui.downloadPng.disabled = false;
  ui.downloadExr.disabled = false;
  const { width, height, spp, time } = render.settings;
  const dropped = render.nonfinite
    ? `; ${render.nonfinite} samples returned NaN or infinity and were left out of the image`
    : '';
  let passes = '';
  if (render.progressive) {
    const count = `${render.pass} pass${render.pass === 1 ? '' : 'es'}`;
    passes = render.taken < spp
      ? `: the ${time} s time budget ran out after ${count}, at ${render.taken} of ${spp} samples per pixel`
      : `: ${count}, ${spp} samples per pixel`;
  }
  setStatus('done', `rendered ${width}x${height} in ${ui.elapsed.textContent}${passes}${dropped}`);
}

// In passes, what the last complete pass left stays on the canvas and can be downloaded: a user
// may stop a render once its image is good enough.
function cancelRender() {
  if (!render?.running) return;
  endRender();
  stopPool();
  startPool();
  if (render.progressive && render.taken > 0) {
    setStatus('cancelled', `cancelled in pass ${render.pass} after ${render.done} of ${render.total} `
      + `tiles; ${passText()}`);
  } else {
    setStatus('cancelled', `cancelled after ${render.done} of ${render.total} tiles`);
  }
}

function failRender(error) {
  if (!render?.running) return;
  endRender();
  stopPool();
  startPool();
  setStatus('error', `the render failed: ${error}`);
}

function download(format) {
  const { width, height } = render.settings;
  const features = format === 'exr' && render.albedo;
  // The render's own settings (checked when it started): its display transform for the PNG.
  const settings = makeSettings(Settings, render.settings);
  let bytes;
  try {
    bytes = settings.encode(
      format, width, height, render.pixels,
      features ? render.albedo : undefined,
      features ? render.normal : undefined,
      features ? render.depth : undefined,
    );
  } finally {
    settings.free();
  }
  const url = URL.createObjectURL(new Blob([bytes], { type: `image/${format === 'png' ? 'png' : 'x-exr'}` }));
  const link = document.createElement('a');
  link.href = url;
  link.download = `${scenePath.split('/').pop().replace(SCENE_FILE, '')}.${format}`;
  link.click();
  setTimeout(() => URL.revokeObjectURL(url), 10000);
}

// ---- Wiring ----

async function main() {
  await init();
  EXAMPLES.forEach((example, index) => ui.example.add(new Option(example.name, String(index))));
  ui.example.onchange = () => {
    if (ui.example.value !== '') chooseExample(Number(ui.example.value)).catch((error) => {
      ui.diagnostics.textContent = `error: ${error.message}`;
    });
  };
  ui.sceneFile.onchange = () => showScene(ui.sceneFile.value);
  ui.openFiles.onchange = async () => setFiles(await inputFiles(ui.openFiles));
  ui.openFolder.onchange = async () => setFiles(await inputFiles(ui.openFolder));
  ui.dropZone.ondragover = (event) => {
    event.preventDefault();
    ui.dropZone.classList.add('over');
  };
  ui.dropZone.ondragleave = () => ui.dropZone.classList.remove('over');
  ui.dropZone.ondrop = async (event) => {
    event.preventDefault();
    ui.dropZone.classList.remove('over');
    setFiles(await droppedFiles(event.dataTransfer));
  };
  ui.render.onclick = startRender;
  ui.cancel.onclick = cancelRender;
  ui.downloadPng.onclick = () => download('png');
  ui.downloadExr.onclick = () => download('exr');
  startPool();
  // A newcomer's page is ready to render: the first example is loaded before the page says so.
  ui.example.value = '0';
  await chooseExample(0).catch((error) => {
    ui.diagnostics.textContent = `error: ${error.message}`;
  });
  ui.render.disabled = false;
  setStatus('idle', 'ready');
}

main().catch((error) => setStatus('error', `cannot start the renderer: ${error}`));
