//! What a scene may ask of the machine. Every limit is checked before the memory is taken: a
//! file's size before it is read, an image's dimensions (from its header) before it is decoded,
//! so that a hostile or mistaken file is refused with a located error instead of growing until
//! the kernel kills the process.

/// The limits a load runs under. The defaults are far above what any course scene needs (its
/// largest file is 3.7 MB, its largest texture 2048 x 1024) and far below what would take the
/// machine down; front ends let a user raise them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Largest scene file, and largest mesh, texture or environment-map file, in bytes.
    pub max_file_bytes: u64,
    /// Most triangles one mesh file may make (its faces fan-triangulated), counted before
    /// the file is parsed.
    pub max_triangles: u64,
    /// Largest texture or environment-map side, in pixels (checked from the image header).
    pub max_texture_side: u32,
    /// Memory the loaded textures may take together, in bytes (checked before each decode).
    pub max_texture_bytes: u64,
}

/// 256 MiB.
pub const DEFAULT_MAX_FILE_BYTES: u64 = 256 << 20;
/// 20 million: 200 times the course's largest mesh (the 100k-triangle dragon), about 1.5 GB
/// with its acceleration structure.
pub const DEFAULT_MAX_TRIANGLES: u64 = 20_000_000;
/// 8192 pixels: an 8K texture; a 2048-pixel-face vertical cross is 6144 x 8192.
pub const DEFAULT_MAX_TEXTURE_SIDE: u32 = 8192;
/// 2 GiB.
pub const DEFAULT_MAX_TEXTURE_BYTES: u64 = 2 << 30;

/// Memory one decoded texel takes while its texture loads: 12 bytes as the renderer keeps it
/// (three f32) and up to 8 more in the decoder's buffer and its RGB8 copy.
pub const BYTES_PER_TEXEL: u64 = 20;

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_file_bytes: DEFAULT_MAX_FILE_BYTES,
            max_triangles: DEFAULT_MAX_TRIANGLES,
            max_texture_side: DEFAULT_MAX_TEXTURE_SIDE,
            max_texture_bytes: DEFAULT_MAX_TEXTURE_BYTES,
        }
    }
}

impl Limits {
    /// No limits (trusted input only: tests, benchmarks).
    pub fn none() -> Limits {
        Limits {
            max_file_bytes: u64::MAX,
            max_triangles: u64::MAX,
            max_texture_side: u32::MAX,
            max_texture_bytes: u64::MAX,
        }
    }
}

/// A byte count for messages: "256 MiB", "1.5 GiB", "900 bytes".
pub fn format_bytes(bytes: u64) -> String {
    const UNITS: [(u64, &str); 3] = [(1 << 30, "GiB"), (1 << 20, "MiB"), (1 << 10, "KiB")];
    for (scale, unit) in UNITS {
        if bytes >= scale {
            let value = bytes as f64 / scale as f64;
            return if value.fract() == 0.0 {
                format!("{value:.0} {unit}")
            } else {
                format!("{value:.1} {unit}")
            };
        }
    }
    format!("{bytes} bytes")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn byte_counts_read_well() {
        assert_eq!(format_bytes(DEFAULT_MAX_FILE_BYTES), "256 MiB");
        assert_eq!(format_bytes(3 << 29), "1.5 GiB");
        assert_eq!(format_bytes(900), "900 bytes");
    }
}
