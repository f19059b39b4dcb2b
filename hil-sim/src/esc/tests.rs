extern crate std;
use super::*;
use crate::frame::testutil::{phys, xfer1};
use ::esc::{
    sii::{config_checksum, control},
    sm::{activate, pdi_control, status},
    PdiExt, SmControl, SmDirection, SmMode,
};
use std::vec::Vec;

const ALIAS: u16 = 0x1234;

/// A small SII image with a valid configuration area, alias and identity.
fn sii_image() -> [u8; 128] {
    let mut s = [0u8; 128];
    s[..4].copy_from_slice(&[0x80, 0x0C, 0x88, 0x88]);
    s[8..10].copy_from_slice(&ALIAS.to_le_bytes());
    s[14] = config_checksum(&s[..14]);
    // words 8..11: vendor id, product code
    s[16..24].copy_from_slice(&[0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08]);
    s
}

fn esc() -> Esc {
    Esc::new(EscConfig::default(), &sii_image())
}

fn wr(e: &mut Esc, addr: u16, data: &[u8], now: u64) -> u16 {
    xfer1(e, Command::Apwr, phys(0, addr), data, now).1
}

fn rd(e: &mut Esc, addr: u16, len: usize, now: u64) -> (Vec<u8>, u16) {
    xfer1(e, Command::Aprd, phys(0, addr), &std::vec![0xEE; len], now)
}

fn reg16(e: &Esc, addr: u16) -> u16 {
    let mut b = [0u8; 2];
    e.read_reg(addr, &mut b);
    u16::from_le_bytes(b)
}

fn setup_sm(e: &mut Esc, n: u8, start: u16, len: u16, control: u8) {
    let sm = SyncManager {
        start,
        length: len,
        control,
        status: 0,
        activate: activate::ENABLE,
        pdi_control: 0,
    };
    assert_eq!(wr(e, regs::sm(n), &sm.to_bytes(), 0), 1);
}

fn sm_status(e: &Esc, n: u8) -> u8 {
    e.sync_manager(n).status
}

const MBX_OUT: u8 = 0x26; // mailbox, master write, PDI IRQ
const MBX_IN: u8 = 0x22; // mailbox, master read, PDI IRQ
const PD_OUT: u8 = 0x64; // 3-buffer, master write, PDI IRQ, watchdog
const PD_IN: u8 = 0x20; // 3-buffer, master read, PDI IRQ

#[test]
fn control_constants_match_the_register_map() {
    let c = |m, d, irq, wd| SmControl::new(m, d, irq, wd).0;
    assert_eq!(MBX_OUT, c(SmMode::Mailbox, SmDirection::MasterWrite, true, false));
    assert_eq!(MBX_IN, c(SmMode::Mailbox, SmDirection::MasterRead, true, false));
    assert_eq!(PD_OUT, c(SmMode::Buffered, SmDirection::MasterWrite, true, true));
    assert_eq!(PD_IN, c(SmMode::Buffered, SmDirection::MasterRead, true, false));
}

#[test]
fn power_on_loads_sii_config_and_defaults() {
    let mut e = esc();
    assert_eq!(e.station_alias(), ALIAS);
    let mut b = [0u8; 2];
    e.read_reg(regs::PDI_CONTROL, &mut b);
    assert_eq!(b, [0x80, 0x0C]);
    assert_eq!(reg16(&e, regs::PDI_CONFIG), 0x8888);
    assert_eq!(reg16(&e, regs::SII_CONTROL), control::READ_8_BYTES);
    assert_eq!(e.al_status(), 0x0001);
    assert_eq!(reg16(&e, regs::WATCHDOG_DIVIDER), 2498);
    assert_eq!(reg16(&e, regs::WATCHDOG_TIME_PD), 1000);
    assert_eq!(reg16(&e, regs::WATCHDOG_TIME_PDI), 1000);
    let dl = reg16(&e, regs::DL_STATUS);
    assert_eq!(
        dl & (dl::PDI_OPERATIONAL | dl::LINK0 | dl::COMM0 | dl::LOOP1),
        0x0611
    );
    assert_eq!(e.read_u32(regs::AL_EVENT_MASK).unwrap(), 0xFFFF_FFFF);
    let (d, wkc) = rd(&mut e, regs::TYPE, 10, 0);
    assert_eq!(wkc, 1);
    assert_eq!(d[regs::FMMU_COUNT as usize], 8);
    assert_eq!(d[regs::SM_COUNT as usize], 8);
    assert_eq!(d[regs::RAM_SIZE as usize], 8);
    assert_eq!(u16::from_le_bytes([d[8], d[9]]) & FEATURES_DC, FEATURES_DC);
    assert_eq!(e.sii().len(), SII_MAX_BYTES);
    assert_eq!(&e.sii()[..128], &sii_image()[..]);
    assert!(e.sii()[128..].iter().all(|&b| b == 0xFF), "padded with 0xFF");
}

#[test]
fn sii_bad_checksum_sets_bit_11() {
    let mut s = sii_image();
    s[14] ^= 1;
    let e = Esc::new(EscConfig::default(), &s);
    assert_eq!(reg16(&e, regs::SII_CONTROL) & control::CHECKSUM_ERROR, 1 << 11);
    assert_eq!(reg16(&e, regs::DL_STATUS) & dl::PDI_OPERATIONAL, 0);
    let e = Esc::new(EscConfig::default(), &[]);
    assert_ne!(reg16(&e, regs::SII_CONTROL) & control::CHECKSUM_ERROR, 0);
}

/// Sends an SII command the way ethercrab does: control, then the address, in one write.
fn sii_cmd(e: &mut Esc, ctrl: u16, word: u16, now: u64) -> u16 {
    let mut b = [0u8; 6];
    b[..2].copy_from_slice(&ctrl.to_le_bytes());
    b[2..4].copy_from_slice(&word.to_le_bytes());
    wr(e, regs::SII_CONTROL, &b, now)
}

#[test]
fn sii_read_words_8_to_11() {
    let mut e = esc();
    assert_eq!(sii_cmd(&mut e, control::CMD_READ, 8, 0), 1);
    let (st, _) = rd(&mut e, regs::SII_CONTROL, 2, 0);
    let st = u16::from_le_bytes([st[0], st[1]]);
    assert_eq!(st & (control::BUSY | control::ACK_ERROR | control::CMD_MASK), 0);
    let (d, wkc) = rd(&mut e, regs::SII_DATA, 8, 0);
    assert_eq!(wkc, 1);
    assert_eq!(d, &sii_image()[16..24]);
    // the last words of the EEPROM, then past it
    sii_cmd(&mut e, control::CMD_READ, 2046, 0);
    assert_eq!(rd(&mut e, regs::SII_DATA, 8, 0).0, [0xFF; 8]);
    assert_eq!(reg16(&e, regs::SII_CONTROL) & control::ACK_ERROR, 0);
    sii_cmd(&mut e, control::CMD_READ, 2048, 0);
    assert_ne!(reg16(&e, regs::SII_CONTROL) & control::ACK_ERROR, 0);
}

#[test]
fn sii_invalid_command_sets_ack_error_until_next_command() {
    let mut e = esc();
    sii_cmd(&mut e, 0x0300, 0, 0);
    assert_ne!(reg16(&e, regs::SII_CONTROL) & control::ACK_ERROR, 0);
    sii_cmd(&mut e, control::CMD_READ, 0, 0);
    assert_eq!(reg16(&e, regs::SII_CONTROL) & control::ACK_ERROR, 0);
    assert_eq!(rd(&mut e, regs::SII_DATA, 8, 0).0, &sii_image()[..8]);
}

#[test]
fn sii_write_without_enable_sets_error() {
    let mut e = esc();
    wr(&mut e, regs::SII_DATA, &[0xAA, 0xBB], 0);
    sii_cmd(&mut e, control::CMD_WRITE, 8, 0);
    assert_ne!(reg16(&e, regs::SII_CONTROL) & control::WRITE_ENABLE_ERROR, 0);
    assert_eq!(&e.sii()[16..18], &[0x01, 0x02]);
}

#[test]
fn e152_sii_write_with_enable_and_reload_sets_alias() {
    let mut e = esc();
    let mut img = sii_image();
    img[8..10].copy_from_slice(&0x0777u16.to_le_bytes());
    let crc = config_checksum(&img[..14]);
    for (word, value) in [(4u16, 0x0777u16), (7, u16::from(crc))] {
        wr(&mut e, regs::SII_DATA, &value.to_le_bytes(), 0);
        sii_cmd(&mut e, control::CMD_WRITE | control::WRITE_ENABLE, word, 0);
        assert_eq!(reg16(&e, regs::SII_CONTROL) & 0x7000, 0, "no error");
    }
    assert_eq!(&e.sii()[8..10], &[0x77, 0x07]);
    assert_eq!(e.station_alias(), ALIAS, "registers change only on reload");
    sii_cmd(&mut e, control::CMD_RELOAD, 0, 0);
    assert_eq!(e.station_alias(), 0x0777);
    assert_eq!(reg16(&e, regs::SII_CONTROL) & control::CHECKSUM_ERROR, 0);
    // a reload with a stale checksum reports it
    wr(&mut e, regs::SII_DATA, &0x0888u16.to_le_bytes(), 0);
    sii_cmd(&mut e, control::CMD_WRITE | control::WRITE_ENABLE, 4, 0);
    sii_cmd(&mut e, control::CMD_RELOAD, 0, 0);
    assert_ne!(reg16(&e, regs::SII_CONTROL) & control::CHECKSUM_ERROR, 0);
}

#[test]
fn sii_busy_clears_with_later_time() {
    let cfg = EscConfig {
        sii_busy: Nanos::from_us(20),
        ..EscConfig::default()
    };
    let mut e = Esc::new(cfg, &sii_image());
    sii_cmd(&mut e, control::CMD_READ, 8, 1_000);
    assert_ne!(reg16(&e, regs::SII_CONTROL) & control::BUSY, 0);
    assert_eq!(rd(&mut e, regs::SII_DATA, 8, 20_999).0, [0; 8], "not yet");
    // a command while busy is ignored
    sii_cmd(&mut e, control::CMD_READ, 0, 21_000 - 1);
    e.tick(Nanos::from_ns(21_000));
    assert_eq!(
        reg16(&e, regs::SII_CONTROL) & (control::BUSY | control::CMD_MASK),
        0
    );
    assert_eq!(rd(&mut e, regs::SII_DATA, 8, 21_000).0, &sii_image()[16..24]);
    // completion also happens on a datagram with a later time
    sii_cmd(&mut e, control::CMD_READ, 0, 30_000);
    let (st, _) = rd(&mut e, regs::SII_CONTROL, 2, 50_000);
    assert_eq!(u16::from_le_bytes([st[0], st[1]]) & control::BUSY, 0);
    assert_eq!(rd(&mut e, regs::SII_DATA, 8, 50_000).0, &sii_image()[..8]);
}

#[test]
fn al_control_write_sets_event_and_pdi_read_clears_it() {
    let mut e = esc();
    assert_eq!(e.al_event().unwrap() & al_event::AL_CONTROL, 0);
    assert_eq!(wr(&mut e, regs::AL_CONTROL, &[0x02, 0x00], 0), 1);
    assert_eq!(e.al_control(), 2);
    assert_ne!(e.al_event().unwrap() & al_event::AL_CONTROL, 0);
    // reading the event register does not clear it
    assert_ne!(e.al_event().unwrap() & al_event::AL_CONTROL, 0);
    assert_eq!(e.read_u16(regs::AL_CONTROL).unwrap(), 2);
    assert_eq!(e.al_event().unwrap() & al_event::AL_CONTROL, 0);
    // the PDI cannot write AL control
    e.write_u16(regs::AL_CONTROL, 8).unwrap();
    assert_eq!(e.al_control(), 2);
}

#[test]
fn al_event_is_masked_by_the_mask_register() {
    let mut e = esc();
    wr(&mut e, regs::AL_CONTROL, &[0x02, 0x00], 0);
    e.write_u32(regs::AL_EVENT_MASK, !al_event::AL_CONTROL).unwrap();
    assert_eq!(e.pdi().al_event().unwrap() & al_event::AL_CONTROL, 0);
    assert_ne!(e.al_event_request() & al_event::AL_CONTROL, 0);
}

#[test]
fn al_status_is_written_only_by_the_pdi() {
    let mut e = esc();
    assert_eq!(wr(&mut e, regs::AL_STATUS, &[0x08, 0x00, 0, 0, 0x1B, 0x00], 0), 1);
    assert_eq!(e.al_status(), 1);
    assert_eq!(e.al_status_code(), 0);
    let mut p = e.pdi();
    p.write_u16(regs::AL_STATUS, 0x12).unwrap();
    p.write_u16(regs::AL_STATUS_CODE, 0x001B).unwrap();
    assert_eq!(rd(&mut e, regs::AL_STATUS, 2, 0).0, [0x12, 0]);
    assert_eq!(e.al_status_code(), 0x001B);
}

#[test]
fn registers_0000_to_000f_are_read_only_from_ecat() {
    let mut e = esc();
    let (before, _) = rd(&mut e, 0, 16, 0);
    assert_eq!(wr(&mut e, 0, &[0x55; 16], 0), 1);
    assert_eq!(rd(&mut e, 0, 16, 0).0, before);
    e.write(0, &[0x55; 16]).unwrap();
    assert_eq!(rd(&mut e, 0, 16, 0).0, before);
}

#[test]
fn not_present_addresses_read_zero_but_count() {
    let mut e = esc();
    assert_eq!(wr(&mut e, 0x3000, &[1, 2, 3], 0), 1);
    assert_eq!(rd(&mut e, 0x3000, 3, 0), (std::vec![0, 0, 0], 1));
    // across the end of RAM and across 0xFFFF
    wr(&mut e, 0x2FFE, &[7, 7, 7, 7], 0);
    assert_eq!(rd(&mut e, 0x2FFE, 4, 0).0, [7, 7, 0, 0]);
    assert_eq!(rd(&mut e, 0xFFFE, 4, 0), (std::vec![0; 4], 1));
    // a smaller RAM
    let mut small = Esc::new(
        EscConfig {
            ram_kib: 4,
            ..EscConfig::default()
        },
        &[],
    );
    wr(&mut small, 0x2000, &[9], 0);
    assert_eq!(rd(&mut small, 0x2000, 1, 0).0, [0]);
    wr(&mut small, 0x1FFF, &[9], 0);
    assert_eq!(rd(&mut small, 0x1FFF, 1, 0).0, [9]);
}

#[test]
fn mailbox_write_full_busy_and_pdi_read_empties() {
    let mut e = esc();
    setup_sm(&mut e, 0, 0x1000, 128, MBX_OUT);
    let msg1: Vec<u8> = (0..128).map(|i| i as u8).collect();
    // a write that misses the last byte does not complete the mailbox
    assert_eq!(wr(&mut e, 0x1000, &[0xAA; 16], 0), 1);
    assert_eq!(sm_status(&e, 0) & status::MAILBOX_FULL, 0);
    assert_eq!(wr(&mut e, 0x1000, &msg1, 0), 1);
    assert_ne!(sm_status(&e, 0) & status::MAILBOX_FULL, 0);
    assert_ne!(e.al_event().unwrap() & al_event::sm(0), 0);
    // full: the next write is refused and does not count
    assert_eq!(wr(&mut e, 0x1000, &[0x55; 128], 0), 0);
    let mut got = [0u8; 128];
    e.read(0x1000, &mut got).unwrap();
    assert_eq!(&got[..], &msg1[..]);
    assert_eq!(sm_status(&e, 0) & status::MAILBOX_FULL, 0);
    assert_eq!(e.al_event().unwrap() & al_event::sm(0), 0);
    // empty again: the PDI sees nothing, the master may write
    let mut again = [0xEEu8; 4];
    e.read(0x1000, &mut again).unwrap();
    assert_eq!(again, [0; 4], "reading an empty write mailbox is refused");
    assert_eq!(wr(&mut e, 0x1000, &[0x55; 128], 0), 1);
}

#[test]
fn mailbox_without_pdi_irq_raises_no_event() {
    let mut e = esc();
    setup_sm(&mut e, 0, 0x1000, 16, MBX_OUT & !0x20);
    wr(&mut e, 0x1000, &[1; 16], 0);
    assert_ne!(sm_status(&e, 0) & status::MAILBOX_FULL, 0);
    assert_eq!(e.al_event().unwrap() & al_event::sm(0), 0);
}

#[test]
fn mailbox_read_pdi_write_then_ecat_read() {
    let mut e = esc();
    setup_sm(&mut e, 1, 0x1080, 64, MBX_IN);
    // empty: no data, WKC 0
    let (d, wkc) = rd(&mut e, 0x1080, 64, 0);
    assert_eq!(wkc, 0);
    assert!(d.iter().all(|&b| b == 0xEE), "data untouched");
    let msg: Vec<u8> = (0..64).map(|i| 100 + i as u8).collect();
    e.write(0x1080, &msg).unwrap();
    assert_ne!(sm_status(&e, 1) & status::MAILBOX_FULL, 0);
    // the PDI cannot overwrite a full mailbox
    e.write(0x1080, &[0; 64]).unwrap();
    let (d, wkc) = rd(&mut e, 0x1080, 64, 0);
    assert_eq!((d, wkc), (msg.clone(), 1));
    assert_eq!(sm_status(&e, 1) & status::MAILBOX_FULL, 0);
    assert_ne!(e.al_event().unwrap() & al_event::sm(1), 0, "read by the master");
    assert_eq!(rd(&mut e, 0x1080, 64, 0).1, 0, "empty again");
    // the next PDI write acknowledges the event
    e.write(0x1080, &msg).unwrap();
    assert_eq!(e.al_event().unwrap() & al_event::sm(1), 0);
}

#[test]
fn mailbox_repeat_toggle_raises_event_and_allows_rewrite() {
    let mut e = esc();
    setup_sm(&mut e, 1, 0x1080, 16, MBX_IN);
    e.read_u8(regs::sm(1) + 6).unwrap(); // acknowledge the activation event
    assert_eq!(e.al_event().unwrap() & al_event::SM_ACTIVATION, 0);
    let msg = [0x42u8; 16];
    e.write(0x1080, &msg).unwrap();
    assert_eq!(rd(&mut e, 0x1080, 16, 0).1, 1); // ... and the reply gets lost
                                                // the master toggles REPEAT
    assert_eq!(
        wr(&mut e, regs::sm(1) + 6, &[activate::ENABLE | activate::REPEAT], 0),
        1
    );
    assert_ne!(e.al_event().unwrap() & al_event::SM_ACTIVATION, 0);
    let act = e.read_u8(regs::sm(1) + 6).unwrap();
    assert_eq!(
        e.al_event().unwrap() & al_event::SM_ACTIVATION,
        0,
        "cleared by reading"
    );
    assert_ne!(act & activate::REPEAT, 0);
    e.write(0x1080, &msg).unwrap();
    e.write_u8(regs::sm(1) + 7, pdi_control::REPEAT_ACK).unwrap();
    let (pc, _) = rd(&mut e, regs::sm(1) + 7, 1, 0);
    assert_eq!(pc[0] & pdi_control::REPEAT_ACK, pdi_control::REPEAT_ACK);
    assert_eq!(rd(&mut e, 0x1080, 16, 0), (msg.to_vec(), 1));
    // a repeat while the mailbox is still full lets the PDI write it again
    e.write(0x1080, &[1; 16]).unwrap();
    wr(&mut e, regs::sm(1) + 6, &[activate::ENABLE], 0);
    e.write(0x1080, &[2; 16]).unwrap();
    assert_eq!(rd(&mut e, 0x1080, 16, 0), (std::vec![2; 16], 1));
}

#[test]
fn sm_disable_resets_state_and_activation_raises_event() {
    let mut e = esc();
    setup_sm(&mut e, 0, 0x1000, 8, MBX_OUT);
    assert_ne!(e.al_event_request() & al_event::SM_ACTIVATION, 0);
    wr(&mut e, 0x1000, &[1; 8], 0);
    assert_eq!(wr(&mut e, 0x1000, &[2; 8], 0), 0);
    wr(&mut e, regs::sm(0) + 6, &[0], 0);
    assert_eq!(sm_status(&e, 0), 0);
    assert_eq!(e.al_event_request() & al_event::sm(0), 0);
    // disabled: plain memory
    assert_eq!(wr(&mut e, 0x1000, &[3; 8], 0), 1);
    wr(&mut e, regs::sm(0) + 6, &[activate::ENABLE], 0);
    assert_eq!(wr(&mut e, 0x1000, &[4; 8], 0), 1, "empty after re-enable");
}

#[test]
fn sm_status_and_pdi_control_are_read_only_from_ecat() {
    let mut e = esc();
    let sm = SyncManager {
        start: 0x1000,
        length: 8,
        control: MBX_OUT,
        status: 0xFF,
        activate: 1,
        pdi_control: 0xFF,
    };
    wr(&mut e, regs::sm(0), &sm.to_bytes(), 0);
    let got = e.sync_manager(0);
    assert_eq!(
        (got.start, got.length, got.control, got.activate),
        (0x1000, 8, MBX_OUT, 1)
    );
    assert_eq!((got.status, got.pdi_control), (0, 0));
    // the PDI may write only the PDI control byte
    e.write(regs::sm(0), &[0x99; 8]).unwrap();
    let got = e.sync_manager(0);
    assert_eq!((got.start, got.control, got.pdi_control), (0x1000, MBX_OUT, 0x99));
}

#[test]
fn three_buffer_reader_gets_newest_complete_buffer() {
    let mut e = esc();
    setup_sm(&mut e, 2, 0x1100, 4, PD_OUT);
    assert_eq!(wr(&mut e, 0x1100, &[1; 4], 0), 1);
    assert_ne!(e.al_event().unwrap() & al_event::sm(2), 0);
    assert_eq!(wr(&mut e, 0x1100, &[2; 4], 0), 1);
    let mut b = [0u8; 4];
    e.read(0x1100, &mut b).unwrap();
    assert_eq!(b, [2; 4], "newest complete buffer");
    assert_eq!(
        e.al_event().unwrap() & al_event::sm(2),
        0,
        "acknowledged by the read"
    );
    // a partial write is never seen
    wr(&mut e, 0x1100, &[3, 3], 0);
    e.read(0x1100, &mut b).unwrap();
    assert_eq!(b, [2; 4]);
    wr(&mut e, 0x1102, &[4, 4], 0);
    e.read(0x1100, &mut b).unwrap();
    assert_eq!(b, [3, 3, 4, 4], "completed in the same buffer");
    // a read in progress keeps its buffer
    let mut half = [0u8; 2];
    wr(&mut e, 0x1100, &[5; 4], 0);
    e.read(0x1100, &mut half).unwrap();
    assert_eq!(half, [5, 5]);
    wr(&mut e, 0x1100, &[6; 4], 0);
    e.read(0x1102, &mut half).unwrap();
    assert_eq!(half, [5, 5], "locked buffer");
    e.read(0x1100, &mut b).unwrap();
    assert_eq!(b, [6; 4]);
    // nothing new: the last buffer is read again
    e.read(0x1100, &mut b).unwrap();
    assert_eq!(b, [6; 4]);
    // buffers 1 and 2 are hidden
    assert_eq!(rd(&mut e, 0x1104, 8, 0).0, [0; 8]);
    let mut raw = [0u8; 12];
    e.read_reg(0x1100, &mut raw);
    assert!(
        raw[4..].iter().any(|&x| x != 0),
        "physically stored behind the area"
    );
    // the master cannot read an output buffer
    assert_eq!(rd(&mut e, 0x1100, 4, 0).1, 0);
}

#[test]
fn three_buffer_inputs_partial_pdi_write_never_seen() {
    let mut e = esc();
    setup_sm(&mut e, 3, 0x1400, 4, PD_IN);
    e.write(0x1400, &[1; 4]).unwrap();
    assert_eq!(rd(&mut e, 0x1400, 4, 0), (std::vec![1; 4], 1));
    assert_ne!(
        e.al_event().unwrap() & al_event::sm(3),
        0,
        "inputs read by the master"
    );
    e.write(0x1400, &[2, 2]).unwrap();
    assert_eq!(e.al_event().unwrap() & al_event::sm(3), 0);
    assert_eq!(rd(&mut e, 0x1400, 4, 0), (std::vec![1; 4], 1), "old buffer again");
    e.write(0x1402, &[5, 5]).unwrap();
    assert_eq!(rd(&mut e, 0x1400, 4, 0), (std::vec![2, 2, 5, 5], 1));
    let st = sm_status(&e, 3);
    assert_ne!(
        st & status::BUFFER_MASK,
        status::BUFFER_MASK,
        "a buffer was written"
    );
    assert_eq!(st & (status::READ_OPEN | status::WRITE_OPEN), 0);
}

#[test]
fn pd_watchdog_expires_after_configured_time() {
    let mut e = esc();
    setup_sm(&mut e, 2, 0x1100, 4, PD_OUT);
    wr(&mut e, regs::WATCHDOG_TIME_PD, &10u16.to_le_bytes(), 0); // 10 × 100 µs
    wr(&mut e, 0x1100, &[1; 4], 1_000_000);
    assert_eq!(reg16(&e, regs::WATCHDOG_STATUS_PD) & 1, 1);
    e.tick(Nanos::from_ns(1_999_999));
    assert_eq!(reg16(&e, regs::WATCHDOG_STATUS_PD) & 1, 1);
    assert_eq!(e.al_event_request() & al_event::WATCHDOG_PD, 0);
    e.tick(Nanos::from_ns(2_000_000));
    assert_eq!(reg16(&e, regs::WATCHDOG_STATUS_PD) & 1, 0);
    assert_eq!(rd(&mut e, regs::WATCHDOG_COUNTER_PD, 1, 2_000_000).0, [1]);
    assert_ne!(e.al_event().unwrap() & al_event::WATCHDOG_PD, 0);
    e.read_u16(regs::WATCHDOG_STATUS_PD).unwrap();
    assert_eq!(e.al_event().unwrap() & al_event::WATCHDOG_PD, 0);
    // retriggered by the next output write, expires once more
    wr(&mut e, 0x1100, &[2; 4], 3_000_000);
    e.tick(Nanos::from_ns(3_500_000));
    assert_eq!(reg16(&e, regs::WATCHDOG_STATUS_PD) & 1, 1);
    e.tick(Nanos::from_ns(4_000_000));
    assert_eq!(rd(&mut e, regs::WATCHDOG_COUNTER_PD, 1, 4_000_000).0, [2]);
    // an ECAT write clears the counter; time 0 disables the watchdog
    wr(&mut e, regs::WATCHDOG_COUNTER_PD, &[0], 4_000_000);
    wr(&mut e, regs::WATCHDOG_TIME_PD, &[0, 0], 4_000_000);
    wr(&mut e, 0x1100, &[3; 4], 5_000_000);
    e.tick(Nanos::from_ns(1_000_000_000));
    assert_eq!(rd(&mut e, regs::WATCHDOG_COUNTER_PD, 1, 1_000_000_000).0, [0]);
}

#[test]
fn pdi_watchdog_expires_without_pdi_access() {
    let mut e = esc();
    e.tick(Nanos::from_ns(1_000));
    e.read_u8(0).unwrap();
    assert_ne!(reg16(&e, regs::DL_STATUS) & dl::PDI_WATCHDOG, 0);
    e.tick(Nanos::from_ns(1_000 + 100_000_000 - 1));
    assert_eq!(e.read_u8(regs::WATCHDOG_COUNTER_PDI).unwrap(), 0); // also retriggers
    e.tick(Nanos::from_ns(200_000_998));
    assert_eq!(e.get_u8(regs::WATCHDOG_COUNTER_PDI), 0);
    e.tick(Nanos::from_ns(200_000_999));
    assert_eq!(e.get_u8(regs::WATCHDOG_COUNTER_PDI), 1);
    assert_eq!(reg16(&e, regs::DL_STATUS) & dl::PDI_WATCHDOG, 0);
}

#[test]
fn dc_write_latches_receive_time_and_system_time_adds_offset() {
    let mut e = esc();
    let now = 0x1_2345_6789u64;
    assert_eq!(
        xfer1(
            &mut e,
            Command::Bwr,
            phys(0, regs::dc::RECEIVE_TIME_PORT0),
            &[0; 4],
            now
        )
        .1,
        1
    );
    let (d, _) = rd(&mut e, regs::dc::RECEIVE_TIME_PORT0, 16, now);
    assert_eq!(&d[..4], &(now as u32).to_le_bytes());
    assert_eq!(&d[4..8], &(now as u32).to_le_bytes());
    let (d, _) = rd(&mut e, regs::dc::RECEIVE_TIME_PU, 8, now);
    assert_eq!(d, now.to_le_bytes());
    wr(
        &mut e,
        regs::dc::SYSTEM_TIME_OFFSET,
        &(-1000i64).to_le_bytes(),
        now,
    );
    let (d, wkc) = rd(&mut e, regs::dc::SYSTEM_TIME, 8, now + 5);
    assert_eq!(
        (u64::from_le_bytes(d.try_into().unwrap()), wkc),
        (now + 5 - 1000, 1)
    );
    // a write of the system time does not overwrite it
    wr(&mut e, regs::dc::SYSTEM_TIME, &[0; 8], now + 10);
    let mut b = [0u8; 8];
    e.read(regs::dc::SYSTEM_TIME, &mut b).unwrap();
    assert_eq!(u64::from_le_bytes(b), now + 10 - 1000);
}

#[test]
fn pdi_handle_and_direct_impl_agree() {
    let mut e = esc();
    e.pdi().write(0x1F00, &[1, 2, 3]).unwrap();
    let mut b = [0u8; 3];
    Pdi::read(&mut e, 0x1F00, &mut b).unwrap();
    assert_eq!(b, [1, 2, 3]);
    // a long PDI write into a mailbox completes it on its last byte
    setup_sm(&mut e, 1, 0x1200, 600, MBX_IN);
    let msg: Vec<u8> = (0..600).map(|i| (i % 251) as u8).collect();
    e.pdi().write(0x1200, &msg).unwrap();
    assert_ne!(sm_status(&e, 1) & status::MAILBOX_FULL, 0);
    assert_eq!(rd(&mut e, 0x1200, 600, 0), (msg, 1));
}

/// Every access kind, for the randomized data-phase comparisons.
const OPS: [Op; 5] = [Op::Read, Op::ReadOr, Op::Write, Op::ReadWrite, Op::ReadOrWrite];

/// Every memory byte `i` of `e` set to `i * mul ^ xor` (wrapping).
fn fill(e: &mut Esc, mul: u8, xor: u8) {
    for (i, m) in e.mem.iter_mut().enumerate() {
        *m = (i as u8).wrapping_mul(mul) ^ xor;
    }
}

/// A xorshift64 generator from `seed`.
fn xorshift(seed: u64) -> impl FnMut() -> u64 {
    let mut x = seed;
    move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    }
}

/// The data phase of an access no SyncManager area overlaps
/// (`Esc::plain_data`, slices where it can) does byte for byte what the
/// general per-byte phase does with every byte plain (`Esc::sm_data` with no
/// SM near): random accesses of every kind, from both sides, over the
/// registers (the DC system time computed, the EEPROM registers locked while
/// a command runs), the process RAM and beyond the present memory.
#[test]
fn plain_data_phase_is_the_per_byte_phase() {
    let mut base = esc();
    // a system time that is not zero and moves
    base.set_clock(30_000, 123_456_789);
    base.tick(Nanos::from_us(777));
    fill(&mut base, 37, 0x5A);
    let mut next = xorshift(0x9E37_79B9_7F4A_7C15u64);
    for round in 0..20_000 {
        let r = next();
        let addr = match r % 4 {
            0 => 0x0900 + (r >> 8) as u32 % 0x40,
            1 => 0x0500 + (r >> 8) as u32 % 0x20,
            2 => (r >> 8) as u32 % 0x3100,
            _ => 0x1000 + (r >> 8) as u32 % 0x2100,
        };
        let len = 1 + (next() % 40) as usize;
        let op = OPS[(next() % 5) as usize];
        let side = if next() % 2 == 0 { Side::Ecat } else { Side::Pdi };
        let mut e = base.clone();
        e.sii_pending = (round % 3 == 0).then_some(SiiPending {
            command: 0x0100,
            done_at: Nanos::from_secs(1),
        });
        let t = Nanos::from_us(round);
        let mut f = e.clone();
        let data: Vec<u8> = (0..len).map(|_| next() as u8).collect();
        let (mut a, mut b) = (data.clone(), data);
        e.plain_data(side, addr, &mut a, op, t);
        f.sm_data(side, addr, &mut b, op, t, &[]);
        assert_eq!(a, b, "{op:?} {side:?} {addr:#06x} +{len}: data");
        assert!(e.mem == f.mem, "{op:?} {side:?} {addr:#06x} +{len}: memory");
    }
}

/// The data phase of an access inside one SyncManager's buffer area
/// (`Esc::sm_data` with one SM near: slices) does byte for byte what the
/// per-byte phase does (`Esc::sm_data_bytes`): random SMs (mailbox and
/// three-buffer, reader and writer side, refused, buffers 0..2, areas over
/// the registers, the RAM and its end) and random accesses in and around them.
#[test]
fn buffer_data_phase_is_the_per_byte_phase() {
    let mut base = esc();
    base.set_clock(-20_000, 987_654_321);
    base.tick(Nanos::from_us(1234));
    fill(&mut base, 91, 0xA5);
    let mut next = xorshift(0x1234_5678_9ABC_DEF1u64);
    for _ in 0..20_000 {
        let start = match next() % 3 {
            0 => 0x0900 + (next() % 0x20) as u32,
            1 => 0x1000 + (next() % 0x2000) as u32,
            _ => 0x2F00 + (next() % 0x100) as u32,
        };
        let len = 1 + (next() % 64) as u32;
        let reader = next() % 2 == 0;
        let ok = next() % 4 != 0;
        let p = sm::Plan {
            active: true,
            buffered: next() % 2 == 0,
            start,
            len,
            side: if next() % 2 == 0 { Side::Ecat } else { Side::Pdi },
            reader,
            involved: true,
            read_ok: ok && reader,
            write_ok: ok && !reader,
            buffer: (next() % 3) as u8,
            ..sm::Plan::default()
        };
        let addr = start + (next() % u64::from(len + 4)) as u32 - (next() % 3) as u32;
        let n = 1 + (next() % 70) as usize;
        let op = OPS[(next() % 5) as usize];
        let (mut e, mut f) = (base.clone(), base.clone());
        let data: Vec<u8> = (0..n).map(|_| next() as u8).collect();
        let (mut a, mut b) = (data.clone(), data);
        let t = Nanos::from_us(next() % 10_000);
        e.sm_data(p.side, addr, &mut a, op, t, &[p]);
        f.sm_data_bytes(p.side, addr, &mut b, op, t, &[p]);
        assert_eq!(a, b, "{op:?} {p:?} at {addr:#06x} +{n}: data");
        assert!(e.mem == f.mem, "{op:?} {p:?} at {addr:#06x} +{n}: memory");
    }
}
