//! `'static` values built in place, handed out once.
//!
//! Every image keeps its drive (about 30 KiB), its IP stack and its rings in
//! statics written in place by a `make_*` function of its own, never inlined
//! (built by value in `init` they needed more stack than a board leaves, and
//! `cortex_m::singleton!` copies the value through the caller's frame).
//! [`Once`] is that static: [`Once::take`] gives its uninitialised storage
//! once, the caller `write`s the value into it.

use core::cell::UnsafeCell;
use core::mem::MaybeUninit;
use core::sync::atomic::{AtomicBool, Ordering};

/// Storage for one `T`, handed out at most once.
pub struct Once<T> {
    cell: UnsafeCell<MaybeUninit<T>>,
    taken: AtomicBool,
}

// SAFETY: the storage is reached only through the one `&mut` that `take`
// hands out (guarded by the atomic flag), so sharing the `Once` shares no
// `T`; the `T` may be used from any context it is moved to (`T: Send`).
#[allow(unsafe_code)]
unsafe impl<T: Send> Sync for Once<T> {}

impl<T> Once<T> {
    /// Empty storage (for a `static`).
    #[allow(clippy::new_without_default)]
    pub const fn new() -> Self {
        Self {
            cell: UnsafeCell::new(MaybeUninit::uninit()),
            taken: AtomicBool::new(false),
        }
    }

    /// The storage, the first time; `None` after. `write` into it builds the
    /// value in place.
    #[inline(always)]
    #[allow(unsafe_code)]
    // one `&mut` from a shared `&'static`: the flag makes it the only one
    #[allow(clippy::mut_from_ref)]
    pub fn take(&'static self) -> Option<&'static mut MaybeUninit<T>> {
        if self.taken.swap(true, Ordering::AcqRel) {
            return None;
        }
        // SAFETY: the flag was false, so no other reference to the storage
        // was ever handed out, and none will be.
        Some(unsafe { &mut *self.cell.get() })
    }
}
