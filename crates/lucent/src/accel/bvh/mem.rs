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

/// Size of a transparent huge page on x86_64 and aarch64 (4 KiB base
/// pages).
const HUGE: usize = 2 << 20;

/// The whole, aligned huge pages inside the buffer `[start, start + len)`:
/// the range that may be advised without touching memory that is not ours.
/// None when the buffer holds no whole huge page.
fn huge_pages_within(start: usize, len: usize) -> Option<(usize, usize)> {
    let a = start.checked_next_multiple_of(HUGE)?;
    let b = start.checked_add(len)? & !(HUGE - 1);
    // `then`, not `then_some`: b − a is only taken where it is positive
    (b > a).then(|| (a, b - a))
}

/// Asks the kernel to back the whole huge pages of `[start, start + len)`
/// with huge pages (Linux on x86_64 and aarch64; elsewhere nothing).
fn advise(start: usize, len: usize) {
    let Some((a, n)) = huge_pages_within(start, len) else {
        return;
    };
    #[cfg(all(
        target_os = "linux",
        any(target_arch = "x86_64", target_arch = "aarch64")
    ))]
    {
        use std::ffi::{c_int, c_void};
        extern "C" {
            fn madvise(addr: *mut c_void, len: usize, advice: c_int) -> c_int;
        }
        const MADV_HUGEPAGE: c_int = 14;
        // SAFETY: madvise only attaches a hint to pages of our own
        // allocation (whole pages inside [start, start + len)); it reads
        // and writes no memory. Failure (e.g. THP disabled) changes
        // nothing, so it is ignored.
        unsafe {
            madvise(a as *mut c_void, n, MADV_HUGEPAGE);
        }
    }
    #[cfg(not(all(
        target_os = "linux",
        any(target_arch = "x86_64", target_arch = "aarch64")
    )))]
    let _ = (a, n);
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The advised range starts and ends on huge-page boundaries and lies
    /// inside the buffer, and is the largest such range.
    #[test]
    fn only_whole_huge_pages_inside_the_buffer_are_advised() {
        const K: usize = 4096;
        assert_eq!(huge_pages_within(0, HUGE), Some((0, HUGE)));
        assert_eq!(
            huge_pages_within(HUGE, 3 * HUGE + K),
            Some((HUGE, 3 * HUGE))
        );
        assert_eq!(
            huge_pages_within(HUGE - K, 2 * HUGE + 2 * K),
            Some((HUGE, 2 * HUGE))
        );
        assert_eq!(huge_pages_within(K, 2 * HUGE), Some((HUGE, HUGE)));
        assert_eq!(huge_pages_within(K, HUGE), None);
        assert_eq!(huge_pages_within(0, HUGE - 1), None);
        assert_eq!(huge_pages_within(usize::MAX - K, K), None);
        for (start, len) in [(12_345 * K + 17, 9 * HUGE + 5), (7 * HUGE - 1, 5 * HUGE)] {
            let (a, n) = huge_pages_within(start, len).unwrap();
            assert!(a % HUGE == 0 && n % HUGE == 0 && n > 0);
            assert!(a >= start && a + n <= start + len);
            assert!(a - start < HUGE && start + len - (a + n) < HUGE);
        }
    }

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
