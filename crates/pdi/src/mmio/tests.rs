//! `OnChip` over a RAM-backed window that checks and records every access.

extern crate std;
use std::vec;
use std::vec::Vec;

use esc::{Pdi, PdiExt};

use super::*;

/// RAM standing in for the ESC window. Like the bus, it refuses misaligned
/// and out-of-window accesses; it logs `(offset, width, is_write)`.
struct RamWindow {
    mem: Vec<u8>,
    log: Vec<(usize, Width, bool)>,
}

impl RamWindow {
    fn new(len: usize) -> Self {
        let mem = (0..len)
            .map(|i| (i as u8) ^ ((i >> 8) as u8).wrapping_mul(31))
            .collect();
        Self { mem, log: Vec::new() }
    }

    fn check(&self, offset: usize, width: Width) -> Result<(), BadAccess> {
        let n = width.bytes();
        if offset % n != 0 || offset + n > self.mem.len() {
            return Err(BadAccess { offset, width });
        }
        Ok(())
    }
}

impl RegisterWindow for RamWindow {
    fn len(&self) -> usize {
        self.mem.len()
    }

    fn read(&mut self, offset: usize, width: Width) -> Result<u32, BadAccess> {
        self.check(offset, width)?;
        self.log.push((offset, width, false));
        let mut b = [0u8; 4];
        b[..width.bytes()].copy_from_slice(&self.mem[offset..offset + width.bytes()]);
        Ok(u32::from_le_bytes(b))
    }

    fn write(&mut self, offset: usize, width: Width, value: u32) -> Result<(), BadAccess> {
        self.check(offset, width)?;
        self.log.push((offset, width, true));
        let n = width.bytes();
        self.mem[offset..offset + n].copy_from_slice(&value.to_le_bytes()[..n]);
        Ok(())
    }
}

fn onchip() -> OnChip<RamWindow> {
    OnChip::new(RamWindow::new(XMC4800_ECAT0_LEN))
}

#[test]
fn onchip_reads_every_length_and_alignment() {
    let mut pdi = onchip();
    let expect = pdi.window().mem.clone();
    for addr in 0x0120u16..0x0128 {
        for len in 0..=13usize {
            let mut buf = vec![0u8; len];
            pdi.read(addr, &mut buf).unwrap();
            let a = usize::from(addr);
            assert_eq!(buf, expect[a..a + len], "addr {addr:#06x} len {len}");
        }
    }
}

#[test]
fn onchip_writes_every_length_and_alignment_touching_only_the_target() {
    for addr in 0x1000u16..0x1008 {
        for len in 1..=13usize {
            let mut pdi = onchip();
            let mut expect = pdi.window().mem.clone();
            let data: Vec<u8> = (0..len).map(|i| 0xA0 ^ i as u8).collect();
            pdi.write(addr, &data).unwrap();
            let a = usize::from(addr);
            expect[a..a + len].copy_from_slice(&data);
            assert_eq!(pdi.window().mem, expect, "addr {addr:#06x} len {len}");
        }
    }
}

#[test]
fn onchip_splits_into_widest_naturally_aligned_accesses() {
    let mut pdi = onchip();
    let mut buf = [0u8; 7];
    pdi.read(0x0121, &mut buf).unwrap();
    assert_eq!(
        pdi.window().log,
        [
            (0x121, Width::U8, false),
            (0x122, Width::U16, false),
            (0x124, Width::U32, false)
        ]
    );
    let mut pdi = onchip();
    pdi.write(0x0802, &[1, 2, 3, 4, 5, 6, 7, 8, 9]).unwrap();
    assert_eq!(
        pdi.window().log,
        [
            (0x802, Width::U16, true),
            (0x804, Width::U32, true),
            (0x808, Width::U16, true),
            (0x80A, Width::U8, true)
        ]
    );
}

#[test]
fn onchip_al_event_is_one_32bit_read_of_0x0220() {
    let mut pdi = onchip();
    pdi.write_u32(0x0220, 0x0001_0305).unwrap();
    pdi.window.log.clear();
    assert_eq!(pdi.al_event().unwrap(), 0x0001_0305);
    assert_eq!(pdi.window().log, [(0x220, Width::U32, false)]);
}

#[test]
fn onchip_16bit_register_read_whole_is_one_16bit_access() {
    let mut pdi = onchip();
    pdi.write_u16(esc::regs::AL_STATUS_CODE, 0x001B).unwrap();
    pdi.window.log.clear();
    assert_eq!(pdi.read_u16(esc::regs::AL_STATUS_CODE).unwrap(), 0x001B);
    assert_eq!(pdi.window().log, [(0x134, Width::U16, false)]);
}

#[test]
fn onchip_mailbox_sized_buffer_roundtrip() {
    let mut pdi = onchip();
    let mbx: Vec<u8> = (0..128u32).map(|i| (i * 7) as u8).collect();
    pdi.write(0x1000, &mbx).unwrap();
    let mut back = vec![0u8; 128];
    pdi.read(0x1000, &mut back).unwrap();
    assert_eq!(back, mbx);
    // 128 bytes at an aligned address: 32 word accesses each way.
    assert_eq!(pdi.window().log.len(), 64);
    // The last process RAM byte is reachable; one past it is not.
    pdi.write(0x2FFF, &[0x5A]).unwrap();
    assert_eq!(pdi.read_u8(0x2FFF).unwrap(), 0x5A);
}

#[test]
fn onchip_out_of_window_access_is_an_error_without_bus_access() {
    let mut pdi = onchip();
    let mut buf = [0u8; 2];
    assert_eq!(
        pdi.read(0x2FFF, &mut buf),
        Err(Error::OutOfRange { addr: 0x2FFF, len: 2 })
    );
    assert_eq!(
        pdi.write(0xFFFF, &[0; 4]),
        Err(Error::OutOfRange { addr: 0xFFFF, len: 4 })
    );
    assert!(pdi.window().log.is_empty());
    // A window smaller than the AL event register's address: an error too.
    let mut tiny = OnChip::new(RamWindow::new(0x100));
    assert_eq!(tiny.al_event(), Err(Error::OutOfRange { addr: 0x220, len: 4 }));
}
