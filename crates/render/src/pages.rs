//! Memory for big arrays (the trees' nodes and triangle blocks, the textures' texels), advised
//! for transparent huge pages (Linux's `madvise(MADV_HUGEPAGE)`), as Embree advises the memory
//! of its own trees (`os_malloc`, `common/sys/alloc.cpp`). At the bottom of the crate: it
//! knows nothing of what it holds.
//!
//! Rays that wander over a big mesh (igea-sub4's random rays: 16 MB of nodes and 39 MB of
//! blocks, each ray touching a few of them far apart) miss the TLB at nearly every node on
//! 4 KB pages; 2 MB pages cover the whole tree with a few dozen entries. Where the system
//! keeps huge pages for those who ask (the `madvise` setting of
//! `/sys/kernel/mm/transparent_hugepage/enabled`, Debian's default) nothing else asks. The
//! advice changes no byte of the memory, only how the kernel backs it, and it is a hint:
//! where it is refused or unknown (other systems, wasm32) the arrays are ordinary `Vec`s on
//! whatever pages the system gives.
//!
//! The second module of glint-render allowed `unsafe` (DESIGN.md, Tooling; the first is
//! `accel::simd`): the one `madvise` call below, no crate offering it without `unsafe` for memory
//! a `Vec` owns. The benchmark that justified it: igea-sub4's random rays 2.38 -> 2.58 Mrays/s
//! and its build 0.322 -> 0.306 s (1 thread), `glint bench rays` alternating with a binary
//! without it; no other set moved beyond noise.

#![allow(unsafe_code)]

/// Below this many bytes an array could not fill one 2 MB page, so it is not advised.
#[cfg(target_os = "linux")]
const HUGE_PAGE: usize = 2 << 20;

/// An empty `Vec` with room for `capacity` elements, whose buffer is advised for huge pages
/// where it spans at least one. The advice holds for the buffer as allocated: call before
/// filling it (pages already touched stay as they are until the kernel merges them), and a
/// `Vec` that outgrows `capacity` moves to a buffer of its own, not advised.
pub(crate) fn vec_with_capacity<T>(capacity: usize) -> Vec<T> {
    let v: Vec<T> = Vec::with_capacity(capacity);
    advise(
        v.as_ptr().cast(),
        v.capacity().saturating_mul(std::mem::size_of::<T>()),
    );
    v
}

#[cfg(target_os = "linux")]
fn advise(start: *const u8, bytes: usize) {
    if bytes < HUGE_PAGE {
        return;
    }
    // SAFETY: sysconf reads a system constant.
    let page = match unsafe { libc::sysconf(libc::_SC_PAGESIZE) } {
        p if p > 0 => p as usize,
        _ => return,
    };
    // The whole pages inside [start, start + bytes): madvise wants a page-aligned start.
    let (start, end) = (start as usize, start as usize + bytes);
    let (first, last) = (start.next_multiple_of(page), end / page * page);
    if first < last {
        // SAFETY: MADV_HUGEPAGE changes how the kernel backs these pages, never their contents
        // or whether they are mapped; the range lies inside one allocation of ours. The result
        // is ignored: the advice is a hint, and a kernel without transparent huge pages
        // (EINVAL) leaves the memory as it was.
        unsafe {
            libc::madvise(
                first as *mut libc::c_void,
                last - first,
                libc::MADV_HUGEPAGE,
            );
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn advise(_start: *const u8, _bytes: usize) {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn advised_vectors_are_ordinary_vectors() {
        for capacity in [0, 1, 1000, 3 << 20] {
            let mut v: Vec<u64> = vec_with_capacity(capacity);
            assert!(v.is_empty() && v.capacity() >= capacity);
            v.extend((0..capacity as u64 + 5).map(|i| i * 3));
            assert_eq!(v.len(), capacity + 5);
            assert!(v.iter().enumerate().all(|(i, &x)| x == i as u64 * 3));
        }
    }

    /// On Linux with transparent huge pages offered on request, an advised buffer of 64 MB,
    /// once written, is backed by huge pages: its mapping's `AnonHugePages` in
    /// `/proc/self/smaps` is at least 32 MB (half of it, leaving room for the kernel's
    /// alignment and a busy machine). Skipped where the system does not offer them on request.
    #[test]
    #[cfg(target_os = "linux")]
    fn advised_buffers_get_huge_pages() {
        let offered = std::fs::read_to_string("/sys/kernel/mm/transparent_hugepage/enabled")
            .is_ok_and(|s| s.contains("[madvise]") || s.contains("[always]"));
        if !offered {
            eprintln!("transparent huge pages not offered here; nothing to check");
            return;
        }
        let mut v: Vec<u8> = vec_with_capacity(64 << 20);
        v.resize(64 << 20, 1);
        // The mapping holding the buffer's middle (the advice splits off its unaligned ends).
        let middle = v.as_ptr() as usize + (32 << 20);
        let smaps = std::fs::read_to_string("/proc/self/smaps").unwrap();
        let mut inside = false;
        let mut huge_kb = None;
        for line in smaps.lines() {
            let first = line.split_whitespace().next().unwrap_or("");
            if let Some((lo, hi)) = first.split_once('-') {
                if let (Ok(lo), Ok(hi)) =
                    (usize::from_str_radix(lo, 16), usize::from_str_radix(hi, 16))
                {
                    inside = (lo..hi).contains(&middle);
                    continue;
                }
            }
            if inside && first == "AnonHugePages:" {
                huge_kb = line
                    .split_whitespace()
                    .nth(1)
                    .and_then(|k| k.parse::<u64>().ok());
            }
        }
        assert!(v.iter().all(|&b| b == 1));
        let huge_kb = huge_kb.expect("the buffer's mapping in /proc/self/smaps");
        assert!(huge_kb >= 32 << 10, "AnonHugePages {huge_kb} kB");
    }
}
