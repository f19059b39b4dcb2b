//! EtherCAT frames as checked, mutable views (smoltcp style), and a line of
//! simulated slaves that processes them.
//!
//! Layout (ETG.1000.4 §5): Ethernet II header (destination 6, source 6,
//! optionally one 802.1Q tag, EtherType 0x88A4), the EtherCAT frame header
//! (u16 LE: bits 0..10 length of the datagram area, bits 12..15 type, 1 =
//! EtherCAT commands), then datagrams: a 10-byte header (command, index,
//! 32-bit address, u16 length/flags, u16 IRQ), `len` data bytes and a u16
//! working counter.
//!
//! Everything here is `no_std` and heap-free; a malformed frame is an error,
//! never a panic.
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]
#![deny(missing_docs)]

use crate::esc::Esc;
use nanos::Nanos;

/// EtherType of EtherCAT frames.
pub const ETHERTYPE_ETHERCAT: u16 = 0x88A4;
/// EtherType of an IEEE 802.1Q VLAN tag (skipped when present).
pub const ETHERTYPE_VLAN: u16 = 0x8100;
/// Length of the Ethernet II header without VLAN tag.
pub const ETHERNET_HEADER_LEN: usize = 14;
/// Length of the EtherCAT frame header.
pub const ECAT_HEADER_LEN: usize = 2;
/// Length of a datagram header.
pub const DATAGRAM_HEADER_LEN: usize = 10;
/// Length of the working counter after a datagram's data.
pub const WKC_LEN: usize = 2;
/// EtherCAT frame type "EtherCAT commands" (header bits 12..15).
pub const FRAME_TYPE_COMMANDS: u8 = 1;
/// Bit of the first source-MAC byte that marks a locally administered address;
/// an ESC's port 0 sets it on the frame's way back to the master.
pub const MAC_LOCAL_BIT: u8 = 0x02;

/// Why a frame was rejected (it is then left untouched).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameError {
    /// Shorter than the Ethernet and EtherCAT headers.
    Truncated,
    /// The EtherType (after an optional VLAN tag) is not 0x88A4.
    NotEthercat(u16),
    /// The EtherCAT header's type is not 1 (EtherCAT commands).
    UnsupportedType(u8),
    /// A datagram runs past the datagram area, or the area holds no complete datagram.
    MalformedDatagram,
}

/// EtherCAT command codes (ETG.1000.4 Table 2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    /// No operation (0).
    Nop,
    /// Auto-increment physical read (1).
    Aprd,
    /// Auto-increment physical write (2).
    Apwr,
    /// Auto-increment physical read-write (3).
    Aprw,
    /// Configured-address physical read (4).
    Fprd,
    /// Configured-address physical write (5).
    Fpwr,
    /// Configured-address physical read-write (6).
    Fprw,
    /// Broadcast read (7).
    Brd,
    /// Broadcast write (8).
    Bwr,
    /// Broadcast read-write (9).
    Brw,
    /// Logical read (10).
    Lrd,
    /// Logical write (11).
    Lwr,
    /// Logical read-write (12).
    Lrw,
    /// Auto-increment read, multiple write (13).
    Armw,
    /// Configured-address read, multiple write (14).
    Frmw,
    /// Any other code (treated as a no-op by the ESC).
    Unknown(u8),
}

impl Command {
    /// The command for a code.
    pub const fn from_code(code: u8) -> Self {
        match code {
            0 => Command::Nop,
            1 => Command::Aprd,
            2 => Command::Apwr,
            3 => Command::Aprw,
            4 => Command::Fprd,
            5 => Command::Fpwr,
            6 => Command::Fprw,
            7 => Command::Brd,
            8 => Command::Bwr,
            9 => Command::Brw,
            10 => Command::Lrd,
            11 => Command::Lwr,
            12 => Command::Lrw,
            13 => Command::Armw,
            14 => Command::Frmw,
            c => Command::Unknown(c),
        }
    }

    /// The wire code.
    pub const fn code(self) -> u8 {
        match self {
            Command::Nop => 0,
            Command::Aprd => 1,
            Command::Apwr => 2,
            Command::Aprw => 3,
            Command::Fprd => 4,
            Command::Fpwr => 5,
            Command::Fprw => 6,
            Command::Brd => 7,
            Command::Bwr => 8,
            Command::Brw => 9,
            Command::Lrd => 10,
            Command::Lwr => 11,
            Command::Lrw => 12,
            Command::Armw => 13,
            Command::Frmw => 14,
            Command::Unknown(c) => c,
        }
    }

    /// Logical addressing (LRD, LWR, LRW): the address field is one 32-bit logical address.
    pub const fn is_logical(self) -> bool {
        matches!(self, Command::Lrd | Command::Lwr | Command::Lrw)
    }
}

/// Reads a little-endian u16 at `off`, 0 when out of range (callers validated the length).
fn get_u16(b: &[u8], off: usize) -> u16 {
    match off.checked_add(2).and_then(|end| b.get(off..end)) {
        Some(&[lo, hi]) => u16::from_le_bytes([lo, hi]),
        _ => 0,
    }
}

/// Writes a little-endian u16 at `off`; ignored when out of range.
fn put_u16(b: &mut [u8], off: usize, v: u16) {
    if let Some(s) = off.checked_add(2).and_then(|end| b.get_mut(off..end)) {
        s.copy_from_slice(&v.to_le_bytes());
    }
}

/// One datagram inside a frame: header, data and working counter, checked on construction.
#[derive(Debug)]
pub struct Datagram<'a> {
    buf: &'a mut [u8],
}

impl<'a> Datagram<'a> {
    /// Wraps the bytes of one datagram (header, data, WKC). `buf` may be longer
    /// than the datagram; the datagram takes what its length field says.
    /// Errors when `buf` is too short for the header or for the stated data and WKC.
    pub fn new_checked(buf: &'a mut [u8]) -> Result<Self, FrameError> {
        let total = Self::total_len_of(buf)?;
        match buf.get_mut(..total) {
            Some(b) => Ok(Self { buf: b }),
            None => Err(FrameError::MalformedDatagram),
        }
    }

    /// Total length (header + data + WKC) of the datagram starting at `buf`,
    /// checked against `buf`'s length.
    fn total_len_of(buf: &[u8]) -> Result<usize, FrameError> {
        if buf.len() < DATAGRAM_HEADER_LEN {
            return Err(FrameError::MalformedDatagram);
        }
        let len = usize::from(get_u16(buf, 6) & 0x07FF);
        let total = DATAGRAM_HEADER_LEN + len + WKC_LEN;
        if total > buf.len() {
            return Err(FrameError::MalformedDatagram);
        }
        Ok(total)
    }

    /// Command.
    pub fn command(&self) -> Command {
        Command::from_code(self.buf.first().copied().unwrap_or(0))
    }

    /// Index (the master's tag, echoed unchanged).
    pub fn index(&self) -> u8 {
        self.buf.get(1).copied().unwrap_or(0)
    }

    /// Position/configured address (ADP) of a physical command.
    pub fn adp(&self) -> u16 {
        get_u16(self.buf, 2)
    }

    /// Sets ADP (auto-increment commands count it up at each slave).
    pub fn set_adp(&mut self, adp: u16) {
        put_u16(self.buf, 2, adp);
    }

    /// Register offset (ADO) of a physical command.
    pub fn ado(&self) -> u16 {
        get_u16(self.buf, 4)
    }

    /// The 32-bit logical address of a logical command (the same four bytes as ADP/ADO).
    pub fn logical_address(&self) -> u32 {
        u32::from(self.adp()) | u32::from(self.ado()) << 16
    }

    /// Data length (length field bits 0..10).
    pub fn data_len(&self) -> usize {
        usize::from(get_u16(self.buf, 6) & 0x07FF)
    }

    /// Circulating frame bit (length field bit 14).
    pub fn circulating(&self) -> bool {
        get_u16(self.buf, 6) & 0x4000 != 0
    }

    /// "More datagrams follow" bit (length field bit 15).
    pub fn more_follows(&self) -> bool {
        get_u16(self.buf, 6) & 0x8000 != 0
    }

    /// IRQ field.
    pub fn irq(&self) -> u16 {
        get_u16(self.buf, 8)
    }

    /// The data bytes.
    pub fn data(&self) -> &[u8] {
        let end = DATAGRAM_HEADER_LEN + self.data_len();
        self.buf.get(DATAGRAM_HEADER_LEN..end).unwrap_or_default()
    }

    /// The data bytes, mutable.
    pub fn data_mut(&mut self) -> &mut [u8] {
        let end = DATAGRAM_HEADER_LEN + self.data_len();
        self.buf.get_mut(DATAGRAM_HEADER_LEN..end).unwrap_or_default()
    }

    /// Working counter.
    pub fn wkc(&self) -> u16 {
        get_u16(self.buf, DATAGRAM_HEADER_LEN + self.data_len())
    }

    /// Sets the working counter.
    pub fn set_wkc(&mut self, wkc: u16) {
        let off = DATAGRAM_HEADER_LEN + self.data_len();
        put_u16(self.buf, off, wkc);
    }

    /// Adds `n` to the working counter (wrapping, as the 16-bit field does).
    pub fn add_wkc(&mut self, n: u16) {
        let w = self.wkc().wrapping_add(n);
        self.set_wkc(w);
    }

    /// Length of the whole datagram (header + data + WKC).
    pub fn total_len(&self) -> usize {
        self.buf.len()
    }
}

/// Iterator over the datagrams of a frame's datagram area, yielding mutable
/// views. Yields `Err` once and stops at a malformed datagram.
#[derive(Debug)]
pub struct Datagrams<'a> {
    rest: &'a mut [u8],
    done: bool,
}

impl<'a> Datagrams<'a> {
    /// Iterates over the datagrams in `area` (the bytes after the EtherCAT header,
    /// exactly as long as the header's length field says).
    pub fn new(area: &'a mut [u8]) -> Self {
        Self {
            rest: area,
            done: false,
        }
    }
}

impl<'a> Iterator for Datagrams<'a> {
    type Item = Result<Datagram<'a>, FrameError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let rest = core::mem::take(&mut self.rest);
        let total = match Datagram::total_len_of(rest) {
            Ok(t) => t,
            Err(e) => {
                self.done = true;
                return Some(Err(e));
            }
        };
        let Some((this, tail)) = rest.split_at_mut_checked(total) else {
            self.done = true;
            return Some(Err(FrameError::MalformedDatagram));
        };
        let dg = Datagram { buf: this };
        if dg.more_follows() {
            self.rest = tail;
        } else {
            self.done = true;
        }
        Some(Ok(dg))
    }
}

/// Where the EtherCAT header and datagram area sit in an Ethernet frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Layout {
    /// Offset of the datagram area (just after the EtherCAT header).
    area_start: usize,
    /// Length of the datagram area.
    area_len: usize,
}

/// Checks the Ethernet and EtherCAT headers and every datagram; returns the layout.
///
/// As an ESC does (issue 33): the datagrams are followed from the first one by
/// their own length fields and "more" bits; the EtherCAT header's length field
/// is not relied on (libethercat writes it 16 bytes too large), bytes after
/// the last datagram are padding or trailer and ignored, and a frame shorter
/// than Ethernet's 60 bytes (veth does not pad) is processed like any other.
/// Strict where silicon is: the EtherType, frame type 1, and a datagram that
/// runs past the end of the frame (the ESC would see the frame end early and
/// commit nothing).
fn check(frame: &[u8]) -> Result<Layout, FrameError> {
    let mut ethertype = get_u16_be(frame, 12).ok_or(FrameError::Truncated)?;
    let mut ecat = ETHERNET_HEADER_LEN;
    if ethertype == ETHERTYPE_VLAN {
        ethertype = get_u16_be(frame, 16).ok_or(FrameError::Truncated)?;
        ecat += 4;
    }
    if ethertype != ETHERTYPE_ETHERCAT {
        return Err(FrameError::NotEthercat(ethertype));
    }
    if frame.len() < ecat + ECAT_HEADER_LEN {
        return Err(FrameError::Truncated);
    }
    let hdr = get_u16(frame, ecat);
    let kind = (hdr >> 12) as u8;
    if kind != FRAME_TYPE_COMMANDS {
        return Err(FrameError::UnsupportedType(kind));
    }
    let area_start = ecat + ECAT_HEADER_LEN;
    let area = frame.get(area_start..).ok_or(FrameError::Truncated)?;
    // Walk the chain: every datagram must fit in the frame, the last one clears "more".
    let mut off = 0usize;
    loop {
        let rest = area.get(off..).ok_or(FrameError::MalformedDatagram)?;
        let total = Datagram::total_len_of(rest)?;
        let more = get_u16(rest, 6) & 0x8000 != 0;
        off += total;
        if !more {
            break;
        }
    }
    Ok(Layout {
        area_start,
        area_len: off,
    })
}

/// Reads a big-endian u16 (Ethernet byte order) at `off`.
fn get_u16_be(b: &[u8], off: usize) -> Option<u16> {
    match b.get(off..off + 2) {
        Some(&[hi, lo]) => Some(u16::from_be_bytes([hi, lo])),
        _ => None,
    }
}

/// A checked EtherCAT frame (Ethernet II + EtherCAT header + datagrams).
#[derive(Debug)]
pub struct EthercatFrame<'a> {
    buf: &'a mut [u8],
    layout: Layout,
}

impl<'a> EthercatFrame<'a> {
    /// Checks the headers and the whole datagram chain; errors leave `buf` untouched.
    pub fn new_checked(buf: &'a mut [u8]) -> Result<Self, FrameError> {
        let layout = check(buf)?;
        Ok(Self { buf, layout })
    }

    /// Length of the datagram area: the bytes the datagram chain spans (not
    /// the EtherCAT header's length field, which an ESC does not rely on).
    pub fn area_len(&self) -> usize {
        self.layout.area_len
    }

    /// Iterates over the datagrams, mutable.
    pub fn datagrams(&mut self) -> Datagrams<'_> {
        let Layout { area_start, area_len } = self.layout;
        let area = self
            .buf
            .get_mut(area_start..area_start + area_len)
            .unwrap_or_default();
        Datagrams::new(area)
    }

    /// The source MAC address.
    pub fn source_mac(&self) -> [u8; 6] {
        let mut mac = [0u8; 6];
        if let Some(s) = self.buf.get(6..12) {
            mac.copy_from_slice(s);
        }
        mac
    }

    /// Sets the locally-administered bit in the source MAC, as port 0 of a real
    /// ESC does on the frame's way back (masters such as ethercrab drop replies without it).
    pub fn mark_returned(&mut self) {
        if let Some(b) = self.buf.get_mut(6) {
            *b |= MAC_LOCAL_BIT;
        }
    }
}

/// Passes `frame` through a line of slaves, position 0 first: every slave
/// processes every datagram in order, as the frame travels down a real line.
/// On return the source MAC carries the locally-administered bit.
///
/// `escs` is the physical line: before processing, port 1 of every slave but
/// the last is marked linked and open in its DL status ([`connect_line`]);
/// masters derive the topology (and DC delays) from these bits.
///
/// A frame that is not EtherCAT or is malformed (truncated, a datagram past
/// the end of the frame) is an error and left untouched; the EtherCAT header's
/// length, padding and trailing bytes are not looked at (see `check`).
pub fn process_frame(escs: &mut [&mut Esc], frame: &mut [u8], now: Nanos) -> Result<(), FrameError> {
    let mut f = EthercatFrame::new_checked(frame)?;
    connect_line(escs);
    for esc in escs.iter_mut() {
        for dg in f.datagrams() {
            // The chain was validated in `new_checked`; an error here cannot happen.
            let mut dg = dg?;
            esc.process_datagram(&mut dg, now);
        }
    }
    f.mark_returned();
    Ok(())
}

/// Sets the DL status of a line: every slave but the last has a link on port 1
/// (open towards the next slave), the last one has port 1 closed.
/// [`process_frame`] does this for the line it is given.
pub fn connect_line(escs: &mut [&mut Esc]) {
    let n = escs.len();
    for (i, esc) in escs.iter_mut().enumerate() {
        esc.set_port_link(1, i + 1 < n);
    }
}

/// Frame building and parsing for the tests of this crate.
#[cfg(test)]
pub(crate) mod testutil {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    /// Master MAC used by the tests (not locally administered).
    pub const MASTER_MAC: [u8; 6] = [0x10, 0x10, 0x10, 0x10, 0x10, 0x10];

    /// Physical address field: ADP in the low half, ADO in the high half.
    pub fn phys(adp: u16, ado: u16) -> u32 {
        u32::from(adp) | u32::from(ado) << 16
    }

    /// Auto-increment ADP for slave position `pos`.
    pub fn pos(p: u16) -> u16 {
        0u16.wrapping_sub(p)
    }

    /// Builds an Ethernet + EtherCAT frame with the given datagrams (WKC 0).
    pub fn build(dgs: &[(Command, u32, &[u8])]) -> Vec<u8> {
        let mut area = Vec::new();
        for (i, (cmd, addr, data)) in dgs.iter().enumerate() {
            area.push(cmd.code());
            area.push(i as u8);
            area.extend_from_slice(&addr.to_le_bytes());
            let more = if i + 1 < dgs.len() { 0x8000 } else { 0 };
            area.extend_from_slice(&((data.len() as u16) | more).to_le_bytes());
            area.extend_from_slice(&0u16.to_le_bytes());
            area.extend_from_slice(data);
            area.extend_from_slice(&0u16.to_le_bytes());
        }
        let mut f = Vec::new();
        f.extend_from_slice(&[0xFF; 6]);
        f.extend_from_slice(&MASTER_MAC);
        f.extend_from_slice(&ETHERTYPE_ETHERCAT.to_be_bytes());
        f.extend_from_slice(&((area.len() as u16) | 0x1000).to_le_bytes());
        f.extend_from_slice(&area);
        while f.len() < 60 {
            f.push(0);
        }
        f
    }

    /// A datagram as the master sees it after the round trip.
    #[derive(Debug, Clone, PartialEq, Eq)]
    pub struct Reply {
        pub cmd: Command,
        pub addr: u32,
        pub data: Vec<u8>,
        pub wkc: u16,
    }

    /// Parses the datagrams of a returned frame.
    pub fn parse(frame: &mut [u8]) -> Vec<Reply> {
        let mut f = EthercatFrame::new_checked(frame).unwrap();
        f.datagrams()
            .map(|d| {
                let d = d.unwrap();
                Reply {
                    cmd: d.command(),
                    addr: d.logical_address(),
                    data: d.data().to_vec(),
                    wkc: d.wkc(),
                }
            })
            .collect()
    }

    /// Sends one datagram through the line at `now` ns and returns (data, wkc).
    pub fn xfer(escs: &mut [&mut Esc], cmd: Command, addr: u32, data: &[u8], now: u64) -> (Vec<u8>, u16) {
        let mut f = build(&[(cmd, addr, data)]);
        process_frame(escs, &mut f, Nanos::from_ns(now)).unwrap();
        let r = parse(&mut f).remove(0);
        (r.data, r.wkc)
    }

    /// One datagram to a single slave.
    pub fn xfer1(esc: &mut Esc, cmd: Command, addr: u32, data: &[u8], now: u64) -> (Vec<u8>, u16) {
        xfer(&mut [esc], cmd, addr, data, now)
    }
}

#[cfg(test)]
mod tests;
