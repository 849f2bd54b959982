//! Transparent huge pages for the large buffers of a fit (the MERL table, the per-source rows,
//! the grid geometry): each is written once, all of it, right after it is allocated, and with
//! 4 KiB pages a fresh 35 MB buffer costs some 9 000 page faults, tens of milliseconds of a
//! `facet fit` process. Linux only, and only a hint: where the kernel gives no huge pages
//! (`/sys/kernel/mm/transparent_hugepage/enabled` = never) nothing changes.

/// Asks the kernel to back the 2 MiB-aligned part of `buf` with huge pages, before it is first
/// written (untouched pages of a fresh zeroed allocation are not yet mapped).
pub fn advise<T>(buf: &mut [T]) {
    #[cfg(target_os = "linux")]
    {
        const HUGE: usize = 2 << 20;
        let start = buf.as_mut_ptr() as usize;
        let end = start + std::mem::size_of_val(buf);
        let (a, b) = (start.next_multiple_of(HUGE), end / HUGE * HUGE);
        if b > a {
            // SAFETY: [a, b) lies inside `buf`, memory this process owns; MADV_HUGEPAGE changes
            // how it is backed, never its contents. A failure (EINVAL without THP) is ignored.
            unsafe {
                libc::madvise(a as *mut libc::c_void, b - a, libc::MADV_HUGEPAGE);
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = buf;
}
