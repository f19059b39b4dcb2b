//! Telegrams compiled into per-slot handles (issue 36): where the telegrams
//! are configured, or where the personality prepares for the next cycle
//! (not in the control cycle), each object entry of every layout is
//! resolved once by the access ([`SlotAccess::resolve`]) into a handle of
//! its own choosing (a catalogue position, an object's index). The cyclic
//! path ([`Telegrams::apply_receive_compiled`],
//! [`Telegrams::build_response_compiled`]) hands the handle to the access
//! instead of the address to look up; an entry without a handle, and every
//! entry when the handles were compiled for other layouts, takes the
//! address path ([`ParamAccess::write`], [`ParamAccess::read`]). The
//! answers are the address path's: a handle only saves the lookup.

use super::cyclic::{RxOutcome, TxOutcome};
use super::{Dir, Kind, Telegrams, MAX_ENTRIES, TELEGRAMS};
use crate::{Addr, Completion, ParamAccess, PdError};
use core::sync::atomic::{AtomicU32, Ordering};

/// The last stamp handed out ([`stamp`]).
static STAMPS: AtomicU32 = AtomicU32::new(0);

/// A new stamp for a configuration of layouts (never 0, the stamp of no
/// configuration; wraps after 2^32 configurations).
pub(super) fn stamp() -> u32 {
    let s = STAMPS.fetch_add(1, Ordering::Relaxed).wrapping_add(1);
    if s == 0 {
        STAMPS.fetch_add(1, Ordering::Relaxed).wrapping_add(1)
    } else {
        s
    }
}

/// A parameter access whose telegram entries can be resolved ahead into
/// handles. `write_handle` / `read_handle` of the handle `resolve` gave for
/// `addr` answer and act exactly as `write(addr, value, true)` /
/// `read(addr)` would.
pub trait SlotAccess: ParamAccess {
    /// What a resolved entry is to the access.
    type Handle: Copy;

    /// `addr` of a `dir` telegram resolved, or `None` (the entry takes the
    /// address path).
    fn resolve(&mut self, dir: Dir, addr: Addr) -> Option<Self::Handle>;

    /// The cyclic write of `value` to the entry `h` stands for (`addr`).
    fn write_handle(&mut self, h: Self::Handle, addr: Addr, value: i64) -> Result<Completion, PdError>;

    /// The read of the entry `h` stands for (`addr`).
    fn read_handle(&mut self, h: Self::Handle, addr: Addr) -> Result<i64, PdError>;
}

/// The handles of every slot of every layout, for the layouts they were
/// compiled for.
#[derive(Debug, Clone)]
pub struct Compiled<H> {
    /// The layouts' stamp, 0 = none compiled.
    stamp: u32,
    receive: [[Option<H>; MAX_ENTRIES]; TELEGRAMS],
    response: [[Option<H>; MAX_ENTRIES]; TELEGRAMS],
}

impl<H: Copy> Default for Compiled<H> {
    fn default() -> Self {
        Self::new()
    }
}

impl<H: Copy> Compiled<H> {
    /// Nothing compiled: every entry takes the address path.
    pub const fn new() -> Self {
        Self {
            stamp: 0,
            receive: [[None; MAX_ENTRIES]; TELEGRAMS],
            response: [[None; MAX_ENTRIES]; TELEGRAMS],
        }
    }

    /// Compiled for the layouts `t` has in force?
    pub fn is_for(&self, t: &Telegrams) -> bool {
        t.configured && self.stamp == t.stamp
    }

    /// Forgets the handles (the entries take the address path until the
    /// next [`compile`](Self::compile)), for a change the handles depend
    /// on that the layouts do not show (another axis).
    pub fn clear(&mut self) {
        self.stamp = 0;
    }

    /// Resolves every object entry of `t`'s layouts through `access`.
    pub fn compile<A: SlotAccess<Handle = H>>(&mut self, t: &Telegrams, access: &mut A) {
        self.stamp = 0;
        if !t.configured {
            return;
        }
        for dir in [Dir::Receive, Dir::Response] {
            let (layouts, handles) = match dir {
                Dir::Receive => (&t.receive, &mut self.receive),
                Dir::Response => (&t.response, &mut self.response),
            };
            for (layout, handles) in layouts.iter().zip(handles.iter_mut()) {
                *handles = [None; MAX_ENTRIES];
                for (s, h) in layout.slots().iter().zip(handles.iter_mut()) {
                    // receive: CW1 is returned, not written (no handle)
                    *h = match s.kind {
                        Kind::Object(_) => access.resolve(dir, s.addr),
                        Kind::Cw1 if dir == Dir::Response => access.resolve(dir, s.addr),
                        _ => None,
                    };
                }
            }
        }
        self.stamp = t.stamp;
    }

    fn handle(&self, dir: Dir, n: u8, i: usize) -> Option<H> {
        let table = match dir {
            Dir::Receive => &self.receive,
            Dir::Response => &self.response,
        };
        table.get(usize::from(n))?.get(i).copied().flatten()
    }
}

impl Telegrams {
    /// [`apply_receive`](Self::apply_receive) through the handles of
    /// `compiled` where it holds them for these layouts (the same outcome
    /// and writes; the address path for the rest).
    pub fn apply_receive_compiled<A: SlotAccess>(
        &mut self,
        frame: &[u8],
        access: &mut A,
        compiled: &Compiled<A::Handle>,
    ) -> RxOutcome {
        if !compiled.is_for(self) {
            return self.apply_receive(frame, access);
        }
        self.receive_through(frame, access, |a, n, i, addr, v| {
            match compiled.handle(Dir::Receive, n, i) {
                Some(h) => a.write_handle(h, addr, v).is_ok(),
                None => a.write(addr, v, true).is_ok(),
            }
        })
    }

    /// [`build_response`](Self::build_response) through the handles of
    /// `compiled` where it holds them for these layouts (the same bytes and
    /// outcome; the address path for the rest).
    pub fn build_response_compiled<A: SlotAccess>(
        &mut self,
        n: u8,
        access: &mut A,
        pkw: [u8; 8],
        buf: &mut [u8],
        compiled: &Compiled<A::Handle>,
    ) -> Option<TxOutcome> {
        if !compiled.is_for(self) {
            return self.build_response(n, access, pkw, buf);
        }
        self.respond_through(n, access, pkw, buf, |a, i, addr| {
            match compiled.handle(Dir::Response, n, i) {
                Some(h) => a.read_handle(h, addr),
                None => a.read(addr),
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fake::Fake;
    use std::vec::Vec;

    /// The fake drive with handles: an entry's position in its object
    /// list; every handle access counted.
    struct Handled {
        f: Fake,
        by_handle: Vec<Addr>,
    }

    impl Handled {
        /// Handle `h` must stand for `addr`; the access is counted.
        fn used(&mut self, h: usize, addr: Addr) -> Result<(), PdError> {
            let a = self
                .f
                .objs
                .get(h)
                .map(|o| o.addr)
                .ok_or(PdError::IMPERMISSIBLE_PNU)?;
            assert_eq!(a, addr, "the handle stands for its address");
            self.by_handle.push(addr);
            Ok(())
        }
    }

    impl ParamAccess for Handled {
        fn describe(&self, addr: Addr) -> Result<crate::Describe, PdError> {
            self.f.describe(addr)
        }
        fn read(&mut self, addr: Addr) -> Result<i64, PdError> {
            self.f.read(addr)
        }
        fn write(&mut self, addr: Addr, value: i64, cyclic: bool) -> Result<Completion, PdError> {
            self.f.write(addr, value, cyclic)
        }
    }

    impl SlotAccess for Handled {
        type Handle = usize;
        fn resolve(&mut self, _dir: Dir, addr: Addr) -> Option<usize> {
            self.f.objs.iter().position(|o| o.addr == addr)
        }
        fn write_handle(&mut self, h: usize, addr: Addr, value: i64) -> Result<Completion, PdError> {
            self.used(h, addr)?;
            self.f.write(addr, value, true)
        }
        fn read_handle(&mut self, h: usize, addr: Addr) -> Result<i64, PdError> {
            self.used(h, addr)?;
            self.f.read(addr)
        }
    }

    /// Issue 36, P-067, P-074: the compiled telegrams write and read through
    /// their handles with the address path's bytes, writes and outcome;
    /// handles compiled for other layouts (a telegram reconfigured, another
    /// instance) are not used.
    #[test]
    fn issue36_p067_compiled_telegrams_answer_as_the_address_path() {
        let mut a = Handled {
            f: Fake::drive(),
            by_handle: Vec::new(),
        };
        let mut b = Fake::drive();
        let mut ta = Telegrams::with_defaults(&a).unwrap();
        let mut tb = ta.clone();
        let mut compiled = Compiled::new();
        assert!(!compiled.is_for(&ta));
        compiled.compile(&ta, &mut a);
        assert!(
            compiled.is_for(&ta) && compiled.is_for(&tb),
            "a clone has the same layouts"
        );
        let mut frame = [0u8; 36];
        frame[0] = 0xE0;
        frame[1] = 3;
        frame[2..4].copy_from_slice(&0x047Fu16.to_be_bytes());
        frame[4..8].copy_from_slice(&(-5000i32).to_be_bytes());
        frame[32..36].copy_from_slice(&77i32.to_be_bytes());
        let ra = ta.apply_receive_compiled(&frame, &mut a, &compiled);
        let rb = tb.apply_receive(&frame, &mut b);
        assert_eq!(ra, rb);
        assert_eq!(a.f.writes, b.writes);
        assert!(a.by_handle.contains(&Addr::new(1001, 0)), "{:?}", a.by_handle);
        let (mut oa, mut ob) = ([0u8; 36], [0u8; 36]);
        let xa = ta.build_response_compiled(0, &mut a, [1; 8], &mut oa, &compiled);
        let xb = tb.build_response(0, &mut b, [1; 8], &mut ob);
        assert_eq!((xa, oa), (xb, ob));
        assert!(a.by_handle.contains(&Addr::new(1100, 0)));
        // reconfigured: a new stamp, the handles are stale until compiled
        ta.configure(&super::super::FB_DEFAULTS, &a).unwrap();
        assert!(!compiled.is_for(&ta));
        a.by_handle.clear();
        let ra = ta.apply_receive_compiled(&frame, &mut a, &compiled);
        assert_eq!(ra.telegram, Some(0));
        assert!(a.by_handle.is_empty(), "the address path: {:?}", a.by_handle);
        // another instance configured alike has its own stamp
        let other = Telegrams::with_defaults(&b).unwrap();
        assert!(!compiled.is_for(&other));
        compiled.compile(&ta, &mut a);
        assert!(compiled.is_for(&ta));
        compiled.clear();
        assert!(!compiled.is_for(&ta));
    }
}
