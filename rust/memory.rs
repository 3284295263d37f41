//! Large buffers: how the kernel backs them.

/// Buffers at least this large are backed by transparent huge pages where the
/// kernel offers them (as numpy does for its own large arrays).
const HUGE_MIN_BYTES: usize = 4 << 20;

/// Ask the kernel to back `v`'s allocation with transparent huge pages: a
/// first touch then costs one fault per 2 MB instead of one per 4 kB, which is
/// most of the time spent writing a large fresh output table. Only advice: a
/// kernel that refuses it changes nothing.
#[cfg(target_os = "linux")]
pub(crate) fn advise_huge_pages<T>(v: &Vec<T>) {
    extern "C" {
        fn madvise(addr: *mut core::ffi::c_void, len: usize, advice: core::ffi::c_int) -> i32;
    }
    const MADV_HUGEPAGE: core::ffi::c_int = 14;
    const PAGE: usize = 4096;
    let bytes = v.capacity() * std::mem::size_of::<T>();
    if bytes < HUGE_MIN_BYTES {
        return;
    }
    let addr = v.as_ptr() as usize;
    let start = (addr + PAGE - 1) & !(PAGE - 1);
    let end = (addr + bytes) & !(PAGE - 1);
    if end > start {
        // SAFETY: [start, end) lies inside the live allocation of `v` (its whole
        // capacity); MADV_HUGEPAGE changes neither its contents nor its validity,
        // only how the kernel backs it. A failure (old kernel, other page size)
        // is harmless, so the result is ignored.
        unsafe {
            madvise(start as *mut core::ffi::c_void, end - start, MADV_HUGEPAGE);
        }
    }
}

#[cfg(not(target_os = "linux"))]
pub(crate) fn advise_huge_pages<T>(_v: &Vec<T>) {}
