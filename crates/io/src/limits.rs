//! What a scene may ask of the machine. Every limit is checked before the memory is taken: a
//! file's size before it is read, an image's dimensions (from its header) before it is decoded,
//! so that a hostile or mistaken file is refused with a located error instead of growing until
//! the kernel kills the process.

/// The limits a load runs under, and how it treats a file it cannot read. The defaults are far above what any course scene needs (its
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
    /// The render's memory budget, in bytes (the CLI's `--max-memory`): a scene's parse tree
    /// and a mesh's buffers are estimated against it while they load, from upper bounds of
    /// what each element, value or triangle holds, and refused where they would pass it.
    pub max_memory: u64,
    /// Whether a file the scene names that cannot be read (missing, unreadable, not a file,
    /// or not a mesh or image) is only a warning, as the course renderer had it: a course
    /// scene then loads without it (the mesh left out, the texture's plain colour, the
    /// background colour for an environment map), and so does a Mitsuba scene's mesh (the
    /// shape left out). By default (false) each such file is an error, all of them reported
    /// together, and the scene does not load. A glTF model's buffers and images, and a
    /// Mitsuba scene's textures and volume grids, are errors either way: there is nothing to
    /// render in their place. (The CLI's `--allow-missing-assets`.)
    pub allow_missing_assets: bool,
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

/// 4 GiB, what the CLI plans for where it cannot tell the machine's memory.
pub const DEFAULT_MAX_MEMORY: u64 = 4 << 30;

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
            max_memory: DEFAULT_MAX_MEMORY,
            allow_missing_assets: false,
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
            max_memory: u64::MAX,
            allow_missing_assets: false,
        }
    }
}

/// Memory a course or Mitsuba XML file's parse holds per tag (`<` of an element, end tag,
/// comment or declaration), at most: roxmltree's node for the element and one for the text
/// after it, the located tree's node, its share of the vectors' spare capacity, and the
/// warning an unknown element gets. Measured with `scripts/hostile-figures.py`'s
/// `40 MB empty elements` case at several sizes (see the commit that set it).
pub(crate) const XML_BYTES_PER_TAG: u64 = 400;
/// Memory an XML attribute holds, at most: roxmltree's attribute and the located tree's node.
pub(crate) const XML_BYTES_PER_ATTRIBUTE: u64 = 200;
/// Memory a JSON value holds, at most: jsonc-parser's syntax node, the located tree's node,
/// their share of spare capacity and a warning.
pub(crate) const JSON_BYTES_PER_VALUE: u64 = 160;
/// Memory a mesh file's triangle holds while it loads, at most: the OBJ reader's corners (a
/// fan's are one a triangle; separate triangles' are three, with their face record), its
/// triangle of three corners (36 bytes), and the scene's shape and material index made from
/// it while the triangles are still held.
pub(crate) const MESH_BYTES_PER_TRIANGLE: u64 = 160;
/// Memory a scene file's text holds per byte while it is parsed: the text, and the table of
/// character counts a text that is not all ASCII gets (`diagnostic::LineIndex`).
pub(crate) const TEXT_BYTES_PER_BYTE: u64 = 2;

/// The memory a load is estimated to hold, against `Limits::max_memory`: charged as the
/// parse goes, so that the file, line and column where it would pass the budget are known.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MemoryBudget {
    limit: u64,
    used: u64,
}

impl MemoryBudget {
    pub fn new(limits: &Limits) -> MemoryBudget {
        MemoryBudget {
            limit: limits.max_memory,
            used: 0,
        }
    }

    /// No budget (for scans whose other findings are wanted alone).
    #[cfg(test)]
    pub fn unlimited() -> MemoryBudget {
        MemoryBudget {
            limit: u64::MAX,
            used: 0,
        }
    }

    /// Adds `bytes`; false once the total is over the budget.
    pub fn charge(&mut self, bytes: u64) -> bool {
        self.used = self.used.saturating_add(bytes);
        self.used <= self.limit
    }

    /// The message for a load stopped at the point where `what` passed the budget.
    pub fn refusal(&self, what: &str) -> String {
        format!(
            "{what} would hold about {}, more than the memory budget of {} \
             (--max-memory raises it)",
            format_bytes(self.used),
            format_bytes(self.limit)
        )
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
