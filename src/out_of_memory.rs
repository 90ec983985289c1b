//! The process's allocator: the system's, except that an allocation it
//! cannot satisfy ends the command cleanly instead of aborting. std's
//! allocation-error hook is unstable, so the allocator itself reports
//! "error: out of memory: cannot allocate N MB while <phase>"
//! ([`lucent::memory`]), removes the temporary files being written and
//! exits 1 (docs/output.md, "Out of memory"). Fallible allocations
//! (`try_reserve`) end the same way: the message names the phase instead
//! of the buffer.

use std::alloc::{GlobalAlloc, Layout, System};
use std::io::Write as _;

/// [`System`], with an allocation failure reported and the process ended.
pub struct ReportingAllocator;

// SAFETY: every method forwards to `System` with the caller's arguments
// and returns its result unchanged; on a null result the process exits,
// which upholds any contract.
unsafe impl GlobalAlloc for ReportingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        // SAFETY: forwarded as is (see the impl's note).
        checked(unsafe { System.alloc(layout) }, layout)
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        // SAFETY: forwarded as is.
        checked(unsafe { System.alloc_zeroed(layout) }, layout)
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        // SAFETY: forwarded as is; `ptr` and `layout` are the caller's.
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        checked(
            p,
            Layout::from_size_align(new_size, layout.align()).unwrap_or(layout),
        )
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded as is.
        unsafe { System.dealloc(ptr, layout) }
    }
}

/// `p`, or the end of the process if it is null.
fn checked(p: *mut u8, layout: Layout) -> *mut u8 {
    if p.is_null() {
        out_of_memory(layout.size());
    }
    p
}

/// Says how much could not be allocated and while doing what, removes
/// the temporaries and exits 1 at once. Writes from a stack buffer: the heap is
/// what ran out.
fn out_of_memory(bytes: usize) -> ! {
    let mut buf = [0u8; 160];
    let mut w = &mut buf[..];
    let _ = writeln!(
        w,
        "error: out of memory: cannot allocate {} MB while {}",
        bytes.div_ceil(1 << 20),
        lucent::memory::doing()
    );
    let left = w.len();
    let used = buf.len() - left;
    let _ = std::io::stderr().write_all(&buf[..used]);
    lucent::interrupt::remove_temporaries_if_free();
    // SAFETY: _exit ends the process at once; it runs no exit handlers
    // (which could allocate again) and has no preconditions.
    unsafe { libc::_exit(1) }
}
