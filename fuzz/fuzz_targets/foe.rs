//! FoE sessions into a drive in Bootstrap with firmware slots (slot A
//! holds a confirmed image): the input is a list of FoE operations, each
//! sent as a well-formed mailbox through the drive's mailbox task (behind
//! `mbx_esc.rs`): write requests (the firmware's name or another, a
//! password), data packets (the next number or another; a chunk of a valid
//! signed image for slot B or arbitrary bytes; full or short), a master's
//! ERROR, read requests, stray ACK/BUSY packets, and time passing (the FoE
//! timeout). Oracles:
//! - every answer is an FoE ACK, ERROR or BUSY (a mailbox error for a
//!   request the mailbox refuses), an ACK names the packet it answers
//!   (0 for a write request);
//! - slot A stays confirmed and the running image;
//! - slot B becomes pending only when the bytes the drive acknowledged in
//!   one session are the valid image, in order.
#![no_main]

#[path = "mbx_esc.rs"]
mod mbx_esc;

use drive_ecat::boot::{BootSlots, ImageHeader, Slot, SlotState};
use ecat::foe::opcode;
use libfuzzer_sys::fuzz_target;
use mbx_esc::{MailboxEsc, LEN};
use nanos::Nanos;

/// The firmware flash of the target: 2 × 32 sectors of 256 bytes (8 KiB a slot).
type Small = drive_ecat::boot::RamFlash<256, 64>;
type Drive = drive_ecat::runtime::Drive<hil_sim::sim::SimFlash, Small>;

/// FoE data bytes per full packet (a 256-byte mailbox).
const SEGMENT: usize = LEN - 12;

/// The signed update file of `len` body bytes for `slot` of `slots`.
fn image(slots: &BootSlots<Small>, slot: Slot, version: u32, len: usize) -> Vec<u8> {
    let seed = drive_ecat::boot::parse_key_hex(include_str!("../../keys/dev-ed25519.key")).unwrap_or([0; 32]);
    let body: Vec<u8> = (0..len).map(|i| (i as u32).wrapping_mul(2_654_435_761).to_le_bytes()[3]).collect();
    let mut h = ImageHeader::for_body(&body, version, slots.load_address(slot), 1);
    h.sign(&body, &seed);
    let mut f = h.to_bytes().to_vec();
    f.extend_from_slice(&body);
    f
}

/// A drive whose slot A holds a confirmed image, in Bootstrap (the AL
/// state set as the master's Init → Bootstrap request leaves it), and the
/// valid update file for slot B.
fn build() -> (Drive, Vec<u8>) {
    let mut slots = BootSlots::new(Small::new());
    let _ = slots.boot();
    let factory = image(&slots, Slot::A, 1, 1000);
    let _ = slots.begin();
    let _ = slots.write(&factory);
    let _ = slots.finish_verified(&drive_ecat::runtime::FIRMWARE_PUBLIC_KEY);
    let mut slots = BootSlots::new(slots.into_inner());
    let _ = slots.boot();
    let _ = slots.confirm();
    let update = image(&slots, Slot::B, 2, 1200);
    let mut slots = BootSlots::new(slots.into_inner());
    let _ = slots.boot_verified(&drive_ecat::runtime::FIRMWARE_PUBLIC_KEY, 0);
    let mut drive = Drive::with_boot(hil_sim::sim::SimFlash::new(), Some(slots));
    // the master's Init → Bootstrap request, with the bootstrap mailbox set up
    let mut esc = MailboxEsc::new();
    esc.master_al_control(3);
    let _ = drive.poll(&mut esc, Nanos::from_ms(1));
    assert_eq!(drive.slave().state(), esc::AlState::Bootstrap, "Bootstrap");
    (drive, update)
}

thread_local! {
    static BOOT: (Drive, Vec<u8>) = build();
}

fn take<'a>(data: &mut &'a [u8], n: usize) -> &'a [u8] {
    let (a, b) = data.split_at(n.min(data.len()));
    *data = b;
    a
}

fn byte(data: &mut &[u8]) -> u8 {
    take(data, 1).first().copied().unwrap_or(0)
}

fn u32_of(data: &mut &[u8]) -> u32 {
    let mut b = [0u8; 4];
    for (d, s) in b.iter_mut().zip(take(data, 4)) {
        *d = *s;
    }
    u32::from_le_bytes(b)
}

fuzz_target!(|input: &[u8]| {
    let (mut drive, update) = BOOT.with(|(d, u)| (d.clone(), u.clone()));
    let mut esc = MailboxEsc::new();
    let mut now = Nanos::from_ms(10);
    let mut data = input;
    let mut counter = 0u8;
    // the data packet numbers sent and acknowledged in this session, and
    // whether every acknowledged packet was the image's next chunk
    let mut next = 1u32;
    let mut acked: Vec<u8> = Vec::new();
    let mut faithful = true;
    let mut last_sent: Option<u32>;
    for _ in 0..32 {
        if data.is_empty() {
            break;
        }
        let op = byte(&mut data);
        let mut foe = Vec::new();
        let mut chunk_sent: Option<(u32, Vec<u8>, bool)> = None;
        match op % 8 {
            0 | 1 => {
                // write request: the firmware file, or a name from the input
                foe.extend_from_slice(&[opcode::WRITE, 0]);
                foe.extend_from_slice(&u32_of(&mut data).to_le_bytes()); // password
                if op & 0x80 == 0 {
                    foe.extend_from_slice(drive_ecat::runtime::FIRMWARE_FILE);
                } else {
                    let n = usize::from(byte(&mut data) % 24);
                    foe.extend_from_slice(take(&mut data, n));
                }
                last_sent = Some(0);
            }
            2..=4 => {
                // data: the expected number or another, the image's chunk or other bytes
                let flags = byte(&mut data);
                let number = if flags & 1 == 0 { next } else { u32_of(&mut data) };
                let k = usize::try_from(number.wrapping_sub(1)).unwrap_or(usize::MAX);
                let image_chunk = update.chunks(SEGMENT).nth(k).map(<[u8]>::to_vec);
                let (payload, faithful_chunk) = match (flags & 2 == 0, image_chunk) {
                    (true, Some(c)) => (c, true),
                    (_, _) => {
                        let n = usize::from(byte(&mut data)) % (SEGMENT + 1);
                        (take(&mut data, n).to_vec(), false)
                    }
                };
                foe.extend_from_slice(&[opcode::DATA, 0]);
                foe.extend_from_slice(&number.to_le_bytes());
                foe.extend_from_slice(&payload);
                chunk_sent = Some((number, payload, faithful_chunk));
                last_sent = Some(number);
            }
            5 => {
                // the master aborts (ERROR), or reads a file
                if op & 0x80 == 0 {
                    foe.extend_from_slice(&[opcode::ERROR, 0]);
                    foe.extend_from_slice(&u32_of(&mut data).to_le_bytes());
                } else {
                    foe.extend_from_slice(&[opcode::READ, 0, 0, 0, 0, 0]);
                    foe.extend_from_slice(drive_ecat::runtime::FIRMWARE_FILE);
                }
                last_sent = None;
            }
            6 => {
                // a stray ACK or BUSY from the master
                let code = if op & 0x80 == 0 { opcode::ACK } else { opcode::BUSY };
                foe.extend_from_slice(&[code, 0]);
                foe.extend_from_slice(&u32_of(&mut data).to_le_bytes());
                last_sent = None;
            }
            _ => {
                // time passes: up to about 10 s (the FoE timeout is 5 s)
                now = now + Nanos::from_ms(u64::from(byte(&mut data)) * 40);
                let Ok(()) = drive.poll_mailbox(&mut esc, now);
                continue;
            }
        }
        counter = counter % 7 + 1;
        let mut buf = [0u8; LEN];
        let len = foe.len().min(LEN - 6);
        buf[0..2].copy_from_slice(&(len as u16).to_le_bytes());
        buf[5] = (counter << 4) | 4; // FoE
        buf[6..6 + len].copy_from_slice(&foe[..len]);
        for _ in 0..4 {
            if esc.master_write(&buf) {
                break;
            }
            now = now + Nanos::from_us(200);
            let Ok(()) = drive.poll_mailbox(&mut esc, now);
        }
        for _ in 0..4 {
            now = now + Nanos::from_us(200);
            let Ok(()) = drive.poll_mailbox(&mut esc, now);
            let Some(answer) = esc.master_read() else {
                continue;
            };
            let kind = answer[5] & 0x0F;
            if kind == 0 {
                continue; // a mailbox error for a refused request
            }
            assert_eq!(kind, 4, "an answer to FoE is FoE: {:02x?}", &answer[..16]);
            let code = answer[6];
            let field = u32::from_le_bytes([answer[8], answer[9], answer[10], answer[11]]);
            assert!(
                matches!(code, opcode::ACK | opcode::ERROR | opcode::BUSY),
                "FoE answer opcode {code}"
            );
            if code == opcode::ACK {
                assert_eq!(Some(field), last_sent, "the ACK names the packet it answers");
                if field == 0 {
                    // a write request taken: a new session
                    acked.clear();
                    faithful = true;
                    next = 1;
                } else if let Some((number, payload, faithful_chunk)) = chunk_sent.take() {
                    faithful &= faithful_chunk && number == next;
                    acked.extend_from_slice(&payload);
                    next = number.wrapping_add(1);
                }
            }
        }
    }
    let slots = drive.boot_slots_mut().expect("slots");
    assert!(
        matches!(slots.state(Slot::A), Ok(SlotState::Confirmed { .. })),
        "slot A stays confirmed"
    );
    if matches!(slots.state(Slot::B), Ok(SlotState::Pending { .. })) {
        assert!(faithful && acked == update, "slot B pending from other bytes than the image");
    }
});
