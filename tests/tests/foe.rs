//! FoE firmware update through a real master's frames (issue 8): Bootstrap
//! through Init only, the download of an image into the inactive slot, its
//! CRC check, the switch at the next power-on, confirmation and rollback, a
//! cut connection, FoE errors. Signed images (issue 18): a changed body or
//! header, another key, a wrong load address or a lower security counter are
//! refused through the real FoE path. ethercrab has no FoE: the FoE packets
//! go through [`drive_tests::RawMailbox`] ([`FoeClient`]).

use drive_ecat::boot::{ImageHeader, IMAGE_HEADER_LEN};
use drive_ecat::boot::{Slot, SlotState};
use drive_tests::al::{ACK, BOOT, ERR, INIT, PREOP};
use drive_tests::{
    al_status, dev_seed, firmware_file, in_boot, request, signed_file, to_boot, with_preop, FoeClient,
    FoeReply, FwNode, RawMailbox,
};
use ecat::foe::{FoeError, FOE_TIMEOUT};
use ecat::mailbox::MailboxError;
use hil_sim::sim::Simulation;
use std::cell::RefCell;

/// The image file the tests download: 256 KiB in all (header + body).
const IMAGE_FILE_LEN: usize = 256 * 1024;
/// Body of the factory image in slot A.
const FACTORY_LEN: usize = 20_000;

fn line() -> RefCell<Simulation<FwNode>> {
    RefCell::new(Simulation::with_nodes(vec![FwNode::factory(FACTORY_LEN)]))
}

fn node(sim: &RefCell<Simulation<FwNode>>) -> std::cell::RefMut<'_, FwNode> {
    std::cell::RefMut::map(sim.borrow_mut(), |s| &mut s.drives_mut()[0])
}

fn power_cycle(sim: &RefCell<Simulation<FwNode>>) {
    node(sim).power_cycle();
}

#[test]
fn e022_e023_bootstrap_only_through_init_when_foe_is_declared() {
    let sim = line();
    with_preop(&sim, async |sd| {
        // Pre-Op -> Bootstrap: an invalid change (0011h), not "not supported"
        request(&sd, BOOT).await;
        assert_eq!(al_status(&sd).await, (PREOP | ERR, 0x0011));
        request(&sd, INIT | ACK).await;
        assert_eq!(al_status(&sd).await, (INIT, 0));
        request(&sd, BOOT).await;
        assert_eq!(al_status(&sd).await, (BOOT, 0), "Init -> Bootstrap");
        // Bootstrap -> Pre-Op (and up): only through Init
        for to in [PREOP, 4, 8] {
            request(&sd, to).await;
            assert_eq!(al_status(&sd).await, (BOOT | ERR, 0x0011), "Boot -> {to}");
            request(&sd, BOOT | ACK).await;
            assert_eq!(al_status(&sd).await, (BOOT, 0));
        }
        // in Bootstrap the mailbox carries FoE only: CoE gets 0002h
        let mut mbx = RawMailbox::new();
        let resp = mbx
            .exchange(&sd, 3, &[0x00, 0x20, 0x40, 0x00, 0x10, 0, 0, 0, 0, 0])
            .await
            .expect("a reply");
        assert_eq!(resp.0, 0, "mailbox error");
        assert_eq!(
            u16::from_le_bytes([resp.1[2], resp.1[3]]),
            MailboxError::UNSUPPORTED_PROTOCOL.0
        );
        request(&sd, INIT).await;
        assert_eq!(al_status(&sd).await, (INIT, 0), "Bootstrap -> Init");
        request(&sd, PREOP).await;
        assert_eq!(al_status(&sd).await, (PREOP, 0));
    });
}

#[test]
fn foe_256k_image_switches_on_next_power_cycle_and_confirms() {
    let sim = line();
    assert_eq!(node(&sim).boot.map(|d| d.slot), Some(Slot::A));
    let file = firmware_file(2, IMAGE_FILE_LEN - drive_ecat::boot::IMAGE_HEADER_LEN);
    assert_eq!(file.len(), IMAGE_FILE_LEN);
    let packets = download(&sim, "firmware.efw", &file).expect("download accepted");
    assert_eq!(packets as usize, IMAGE_FILE_LEN / FoeClient::SEGMENT + 1);
    {
        let mut n = node(&sim);
        assert_eq!(n.slots().active(), Some(Slot::A), "still running A");
        assert_eq!(n.slots().state(Slot::B).unwrap(), SlotState::Pending { seq: 2 });
        assert_eq!(n.slots().header(Slot::B).unwrap().map(|h| h.version), Some(2));
    }
    // the next power-on starts B on trial; it confirms itself
    power_cycle(&sim);
    {
        let mut n = node(&sim);
        let d = n.boot.expect("a slot starts");
        assert_eq!((d.slot, d.trial), (Slot::B, true));
        assert!(n.drive.confirm_firmware());
        assert_eq!(n.slots().state(Slot::B).unwrap(), SlotState::Confirmed { seq: 2 });
    }
    power_cycle(&sim);
    let d = node(&sim).boot.expect("a slot starts");
    assert_eq!((d.slot, d.trial, d.rolled_back), (Slot::B, false, None));
    // the updated drive still works on the bus
    with_preop(&sim, async |sd| {
        assert_eq!(al_status(&sd).await, (PREOP, 0));
    });
}

#[test]
fn foe_unconfirmed_image_rolls_back_at_the_next_boot() {
    let sim = line();
    let file = firmware_file(2, 5000);
    download(&sim, "firmware", &file).unwrap();
    power_cycle(&sim);
    assert_eq!(node(&sim).boot.map(|d| (d.slot, d.trial)), Some((Slot::B, true)));
    // no confirmation (the new image did not come up): back to A
    power_cycle(&sim);
    let d = node(&sim).boot.unwrap();
    assert_eq!((d.slot, d.trial, d.rolled_back), (Slot::A, false, Some(Slot::B)));
}

#[test]
fn foe_corrupt_image_is_rejected_and_the_old_slot_stays_active() {
    let sim = line();
    let mut file = firmware_file(2, 30_000);
    file[12_345] ^= 0x01; // one bit of the body: the CRC no longer matches
    let r = download(&sim, "firmware.efw", &file);
    assert_eq!(
        r,
        Err(FoeReply::Error(FoeError::CHECKSUM.0)),
        "800Ch on the last packet"
    );
    assert_eq!(node(&sim).slots().state(Slot::B).unwrap(), SlotState::Empty);
    power_cycle(&sim);
    let d = node(&sim).boot.unwrap();
    assert_eq!((d.slot, d.trial), (Slot::A, false));
    // a file that is not an image at all: 8004h at the header
    let r = download(&sim, "firmware.efw", &[0x55; 1000]);
    assert_eq!(r, Err(FoeReply::Error(FoeError::ILLEGAL.0)));
}

#[test]
fn foe_cut_connection_times_out_and_the_slot_is_not_pending() {
    let sim = line();
    let file = firmware_file(2, 100_000);
    in_boot(&sim, async |_, sd| {
        let mut foe = FoeClient::new();
        assert_eq!(foe.write_request(&sd, "firmware.efw").await, FoeReply::Ack(0));
        for (i, c) in file.chunks(FoeClient::SEGMENT).take(100).enumerate() {
            assert_eq!(foe.data(&sd, i as u32 + 1, c).await, FoeReply::Ack(i as u32 + 1));
        }
        // the cable is cut: no packet for longer than the timeout
        let t = sim.borrow().now().as_ns();
        sim.borrow_mut()
            .advance_to(nanos::Nanos::from_ns(t + FOE_TIMEOUT.as_ns() + 1_000_000));
        {
            let mut n = node(&sim);
            assert_eq!(n.drive.slave().foe().timeouts(), 1, "transfer dropped");
            assert!(!n.drive.slave().foe().busy());
            assert!(!n.slots().downloading());
        }
        // the master comes back and continues: no transfer any more
        assert_eq!(
            foe.data(
                &sd,
                101,
                &file[100 * FoeClient::SEGMENT..101 * FoeClient::SEGMENT]
            )
            .await,
            FoeReply::Error(FoeError::ILLEGAL.0)
        );
    });
    assert_eq!(node(&sim).slots().state(Slot::B).unwrap(), SlotState::Empty);
    power_cycle(&sim);
    let d = node(&sim).boot.unwrap();
    assert_eq!((d.slot, d.trial), (Slot::A, false), "the old image runs");
}

#[test]
fn foe_write_outside_bootstrap_is_refused_with_8008() {
    let sim = line();
    with_preop(&sim, async |sd| {
        assert_eq!(al_status(&sd).await, (PREOP, 0));
        let mut foe = FoeClient::new();
        assert_eq!(
            foe.write_request(&sd, "firmware.efw").await,
            FoeReply::Error(FoeError::BOOTSTRAP_ONLY.0)
        );
        // and no DATA without a write request
        assert_eq!(
            foe.data(&sd, 1, &[0; 10]).await,
            FoeReply::Error(FoeError::ILLEGAL.0)
        );
        // read requests: nothing to read
        assert_eq!(
            foe.send(&sd, 1, 0, b"firmware.efw").await,
            FoeReply::Error(FoeError::NOT_FOUND.0)
        );
    });
    assert!(!node(&sim).slots().downloading());
    assert_eq!(node(&sim).slots().state(Slot::B).unwrap(), SlotState::Empty);
}

#[test]
fn foe_wrong_packet_number_gets_8005_and_ends_the_transfer() {
    let sim = line();
    let file = firmware_file(2, 3000);
    in_boot(&sim, async |_, sd| {
        let mut foe = FoeClient::new();
        let seg = FoeClient::SEGMENT;
        assert_eq!(foe.write_request(&sd, "firmware.efw").await, FoeReply::Ack(0));
        assert_eq!(foe.data(&sd, 1, &file[..seg]).await, FoeReply::Ack(1));
        // packet 3 instead of 2
        assert_eq!(
            foe.data(&sd, 3, &file[seg..2 * seg]).await,
            FoeReply::Error(FoeError::PACKET_NUMBER.0)
        );
        // the transfer is over: the right number now is too late
        assert_eq!(
            foe.data(&sd, 2, &file[seg..2 * seg]).await,
            FoeReply::Error(FoeError::ILLEGAL.0)
        );
        // the same packet again (a repeat) is also a wrong number
        assert_eq!(foe.write_request(&sd, "firmware.efw").await, FoeReply::Ack(0));
        assert_eq!(foe.data(&sd, 1, &file[..seg]).await, FoeReply::Ack(1));
        assert_eq!(
            foe.data(&sd, 1, &file[..seg]).await,
            FoeReply::Error(FoeError::PACKET_NUMBER.0)
        );
        // other file names are not found
        assert_eq!(
            foe.write_request(&sd, "parameters.bin").await,
            FoeReply::Error(FoeError::NOT_FOUND.0)
        );
        // a complete download still works afterwards
        assert_eq!(foe.write_file(&sd, "firmware.efw", &file).await, Ok(13));
    });
    assert_eq!(
        node(&sim).slots().state(Slot::B).unwrap(),
        SlotState::Pending { seq: 2 }
    );
}

/// `hil-sim serve`'s drives ([`hil_sim::sim::SimDrive::with_firmware_slots`])
/// take an FoE download in Bootstrap into a slot (pending), and the next
/// power-on starts it on trial.
#[test]
fn foe_into_a_simulated_drive_with_firmware_slots() {
    let sim = RefCell::new(Simulation::with_nodes(vec![
        hil_sim::sim::SimDrive::with_firmware_slots(),
    ]));
    // both slots empty: the download goes to A
    let file = signed_file(Slot::A, 3, 1, 30_000, &dev_seed());
    with_preop(&sim, async |sd| {
        to_boot(&sd).await;
        FoeClient::new()
            .write_file(&sd, "firmware.efw", &file)
            .await
            .expect("download accepted");
        request(&sd, INIT).await;
    });
    let mut s = sim.borrow_mut();
    let d = &mut s.drives_mut()[0];
    let slots = d.drive.boot_slots_mut().expect("slots");
    let pending = [Slot::A, Slot::B]
        .into_iter()
        .find(|&sl| matches!(slots.state(sl), Ok(SlotState::Pending { .. })));
    let pending = pending.expect("the download is pending in a slot");
    assert_eq!(slots.header(pending).unwrap().map(|h| h.version), Some(3));
    d.power_cycle();
    let slots = d.drive.boot_slots_mut().expect("slots after power-on");
    assert_eq!(slots.active(), Some(pending), "the new image starts");
}

/// Writes `file` as `name` through FoE with the drive in Bootstrap: the
/// packets it took, or the drive's refusal.
fn download(sim: &RefCell<Simulation<FwNode>>, name: &str, file: &[u8]) -> Result<u32, FoeReply> {
    in_boot(sim, async |_, sd| {
        FoeClient::new().write_file(&sd, name, file).await
    })
}

/// Downloads `file` and checks it was refused with `code` and changed nothing:
/// slot B empty, the next power-on starts A as before.
fn refused(sim: &RefCell<Simulation<FwNode>>, what: &str, file: &[u8], code: FoeError) {
    let r = download(sim, "firmware.efw", file);
    assert_eq!(r, Err(FoeReply::Error(code.0)), "{what}");
    assert!(!node(sim).slots().downloading(), "{what}");
    assert_eq!(
        node(sim).slots().state(Slot::B).unwrap(),
        SlotState::Empty,
        "{what}: no VALID mark"
    );
    power_cycle(sim);
    let d = node(sim).boot.unwrap();
    assert_eq!((d.slot, d.trial, d.rolled_back), (Slot::A, false, None), "{what}");
}

#[test]
fn foe_signature_refuses_changed_images_other_keys_wrong_slots_and_downgrades() {
    let sim = line();
    let good = firmware_file(2, 20_000);
    let body = &good[IMAGE_HEADER_LEN..];
    // one flipped body byte: the CRC fails first (800Ch at the end)
    let mut flipped = good.clone();
    flipped[IMAGE_HEADER_LEN + 7_777] ^= 0x08;
    refused(&sim, "body byte", &flipped, FoeError::CHECKSUM);
    // the same body with its CRC mended: the signature fails (800Ch)
    let mut h = ImageHeader::parse(&flipped).unwrap();
    h.crc = drive_ecat::boot::crc32(&flipped[IMAGE_HEADER_LEN..]);
    flipped[..IMAGE_HEADER_LEN].copy_from_slice(&h.to_bytes());
    refused(&sim, "body byte, CRC mended", &flipped, FoeError::CHECKSUM);
    // one flipped header byte (the version): signature (800Ch)
    let mut header = good.clone();
    header[13] ^= 0x01;
    refused(&sim, "header byte", &header, FoeError::CHECKSUM);
    // signed with another key
    let other = signed_file(Slot::B, 2, 1, 20_000, &[0x5A; 32]);
    assert_eq!(&other[IMAGE_HEADER_LEN..], body);
    refused(&sim, "other key", &other, FoeError::CHECKSUM);
    // linked for slot A (the running one): 8004h at the header
    let for_a = signed_file(Slot::A, 2, 1, 20_000, &dev_seed());
    refused(&sim, "load address", &for_a, FoeError::ILLEGAL);
    // security counter 0 below the running image's 1: 800Ah at the header
    let old = signed_file(Slot::B, 2, 0, 20_000, &dev_seed());
    refused(&sim, "security counter", &old, FoeError::NO_RIGHTS);
    // an unsigned v1 file (16-byte header): 8004h
    let mut v1 = good[..16].to_vec();
    v1.extend_from_slice(body);
    refused(&sim, "v1 header", &v1, FoeError::ILLEGAL);
    // and the good file still goes in and starts
    download(&sim, "firmware.efw", &good).expect("taken");
    assert_eq!(
        node(&sim).slots().state(Slot::B).unwrap(),
        SlotState::Pending { seq: 2 }
    );
    power_cycle(&sim);
    let d = node(&sim).boot.unwrap();
    assert_eq!((d.slot, d.trial), (Slot::B, true));
}

#[test]
fn foe_signature_counter_floor_follows_the_running_image() {
    let sim = line();
    // counter 3 over the factory's 1: taken, started, confirmed
    let three = signed_file(Slot::B, 2, 3, 5_000, &dev_seed());
    download(&sim, "firmware", &three).expect("taken");
    power_cycle(&sim);
    assert!(node(&sim).drive.confirm_firmware());
    assert_eq!(node(&sim).slots().security_floor(), 3);
    // now an image with counter 2 for slot A is a downgrade; 3 is not
    let two = signed_file(Slot::A, 3, 2, 5_000, &dev_seed());
    let r = download(&sim, "firmware", &two);
    assert_eq!(r, Err(FoeReply::Error(FoeError::NO_RIGHTS.0)));
    let same = signed_file(Slot::A, 3, 3, 5_000, &dev_seed());
    download(&sim, "firmware", &same).expect("taken");
    assert_eq!(
        node(&sim).slots().state(Slot::A).unwrap(),
        SlotState::Pending { seq: 3 }
    );
}

/// E-019: new firmware takes effect at a restart, which A09 requests over
/// the bus: a downloaded image stays pending while the drive runs, and the
/// restart A09 asks for starts it on trial.
#[test]
fn e019_e140_a09_restart_starts_a_pending_firmware_image() {
    const A09: u16 = drive_ecat::parameter_index(0, 9);
    let sim = line();
    let file = firmware_file(2, 5000);
    download(&sim, "firmware", &file).unwrap();
    assert!(matches!(
        node(&sim).slots().state(Slot::B).unwrap(),
        SlotState::Pending { .. }
    ));
    with_preop(&sim, async |sd| {
        assert_eq!(node(&sim).boot.map(|d| d.slot), Some(Slot::A), "A runs");
        sd.sdo_write(A09, 1, 1u8).await.expect("A09[0] = 1");
    });
    let t = sim.borrow().now().as_ns();
    sim.borrow_mut().advance_to(nanos::Nanos::from_ns(
        t + drive_ecat::runtime::RESTART_DELAY.as_ns() + 1_000_000,
    ));
    let d = node(&sim).boot.expect("a slot starts");
    assert_eq!(
        (d.slot, d.trial),
        (Slot::B, true),
        "the restart started B on trial"
    );
}
