//! One datagram against the register model: the addressing (position,
//! configured, broadcast, logical through the FMMUs), the working counter,
//! and every byte's access rule (read, write, the side effects of the ESC's
//! registers, SyncManager buffers and mailboxes).

use super::*;

/// Who accesses the memory.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Side {
    /// The master, through datagrams.
    Ecat,
    /// The slave's application processor.
    Pdi,
}

/// What an access does with each byte.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Op {
    /// Memory → data.
    Read,
    /// Memory OR-ed into data (broadcast read).
    ReadOr,
    /// Data → memory.
    Write,
    /// Old memory → data, incoming data → memory.
    ReadWrite,
    /// Old memory OR-ed into data, incoming data → memory.
    ReadOrWrite,
}

impl Op {
    pub(super) fn reads(self) -> bool {
        !matches!(self, Op::Write)
    }
    pub(super) fn writes(self) -> bool {
        matches!(self, Op::Write | Op::ReadWrite | Op::ReadOrWrite)
    }
    pub(super) fn ors(self) -> bool {
        matches!(self, Op::ReadOr | Op::ReadOrWrite)
    }
}

/// Result of one access: whether the read and the write part took place
/// (a SyncManager may refuse either; the WKC then does not count it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(super) struct Outcome {
    pub(super) read: bool,
    pub(super) written: bool,
}

/// How a command counts towards the working counter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Kind {
    Read,
    Write,
    ReadWrite,
}

impl Kind {
    pub(super) fn wkc(self, o: Outcome) -> u16 {
        match self {
            Kind::Read => u16::from(o.read),
            Kind::Write => u16::from(o.written),
            Kind::ReadWrite => u16::from(o.read) + 2 * u16::from(o.written),
        }
    }
    pub(super) fn op(self) -> Op {
        match self {
            Kind::Read => Op::Read,
            Kind::Write => Op::Write,
            Kind::ReadWrite => Op::ReadWrite,
        }
    }
}

/// How a physical command counts.
pub(super) fn physical_kind(cmd: Command) -> Kind {
    match cmd {
        Command::Aprd | Command::Fprd => Kind::Read,
        Command::Apwr | Command::Fpwr => Kind::Write,
        _ => Kind::ReadWrite,
    }
}

/// DL status bits, named as the simulated ESC uses them.
pub(super) mod dl {
    use ::esc::regs::dl_status;
    pub const PDI_OPERATIONAL: u16 = dl_status::PDI_OPERATIONAL;
    pub const PDI_WATCHDOG: u16 = dl_status::PDI_WATCHDOG;
    pub const LINK0: u16 = dl_status::link(0);
    pub const LOOP1: u16 = dl_status::loop_closed(1);
    pub const COMM0: u16 = dl_status::communication(0);
    pub const LOOP2: u16 = dl_status::loop_closed(2);
    pub const LOOP3: u16 = dl_status::loop_closed(3);
}

/// Whether a plain (non-SyncManager) byte at `a` takes writes from `side`.
pub(super) fn writable(side: Side, a: u32) -> bool {
    let sm_lo = u32::from(regs::SM_BASE);
    let sm_hi = sm_lo + u32::from(regs::SM_LEN) * MAX_SM as u32;
    match side {
        Side::Ecat => match a {
            0x0000..=0x000F => false,
            // alias and EEPROM-loaded configuration
            0x0012..=0x0013 | 0x0140..=0x0141 | 0x0150..=0x0153 => false,
            // DL status, AL status, AL status code
            0x0110..=0x0111 | 0x0130..=0x0137 => false,
            // event requests
            0x0210..=0x0211 | 0x0220..=0x0223 => false,
            // watchdog status; counters are cleared by a write (side effect)
            0x0440..=0x0443 => false,
            // SII control/status: command execution (side effect)
            0x0502..=0x0503 => false,
            // DC receive times (latched by a write), system time, receive time PU
            0x0900..=0x091F => false,
            // DC system time difference, speed counter difference, cyclic unit status
            0x092C..=0x092F | 0x0932..=0x0933 | 0x0984 | 0x098E..=0x098F | 0x0998..=0x099F => false,
            _ if (sm_lo..sm_hi).contains(&a) => !matches!((a - sm_lo) % 8, 5 | 7),
            _ => true,
        },
        Side::Pdi => match a {
            0x0000..=0x0011 => false,
            0x0110..=0x0111 | 0x0120..=0x0121 => false,
            0x0210..=0x0211 | 0x0220..=0x0223 => false,
            0x0440..=0x0443 => false,
            0x0502..=0x0503 => false,
            0x0600..=0x06FF => false,
            0x0900..=0x091F => false,
            _ if (sm_lo..sm_hi).contains(&a) => (a - sm_lo) % 8 == 7,
            _ => true,
        },
    }
}

impl Esc {
    /// Processes one datagram as it passes this ESC: addressing, memory access
    /// with all side effects, working counter, ADP auto-increment. `now` is
    /// the time the frame entered the line; DC registers use the frame's
    /// arrival at this ESC (see [`Esc::set_line_timing`]).
    pub fn process_datagram(&mut self, dg: &mut Datagram<'_>, now: Nanos) {
        self.tick(now);
        self.last_frame = Some(self.now);
        self.dc.ecat_time = self.now.saturating_add(self.dc.line.arrival);
        let adp = dg.adp();
        let ado = u32::from(dg.ado());
        let cmd = dg.command();
        let wkc = match cmd {
            Command::Nop | Command::Unknown(_) => 0,
            Command::Aprd | Command::Apwr | Command::Aprw => {
                dg.set_adp(adp.wrapping_add(1));
                if adp == 0 {
                    let kind = physical_kind(cmd);
                    kind.wkc(self.access(Side::Ecat, ado, dg.data_mut(), kind.op()))
                } else {
                    0
                }
            }
            Command::Fprd | Command::Fpwr | Command::Fprw => {
                if self.configured_match(adp) {
                    let kind = physical_kind(cmd);
                    kind.wkc(self.access(Side::Ecat, ado, dg.data_mut(), kind.op()))
                } else {
                    0
                }
            }
            Command::Brd => {
                dg.set_adp(adp.wrapping_add(1));
                Kind::Read.wkc(self.access(Side::Ecat, ado, dg.data_mut(), Op::ReadOr))
            }
            Command::Bwr => {
                dg.set_adp(adp.wrapping_add(1));
                Kind::Write.wkc(self.access(Side::Ecat, ado, dg.data_mut(), Op::Write))
            }
            Command::Brw => {
                dg.set_adp(adp.wrapping_add(1));
                Kind::ReadWrite.wkc(self.access(Side::Ecat, ado, dg.data_mut(), Op::ReadOrWrite))
            }
            Command::Lrd | Command::Lwr | Command::Lrw => {
                let kind = match cmd {
                    Command::Lrd => Kind::Read,
                    Command::Lwr => Kind::Write,
                    _ => Kind::ReadWrite,
                };
                let laddr = dg.logical_address();
                kind.wkc(self.logical(kind, laddr, dg.data_mut()))
            }
            Command::Armw => {
                dg.set_adp(adp.wrapping_add(1));
                self.read_multiple_write(adp == 0, ado, dg.data_mut())
            }
            Command::Frmw => {
                let me = self.configured_match(adp);
                self.read_multiple_write(me, ado, dg.data_mut())
            }
        };
        if wkc != 0 {
            dg.add_wkc(wkc);
        }
    }

    /// ARMW/FRMW: the addressed slave reads, every other slave writes; +1 either way.
    /// A write that includes 0x0910 (the system time) feeds the drift-control loop.
    pub(super) fn read_multiple_write(&mut self, addressed: bool, ado: u32, data: &mut [u8]) -> u16 {
        if addressed {
            Kind::Read.wkc(self.access(Side::Ecat, ado, data, Op::Read))
        } else {
            let wkc = Kind::Write.wkc(self.access(Side::Ecat, ado, data, Op::Write));
            let st = u32::from(regs::dc::SYSTEM_TIME);
            if let Some(off) = st.checked_sub(ado) {
                let off = off as usize;
                if let Some(w) = data.get(off..data.len().min(off.saturating_add(8))) {
                    self.dc_system_time_written(w);
                }
            }
            wkc
        }
    }

    /// Configured-address match: station address, or the alias when DL control bit 24 is set.
    pub(super) fn configured_match(&self, adp: u16) -> bool {
        adp == self.station_address()
            || (self.get_u32(regs::DL_CONTROL) & (1 << 24) != 0 && adp == self.station_alias())
    }

    /// Logical access through the enabled FMMUs. Write-only mappings go first,
    /// then read-write, then read-only ones, so an LRW returns inputs while the
    /// outputs written are the master's.
    pub(super) fn logical(&mut self, kind: Kind, laddr: u32, data: &mut [u8]) -> Outcome {
        let mut out = Outcome::default();
        let d_lo = u64::from(laddr);
        let d_hi = d_lo + data.len() as u64;
        for pass in [Op::Write, Op::ReadWrite, Op::Read] {
            for n in 0..self.config.fmmu_count {
                let f = self.fmmu(n);
                if !f.enabled() {
                    continue;
                }
                let r = kind != Kind::Write && f.kind & Fmmu::READ != 0;
                let w = kind != Kind::Read && f.kind & Fmmu::WRITE != 0;
                let op = match (r, w) {
                    (true, true) => Op::ReadWrite,
                    (true, false) => Op::Read,
                    (false, true) => Op::Write,
                    (false, false) => continue,
                };
                if op != pass {
                    continue;
                }
                let f_lo = u64::from(f.logical_start);
                let f_hi = f_lo + u64::from(f.length);
                let lo = d_lo.max(f_lo);
                let hi = d_hi.min(f_hi);
                if lo >= hi {
                    continue;
                }
                let Some(phys) = u32::try_from(lo).ok().and_then(|l| f.map(l)) else {
                    continue;
                };
                let Some(sub) = data.get_mut((lo - d_lo) as usize..(hi - d_lo) as usize) else {
                    continue;
                };
                let o = self.access(Side::Ecat, u32::from(phys), sub, op);
                out.read |= o.read;
                out.written |= o.written;
            }
        }
        out
    }

    /// End of the present memory (exclusive).
    pub(super) fn present_end(&self) -> u32 {
        RAM_START + u32::from(self.config.ram_kib.min(8)) * 1024
    }

    /// Raw memory byte; 0 when not present.
    pub(super) fn raw(&self, a: u32) -> u8 {
        if a < self.present_end() {
            self.mem.get(a as usize).copied().unwrap_or(0)
        } else {
            0
        }
    }

    /// Bytes computed on read at time `t`: the DC system time (local time + offset).
    pub(super) fn computed(&self, a: u32, t: Nanos) -> Option<u8> {
        self.dc_computed(a, t)
    }

    /// One access from `side` at `addr` with all ESC side effects.
    pub(super) fn access(&mut self, side: Side, addr: u32, data: &mut [u8], op: Op) -> Outcome {
        if side == Side::Pdi {
            self.pdi_touch();
        }
        let len = data.len() as u32;
        let end = addr.saturating_add(len);
        // Old values of the bytes with write side effects (a write's only).
        let (old_activate, old_pdi_control) = if op.writes() {
            (self.sm_bytes(6), self.sm_bytes(7))
        } else {
            ([0; MAX_SM], [0; MAX_SM])
        };

        // the SMs whose area (three buffers at most) can overlap the access;
        // the others play no part in it (their registers are not parsed)
        let mut near_sms = 0u16;
        for n in 0..self.config.sm_count.min(MAX_SM as u8) {
            let base = regs::sm(n);
            let (start, length) = (u32::from(self.get_u16(base)), u32::from(self.get_u16(base + 2)));
            if start < end && addr < start + 3 * length {
                near_sms |= 1 << n;
            }
        }
        let out = if near_sms == 0 {
            // every byte plain memory (what the SM phases find then)
            let t_read = self.read_time(side);
            self.plain_data(side, addr, data, op, t_read);
            Outcome {
                read: op.reads(),
                written: op.writes(),
            }
        } else {
            self.sm_phases(side, addr, data, op, near_sms)
        };

        // Register side effects.
        let touches = |lo: u16, hi: u16| addr <= u32::from(hi) && u32::from(lo) < end;
        // (the SM register blocks looked at one by one only when touched)
        let sm_count = self.config.sm_count;
        let sm_block = sm_count > 0 && touches(regs::SM_BASE, regs::sm(sm_count) - 1);
        match side {
            Side::Ecat if op.writes() => {
                if touches(regs::AL_CONTROL, regs::AL_CONTROL + 1) {
                    self.set_al_event(al_event::AL_CONTROL);
                }
                for n in (0..sm_count).filter(|_| sm_block) {
                    let a = regs::sm(n) + 6;
                    if touches(a, a) {
                        let old = old_activate.get(usize::from(n)).copied().unwrap_or(0);
                        self.sm_activate_written(n, old);
                    }
                }
                if touches(regs::SII_CONTROL + 1, regs::SII_CONTROL + 1) {
                    let lo = if touches(regs::SII_CONTROL, regs::SII_CONTROL) {
                        data.get((u32::from(regs::SII_CONTROL) - addr) as usize)
                            .copied()
                            .unwrap_or(0)
                    } else {
                        0
                    };
                    let hi = data
                        .get((u32::from(regs::SII_CONTROL) + 1 - addr) as usize)
                        .copied()
                        .unwrap_or(0);
                    self.sii_command_written(u16::from_le_bytes([lo, hi]));
                }
                if touches(regs::dc::RECEIVE_TIME_PORT0, regs::dc::RECEIVE_TIME_PORT0 + 3) {
                    self.dc_latch_receive_times();
                }
                if touches(regs::dc::SPEED_COUNTER_START, regs::dc::SPEED_COUNTER_START + 1) {
                    self.dc_loop_reset();
                }
                if touches(regs::dc::ACTIVATION, regs::dc::ACTIVATION) {
                    self.dc_activation_written();
                }
                for reg in [regs::WATCHDOG_COUNTER_PD, regs::WATCHDOG_COUNTER_PDI] {
                    if touches(reg, reg) {
                        self.set_u8(reg, 0);
                    }
                }
            }
            Side::Pdi => {
                if op.reads() {
                    if touches(regs::AL_CONTROL, regs::AL_CONTROL + 1) {
                        self.clear_al_event(al_event::AL_CONTROL);
                    }
                    if sm_block && (0..sm_count).any(|n| touches(regs::sm(n) + 6, regs::sm(n) + 6)) {
                        self.clear_al_event(al_event::SM_ACTIVATION);
                    }
                    if touches(regs::WATCHDOG_STATUS_PD, regs::WATCHDOG_STATUS_PD + 1) {
                        self.clear_al_event(al_event::WATCHDOG_PD);
                    }
                    self.dc_pdi_read(|r| touches(r, r));
                }
                if op.writes() {
                    for n in (0..sm_count).filter(|_| sm_block) {
                        let a = regs::sm(n) + 7;
                        if touches(a, a) {
                            let old = old_pdi_control.get(usize::from(n)).copied().unwrap_or(0);
                            self.sm_pdi_control_written(n, old);
                        }
                    }
                    if touches(regs::AL_STATUS, regs::AL_STATUS + 1) {
                        // ECAT event request bit 3: AL status changed.
                        let e = self.get_u16(regs::ECAT_EVENT_REQUEST) | 1 << 3;
                        self.set_u16(regs::ECAT_EVENT_REQUEST, e);
                    }
                }
            }
            Side::Ecat => {}
        }
        out
    }

    /// Where a byte of the DC system time is read at: the frame's arrival
    /// for the master, the ESC's time for the PDI.
    fn read_time(&self, side: Side) -> Nanos {
        match side {
            Side::Ecat => self.dc.ecat_time,
            Side::Pdi => self.now,
        }
    }

    /// The SyncManager phases of an access and its data phase, for an access
    /// the SMs of `near_sms` (bit n: SM n) can concern: permission, buffer
    /// selection and opening; each byte through its SM's buffer mapping;
    /// completion on the last byte.
    fn sm_phases(&mut self, side: Side, addr: u32, data: &mut [u8], op: Op, near_sms: u16) -> Outcome {
        let end = addr.saturating_add(data.len() as u32);
        // SyncManager pre-phase: permission, buffer selection, opening.
        let mut plans = [sm::Plan::default(); MAX_SM];
        let mut out = Outcome {
            read: op.reads(),
            written: op.writes(),
        };
        for n in 0..usize::from(self.config.sm_count) {
            // the plans of the SMs apart from the access stay inactive
            if near_sms & 1 << n == 0 {
                continue;
            }
            let regs_n = self.sync_manager(n as u8);
            let Some(plan) = plans.get_mut(n) else { break };
            *plan = sm::Plan::new(&regs_n, side);
            if !plan.active || !plan.overlaps(addr, end) {
                continue;
            }
            plan.involved = true;
            let Some(state) = self.sm.get_mut(n) else { break };
            let full = regs_n.status & ::esc::sm::status::MAILBOX_FULL != 0;
            plan.decide(state, op, full, addr, end);
            if op.reads() && !plan.read_ok {
                out.read = false;
            }
            if op.writes() && !plan.write_ok {
                out.written = false;
            }
        }
        for n in 0..usize::from(self.config.sm_count) {
            let Some(plan) = plans.get(n).copied() else { break };
            if plan.involved && (plan.read_ok || plan.write_ok) {
                self.sm_open(n as u8, &plan);
            }
        }

        // Data phase.
        let t_read = self.read_time(side);
        // the SMs whose areas (hidden buffers included) the access overlaps,
        // in SM order: only these can classify one of its bytes
        let mut near = [sm::Plan::default(); MAX_SM];
        let mut k = 0;
        for p in plans.iter().filter(|p| p.reaches(addr, end)) {
            if let Some(slot) = near.get_mut(k) {
                *slot = *p;
                k += 1;
            }
        }
        let near = near.get(..k).unwrap_or_default();
        if near.is_empty() {
            self.plain_data(side, addr, data, op, t_read);
        } else {
            self.sm_data(side, addr, data, op, t_read, near);
        }

        // SyncManager post-phase: completion on the last byte.
        for n in 0..usize::from(self.config.sm_count) {
            let Some(plan) = plans.get(n).copied() else { break };
            if plan.involved && plan.touches_last {
                if plan.read_ok {
                    self.sm_read_done(n as u8, &plan);
                }
                if plan.write_ok {
                    self.sm_write_done(n as u8, &plan);
                }
            }
        }
        out
    }

    /// The data phase byte by byte when SyncManager areas overlap the
    /// access (`near`: their plans, in SM order): each byte through its SM's
    /// buffer mapping, hidden, or plain memory ([`sm::classify`]).
    pub(super) fn sm_data(
        &mut self,
        side: Side,
        addr: u32,
        data: &mut [u8],
        op: Op,
        t_read: Nanos,
        near: &[sm::Plan],
    ) {
        if let [p] = near {
            if self.buffer_data(side, addr, data, op, p) {
                return;
            }
        }
        self.sm_data_bytes(side, addr, data, op, t_read, near);
    }

    /// The data phase of an access that lies inside the buffer area of one
    /// SM (`p`, the only one near it), as slices: what
    /// [`Esc::sm_data_bytes`] does byte by byte there. `false` (nothing
    /// done) for an access it does not cover: outside the area, the
    /// buffer past the present memory, the DC system time among the bytes.
    pub(super) fn buffer_data(
        &mut self,
        side: Side,
        addr: u32,
        data: &mut [u8],
        op: Op,
        p: &sm::Plan,
    ) -> bool {
        let end = addr.saturating_add(data.len() as u32);
        let present = self.present_end();
        let st = u32::from(regs::dc::SYSTEM_TIME);
        let computed = self.config.dc_supported && addr < st + 8 && st < end;
        let shift = u32::from(p.buffer) * p.len;
        if !(p.active && p.start <= addr && end <= p.start + p.len) || computed || end + shift > present {
            return false;
        }
        if !(p.read_ok || p.write_ok) {
            // refused: the PDI reads zeros, nothing is written
            if side == Side::Pdi && op.reads() {
                data.fill(0);
            }
            return true;
        }
        let (lo, hi) = ((addr + shift) as usize, (end + shift) as usize);
        let Some(m) = self.mem.get_mut(lo..hi) else {
            return false;
        };
        let (rd, wr) = (p.read_ok, p.write_ok);
        for (m, d) in m.iter_mut().zip(data.iter_mut()) {
            let incoming = *d;
            if op.reads() {
                let value = if rd { *m } else { 0 };
                if op.ors() {
                    *d |= value;
                } else {
                    *d = value;
                }
            }
            if wr {
                *m = incoming;
            }
        }
        true
    }

    /// [`Esc::sm_data`] byte by byte: each byte through [`sm::classify`].
    pub(super) fn sm_data_bytes(
        &mut self,
        side: Side,
        addr: u32,
        data: &mut [u8],
        op: Op,
        t_read: Nanos,
        near: &[sm::Plan],
    ) {
        let present = self.present_end();
        for (i, byte) in data.iter_mut().enumerate() {
            let a = addr + i as u32;
            let incoming = *byte;
            let (phys, rd, wr) = match sm::classify(near, a) {
                sm::Where::Buffer(p) => {
                    if !(p.read_ok || p.write_ok) {
                        if side == Side::Pdi && op.reads() {
                            *byte = 0;
                        }
                        continue;
                    }
                    (a + u32::from(p.buffer) * p.len, p.read_ok, p.write_ok)
                }
                sm::Where::Hidden => (a, false, false),
                sm::Where::Plain => {
                    // the EEPROM address and data registers are locked while busy
                    let sii_locked = self.sii_pending.is_some() && (0x0504..=0x050F).contains(&a);
                    (a, op.reads(), op.writes() && writable(side, a) && !sii_locked)
                }
            };
            let value = if a >= present || !rd {
                0
            } else {
                self.computed(a, t_read).unwrap_or_else(|| self.raw(phys))
            };
            if op.reads() {
                if op.ors() {
                    *byte |= value;
                } else {
                    *byte = value;
                }
            }
            if wr && phys < present {
                if let Some(m) = self.mem.get_mut(phys as usize) {
                    *m = incoming;
                }
            }
        }
    }

    /// The data phase of an access that no SyncManager area overlaps: every
    /// byte is plain memory (what [`sm::classify`] says of it), read from
    /// memory (the DC system time computed at `t_read`, absent memory 0) and
    /// written where `side` may write it (not the EEPROM registers while a
    /// command runs). Ranges in the process RAM and register reads without
    /// the computed system time go as slices.
    pub(super) fn plain_data(&mut self, side: Side, addr: u32, data: &mut [u8], op: Op, t_read: Nanos) {
        let present = self.present_end();
        let end = addr.saturating_add(data.len() as u32);
        let st = u32::from(regs::dc::SYSTEM_TIME);
        let computed = self.config.dc_supported && addr < st + 8 && st < end;
        // every byte present and read from memory as it is
        let reads_mem = end <= present && !computed;
        // every byte writable from both sides (the process RAM)
        let writes_all = addr >= RAM_START && end <= present;
        let (lo, hi) = (addr as usize, end as usize);
        // (the ranges are exactly as long as `data`: `end` is in memory)
        match op {
            Op::Read if reads_mem => {
                if let Some(m) = self.mem.get(lo..hi) {
                    for (d, m) in data.iter_mut().zip(m) {
                        *d = *m;
                    }
                    return;
                }
            }
            Op::ReadOr if reads_mem => {
                if let Some(m) = self.mem.get(lo..hi) {
                    for (d, m) in data.iter_mut().zip(m) {
                        *d |= *m;
                    }
                    return;
                }
            }
            Op::Write if writes_all => {
                if let Some(m) = self.mem.get_mut(lo..hi) {
                    for (m, d) in m.iter_mut().zip(data.iter()) {
                        *m = *d;
                    }
                    return;
                }
            }
            Op::ReadWrite if writes_all && reads_mem => {
                if let Some(m) = self.mem.get_mut(lo..hi) {
                    for (m, d) in m.iter_mut().zip(data.iter_mut()) {
                        core::mem::swap(m, d);
                    }
                    return;
                }
            }
            _ => {}
        }
        let sii_locked = self.sii_pending.is_some();
        for (i, byte) in data.iter_mut().enumerate() {
            let a = addr + i as u32;
            let incoming = *byte;
            if op.reads() {
                let value = if a >= present {
                    0
                } else {
                    self.computed(a, t_read).unwrap_or_else(|| self.raw(a))
                };
                if op.ors() {
                    *byte |= value;
                } else {
                    *byte = value;
                }
            }
            // the EEPROM address and data registers are locked while busy
            let locked = sii_locked && (0x0504..=0x050F).contains(&a);
            if op.writes() && a < present && writable(side, a) && !locked {
                if let Some(m) = self.mem.get_mut(a as usize) {
                    *m = incoming;
                }
            }
        }
    }

    /// Byte `off` of every SM register block (used to see what a write changed).
    pub(super) fn sm_bytes(&self, off: u16) -> [u8; MAX_SM] {
        let mut b = [0u8; MAX_SM];
        for (n, v) in b.iter_mut().enumerate() {
            *v = self.get_u8(regs::sm(n as u8) + off);
        }
        b
    }
}
