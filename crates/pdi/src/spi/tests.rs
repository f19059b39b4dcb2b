//! Driver tests against byte-level models of the chips' SPI protocols.

extern crate std;
use std::vec;
use std::vec::Vec;

use esc::{Pdi, PdiExt};

use super::et1100::header;
use super::mock_et1100::MockEt1100;
use super::mock_lan9252::{BusFault, MockLan9252};
use super::*;

fn lan() -> Lan9252<MockLan9252> {
    Lan9252::new(MockLan9252::new())
}

fn pattern(len: usize, seed: u8) -> Vec<u8> {
    (0..len)
        .map(|i| seed.wrapping_add((i as u8).wrapping_mul(29)))
        .collect()
}

/// On a fresh LAN9252, writing `data` at `addr` changes those bytes of the
/// ESC and nothing else (neither the padding of the first/last DWORD).
fn writes_only_its_bytes(addr: u16, data: &[u8]) {
    let mut pdi = lan();
    let mut expect = pdi.spi_mut().esc.clone();
    pdi.write(addr, data).unwrap();
    let (a, len) = (usize::from(addr), data.len());
    expect[a..a + len].copy_from_slice(data);
    assert!(pdi.spi_mut().esc == expect, "addr {addr:#06x} len {len}");
}

// ---- LAN9252 -------------------------------------------------------------

#[test]
fn lan9252_register_reads_every_length_and_alignment_via_csr() {
    let mut pdi = lan();
    for addr in 0x0120u16..0x0128 {
        for len in 0..=11usize {
            let mut buf = vec![0u8; len];
            pdi.read(addr, &mut buf).unwrap();
            let a = usize::from(addr);
            let esc = &pdi.spi_mut().esc;
            assert_eq!(buf, esc[a..a + len], "addr {addr:#06x} len {len}");
        }
    }
    // Every byte went through the CSR window, no FIFO traffic.
    assert!(pdi.spi_mut().bursts.is_empty());
}

#[test]
fn lan9252_register_writes_every_length_and_alignment_via_csr() {
    for addr in 0x0800u16..0x0808 {
        for len in 1..=11usize {
            writes_only_its_bytes(addr, &pattern(len, addr as u8));
        }
    }
}

#[test]
fn lan9252_csr_chunks_follow_the_address_vs_size_table() {
    let mut pdi = lan();
    let mut buf = [0u8; 9];
    pdi.read(0x0121, &mut buf).unwrap();
    assert_eq!(
        pdi.spi_mut().csr_log,
        [
            (0x121, 1, true),
            (0x122, 2, true),
            (0x124, 4, true),
            (0x128, 2, true)
        ]
    );
    pdi.spi_mut().csr_log.clear();
    pdi.write(0x0132, &[1, 2, 3]).unwrap();
    assert_eq!(pdi.spi_mut().csr_log, [(0x132, 2, false), (0x134, 1, false)]);
}

#[test]
fn lan9252_al_event_is_one_32bit_csr_read_of_0x0220() {
    let mut pdi = lan();
    pdi.spi_mut().esc[0x220..0x224].copy_from_slice(&0x0000_0301u32.to_le_bytes());
    pdi.spi_mut().csr_log.clear();
    assert_eq!(pdi.al_event().unwrap(), 0x0000_0301);
    assert_eq!(pdi.spi_mut().csr_log, [(0x220, 4, true)]);
}

#[test]
fn lan9252_typed_helpers_read_16_and_32_bit_registers_whole() {
    let mut pdi = lan();
    pdi.write_u16(esc::regs::AL_STATUS_CODE, 0x001B).unwrap();
    pdi.write_u32(esc::regs::WATCHDOG_DIVIDER, 0x1234_5678).unwrap();
    pdi.spi_mut().csr_log.clear();
    assert_eq!(pdi.read_u16(esc::regs::AL_STATUS_CODE).unwrap(), 0x001B);
    assert_eq!(pdi.read_u32(esc::regs::WATCHDOG_DIVIDER).unwrap(), 0x1234_5678);
    assert_eq!(pdi.spi_mut().csr_log, [(0x134, 2, true), (0x400, 4, true)]);
}

#[test]
fn lan9252_process_ram_reads_every_length_and_alignment_via_fifo() {
    let mut pdi = lan();
    for addr in 0x1000u16..0x1004 {
        for len in [1usize, 2, 3, 4, 5, 7, 8, 9, 31, 32, 33, 64, 65] {
            let mut buf = vec![0u8; len];
            pdi.read(addr, &mut buf).unwrap();
            let a = usize::from(addr);
            assert_eq!(buf, pdi.spi_mut().esc[a..a + len], "addr {addr:#06x} len {len}");
        }
    }
    assert!(
        pdi.spi_mut().csr_log.is_empty(),
        "process RAM must not use the CSR window"
    );
}

#[test]
fn lan9252_process_ram_writes_every_length_and_alignment_via_fifo() {
    for addr in 0x1100u16..0x1104 {
        for len in [1usize, 2, 3, 4, 5, 6, 8, 13, 32, 33, 70] {
            writes_only_its_bytes(addr, &pattern(len, 0x40));
        }
    }
}

#[test]
fn lan9252_mailbox_sized_buffers_roundtrip() {
    let mut pdi = lan();
    for (addr, len) in [
        (0x1000u16, 128usize),
        (0x1080, 128),
        (0x1200, 512),
        (0x1400, 1024),
    ] {
        let data = pattern(len, len as u8);
        pdi.write(addr, &data).unwrap();
        let mut back = vec![0u8; len];
        pdi.read(addr, &mut back).unwrap();
        assert_eq!(back, data, "mailbox at {addr:#06x}, {len} bytes");
    }
}

#[test]
fn lan9252_fifo_bursts_respect_the_reported_count_and_the_alias() {
    let mut pdi = lan();
    // The engine moves one DWORD per status poll: the driver must never read
    // more than is available (the model panics on an empty FIFO pop).
    pdi.spi_mut().fifo_per_poll = 1;
    let mut buf = vec![0u8; 256];
    pdi.read(0x1002, &mut buf).unwrap();
    assert_eq!(buf, pdi.spi_mut().esc[0x1002..0x1102]);
    assert!(pdi.spi_mut().bursts.iter().all(|&(_, n)| n == 1));
    // Plenty available: bursts are capped at the 8-DWORD alias.
    pdi.spi_mut().fifo_per_poll = 16;
    pdi.spi_mut().bursts.clear();
    pdi.read(0x1000, &mut buf).unwrap();
    assert!(pdi.spi_mut().bursts.iter().all(|&(_, n)| n <= 8));
    assert_eq!(pdi.spi_mut().bursts.iter().map(|&(_, n)| n).sum::<usize>(), 64);
    pdi.spi_mut().bursts.clear();
    pdi.write(0x1000, &buf).unwrap();
    assert!(pdi.spi_mut().bursts.iter().all(|&(w, n)| !w && n <= 8));
}

#[test]
fn lan9252_access_across_0x1000_is_split_between_csr_and_fifo() {
    let mut pdi = lan();
    let data = pattern(8, 0x11);
    pdi.write(0x0FFC, &data).unwrap();
    let mut back = [0u8; 8];
    pdi.read(0x0FFC, &mut back).unwrap();
    assert_eq!(back[..], data[..]);
    let chip = pdi.spi_mut();
    assert_eq!(chip.csr_log, [(0xFFC, 4, false), (0xFFC, 4, true)]);
    assert_eq!(chip.bursts, [(false, 1), (true, 1)]);
    assert_eq!(chip.esc[0xFFC..0x1004], data[..]);
}

#[test]
fn lan9252_csr_busy_is_polled_until_clear() {
    let mut pdi = lan();
    pdi.spi_mut().csr_busy_polls = 7;
    assert_eq!(pdi.read_u8(0x0130).unwrap(), pdi.spi_mut().esc[0x130]);
    // The first access checks for a leftover command (1 read), then 7 busy
    // polls and the one that sees it done.
    assert_eq!(pdi.spi_mut().csr_cmd_reads, 1 + 8);
}

#[test]
fn lan9252_csr_busy_timeout_is_an_error_after_max_polls() {
    let config = Config {
        max_polls: 25,
        ..Config::default()
    };
    let mut pdi = Lan9252::with_config(MockLan9252::new(), config);
    pdi.read_u8(0x0130).unwrap();
    pdi.spi_mut().csr_stuck = true;
    pdi.spi_mut().csr_cmd_reads = 0;
    assert_eq!(
        pdi.read_u8(0x0130),
        Err(Error::Timeout {
            register: lan9252_regs::ECAT_CSR_CMD
        })
    );
    assert_eq!(pdi.spi_mut().csr_cmd_reads, 25);
    // The command is still running: the next access waits for it first and
    // then works once the chip recovers.
    pdi.spi_mut().csr_stuck = false;
    assert_eq!(
        pdi.read_u16(0x0130).unwrap(),
        u16::from_le_bytes([pdi.spi_mut().esc[0x130], pdi.spi_mut().esc[0x131]])
    );
}

#[test]
fn lan9252_process_ram_timeout_then_abort_and_recover() {
    let config = Config {
        max_polls: 10,
        ..Config::default()
    };
    let mut pdi = Lan9252::with_config(MockLan9252::new(), config);
    pdi.spi_mut().pram_stuck = true;
    let mut buf = [0u8; 16];
    assert_eq!(
        pdi.read(0x1000, &mut buf),
        Err(Error::Timeout {
            register: lan9252_regs::ECAT_PRAM_RD_CMD
        })
    );
    assert_eq!(
        pdi.write(0x1000, &buf),
        Err(Error::Timeout {
            register: lan9252_regs::ECAT_PRAM_WR_CMD
        })
    );
    pdi.spi_mut().pram_stuck = false;
    // Both engines are aborted before the next transfer, which then works.
    let data = pattern(16, 3);
    pdi.write(0x1000, &data).unwrap();
    pdi.read(0x1000, &mut buf).unwrap();
    assert_eq!(buf[..], data[..]);
}

#[test]
fn lan9252_spi_errors_propagate_and_the_driver_recovers() {
    for fail_at in 1..=40 {
        let mut pdi = lan();
        pdi.spi_mut().fail_at = Some(fail_at);
        let data = pattern(40, fail_at as u8);
        let r = pdi.write(0x1010, &data);
        if pdi.spi_mut().transactions >= fail_at {
            assert_eq!(r, Err(Error::Spi(BusFault)), "failure at transaction {fail_at}");
        } else {
            r.unwrap();
        }
        pdi.spi_mut().fail_at = None;
        // Whatever the failure left behind, the next accesses succeed.
        pdi.write(0x1010, &data).unwrap();
        let mut back = [0u8; 40];
        pdi.read(0x1010, &mut back).unwrap();
        assert_eq!(back[..], data[..]);
    }
    let mut pdi = lan();
    pdi.spi_mut().fail_at = Some(2);
    assert_eq!(pdi.al_event(), Err(Error::Spi(BusFault)));
}

#[test]
fn lan9252_serial_read_command_variant() {
    let config = Config {
        read_command: ReadCommand::Serial,
        ..Config::default()
    };
    let mut pdi = Lan9252::with_config(MockLan9252::new(), config);
    let mut buf = [0u8; 10];
    pdi.read(0x1003, &mut buf).unwrap();
    assert_eq!(buf[..], pdi.spi_mut().esc[0x1003..0x100D]);
    pdi.read(0x0010, &mut buf[..2]).unwrap();
    assert!(pdi.spi_mut().serial_reads > 0);
    assert_eq!(pdi.spi_mut().fast_reads, 0);
    // The default is the fast read.
    let mut pdi = lan();
    pdi.read_u8(0x0010).unwrap();
    assert_eq!(pdi.spi_mut().serial_reads, 0);
}

#[test]
fn lan9252_own_registers_and_wait_ready() {
    let mut pdi = lan();
    pdi.spi_mut().ready_after = 3;
    pdi.wait_ready().unwrap();
    assert_eq!(pdi.read_register(lan9252_regs::ID_REV).unwrap() >> 16, 0x9252);
    let config = Config {
        max_polls: 5,
        ..Config::default()
    };
    let mut pdi = Lan9252::with_config(MockLan9252::new(), config);
    pdi.spi_mut().ready_after = 100;
    assert_eq!(
        pdi.wait_ready(),
        Err(Error::NotReady {
            byte_test: lan9252_regs::BYTE_TEST_VALUE
        })
    );
}

#[test]
fn lan9252_out_of_range_and_empty_accesses_do_no_spi() {
    let mut pdi = lan();
    let mut buf = [0u8; 2];
    assert_eq!(
        pdi.read(0xFFFF, &mut buf),
        Err(Error::OutOfRange { addr: 0xFFFF, len: 2 })
    );
    assert_eq!(
        pdi.write(0xFFFE, &[0; 3]),
        Err(Error::OutOfRange { addr: 0xFFFE, len: 3 })
    );
    pdi.read(0x1000, &mut []).unwrap();
    pdi.write(0x0100, &[]).unwrap();
    assert_eq!(pdi.spi_mut().transactions, 0);
    // The very last byte of the address space is reachable.
    pdi.write(0xFFFF, &[0xA5]).unwrap();
    assert_eq!(pdi.read_u8(0xFFFF).unwrap(), 0xA5);
}

// ---- ET1100 --------------------------------------------------------------

#[test]
fn et1100_header_encodes_address_extension_and_command() {
    // 0x1234 read with wait state: A[12:5] = 0x91, A[4:0] = 0x14, A[15:13] = 0.
    assert_eq!(header(0x1234, 0b011), [0x91, 0xA6, 0x0C]);
    // 0xE001 write: A[12:5] = 0x00, A[4:0] = 0x01, A[15:13] = 0b111.
    assert_eq!(header(0xE001, 0b100), [0x00, 0x0E, 0xF0]);
    assert_eq!(header(0xFFFF, 0b000), [0xFF, 0xFE, 0xE0]);
}

#[test]
fn et1100_reads_and_writes_every_length_and_alignment() {
    let mut pdi = Et1100::new(MockEt1100::new());
    // Registers, process RAM and addresses that need the third address byte.
    for base in [0x0120u16, 0x1000, 0x1FFC, 0x2F00, 0xFFE0] {
        for off in 0..4u16 {
            for len in [1usize, 2, 3, 4, 5, 8, 17] {
                let addr = base + off;
                let mut buf = vec![0u8; len];
                pdi.read(addr, &mut buf).unwrap();
                let a = usize::from(addr);
                assert_eq!(buf, pdi.spi_mut().esc[a..a + len], "read {addr:#06x} len {len}");
                let data = pattern(len, addr as u8);
                pdi.write(addr, &data).unwrap();
                assert_eq!(
                    pdi.spi_mut().esc[a..a + len],
                    data[..],
                    "write {addr:#06x} len {len}"
                );
            }
        }
    }
    // One frame per access, decoded as the right command and length.
    let log = &pdi.spi_mut().log;
    assert_eq!(log[0], (0b011, 0x0120, 1));
    assert_eq!(log[1], (0b100, 0x0120, 1));
}

#[test]
fn et1100_read_sends_wait_state_and_terminates_with_ff() {
    // The model panics on a missing wait state byte, on MOSI other than
    // 0x00 before the last byte and on a missing 0xFF on the last byte.
    let mut pdi = Et1100::new(MockEt1100::new());
    let mut buf = [0u8; 1];
    pdi.read(0x0130, &mut buf).unwrap();
    let mut buf = [0u8; 300];
    pdi.read(0x1100, &mut buf).unwrap();
    assert_eq!(buf[..], pdi.spi_mut().esc[0x1100..0x122C]);
    assert_eq!(pdi.spi_mut().log.last(), Some(&(0b011, 0x1100, 300)));
}

#[test]
fn et1100_al_event_comes_from_the_command_header() {
    let mut pdi = Et1100::new(MockEt1100::new());
    pdi.spi_mut().esc[0x220..0x224].copy_from_slice(&[0x01, 0x0C, 0x02, 0x77]);
    assert_eq!(pdi.last_al_event(), 0);
    // A NOP header only: three bytes, the ESC clocks out 0x0220..0x0222.
    assert_eq!(pdi.al_event().unwrap(), 0x0002_0C01);
    assert_eq!(pdi.spi_mut().log.last(), Some(&(0b000, 0x0000, 0)));
    assert_eq!(pdi.spi_mut().headers.last().map(|h| h.len()), Some(3));
    // Every access refreshes it, without another frame.
    pdi.spi_mut().esc[0x220] = 0x10;
    let frames = pdi.spi_mut().transactions;
    pdi.read_u16(0x0110).unwrap();
    assert_eq!(pdi.last_al_event(), 0x0002_0C10);
    assert_eq!(pdi.spi_mut().transactions, frames + 1);
}

#[test]
fn et1100_mailbox_sized_buffers_roundtrip() {
    let mut pdi = Et1100::new(MockEt1100::new());
    for (addr, len) in [(0x1000u16, 128usize), (0x1080, 128), (0x1800, 1024)] {
        let data = pattern(len, 9);
        pdi.write(addr, &data).unwrap();
        let mut back = vec![0u8; len];
        pdi.read(addr, &mut back).unwrap();
        assert_eq!(back, data);
    }
}

#[test]
fn et1100_spi_errors_propagate() {
    let mut pdi = Et1100::new(MockEt1100::new());
    pdi.spi_mut().fail_at = Some(1);
    let mut buf = [0u8; 4];
    assert_eq!(pdi.read(0x0120, &mut buf), Err(Error::Spi(BusFault)));
    pdi.spi_mut().fail_at = Some(2);
    assert_eq!(pdi.write(0x0120, &buf), Err(Error::Spi(BusFault)));
    pdi.spi_mut().fail_at = Some(3);
    assert_eq!(pdi.al_event(), Err(Error::Spi(BusFault)));
    pdi.read(0x0120, &mut buf).unwrap();
}

#[test]
fn et1100_out_of_range_and_empty_accesses_do_no_spi() {
    let mut pdi = Et1100::new(MockEt1100::new());
    let mut buf = [0u8; 2];
    assert_eq!(
        pdi.read(0xFFFF, &mut buf),
        Err(Error::OutOfRange { addr: 0xFFFF, len: 2 })
    );
    assert_eq!(
        pdi.write(0xFFF0, &[0; 17]),
        Err(Error::OutOfRange {
            addr: 0xFFF0,
            len: 17
        })
    );
    pdi.read(0x0100, &mut []).unwrap();
    pdi.write(0x0100, &[]).unwrap();
    assert_eq!(pdi.spi_mut().transactions, 0);
}
