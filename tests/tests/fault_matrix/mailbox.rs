//! Faults at the mailbox: a master that stops reading it, requests into a
//! full mailbox, a master restarted during a segmented SDO download and
//! during an FoE download.

use super::{advance, ethercrab};
use drive_ecat::boot::{Slot, SlotState};
use drive_tests::matrix::al;
use drive_tests::{
    al_status, fault_row, firmware_file, in_boot, init, line, to_boot, with_master, with_preop, with_sdo,
    CoeClient, Cyclic, FoeClient, FoeReply, FwNode, RawMailbox, MAILBOX_LEN, REV,
};
use hil_sim::sim::Simulation;
use std::cell::RefCell;

const E72: u16 = drive_ecat::parameter_index(4, 72);

/// A CoE SDO upload request of `index`:`sub` as one SM0 buffer with
/// mailbox counter `counter`.
fn upload_request(counter: u8, index: u16, sub: u8) -> [u8; MAILBOX_LEN] {
    let mut f = [0u8; MAILBOX_LEN];
    f[0] = 10; // mailbox data length
    f[5] = (counter << 4) | 3; // CoE
    let [i0, i1] = index.to_le_bytes();
    f[6..16].copy_from_slice(&[0x00, 0x20, 0x40, i0, i1, sub, 0, 0, 0, 0]);
    f
}

/// One mailbox message as the master read it: "SDO 1018h:02 = 00000001h",
/// "EMCY FF09h/01h event 44 cause 1", or its type.
fn describe(kind: u8, data: &[u8]) -> String {
    let service = u16::from_le_bytes([data[0], data[1]]) >> 12;
    match (kind, service) {
        (3, 3) if data[2] & 0xE0 == 0x40 => format!(
            "SDO {:04X}h:{:02X} = {:08X}h",
            u16::from_le_bytes([data[3], data[4]]),
            data[5],
            u32::from_le_bytes([data[6], data[7], data[8], data[9]])
        ),
        (3, 3) if data[2] == 0x80 => format!(
            "SDO abort {:08X}h",
            u32::from_le_bytes([data[6], data[7], data[8], data[9]])
        ),
        (3, 1) => drive_tests::matrix::emcys(&[data[2..10].to_vec()]),
        _ => format!("type {kind} service {service}"),
    }
}

#[test]
fn e062_e094_a_master_that_stops_reading_the_mailbox_loses_nothing() {
    let row = ethercrab(
        "21",
        "the master sends an SDO upload, then reads no mailbox for 2 s while axis A faults \
         (external fault, event 44); process data goes on",
        "E-062, E-094",
        "Op, AL 0000h; 2000 of 2000 cycles with WKC 3 while the mailbox went unread; then, in \
         order: SDO 1018h:02 = the product code; EMCY FF09h/01h event 44 cause 1; nothing more",
    );
    let sim = line(1);
    let seen = with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let product: u32 = group.subdevice(md, 0).unwrap().sdo_read(0x1018, 2).await.unwrap();
        let group = group.into_op(md).await.expect("OP");
        let sd = group.subdevice(md, 0).unwrap();
        let mut m = Cyclic::new(md, &group, &sim, 0);
        m.csv_at(REV, 100).await;
        let mut mbx = RawMailbox::new();
        mbx.send_raw(&sd, upload_request(1, 0x1018, 2)).await;
        sim.borrow_mut().drives_mut()[0].drive.axes_mut()[0]
            .raise_event(motion::Event { number: 44, cause: 1 });
        let mut full = 0;
        for _ in 0..2000 {
            sd.outputs_raw_mut().copy_from_slice(&m.out);
            advance(&sim, 1_000_000);
            if group.tx_rx(md).await.unwrap().working_counter == 3 {
                full += 1;
            }
        }
        let mut got = Vec::new();
        while let Some((kind, data)) = mbx.receive(&sd).await {
            got.push(describe(kind, &data).replace(&format!("{product:08X}h"), "the product code"));
            if got.len() > 8 {
                break;
            }
        }
        got.push("nothing more".into());
        format!(
            "{}; {full} of 2000 cycles with WKC 3 while the mailbox went unread; then, in order: {}",
            al(al_status(&sd).await),
            got.join("; ")
        )
    });
    fault_row!(row, seen);
}

#[test]
fn e027_requests_into_a_full_mailbox_are_refused_and_nothing_is_lost() {
    let row = ethercrab(
        "22",
        "the master writes six SDO uploads (1018h:01…04, 01, 02) back to back without reading an \
         answer, then reads and repeats each refused write",
        "E-027",
        "writes: taken, taken, taken, refused, refused, refused (WKC 0: SM0 still full); then, in \
         order: SDO 1018h:01 = the vendor; SDO 1018h:02 = the product code; SDO 1018h:03 = the \
         revision; SDO 1018h:04 = the serial number; SDO 1018h:01 = the vendor; SDO 1018h:02 = \
         the product code; nothing more; Pre-Op, AL 0000h",
    );
    let sim = line(1);
    let seen = with_sdo(&sim, async |sd, _| {
        let mut names = Vec::new();
        for (sub, name) in [
            (1u8, "the vendor"),
            (2, "the product code"),
            (3, "the revision"),
            (4, "the serial number"),
        ] {
            let v: u32 = sd.sdo_read(0x1018, sub).await.unwrap();
            names.push((
                format!("SDO 1018h:{sub:02X} = {v:08X}h"),
                format!("SDO 1018h:{sub:02X} = {name}"),
            ));
        }
        // a fresh counter sequence (ethercrab used its own)
        CoeClient::new().hand_over(sd).await;
        let requests: Vec<_> = (1u8..=6)
            .map(|k| upload_request(k % 7 + 1, 0x1018, 1 + (k - 1) % 4))
            .collect();
        let mut writes = Vec::new();
        let mut refused = std::collections::VecDeque::new();
        for r in &requests {
            if sd.register_write(0x1000u16, *r).await.is_ok() {
                writes.push("taken");
            } else {
                writes.push("refused");
                refused.push_back(*r);
            }
        }
        let mut mbx = RawMailbox::new();
        let mut got = Vec::new();
        while let Some((kind, data)) = mbx.receive(sd).await {
            let mut d = describe(kind, &data);
            for (raw, name) in &names {
                d = d.replace(raw.as_str(), name.as_str());
            }
            got.push(d);
            // SM1 read: SM0 may take the next refused request now
            if let Some(r) = refused.front() {
                if sd.register_write(0x1000u16, *r).await.is_ok() {
                    refused.pop_front();
                }
            }
            if got.len() > 12 {
                break;
            }
        }
        got.push("nothing more".into());
        let writes = writes.join(", ")
            + if writes.contains(&"refused") {
                " (WKC 0: SM0 still full)"
            } else {
                ""
            };
        format!(
            "writes: {writes}; then, in order: {}; {}",
            got.join("; "),
            al(al_status(sd).await)
        )
    });
    fault_row!(row, seen);
}

#[test]
fn e037_e065_a_master_restarted_during_a_segmented_download_leaves_the_object_as_it_was() {
    let row = ethercrab(
        "23",
        "the master restarts after the initiate and the first of three segments of a 16-byte \
         download of E72 (axis name)",
        "E-037, E-065",
        "the new master reads the old E72; its own segmented download is taken and reads back; \
         Pre-Op, AL 0000h",
    );
    let sim = line(1);
    let old = with_sdo(&sim, async |sd, c| {
        let old = c.upload(sd, E72, 0).await.unwrap();
        let [i0, i1] = E72.to_le_bytes();
        c.sdo(sd, &[0x21, i0, i1, 0, 16, 0, 0, 0])
            .await
            .expect("initiate");
        c.sdo(sd, b"\x00ABCDEFG").await.expect("segment 1");
        old
    });
    // the master process ended; another one starts on the same line
    let seen = with_sdo(&sim, async |sd, c| {
        c.hand_over(sd).await;
        let now = c.upload(sd, E72, 0).await.unwrap();
        let first = if now == old {
            "the new master reads the old E72".to_string()
        } else {
            format!("the new master reads E72 = {now:02x?}")
        };
        let ok = c
            .download_segmented(sd, E72, 0, b"after restart", false)
            .await
            .is_ok()
            && c.upload(sd, E72, 0).await == Ok(b"after restart".to_vec());
        format!(
            "{first}; its own segmented download is {}; {}",
            if ok { "taken and reads back" } else { "refused" },
            al(al_status(sd).await)
        )
    });
    fault_row!(row, seen);
}

fn node(sim: &RefCell<Simulation<FwNode>>) -> std::cell::RefMut<'_, FwNode> {
    std::cell::RefMut::map(sim.borrow_mut(), |s| &mut s.drives_mut()[0])
}

#[test]
fn e037_a_master_restarted_during_an_foe_download_keeps_the_running_image() {
    let row = ethercrab(
        "24",
        "the master restarts after 40 of 124 packets of an FoE firmware download",
        "E-037",
        "slot B not pending, image A runs; the new master's download is taken; slot B pending; \
         the next power-on starts B on trial",
    );
    let sim = RefCell::new(Simulation::with_nodes(vec![FwNode::factory(20_000)]));
    let file = firmware_file(2, 30_000);
    with_preop(&sim, async |sd| {
        to_boot(&sd).await;
        let mut foe = FoeClient::new();
        assert_eq!(foe.write_request(&sd, "firmware.efw").await, FoeReply::Ack(0));
        for (i, c) in file.chunks(FoeClient::SEGMENT).take(40).enumerate() {
            assert_eq!(foe.data(&sd, i as u32 + 1, c).await, FoeReply::Ack(i as u32 + 1));
        }
    });
    let interrupted = {
        let mut n = node(&sim);
        let b = n.slots().state(Slot::B).unwrap();
        let runs = n.slots().active();
        format!(
            "slot B {}, image {} runs",
            if matches!(b, SlotState::Pending { .. }) {
                "pending"
            } else {
                "not pending"
            },
            match runs {
                Some(Slot::A) => "A",
                Some(Slot::B) => "B",
                None => "none",
            }
        )
    };
    let r = in_boot(&sim, async |_, sd| {
        FoeClient::new().write_file(&sd, "firmware.efw", &file).await
    });
    let pending = matches!(
        node(&sim).slots().state(Slot::B).unwrap(),
        SlotState::Pending { .. }
    );
    node(&sim).power_cycle();
    let boot = node(&sim).boot.map(|d| (d.slot, d.trial));
    let seen = format!(
        "{interrupted}; the new master's download is {}; slot B {}; the next power-on starts {}",
        if r.is_ok() { "taken" } else { "refused" },
        if pending { "pending" } else { "not pending" },
        match boot {
            Some((Slot::B, true)) => "B on trial".to_string(),
            other => format!("{other:?}"),
        }
    );
    fault_row!(row, seen);
}
