// The page's settings as glint-wasm's `Settings`, built in one place for the page (which checks
// and encodes with them) and the workers (which render with them), so the two cannot differ.

/**
 * A `Settings` for `s` (what `readSettings` in app.js returns, or its preview); throws what
 * glint-wasm refuses, in its words. The caller frees it.
 */
export function makeSettings(Settings, s) {
  const settings = new Settings(
    s.width, s.height, s.spp, s.integrator, BigInt(s.seed), s.maxDepth, s.features,
  );
  try {
    settings.set_background(s.background ?? '');
    settings.set_depth_of_field(s.focus, s.aperture);
    settings.set_display(s.exposure, s.tonemap, s.transfer);
  } catch (error) {
    settings.free();
    throw error;
  }
  return settings;
}
