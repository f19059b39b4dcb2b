//! FoE firmware download throughput: a 256 KiB image through the whole chain
//! (ethercrab in-process -> simulated ESC -> slave stack FoE server -> the
//! drive's firmware slots on a simulated NOR flash), in simulated time.
//!
//! `cargo bench -p hil-sim --bench foe [-- --runs N]`
//!
//! ethercrab 0.7.1 has no FoE: the packets are written into SM0 and read
//! from SM1 with plain register accesses (one write, SM1 status polls, one
//! read per packet), as `drive_tests::FoeClient` does. Mailbox 256 bytes:
//! 244 data bytes per packet.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::indexing_slicing,
    clippy::panic
)]

mod line;
use drive_ecat::boot::{BootSlots, ImageHeader, IMAGE_HEADER_LEN};
use drive_ecat::runtime::Drive;
use ethercrab::SubDeviceRef;
use hil_sim::esc::{Esc, EscConfig};
use hil_sim::sim::{FirmwareFlash, Node, SimFlash, Simulation};
use nanos::Nanos;
use std::cell::RefCell;
use std::time::Instant;

const FILE_LEN: usize = 256 * 1024;
const MAILBOX_LEN: usize = 256;
const SEGMENT: usize = MAILBOX_LEN - 12;

/// 2 × 66 sectors of 4 KiB, on the heap.
struct FwNode {
    esc: Esc,
    drive: Drive<SimFlash, FirmwareFlash>,
}

impl Node for FwNode {
    fn esc_mut(&mut self) -> &mut Esc {
        &mut self.esc
    }
    fn poll(&mut self, now: Nanos) {
        self.esc.tick(now);
        let _ = self.drive.poll(&mut self.esc.pdi(), now);
    }
}

struct Mbx {
    counter: u8,
}

impl Mbx {
    /// One FoE request, its reply (opcode, 32-bit field).
    async fn foe<S>(&mut self, sd: &SubDeviceRef<'_, S>, op: u8, field: u32, data: &[u8]) -> (u8, u32) {
        self.counter = self.counter % 7 + 1;
        let mut frame = [0u8; MAILBOX_LEN];
        let len = 6 + data.len();
        frame[0..2].copy_from_slice(&(len as u16).to_le_bytes());
        frame[5] = 4 | (self.counter << 4);
        frame[6] = op;
        frame[8..12].copy_from_slice(&field.to_le_bytes());
        frame[12..12 + data.len()].copy_from_slice(data);
        sd.register_write(0x1000u16, frame).await.expect("SM0");
        for _ in 0..50 {
            let status: u8 = sd.register_read(esc::regs::sm(1) + 5).await.expect("SM1 status");
            if status & esc::sm::status::MAILBOX_FULL != 0 {
                let r: [u8; MAILBOX_LEN] = sd.register_read(0x1100u16).await.expect("SM1");
                assert_eq!(r[5] & 0x0F, 4, "FoE reply");
                return (r[6], u32::from_le_bytes([r[8], r[9], r[10], r[11]]));
            }
        }
        panic!("no FoE reply");
    }
}

fn file(version: u32) -> Vec<u8> {
    let body = hil_sim::sim::firmware_body(FILE_LEN - IMAGE_HEADER_LEN, version);
    // signed with the development key for slot A, where the download goes
    // (the flash is empty); the drive verifies it at the end (issue 18)
    let seed = drive_ecat::boot::parse_key_hex(include_str!("../../keys/dev-ed25519.key")).expect("dev key");
    let load = BootSlots::new(FirmwareFlash::new()).load_address(drive_ecat::boot::Slot::A);
    let mut h = ImageHeader::for_body(&body, version, load, 1);
    h.sign(&body, &seed);
    let mut f = h.to_bytes().to_vec();
    f.extend_from_slice(&body);
    f
}

fn main() {
    let runs = line::runs_arg(3);
    let mut sii = [0u8; ecat::sii::EEPROM_BYTES];
    let n = ecat::build_sii(&drive_ecat::DEVICE, &mut sii).expect("SII");
    let mut slots = BootSlots::new(FirmwareFlash::new());
    slots
        .boot_verified(&drive_ecat::runtime::FIRMWARE_PUBLIC_KEY, 0)
        .expect("boot");
    let node = FwNode {
        esc: Esc::new(EscConfig::default(), &sii[..n]),
        drive: Drive::with_boot(SimFlash::new(), Some(slots)),
    };
    let sim = RefCell::new(Simulation::with_nodes(vec![node]));
    let image = file(2);
    let results = hil_sim::master::with_first_subdevice(&sim, async |sd, _clock| {
        for state in [1u16, 3] {
            sd.register_write(esc::regs::AL_CONTROL, state)
                .await
                .expect("AL control");
            let _: u16 = sd.register_read(esc::regs::AL_STATUS).await.expect("AL status");
        }
        let st: u16 = sd.register_read(esc::regs::AL_STATUS).await.expect("AL status");
        assert_eq!(st, 3, "Bootstrap");
        let mut mbx = Mbx { counter: 0 };
        let mut results = Vec::new();
        for _ in 0..runs {
            let (t0, f0) = {
                let s = sim.borrow();
                (s.now().as_ns(), s.frames())
            };
            let start = Instant::now();
            assert_eq!(mbx.foe(&sd, 2, 0, b"firmware.efw").await, (4, 0), "WRQ acked");
            let mut chunks: Vec<&[u8]> = image.chunks(SEGMENT).collect();
            if image.len() % SEGMENT == 0 {
                chunks.push(&[]);
            }
            for (i, c) in chunks.iter().enumerate() {
                let k = i as u32 + 1;
                assert_eq!(mbx.foe(&sd, 3, k, c).await, (4, k), "packet {k}");
            }
            let wall = start.elapsed();
            let s = sim.borrow();
            results.push((wall, s.now().as_ns() - t0, s.frames() - f0, chunks.len()));
        }
        results
    })
    .expect("the line's first SubDevice");
    {
        let mut s = sim.borrow_mut();
        let slots = s.drives_mut()[0].drive.boot_slots_mut().expect("slots");
        let state = slots.state(slots.inactive()).expect("state");
        assert!(
            matches!(state, drive_ecat::boot::SlotState::Pending { .. }),
            "{state:?}"
        );
    }
    println!("FoE download of a {FILE_LEN}-byte image file, mailbox {MAILBOX_LEN} bytes ({SEGMENT} data bytes per packet), {runs} runs");
    for (i, (wall, sim_ns, frames, packets)) in results.iter().enumerate() {
        println!(
            "run {}: {packets} packets, {frames} frames, {:.1} ms simulated, {:.0} KiB/s simulated time, {:.0} KiB/s wall clock ({:.0} ms)",
            i + 1,
            *sim_ns as f64 / 1e6,
            FILE_LEN as f64 / 1024.0 / (*sim_ns as f64 / 1e9),
            FILE_LEN as f64 / 1024.0 / wall.as_secs_f64(),
            wall.as_secs_f64() * 1e3,
        );
    }
}
