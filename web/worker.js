// One render worker: loads the scene into its own copy of the renderer, then renders the tiles
// the page hands it, one at a time, until the page terminates it. For the path tracers a tile
// comes once a pass: the worker keeps its running sums (`TilePasses`) from pass to pass, and the
// page sends each tile back to the worker that rendered its first pass.
// A render's preview (`Settings.preview`) comes first, in strips, rendered as tiles are.
import init, { Files, Settings, load_bytes as loadBytes } from './pkg/glint_wasm.js';
import { makeSettings } from './settings.js';

const ready = init();
// { job, loaded, settings, preview (or null), passes: Map(tile index -> TilePasses) }
let current = null;

function release() {
  if (current) {
    for (const passes of current.passes.values()) passes.free();
    current.loaded.free();
    current.settings.free();
    current.preview?.free();
    current = null;
  }
}

// `preview`: the preview's scale (its pixels stand for preview x preview blocks), or null.
function startJob({ job, bytes, path, files, settings, preview }) {
  release();
  const assets = new Files();
  for (const [name, bytes] of files) assets.add(name, bytes);
  const loaded = loadBytes(bytes, path, assets);
  assets.free();
  if (!loaded.ok) {
    const error = loaded.messages[0]?.text ?? 'the scene did not load';
    loaded.free();
    return { type: 'failed', job, error };
  }
  let renderSettings;
  try {
    renderSettings = makeSettings(Settings, settings);
    // The CLI's --background, -d and --aperture change the scene, once per job.
    loaded.apply(renderSettings);
  } catch (error) {
    renderSettings?.free();
    loaded.free();
    return { type: 'failed', job, error: String(error) };
  }
  current = {
    job,
    loaded,
    settings: renderSettings,
    preview: preview ? renderSettings.preview(preview) : null,
    passes: new Map(),
  };
  return { type: 'ready', job };
}

// Takes `tile` to `samples` samples per pixel, starting its passes on its first.
function passTile(tile, samples) {
  let passes = current.passes.get(tile.index);
  if (!passes) {
    passes = current.loaded.start_passes(current.settings, tile.x0, tile.y0, tile.x1, tile.y1);
    current.passes.set(tile.index, passes);
  }
  const result = passes.pass(current.loaded, samples - passes.samples_taken);
  return { result, taken: passes.samples_taken };
}

// `samples` (the samples per pixel the tile's pass reaches) is there only for a render in passes.
// A preview strip is a tile of the preview's settings.
function renderTile({ type, job, tile, samples }) {
  if (!current || current.job !== job) return { type: 'failed', job, error: 'no scene loaded' };
  const settings = type === 'preview' ? current.preview : current.settings;
  const { result, taken } = samples === undefined
    ? { result: current.loaded.render_tile(settings, tile.x0, tile.y0, tile.x1, tile.y1) }
    : passTile(tile, samples);
  const message = {
    type: 'tile',
    job,
    tile,
    taken,
    rgb8: result.rgb8,
    pixels: result.pixels,
    albedo: result.albedo,
    normal: result.normal,
    depth: result.depth,
    rays: result.rays,
    nonfinite: result.nonfinite_samples,
  };
  result.free();
  return message;
}

self.onmessage = async ({ data }) => {
  await ready;
  let reply;
  try {
    reply = data.type === 'job' ? startJob(data) : renderTile(data);
  } catch (error) {
    reply = { type: 'failed', job: data.job, error: String(error) };
  }
  const transfer = reply.type === 'tile'
    ? [reply.rgb8, reply.pixels, reply.albedo, reply.normal, reply.depth].map((a) => a.buffer)
    : [];
  self.postMessage(reply, transfer);
};
