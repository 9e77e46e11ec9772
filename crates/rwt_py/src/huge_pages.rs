//! Huge pages for large fresh columns. numpy asks Linux for them for its own arrays of
//! 4 MB or more (`madvise(MADV_HUGEPAGE)`, which matters where transparent huge pages are
//! set to `madvise`, most distributions' default); the columns `rwt_noise.sample` hands to
//! numpy are allocated here, so they ask too. A fresh 400 MB of columns (10 million points)
//! then faults in 2 MB at a time instead of 4 KB: the faults took more than half of such a
//! call (about 375 ms a call, 160 ms with huge pages, on the 2-core CI machine). The
//! columns' contents are checked by the Python tests of large samples (the union of chunk
//! queries, the all-core queries).

/// Smallest spare capacity worth advising, in bytes (numpy's threshold).
#[cfg(target_os = "linux")]
const LEAST: usize = 4 << 20;

/// Page size the advised range is aligned to. Where pages are larger, the kernel refuses
/// the unaligned range, and nothing changes.
#[cfg(target_os = "linux")]
const PAGE: usize = 4096;

/// Asks the kernel to back the spare capacity of `v` with huge pages (on Linux, from 4 MB;
/// elsewhere nothing). Advice only: the contents and the vector are unchanged, and a
/// refusal changes nothing but speed.
pub fn advise<T>(v: &mut Vec<T>) {
    #[cfg(target_os = "linux")]
    {
        let spare = v.spare_capacity_mut();
        let bytes = std::mem::size_of_val(spare);
        if bytes < LEAST {
            return;
        }
        let start = spare.as_mut_ptr() as usize;
        let aligned = start.next_multiple_of(PAGE);
        let len = (start + bytes - aligned) / PAGE * PAGE;
        madvise_huge(aligned, len);
    }
    #[cfg(not(target_os = "linux"))]
    let _ = v;
}

/// `madvise(start, len, MADV_HUGEPAGE)`, its result ignored.
#[cfg(target_os = "linux")]
#[allow(unsafe_code)]
fn madvise_huge(start: usize, len: usize) {
    // SAFETY: `[start, start + len)` lies inside the spare capacity of a vector borrowed
    // mutably by the caller (page-aligned, within its allocation), so no one else reads or
    // writes it meanwhile. MADV_HUGEPAGE only changes how the range's pages are backed,
    // never their contents or the mapping's protection, and an error leaves it as it was.
    unsafe {
        libc::madvise(start as *mut libc::c_void, len, libc::MADV_HUGEPAGE);
    }
}
