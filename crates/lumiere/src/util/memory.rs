//! Large buffers and hints about memory. A render's buffers as large as its image are allocated
//! zeroed and fallibly (memory that runs out is an error to report, not an abort). The hints change
//! no value. Fresh memory: large buffers a render or a build writes once, whose first touch is a
//! page fault per 4 KB page that zeroes it (measured at 1.3 GB/s in this project's VM, against 7
//! GB/s for writing memory already touched). Records read soon: a prefetch, so that other work
//! runs while they come from memory.

/// Types for which all-zero bytes are a valid value: the float buffers a render allocates.
///
/// # Safety
/// Only for types whose every field is a float or an integer.
pub unsafe trait ZeroIsValid: Copy {}
// SAFETY: floats, and arrays of them; all-zero bytes are +0.0.
unsafe impl ZeroIsValid for f64 {}
// SAFETY: as above.
unsafe impl ZeroIsValid for [f64; 3] {}
// SAFETY: as above.
unsafe impl ZeroIsValid for [f32; 3] {}

/// `vec![zero; len]`, or `None` when the memory cannot be had, where `vec!` would abort the
/// process: allocated zeroed by the allocator as `vec!` does (fresh pages, zeroed at their first
/// touch, not written here).
pub fn try_zeroed_vec<T: ZeroIsValid>(len: usize) -> Option<Vec<T>> {
    let layout = std::alloc::Layout::array::<T>(len).ok()?;
    if layout.size() == 0 {
        return Some(Vec::new());
    }
    // SAFETY: the layout has a non-zero size; all-zero bytes are a valid `T`; the pointer comes
    // from the global allocator with the layout of `len` values, as `Vec::from_raw_parts` needs.
    unsafe {
        let pointer = std::alloc::alloc_zeroed(layout).cast::<T>();
        (!pointer.is_null()).then(|| Vec::from_raw_parts(pointer, len, len))
    }
}

/// Asks the kernel to back the `len` values of type `T` at `start`, not yet touched, with 2 MB
/// pages where it can: with transparent huge pages in `madvise` mode (the common default) one
/// fault then zeroes 2 MB. Only a request: the answer is ignored, and nothing but speed depends
/// on it.
#[cfg(target_os = "linux")]
pub fn ask_for_huge_pages<T>(start: *const T, len: usize) {
    const PAGE: usize = 4096;
    let begin = (start as usize).next_multiple_of(PAGE);
    let end = (start as usize + len * size_of::<T>()) & !(PAGE - 1);
    if end > begin {
        // SAFETY: the range lies inside the caller's allocation; MADV_HUGEPAGE changes no contents.
        unsafe { libc::madvise(begin as *mut libc::c_void, end - begin, libc::MADV_HUGEPAGE) };
    }
}

#[cfg(not(target_os = "linux"))]
pub fn ask_for_huge_pages<T>(_: *const T, _: usize) {}

/// Asks the CPU to bring the cache line holding `value` into its caches, without waiting for it:
/// a hint, so that a load issued later finds it there. No effect on what any load returns.
#[inline(always)]
pub fn prefetch<T>(value: &T) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch reads nothing the program sees and cannot fault; SSE is baseline on x86-64.
    unsafe {
        std::arch::x86_64::_mm_prefetch::<{ std::arch::x86_64::_MM_HINT_T0 }>((value as *const T).cast())
    };
    #[cfg(not(target_arch = "x86_64"))]
    let _ = value;
}
