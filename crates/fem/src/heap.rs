//! Handing the allocator's free memory back to the system.
//!
//! A factorization of a large model allocates and frees arrays of tens to hundreds of MB (the
//! tangent's values, the element contributions, the solves' vectors). glibc's allocator keeps
//! freed blocks below its (growing) mmap threshold in its per-thread heaps, and with the
//! assembly's threads interleaving their allocations those heaps fragment: the resident memory
//! then grows above what is live. [`release_free`] asks glibc to return every whole free page
//! (`malloc_trim(0)`); it changes no allocation and no result. Elsewhere it does nothing.

/// The tangent values (one per pattern entry) from which a model counts as large, and returns
/// its free memory after each factorization: 2²² (32 MiB of values, about 160,000 unknowns of
/// the 4-node tube). A shipped case has under 10⁶ and keeps the allocator's default behaviour.
pub const LARGE_VALUES: usize = 1 << 22;

/// Return the allocator's free pages to the system (glibc's `malloc_trim(0)`; a no-op on other
/// allocators).
pub fn release_free() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc_trim only releases memory the allocator holds free; it touches no live
    // allocation and may be called from any thread at any time.
    unsafe {
        libc::malloc_trim(0);
    }
}
