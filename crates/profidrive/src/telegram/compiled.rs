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
