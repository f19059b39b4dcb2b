//! SyncManager buffer handshakes: one-buffer mailbox and three-buffer mode.
//!
//! A three-buffer SM physically occupies `start .. start + 3·length`; both
//! sides always address `start .. start + length − 1` and the ESC maps the
//! access to the buffer the side currently owns. The bytes of buffers 1 and 2
//! are not directly accessible (reads 0, writes ignored).

use ::esc::{
    regs::{self, al_event},
    sm::{activate, pdi_control, status},
    SmDirection, SmMode, SyncManager,
};

use super::{Esc, Op, Side};

/// Internal three-buffer state of one SyncManager (not visible in registers).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(super) struct SmState {
    /// Buffer owned by the reader (read again when nothing newer arrived).
    user: u8,
    /// Newest completely written buffer the reader has not taken yet.
    next: Option<u8>,
    /// Buffer the writer is filling.
    write: Option<u8>,
    /// Last completely written buffer (status bits 4..5).
    last_written: Option<u8>,
}

impl SmState {
    /// A buffer that is neither the reader's nor the newest complete one.
    fn free(&self) -> u8 {
        (0..3u8)
            .find(|b| *b != self.user && Some(*b) != self.next)
            .unwrap_or(0)
    }
}

/// How one access relates to one SyncManager.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Plan {
    /// Enabled with a valid mode and direction and a non-zero length.
    pub active: bool,
    /// Deactivated by the PDI: ECAT accesses to the area are refused.
    pub blocked: bool,
    /// Three-buffer mode (else mailbox).
    pub buffered: bool,
    /// Buffer area start.
    pub start: u32,
    /// Buffer length.
    pub len: u32,
    /// Control byte.
    pub control: u8,
    /// The accessing side.
    pub side: Side,
    /// The accessing side is this SM's reader (else its writer).
    pub reader: bool,
    /// The access overlaps the buffer area.
    pub involved: bool,
    /// The access reads the buffer.
    pub read_ok: bool,
    /// The access writes the buffer.
    pub write_ok: bool,
    /// Buffer index (0..2) the access is mapped to.
    pub buffer: u8,
    /// The access touches the first byte.
    pub touches_first: bool,
    /// The access touches the last byte.
    pub touches_last: bool,
}

impl Default for Plan {
    fn default() -> Self {
        Self {
            active: false,
            blocked: false,
            buffered: false,
            start: 0,
            len: 0,
            control: 0,
            side: Side::Ecat,
            reader: false,
            involved: false,
            read_ok: false,
            write_ok: false,
            buffer: 0,
            touches_first: false,
            touches_last: false,
        }
    }
}

impl Plan {
    /// The plan of SM `sm` for an access from `side` (not yet tied to an address range).
    pub fn new(sm: &SyncManager, side: Side) -> Self {
        let c = sm.control();
        let buffered = match c.mode() {
            SmMode::Buffered => true,
            SmMode::Mailbox => false,
            SmMode::Reserved(_) => return Self::default(),
        };
        let ecat_writes = match c.direction() {
            SmDirection::MasterWrite => true,
            SmDirection::MasterRead => false,
            SmDirection::Reserved(_) => return Self::default(),
        };
        if !sm.enabled() || sm.length == 0 {
            return Self::default();
        }
        let deactivated = sm.pdi_control & pdi_control::DEACTIVATE != 0;
        if deactivated && side == Side::Pdi {
            // the PDI sees plain memory
            return Self::default();
        }
        Self {
            active: true,
            blocked: deactivated,
            buffered,
            start: u32::from(sm.start),
            len: u32::from(sm.length),
            control: sm.control,
            side,
            reader: ecat_writes == (side == Side::Pdi),
            ..Self::default()
        }
    }

    /// The access `addr .. end` overlaps the buffer area.
    pub fn overlaps(&self, addr: u32, end: u32) -> bool {
        self.start < end && addr < self.start + self.len
    }

    /// The access `addr .. end` overlaps the area [`classify`] gives this SM
    /// (an active SM's buffer, and a three-buffer SM's hidden buffers).
    pub fn reaches(&self, addr: u32, end: u32) -> bool {
        let span = if self.buffered { 3 * self.len } else { self.len };
        self.active && self.start < end && addr < self.start + span
    }

    fn last(&self) -> u32 {
        self.start + self.len - 1
    }

    /// Decides whether the access may read/write the buffer and which buffer it
    /// maps to; opens three-buffer reads and writes.
    pub fn decide(&mut self, st: &mut SmState, op: Op, full: bool, addr: u32, end: u32) {
        let last = self.last();
        self.touches_first = addr <= self.start && self.start < end;
        self.touches_last = addr <= last && last < end;
        if self.blocked {
            return;
        }
        self.read_ok = op.reads() && self.reader && (self.buffered || full);
        self.write_ok = op.writes() && !self.reader && (self.buffered || !full);
        if !self.buffered {
            return;
        }
        if self.read_ok {
            if self.touches_first {
                if let Some(n) = st.next.take() {
                    st.user = n;
                }
            }
            self.buffer = st.user;
        } else if self.write_ok {
            let w = match st.write {
                Some(w) => w,
                None => {
                    let w = st.free();
                    st.write = Some(w);
                    w
                }
            };
            self.buffer = w;
        }
    }
}

/// Where a byte lies relative to the SyncManagers.
pub(super) enum Where {
    /// Inside an active SM's buffer area.
    Buffer(Plan),
    /// Inside the hidden buffers 1 and 2 of an active three-buffer SM.
    Hidden,
    /// Ordinary memory.
    Plain,
}

/// Classifies byte `a` (an SM's own area wins over another's hidden buffers).
pub(super) fn classify(plans: &[Plan], a: u32) -> Where {
    if let Some(p) = plans
        .iter()
        .find(|p| p.active && p.start <= a && a < p.start + p.len)
    {
        return Where::Buffer(*p);
    }
    if plans
        .iter()
        .any(|p| p.active && p.buffered && p.start + p.len <= a && a < p.start + 3 * p.len)
    {
        return Where::Hidden;
    }
    Where::Plain
}

/// ECAT event request bit of SM `n` (0x0210 bits 4..11).
fn ecat_event_bit(n: u8) -> u16 {
    if n < 8 {
        1 << (4 + n)
    } else {
        0
    }
}

impl Esc {
    fn sm_status(&self, n: u8) -> u8 {
        self.get_u8(regs::sm(n) + 5)
    }

    fn set_sm_status(&mut self, n: u8, v: u8) {
        self.set_u8(regs::sm(n) + 5, v);
    }

    fn sm_state(&mut self, n: u8) -> Option<&mut SmState> {
        self.sm.get_mut(usize::from(n))
    }

    /// Three-buffer status bits 4..5: last written buffer, 3 = none.
    fn buffer_bits(st: &SmState) -> u8 {
        st.last_written.unwrap_or(3) << 4 & status::BUFFER_MASK
    }

    /// Start of an allowed access: clear the events the access acknowledges
    /// and mark the buffer opened.
    pub(super) fn sm_open(&mut self, n: u8, plan: &Plan) {
        if plan.touches_first || plan.touches_last {
            match plan.side {
                Side::Pdi => self.clear_al_event(al_event::sm(n)),
                Side::Ecat => self.clear_ecat_event(ecat_event_bit(n)),
            }
        }
        let mut s = self.sm_status(n);
        if plan.read_ok && plan.touches_first {
            s &= !status::IRQ_WRITE;
            if plan.buffered {
                s |= status::READ_OPEN;
            }
        }
        if plan.write_ok && plan.touches_first {
            s &= !status::IRQ_READ;
        }
        if plan.write_ok && plan.buffered {
            s |= status::WRITE_OPEN;
        }
        self.set_sm_status(n, s);
    }

    /// The reader read the last byte: the buffer is released.
    pub(super) fn sm_read_done(&mut self, n: u8, plan: &Plan) {
        let mut s = self.sm_status(n) | status::IRQ_READ;
        s &= !(status::READ_OPEN | if plan.buffered { 0 } else { status::MAILBOX_FULL });
        self.set_sm_status(n, s);
        self.sm_notify(n, plan);
    }

    /// The writer wrote the last byte: the buffer is handed to the reader.
    pub(super) fn sm_write_done(&mut self, n: u8, plan: &Plan) {
        let mut s = self.sm_status(n) | status::IRQ_WRITE;
        if plan.buffered {
            let bits = match self.sm_state(n) {
                Some(st) => {
                    if let Some(w) = st.write.take() {
                        st.next = Some(w);
                        st.last_written = Some(w);
                    }
                    Self::buffer_bits(st)
                }
                None => status::BUFFER_MASK,
            };
            s = (s & !(status::WRITE_OPEN | status::BUFFER_MASK)) | bits;
        } else {
            s |= status::MAILBOX_FULL;
        }
        self.set_sm_status(n, s);
        self.sm_notify(n, plan);
        if plan.side == Side::Ecat && ::esc::SmControl(plan.control).watchdog() {
            self.retrigger_pd_watchdog();
        }
    }

    /// Events of a completed buffer: towards the PDI when ECAT completed it,
    /// towards ECAT when the PDI completed it.
    fn sm_notify(&mut self, n: u8, plan: &Plan) {
        let c = ::esc::SmControl(plan.control);
        match plan.side {
            Side::Ecat => {
                if c.pdi_irq() {
                    self.set_al_event(al_event::sm(n));
                }
            }
            Side::Pdi => {
                if c.ecat_irq() {
                    self.set_ecat_event(ecat_event_bit(n));
                }
            }
        }
    }

    /// Resets the buffer state of SM `n` (enable/disable, PDI deactivate).
    fn sm_reset(&mut self, n: u8) {
        if let Some(st) = self.sm_state(n) {
            *st = SmState::default();
        }
        let sm = self.sync_manager(n);
        let s = if sm.control().mode() == SmMode::Buffered {
            status::BUFFER_MASK
        } else {
            0
        };
        self.set_sm_status(n, s);
        self.clear_al_event(al_event::sm(n));
    }

    /// ECAT wrote the activate byte of SM `n` (old value `old`).
    pub(super) fn sm_activate_written(&mut self, n: u8, old: u8) {
        self.set_al_event(al_event::SM_ACTIVATION);
        let sm = self.sync_manager(n);
        let changed = old ^ sm.activate;
        if changed & activate::ENABLE != 0 {
            self.sm_reset(n);
        } else if changed & activate::REPEAT != 0
            && sm.enabled()
            && sm.control().mode() == SmMode::Mailbox
            && sm.control().direction() == SmDirection::MasterRead
        {
            // Repeat request: the read mailbox is emptied so the PDI can write
            // the repeated message; it is full again after the PDI wrote its
            // last byte. The PDI then sets REPEAT_ACK equal to REPEAT.
            let s = self.sm_status(n) & !status::MAILBOX_FULL;
            self.set_sm_status(n, s);
        }
    }

    /// The PDI wrote the PDI control byte of SM `n` (old value `old`).
    pub(super) fn sm_pdi_control_written(&mut self, n: u8, old: u8) {
        let new = self.get_u8(regs::sm(n) + 7);
        if (old ^ new) & pdi_control::DEACTIVATE != 0 {
            self.sm_reset(n);
        }
    }
}
