//! FoE firmware update (`foe.rs`): a drive with firmware slots and an FoE client over
//! [`RawMailbox`] (ethercrab 0.7.1 has no FoE).

use crate::{al, al_status, init, request, with_master_on, RawMailbox, MAILBOX_LEN};
use ethercrab::{MainDevice, SubDeviceRef};
use hil_sim::sim::Simulation;
use nanos::Nanos;
use std::cell::RefCell;

/// The firmware flash of [`FwNode`] (hil-sim's).
pub use hil_sim::sim::FirmwareFlash as FwFlash;

/// The firmware slots of a [`FwNode`].
pub type FwSlots = drive_ecat::boot::BootSlots<FwFlash>;

/// The secret seed of the development key pair (`keys/dev-ed25519.key`),
/// whose public key the drive trusts in the simulator.
pub fn dev_seed() -> [u8; 32] {
    drive_ecat::boot::parse_key_hex(include_str!("../keys/dev-ed25519.key")).expect("keys/dev-ed25519.key")
}

/// The load address of `slot` of a [`FwNode`]'s firmware flash.
pub fn fw_load_address(slot: drive_ecat::boot::Slot) -> u32 {
    FwSlots::new(FwFlash::new()).load_address(slot)
}

/// An image file as the master downloads it: the signed header v2 (length,
/// CRC-32, `version`, the load address of slot B, security counter 1, the
/// development key's signature) and a body of `len` bytes derived from
/// `version`. Slot B is where a [`FwNode::factory`] drive downloads to.
pub fn firmware_file(version: u32, len: usize) -> Vec<u8> {
    signed_file(drive_ecat::boot::Slot::B, version, 1, len, &dev_seed())
}

/// [`firmware_file`] for `slot` with security counter `counter`, signed with `seed`.
pub fn signed_file(
    slot: drive_ecat::boot::Slot,
    version: u32,
    counter: u32,
    len: usize,
    seed: &[u8; 32],
) -> Vec<u8> {
    let body = hil_sim::sim::firmware_body(len, version);
    let mut h = drive_ecat::boot::ImageHeader::for_body(&body, version, fw_load_address(slot), counter);
    h.sign(&body, seed);
    let mut f = h.to_bytes().to_vec();
    f.extend_from_slice(&body);
    f
}

/// A drive with firmware slots behind a simulated ESC (communication only:
/// no motors). [`FwNode::power_cycle`] runs the boot decision again.
pub struct FwNode {
    /// The simulated ESC.
    pub esc: hil_sim::esc::Esc,
    /// The drive runtime with its firmware slots.
    pub drive: drive_ecat::runtime::Drive<hil_sim::sim::SimFlash, FwFlash>,
    /// What the last boot started.
    pub boot: Option<drive_ecat::boot::Decision>,
}

impl FwNode {
    /// Powers on with `param` (parameter flash) and `fw` (firmware flash):
    /// the boot decision, then the drive.
    pub fn power_on(param: hil_sim::sim::SimFlash, fw: FwFlash) -> Self {
        let mut slots = FwSlots::new(fw);
        let boot = slots
            .boot_verified(&drive_ecat::runtime::FIRMWARE_PUBLIC_KEY, 0)
            .expect("boot: read the slots");
        let mut sii = [0u8; ecat::sii::EEPROM_BYTES];
        let n = ecat::build_sii(&drive_ecat::DEVICE, &mut sii).expect("SII");
        Self {
            esc: hil_sim::esc::Esc::new(hil_sim::esc::EscConfig::default(), &sii[..n]),
            drive: drive_ecat::runtime::Drive::with_boot(param, Some(slots)),
            boot,
        }
    }

    /// A drive whose slot A holds a confirmed image of `factory_len` body
    /// bytes, version 1, security counter 1 (the firmware it was delivered with).
    pub fn factory(factory_len: usize) -> Self {
        let mut slots = FwSlots::new(FwFlash::new());
        slots.boot().expect("boot");
        slots.begin().expect("begin");
        let file = signed_file(drive_ecat::boot::Slot::A, 1, 1, factory_len, &dev_seed());
        slots.write(&file).expect("write");
        slots
            .finish_verified(&drive_ecat::runtime::FIRMWARE_PUBLIC_KEY)
            .expect("finish");
        let mut slots = FwSlots::new(slots.into_inner());
        slots.boot().expect("boot");
        slots.confirm().expect("confirm");
        Self::power_on(hil_sim::sim::SimFlash::new(), slots.into_inner())
    }

    /// Switches off and on: only the flashes stay; the boot decides anew.
    pub fn power_cycle(&mut self) {
        let old = std::mem::replace(
            self,
            Self {
                esc: hil_sim::esc::Esc::new(hil_sim::esc::EscConfig::default(), &[]),
                drive: drive_ecat::runtime::Drive::with_boot(hil_sim::sim::SimFlash::new(), None),
                boot: None,
            },
        );
        let (param, fw) = old.drive.into_flashes();
        *self = Self::power_on(param.expect("parameter flash"), fw.expect("firmware flash"));
    }

    /// The firmware slots.
    pub fn slots(&mut self) -> &mut FwSlots {
        self.drive.boot_slots_mut().expect("slots")
    }
}

impl hil_sim::sim::Node for FwNode {
    fn esc_mut(&mut self) -> &mut hil_sim::esc::Esc {
        &mut self.esc
    }
    fn poll(&mut self, now: Nanos) {
        self.esc.tick(now);
        let _ = self.drive.poll(&mut self.esc.pdi(), now);
        if self.drive.restart_due(now) {
            // A09: the device restarts as after a power cycle
            self.power_cycle();
        }
    }
}

/// Pre-Op (ethercrab's init) → Init → Bootstrap.
pub async fn to_boot<S>(sd: &SubDeviceRef<'_, S>) {
    request(sd, al::INIT).await;
    assert_eq!(al_status(sd).await, (al::INIT, 0));
    request(sd, al::BOOT).await;
    assert_eq!(al_status(sd).await, (al::BOOT, 0), "Init -> Bootstrap");
}

/// Runs `body` against the first drive in Bootstrap (and requests Init afterwards).
pub fn in_boot<N: hil_sim::sim::Node, T>(
    sim: &RefCell<Simulation<N>>,
    body: impl for<'a> AsyncFnOnce(&'a MainDevice<'a>, SubDeviceRef<'a, &'a ethercrab::SubDevice>) -> T,
) -> T {
    with_master_on(sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        to_boot(&sd).await;
        let r = body(md, sd).await;
        // back to Init (what a master does after the download)
        request(&group.subdevice(md, 0).unwrap(), al::INIT).await;
        r
    })
}

/// An FoE reply as the client sees it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FoeReply {
    /// ACK with the packet number.
    Ack(u32),
    /// ERROR with the code.
    Error(u32),
    /// BUSY (done, entire).
    Busy(u16, u16),
    /// Something else: mailbox type and data.
    Other(u8, Vec<u8>),
    /// No reply.
    None,
}

/// An FoE client (ETG.1000.6 §5.8) over [`RawMailbox`]: write requests and
/// data packets of `MAILBOX_LEN − 12` bytes.
#[derive(Default)]
pub struct FoeClient {
    mbx: RawMailbox,
    /// BUSY replies seen.
    pub busy: u32,
}

impl FoeClient {
    /// Data bytes per full DATA packet.
    pub const SEGMENT: usize = MAILBOX_LEN - 12;

    /// A fresh client.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sends one FoE message: opcode, the 32-bit field, then `data`.
    pub async fn send<S>(&mut self, sd: &SubDeviceRef<'_, S>, op: u8, field: u32, data: &[u8]) -> FoeReply {
        let mut req = vec![op, 0];
        req.extend_from_slice(&field.to_le_bytes());
        req.extend_from_slice(data);
        match self.mbx.exchange(sd, 4, &req).await {
            Some((4, r)) if r.len() >= 6 => {
                let field = u32::from_le_bytes([r[2], r[3], r[4], r[5]]);
                match r[0] {
                    4 => FoeReply::Ack(field),
                    5 => FoeReply::Error(field),
                    6 => FoeReply::Busy(field as u16, (field >> 16) as u16),
                    _ => FoeReply::Other(4, r),
                }
            }
            Some((kind, r)) => FoeReply::Other(kind, r),
            None => FoeReply::None,
        }
    }

    /// Write request for `name`.
    pub async fn write_request<S>(&mut self, sd: &SubDeviceRef<'_, S>, name: &str) -> FoeReply {
        self.send(sd, 2, 0, name.as_bytes()).await
    }

    /// DATA packet `n` (a BUSY reply is retried with the same packet).
    pub async fn data<S>(&mut self, sd: &SubDeviceRef<'_, S>, n: u32, data: &[u8]) -> FoeReply {
        loop {
            match self.send(sd, 3, n, data).await {
                FoeReply::Busy(..) => self.busy += 1,
                r => return r,
            }
        }
    }

    /// Writes the whole file: write request, DATA packets 1, 2, … (an empty
    /// last one when the length is a multiple of [`Self::SEGMENT`]). Returns
    /// the packets sent, or the first reply that is not the expected ACK.
    pub async fn write_file<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        name: &str,
        file: &[u8],
    ) -> Result<u32, FoeReply> {
        match self.write_request(sd, name).await {
            FoeReply::Ack(0) => {}
            r => return Err(r),
        }
        let mut chunks: Vec<&[u8]> = file.chunks(Self::SEGMENT).collect();
        if file.len() % Self::SEGMENT == 0 {
            chunks.push(&[]);
        }
        for (i, c) in chunks.iter().enumerate() {
            let n = i as u32 + 1;
            match self.data(sd, n, c).await {
                FoeReply::Ack(a) if a == n => {}
                r => return Err(r),
            }
        }
        Ok(chunks.len() as u32)
    }
}
