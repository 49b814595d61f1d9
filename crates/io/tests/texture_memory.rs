//! Memory of a textured scene's load, counted by this test binary's allocator: the texture
//! files read ahead and waiting for their decode are held to 64 MiB together
//! (`prefetch_textures`), not all at once.

#![allow(unsafe_code)]

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

use glint_io::{load_scene_with_assets_limited, Limits, MemoryAssets};

/// The system allocator, counting the bytes it holds and their peak.
struct Counting;

static HELD: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

// SAFETY: every call goes to the system allocator as it came; the counters only add and
// subtract the sizes of what it handed out and took back.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: as the caller's contract.
        let pointer = unsafe { System.alloc(layout) };
        if !pointer.is_null() {
            let held = HELD.fetch_add(layout.size(), Relaxed) + layout.size();
            PEAK.fetch_max(held, Relaxed);
        }
        pointer
    }

    unsafe fn dealloc(&self, pointer: *mut u8, layout: Layout) {
        // SAFETY: as the caller's contract.
        unsafe { System.dealloc(pointer, layout) };
        HELD.fetch_sub(layout.size(), Relaxed);
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// A PNG of one grey pixel padded to about `bytes` by an ancillary chunk decoders skip.
fn padded_png(bytes: usize) -> Vec<u8> {
    let mut png = Vec::new();
    let mut encoder = png::Encoder::new(&mut png, 1, 1);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().unwrap();
    writer
        .write_chunk(png::chunk::ChunkType(*b"peGz"), &vec![0; bytes])
        .unwrap();
    writer.write_image_data(&[128, 128, 128]).unwrap();
    writer.finish().unwrap();
    png
}

/// 32 textures on 32 files of 4 MiB (128 MiB in all): the load holds, beyond the files
/// themselves, less than 64 MiB of waiting files, two files more and some slack, where
/// holding every file read at once would take all 128 MiB.
#[test]
fn texture_files_waiting_for_their_decode_are_held_to_64_mib() {
    const FILES: usize = 32;
    const FILE: usize = 4 << 20;
    let mut assets = MemoryAssets::new();
    let mut scene = String::from(
        "<scene>\n<camera type=\"perspective\"><position>0 0 3</position>\
         <viewDir>0 0 -1</viewDir><focalLength>1</focalLength>\
         <imagePlaneWidth>1</imagePlaneWidth></camera>\n",
    );
    for index in 0..FILES {
        assets.insert(format!("dir/t{index}.png"), padded_png(FILE));
        scene.push_str(&format!(
            "<texture name=\"t{index}\" type=\"image\"><sourcefile>t{index}.png</sourcefile>\
             </texture><shader name=\"s{index}\" type=\"Lambertian\">\
             <diffuse tex=\"t{index}\">1 1 1</diffuse></shader>\n"
        ));
    }
    scene.push_str("<shape type=\"sphere\"><shader ref=\"s0\"/></shape>\n</scene>\n");
    let before = HELD.load(Relaxed);
    PEAK.store(before, Relaxed);
    let loaded = load_scene_with_assets_limited(
        &scene,
        Path::new("dir/scene.xml"),
        &assets,
        &Limits::default(),
    )
    .unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    assert_eq!(loaded.parts.textures.len(), FILES);
    let extra = PEAK.load(Relaxed) - before;
    let bound = (64 << 20) + 2 * FILE + (16 << 20);
    assert!(
        extra < bound && bound < FILES * FILE,
        "the load held {} MiB at its peak (bound {} MiB)",
        extra >> 20,
        bound >> 20
    );
}
