//! Diagnosis (E-132…E-139): the LEDs, A257 with its short texts, the ESC's
//! ports, event 52 and the fieldbus identification.

use super::*;

/// Diag code of a refused ESM transition: this prefix | AL status code (our
/// choice; the message texts belong in the ESI).
pub const DIAG_AL_STATUS: u32 = 0xE000_0000;

/// Diag code of an axis fault: ETG.1020's E800h for an emergency, the
/// EMCY error code (603Fh) in bits 16…31; the message's parameters are
/// the axis (0 = A) and the E82 event << 8 | the E43 cause.
pub const DIAG_EMCY: u32 = 0x0000_E800;

/// The ESC's link and error registers (A257[0..2], the link LEDs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(super) struct PortDiag {
    /// DL status 0x0110.
    pub(super) dl_status: u16,
    /// Lost-link counters 0x0310, ports 0 and 1.
    pub(super) lost: [u8; 2],
    /// Invalid-frame + RX-error counters 0x0300…, ports 0 and 1.
    pub(super) rx_errors: [u16; 2],
    /// The texts were written at least once.
    pub(super) shown: bool,
    /// The Er code shown.
    pub(super) er: u8,
}

/// The four EtherCAT LEDs (spec §13.3) as patterns ([`Drive::leds`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Leds {
    /// Green RUN: the ESM state (E-133).
    pub run: Pattern,
    /// Red ERR: the error indication (E-132).
    pub err: Pattern,
    /// Green LA_EC IN (X200, port 0) and OUT (X201, port 1) (E-134).
    pub ports: [Pattern; 2],
}

impl Leds {
    /// Whether each LED is lit at `t`: RUN, ERR, IN, OUT.
    pub const fn lit(&self, t: Nanos) -> [bool; 4] {
        let [p0, p1] = self.ports;
        [self.run.is_on(t), self.err.is_on(t), p0.is_on(t), p1.is_on(t)]
    }
}

/// Whether `f` is the fault of event 52.
pub(super) fn is_event52(f: &FaultChange) -> bool {
    matches!(f, FaultChange::Raised(f) if f.event == event52::EVENT)
}

/// A short diagnosis text (A257) built without the heap.
pub(super) struct Text {
    pub(super) buf: [u8; 16],
    pub(super) len: usize,
}

impl Text {
    pub(super) const fn new() -> Self {
        Self { buf: [0; 16], len: 0 }
    }

    pub(super) fn push(&mut self, b: u8) {
        if let Some(slot) = self.buf.get_mut(self.len) {
            *slot = b;
            self.len += 1;
        }
    }

    pub(super) fn put(&mut self, s: &[u8]) {
        for &b in s {
            self.push(b);
        }
    }

    /// `v` in decimal, no leading zeros.
    pub(super) fn dec(&mut self, v: u8) {
        if v >= 100 {
            self.push(b'0' + v / 100);
        }
        if v >= 10 {
            self.push(b'0' + (v / 10) % 10);
        }
        self.push(b'0' + v % 10);
    }

    /// The low `digits` hex digits of `v`, upper case, leading zeros.
    pub(super) fn hex(&mut self, v: u16, digits: u32) {
        for i in (0..digits).rev() {
            let nibble = (u32::from(v) >> (4 * i)) & 0xF;
            let c = b"0123456789ABCDEF".get(nibble as usize).copied().unwrap_or(b'?');
            self.push(c);
        }
    }

    pub(super) fn bytes(&self) -> &[u8] {
        self.buf.get(..self.len).unwrap_or_default()
    }
}

impl<F: Flash, B: Flash> Drive<F, B> {
    /// Event 52 "Communication" with `cause` (E-129…E-131, spec §13.4): both
    /// axes (the single-axis device's one) take T13 in their next control cycle and run the fault reaction
    /// of 605Eh (A540: 0 = power unit off at once, brake engages; 1–4 = stop
    /// on the slow-down / quick-stop ramp with the brake released, then
    /// off), ending in Fault with 603Fh = 7500h; a fault reset (controlword
    /// bit 7 edge) clears it. One EMCY 7500h / 10h / 52 / cause for the
    /// device (axis byte 0); the axes' own T13 EMCY for it is dropped.
    /// E82/E43 show the event.
    pub fn raise_event52(&mut self, cause: u8) {
        self.slave
            .emergency(crate::emcy::for_event(event52::EVENT, cause, 0));
        let event = motion::Event {
            number: u16::from(event52::EVENT),
            cause,
        };
        let axes = self.objects.variant().axes();
        for (axis, sent) in self
            .axes
            .iter_mut()
            .zip(self.event52_emcy_sent.iter_mut())
            .take(axes)
        {
            axis.raise_event(event);
            *sent = true;
        }
        let _ = self.objects.set(E82, 0, i64::from(event52::EVENT));
        let _ = self.objects.set(E43, 0, i64::from(cause));
    }

    /// The axes' faults raised since the last poll as error messages in the
    /// history 10F3h (E-144): [`DIAG_EMCY`] with the EMCY code, parameters
    /// the axis (0 = A) and event << 8 | cause.
    pub(super) fn push_fault_messages<P: Pdi>(&mut self, pdi: &mut P, now: Nanos) -> Result<(), P::Error> {
        if self.fault_diag.iter().all(Option::is_none) {
            return Ok(());
        }
        let stamp = self.message_time_stamp(pdi, now)?;
        for (axis, slot) in (0u32..).zip(self.fault_diag.iter_mut()) {
            if let Some(f) = slot.take() {
                let mut msg = DiagMessage::new(DIAG_EMCY | u32::from(f.code) << 16, DiagType::Error, f.code);
                msg.params = [Some(axis), Some(u32::from(f.event) << 8 | u32::from(f.cause))];
                self.diag.push(msg, stamp);
            }
        }
        Ok(())
    }

    /// The projected fieldbus identification (E59\[2\]; from the drive's
    /// configuration project, which the firmware or board support passes
    /// in). A value other than [`FIELDBUS_ID`] raises event 52 cause 15 at
    /// the next poll (E-130).
    pub fn set_projected_fieldbus(&mut self, id: u16) {
        self.projected_fieldbus = id;
    }

    /// E-130: E59[2] against this firmware's fieldbus identification; a
    /// mismatch raises event 52 cause 15 once when it appears (a fault
    /// reset then clears the fault, the mismatch stays visible in E59[2]).
    pub(super) fn check_fieldbus_identification(&mut self) {
        let _ = self.objects.set(E59, 3, i64::from(self.projected_fieldbus));
        let mismatch = self.projected_fieldbus != FIELDBUS_ID;
        if mismatch && !self.wrong_firmware {
            self.raise_event52(event52::WRONG_FIRMWARE);
        }
        self.wrong_firmware = mismatch;
    }

    /// The EtherCAT LEDs now: RUN and ERR from the ESM (E-132, E-133), the
    /// port LEDs from the link state the last poll read from the ESC and
    /// `activity` per port (frames seen lately: on the board the ESC's LED
    /// outputs, in the simulator the ESC's frame log) (E-134).
    pub fn leds(&self, activity: [bool; 2]) -> Leds {
        let link = |n: u8| self.ports.dl_status & regs::dl_status::link(n) != 0;
        let [a0, a1] = activity;
        Leds {
            run: self.slave.run_led(),
            err: self.slave.err_led(),
            ports: [ecat::led::link(link(0), a0), ecat::led::link(link(1), a1)],
        }
    }

    /// A257 Er code (spec §13.5) of the slave's present indication.
    pub(super) fn er_code(&self) -> u8 {
        let s = &self.slave;
        if !s.error() {
            // E-099: a refused EoE IP configuration (EMCY FFF0h sent) shows
            // Er10 until an accepted one replaces it
            return if s.eoe().address_error() { 10 } else { 0 };
        }
        let code = s.al_status_code();
        if s.sync_status().unsolicited {
            return if code == AlStatusCode::SM_WATCHDOG { 4 } else { 3 };
        }
        match code {
            // Er6 "regular process data missing": not steady (001Bh) or none
            // at all (002Bh) at S→O
            AlStatusCode::SM_WATCHDOG | AlStatusCode::NO_VALID_IO => 6,
            AlStatusCode::INVALID_INPUT_CONFIG => 7,
            AlStatusCode::INVALID_OUTPUT_CONFIG => 8,
            AlStatusCode::INVALID_MAILBOX_CONFIG => self.mailbox_er,
            AlStatusCode::INVALID_SM_CONFIG => 2,
            _ => 11,
        }
    }

    /// Reads the ESC's DL status, lost-link and RX-error counters and
    /// updates A257[0..2] when something changed (E-136…E-138).
    pub(super) fn read_ports<P: Pdi>(&mut self, pdi: &mut P) -> Result<(), P::Error> {
        let mut rx = [0u8; 4];
        pdi.read(regs::RX_ERROR_COUNTER, &mut rx)?;
        let mut lost = [0u8; 2];
        pdi.read(regs::LOST_LINK_COUNTER, &mut lost)?;
        let [f0, e0, f1, e1] = rx;
        let now = PortDiag {
            dl_status: pdi.read_u16(regs::DL_STATUS)?,
            lost,
            rx_errors: [u16::from(f0) + u16::from(e0), u16::from(f1) + u16::from(e1)],
            shown: true,
            er: self.er_code(),
        };
        if now != self.ports {
            self.ports = now;
            self.update_a257_texts();
        }
        Ok(())
    }

    /// A257[0] "ErX L0X L1X", [1] "L0 xx L1 xx", [2] "R0 xxxx R1 xxxx".
    pub(super) fn update_a257_texts(&mut self) {
        let p = self.ports;
        let link = |n: u8| u8::from(p.dl_status & regs::dl_status::link(n) != 0);
        let mut t = Text::new();
        t.put(b"Er");
        t.dec(p.er);
        t.put(b" L0");
        t.dec(link(0));
        t.put(b" L1");
        t.dec(link(1));
        let _ = self.objects.set_bytes(A257, 1, t.bytes());
        let [l0, l1] = p.lost;
        let mut t = Text::new();
        t.put(b"L0 ");
        t.hex(u16::from(l0), 2);
        t.put(b" L1 ");
        t.hex(u16::from(l1), 2);
        let _ = self.objects.set_bytes(A257, 2, t.bytes());
        let [r0, r1] = p.rx_errors;
        let mut t = Text::new();
        t.put(b"R0 ");
        t.hex(r0, 4);
        t.put(b" R1 ");
        t.hex(r1, 4);
        let _ = self.objects.set_bytes(A257, 3, t.bytes());
    }
}
