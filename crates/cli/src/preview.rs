//! The preview window (`-x W -y H`, the course's `--winwidth` / `--winheight`): the image as
//! it renders, tile by tile, with the progress in the title, left open after the render until
//! it is closed (or Escape, or Ctrl-C), unless `--preview-close`.
//!
//! The window belongs to the thread that opened it (X11 windows are not shared between
//! threads), so the run goes to a scoped thread and the window's thread only draws: the render
//! threads hand each finished tile, already turned into display pixels, to a channel, and the
//! window's thread copies them into its buffer and shows it at most `FRAME` apart. Pixels map
//! to the window by nearest neighbour and are shown as the PNG writer stores them
//! (clamped, floor(c · 255), no gamma), so at the image's own size the window shows exactly
//! the written PNG.
//!
//! Without the `preview` feature there is no window (no minifb): `-x`/`-y` are refused before
//! the render (`run::refuse_missing`), and `Preview` cannot be made.

// Without a window nothing reads the tiles the sink would carry.
#![cfg_attr(not(feature = "preview"), allow(dead_code))]

use std::sync::mpsc::Sender;
#[cfg(feature = "preview")]
use std::sync::mpsc::{channel, Receiver, RecvTimeoutError};
#[cfg(feature = "preview")]
use std::time::{Duration, Instant};

use glint_render::{Color, PixelBounds, Progress};
#[cfg(feature = "preview")]
use minifb::{Key, Window, WindowOptions};

/// The longest the window waits between redraws while tiles arrive.
#[cfg(feature = "preview")]
const FRAME: Duration = Duration::from_millis(50);

/// One finished tile in display pixels (`0x00RRGGBB`, row-major), and the progress.
#[derive(Debug)]
pub struct Tile {
    pub bounds: PixelBounds,
    pub pixels: Vec<u32>,
    pub done: usize,
    pub total: usize,
}

/// Where the render threads send finished tiles.
#[derive(Clone, Debug)]
pub struct TileSink(Sender<Tile>);

impl TileSink {
    /// Sends `progress`'s tile. A closed window is not an error: the render goes on.
    pub fn send(&self, progress: &Progress) {
        let _ = self.0.send(Tile {
            bounds: progress.tile,
            pixels: progress.pixels.iter().map(|&c| display_pixel(c)).collect(),
            done: progress.tiles_done,
            total: progress.tiles_total,
        });
    }
}

/// A linear colour as the PNG writer stores it (FORMAT.md: clamped, floor(c · 255), no
/// gamma), packed as minifb wants it.
pub fn display_pixel(c: Color) -> u32 {
    let channel = |v: f32| (v.clamp(0.0, 1.0) * 255.0).floor() as u32;
    (channel(c.x) << 16) | (channel(c.y) << 8) | channel(c.z)
}

/// Without the `preview` feature: no window can be opened, so no `Preview` exists.
#[cfg(not(feature = "preview"))]
#[derive(Debug)]
pub enum Preview {}

#[cfg(not(feature = "preview"))]
impl Preview {
    /// Fails: this build has no window.
    pub fn open(
        _width: usize,
        _height: usize,
        _image_width: u32,
        _image_height: u32,
    ) -> Result<Preview, String> {
        Err("this glint was built without the preview window (feature `preview`)".to_owned())
    }

    /// Never runs: there is no `Preview` to run it on.
    pub fn run_while<T: Send, E: Send>(
        self,
        _close: bool,
        _stop: &dyn Fn() -> bool,
        _work: impl FnOnce(TileSink) -> Result<T, E> + Send,
    ) -> Result<T, E> {
        match self {}
    }
}

/// An open preview window.
#[cfg(feature = "preview")]
pub struct Preview {
    window: Window,
    buffer: Vec<u32>,
    window_size: (usize, usize),
    image_size: (u32, u32),
}

#[cfg(feature = "preview")]
impl Preview {
    /// Opens a `width` x `height` window for a `image_width` x `image_height` image. Fails
    /// (with why) where there is no display.
    pub fn open(
        width: usize,
        height: usize,
        image_width: u32,
        image_height: u32,
    ) -> Result<Preview, String> {
        let mut window = Window::new("glint: starting", width, height, WindowOptions::default())
            .map_err(|error| error.to_string())?;
        // Events are polled by `update`; no frame pacing beyond ours.
        window.set_target_fps(0);
        let mut preview = Preview {
            window,
            buffer: vec![0; width * height],
            window_size: (width, height),
            image_size: (image_width, image_height),
        };
        preview.show();
        Ok(preview)
    }

    fn show(&mut self) {
        let (w, h) = self.window_size;
        // A closed window reports an error here; the render goes on without it.
        let _ = self.window.update_with_buffer(&self.buffer, w, h);
    }

    /// Copies a tile into the window's buffer, each window pixel showing the image pixel it
    /// covers (nearest neighbour).
    fn draw(&mut self, tile: &Tile) {
        let (ww, wh) = self.window_size;
        let (iw, ih) = (self.image_size.0 as usize, self.image_size.1 as usize);
        let b = tile.bounds;
        let tile_width = b.width() as usize;
        // Window rows and columns whose image pixel lies in the tile.
        let first =
            |start: u32, window: usize, image: usize| (start as usize * window).div_ceil(image);
        let (x_from, x_to) = (first(b.x0, ww, iw), first(b.x1, ww, iw).min(ww));
        let (y_from, y_to) = (first(b.y0, wh, ih), first(b.y1, wh, ih).min(wh));
        for wy in y_from..y_to {
            let iy = wy * ih / wh;
            let row = (iy - b.y0 as usize) * tile_width;
            for wx in x_from..x_to {
                let ix = wx * iw / ww;
                self.buffer[wy * ww + wx] = tile.pixels[row + ix - b.x0 as usize];
            }
        }
    }

    fn is_open(&self) -> bool {
        self.window.is_open() && !self.window.is_key_down(Key::Escape)
    }

    /// Runs `work` on its own thread with a sink for its tiles, showing them as they come;
    /// then, unless `close` or `work` failed, keeps the window open until it is closed or
    /// `stop()` says so. Returns what `work` returned.
    pub fn run_while<T: Send, E: Send>(
        mut self,
        close: bool,
        stop: &dyn Fn() -> bool,
        work: impl FnOnce(TileSink) -> Result<T, E> + Send,
    ) -> Result<T, E> {
        let (sender, receiver) = channel();
        let result = std::thread::scope(|scope| {
            let worker = scope.spawn(move || work(TileSink(sender)));
            self.follow(&receiver);
            worker
                .join()
                .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
        });
        if result.is_ok() && !close {
            self.window
                .set_title("glint: done (close the window or press Escape)");
            while self.is_open() && !stop() {
                self.window.update();
                std::thread::sleep(FRAME);
            }
        }
        result
    }

    /// Draws tiles until every sender is gone (the run ended).
    fn follow(&mut self, tiles: &Receiver<Tile>) {
        let mut last_frame = Instant::now();
        let mut pending = false;
        loop {
            match tiles.recv_timeout(FRAME) {
                Ok(tile) => {
                    self.draw(&tile);
                    pending = true;
                    if self.is_open() {
                        let percent = 100 * tile.done / tile.total.max(1);
                        self.window.set_title(&format!(
                            "glint: {percent}% ({} of {} tiles)",
                            tile.done, tile.total
                        ));
                    }
                }
                Err(RecvTimeoutError::Timeout) => {}
                Err(RecvTimeoutError::Disconnected) => break,
            }
            if last_frame.elapsed() >= FRAME {
                if pending {
                    self.show();
                    pending = false;
                } else {
                    self.window.update();
                }
                last_frame = Instant::now();
            }
        }
        self.show();
    }
}
