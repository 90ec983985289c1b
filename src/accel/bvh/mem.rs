//! Allocation of the big traversal arrays on transparent huge pages.
//!
//! An incoherent ray touches a few dozen random cache lines spread over
//! tens of megabytes (nodes and triangles of a million-triangle mesh). With
//! 4 KiB pages nearly every one of those loads also misses the TLB and
//! walks the page table; 2 MiB pages cover the whole structure with a
//! handful of TLB entries. Linux backs anonymous memory with huge pages
//! only where asked (`transparent_hugepage=madvise`, the Debian default),
//! so the arrays are advised before they are filled. Embree does the same.

/// An empty vector with room for `n` elements whose (not yet touched)
/// pages the kernel is asked to back with huge pages. A hint only: where it
/// is not honoured the vector is an ordinary one.
pub(super) fn with_huge_pages<T>(n: usize) -> Vec<T> {
    let v: Vec<T> = Vec::with_capacity(n);
    advise(
        v.as_ptr() as usize,
        n.saturating_mul(std::mem::size_of::<T>()),
    );
    v
}

#[cfg(all(
    target_os = "linux",
    any(target_arch = "x86_64", target_arch = "aarch64")
))]
fn advise(start: usize, len: usize) {
    use std::ffi::{c_int, c_void};
    extern "C" {
        fn madvise(addr: *mut c_void, len: usize, advice: c_int) -> c_int;
    }
    const MADV_HUGEPAGE: c_int = 14;
    const HUGE: usize = 2 << 20;
    // Only whole, aligned 2 MiB pages inside the buffer can be huge.
    let a = start.next_multiple_of(HUGE);
    let b = (start + len) & !(HUGE - 1);
    if b > a {
        // SAFETY: madvise only attaches a hint to pages of our own
        // allocation [start, start + len); it reads and writes no memory.
        // Failure (e.g. THP disabled) changes nothing, so it is ignored.
        unsafe {
            madvise(a as *mut c_void, b - a, MADV_HUGEPAGE);
        }
    }
}

#[cfg(not(all(
    target_os = "linux",
    any(target_arch = "x86_64", target_arch = "aarch64")
)))]
fn advise(_start: usize, _len: usize) {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn advised_vectors_are_ordinary_vectors() {
        for n in [0usize, 1, 1000, 3 << 20] {
            let mut v: Vec<u32> = with_huge_pages(n);
            assert!(v.capacity() >= n && v.is_empty());
            v.extend((0..n as u32).map(|i| i ^ 0x5555));
            assert!(v.iter().enumerate().all(|(i, &x)| x == i as u32 ^ 0x5555));
        }
    }
}
