//! PDO channels through a real master (spec §5.1, E-051…E-053): the default
//! channels per axis, the FSoE channel kept from users, and four channels per
//! direction in Op at once.

use drive_tests::al::OP;
use drive_tests::{al_status, init, line, map_pdo, with_master, with_sdo, CoeClient};
use ecat::SdoAbort;

/// Mapping entry: index << 16 | sub << 8 | bit length.
const fn m(index: u16, sub: u8, bits: u8) -> u32 {
    (index as u32) << 16 | (sub as u32) << 8 | bits as u32
}

/// Axis B's index of axis A's object `ia`: CiA 402 objects +800h (6000h…67FFh →
/// 6800h…6FFFh), manufacturer parameters (2000h…5FFFh) +8000h.
fn axis_b(ia: u16) -> u16 {
    if ia >= 0x6000 {
        ia + 0x800
    } else {
        ia + 0x8000
    }
}

/// E-051: channel 1 (1600h/1A00h) carries axis A, channel 2 (1601h/1A01h)
/// the same objects of axis B. Channel 1 is assigned by default (1C12h/1C13h
/// sub 0 = 1, docs/conformance.md "Decisions"); the ESI offers channel 2 as
/// the optional PDO a master assigns when it drives axis B, which takes it
/// as sub 2.
#[test]
fn e051_channel_1_is_axis_a_and_channel_2_axis_b() {
    if !drive_tests::has_axis_b("e051: channel 2 carries axis B") {
        return;
    }
    let sim = line(1);
    with_sdo(&sim, async |sd, _| {
        for (a, b) in [(0x1600u16, 0x1601u16), (0x1A00, 0x1A01)] {
            let n = sd.sdo_read::<u8>(a, 0).await.unwrap();
            assert!(n > 0, "{a:04X}h has a default mapping");
            assert_eq!(
                sd.sdo_read::<u8>(b, 0).await.unwrap(),
                n,
                "{b:04X}h as many entries"
            );
            for s in 1..=n {
                let ea = sd.sdo_read::<u32>(a, s).await.unwrap();
                let eb = sd.sdo_read::<u32>(b, s).await.unwrap();
                let (ia, ib) = ((ea >> 16) as u16, (eb >> 16) as u16);
                assert!(
                    (0x6000..0x6800).contains(&ia) || (0x2000..0x6000).contains(&ia),
                    "{a:04X}h:{s} = {ea:08X}h is axis A"
                );
                assert_eq!(ib, axis_b(ia), "{b:04X}h:{s} = {eb:08X}h is axis B's {ia:04X}h");
                assert_eq!(eb & 0xFFFF, ea & 0xFFFF, "same sub and length");
            }
        }
        for (assign, first) in [(0x1C12u16, 0x1600u16), (0x1C13, 0x1A00)] {
            assert_eq!(sd.sdo_read::<u8>(assign, 0).await.unwrap(), 1, "{assign:04X}h:00");
            assert_eq!(sd.sdo_read::<u16>(assign, 1).await.unwrap(), first);
            sd.sdo_write(assign, 0, 0u8).await.unwrap();
            sd.sdo_write(assign, 2, first + 1).await.unwrap();
            sd.sdo_write(assign, 0, 2u8).await.expect("channel 2 assigned");
            assert_eq!(sd.sdo_read::<u16>(assign, 2).await.unwrap(), first + 1);
        }
    });
}

/// E-052: channel 4 (1603h/1A03h) is the FSoE channel the drive sets up
/// itself: a master's write to its mapping is refused with 0601 0002h
/// (read only) and changes nothing; it stays empty without a safety module.
#[test]
fn e052_channel_4_mapping_is_refused_to_the_master() {
    let sim = line(1);
    with_sdo(&sim, async |sd, c| {
        for (pdo, entry) in [(0x1603u16, m(0x6040, 0, 16)), (0x1A03, m(0x6041, 0, 16))] {
            assert_eq!(
                c.download(sd, pdo, 0, &[0]).await,
                Err(SdoAbort::READ_ONLY.0),
                "{pdo:04X}h:00"
            );
            assert_eq!(
                c.download(sd, pdo, 1, &entry.to_le_bytes()).await,
                Err(SdoAbort::READ_ONLY.0),
                "{pdo:04X}h:01"
            );
            assert_eq!(c.upload(sd, pdo, 0).await, Ok(vec![0]), "{pdo:04X}h stays empty");
            assert_eq!(c.upload(sd, pdo, 1).await, Ok(vec![0; 4]));
        }
    });
}

/// E-053: four channels per direction run at once, one PDO each: channel 3
/// (1602h/1A02h) mapped by the master beside the two axis channels, the
/// (empty) FSoE channel assigned too (1C12h/1C13h sub 0 = 4). In Op the
/// master's process image is the four PDOs back to back, and channel 3's
/// output reaches its object. A 25th entry is refused (0604 0042h).
#[test]
fn e053_four_channels_per_direction_in_op_at_once() {
    if !drive_tests::has_axis_b("e053: axis B in channel 2") {
        return;
    }
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        let mut bytes = [0usize; 2];
        for (i, pdo) in [0x1600u16, 0x1A00].into_iter().enumerate() {
            let n = sd.sdo_read::<u8>(pdo, 0).await.unwrap();
            for s in 1..=n {
                bytes[i] += (sd.sdo_read::<u32>(pdo, s).await.unwrap() & 0xFF) as usize / 8;
            }
        }
        let [rx1, tx1] = bytes;
        // channel 3: profile velocity (6081h) out, statusword and position actual in
        map_pdo(&sd, 0x1602, &[m(0x6081, 0, 32)]).await;
        map_pdo(&sd, 0x1A02, &[m(0x6041, 0, 16), m(0x6064, 0, 32)]).await;
        // all four channels assigned
        for (assign, first) in [(0x1C12u16, 0x1600u16), (0x1C13, 0x1A00)] {
            sd.sdo_write(assign, 0, 0u8).await.unwrap();
            for s in 1..=4u8 {
                sd.sdo_write(assign, s, first + u16::from(s) - 1).await.unwrap();
            }
            sd.sdo_write(assign, 0, 4u8).await.expect("four PDOs assigned");
        }
        // at most 24 entries per PDO
        let mut c = CoeClient::new();
        assert_eq!(
            c.download(&sd, 0x1602, 0, &[25]).await,
            Err(SdoAbort::PDO_LENGTH.0)
        );
        let group = group.into_op(md).await.expect("PRE-OP -> OP with four channels");
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(al_status(&sd).await, (OP, 0));
        {
            let io = sd.io_raw();
            assert_eq!(io.outputs().len(), 2 * rx1 + 4, "channels 1 + 2 + 3 (+ empty 4)");
            assert_eq!(io.inputs().len(), 2 * tx1 + 6, "channels 1 + 2 + 3 (+ empty 4)");
        }
        {
            let mut out = sd.outputs_raw_mut();
            out[2 * rx1..2 * rx1 + 4].copy_from_slice(&0x0001_2345u32.to_le_bytes());
        }
        for _ in 0..10 {
            let r = group.tx_rx(md).await.expect("cycle");
            assert_eq!(r.working_counter, 3);
        }
        assert_eq!(
            sd.sdo_read::<u32>(0x6081, 0).await.unwrap(),
            0x0001_2345,
            "channel 3's output reached 6081h"
        );
        // channel 3's input: the statusword, as in channel 1
        let io = sd.io_raw();
        let inputs = io.inputs();
        assert_eq!(
            &inputs[2 * tx1..2 * tx1 + 2],
            &inputs[0..2],
            "statusword in channels 1 and 3"
        );
        assert_eq!(al_status(&sd).await, (OP, 0), "still Op");
    });
}

/// E-148: F050h (sub 0 = 2) reports the module ident of the PDO
/// configuration each axis's channel carries, the ident of the ESI module
/// that describes it (E-149): the system module of the standard layout on
/// both axes by default, axis B's with its own ident, the ip module after a
/// master puts the ip maps into channel 1 (and axis B's ip module after it
/// puts axis B's into channel 2), a user module (bit 31, the same ident for
/// the same configuration) for any other mapping, 0 for an empty channel.
/// The master cannot write it (0601 0002h).
#[test]
fn e148_f050_reports_the_module_ident_per_axis() {
    if !drive_tests::has_axis_b(
        "e148: F050h:02 for axis B (tests/tests/single_axis.rs checks the single-axis F050h)",
    ) {
        return;
    }
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        let standard = drive_ecat::module_ident(drive_ecat::PdoLayout::Standard, 0);
        let standard_b = drive_ecat::module_ident(drive_ecat::PdoLayout::Standard, 1);
        let ip = drive_ecat::module_ident(drive_ecat::PdoLayout::Ip, 0);
        assert_ne!(standard, standard_b, "axis B's modules have their own idents");
        assert_eq!(sd.sdo_read::<u8>(0xF050, 0).await.unwrap(), 2);
        assert_eq!(sd.sdo_read::<u32>(0xF050, 1).await.unwrap(), standard, "axis A");
        assert_eq!(sd.sdo_read::<u32>(0xF050, 2).await.unwrap(), standard_b, "axis B");
        let remap = async |pdo: u16, entries: &[u32]| {
            sd.sdo_write(pdo, 0, 0u8).await.unwrap();
            for (s, e) in (1u8..).zip(entries) {
                sd.sdo_write(pdo, s, *e).await.unwrap();
            }
            sd.sdo_write(pdo, 0, entries.len() as u8).await.unwrap();
        };
        // the ip layout (cia402.md §6.5.1) in channel 1
        let (rx, tx) = drive_ecat::PdoLayout::Ip.entries();
        let rx: Vec<u32> = rx.iter().map(|e| e.mapping_value()).collect();
        let tx: Vec<u32> = tx.iter().map(|e| e.mapping_value()).collect();
        remap(0x1600, &rx).await;
        remap(0x1A00, &tx).await;
        assert_eq!(sd.sdo_read::<u32>(0xF050, 1).await.unwrap(), ip, "axis A in ip");
        assert_eq!(
            sd.sdo_read::<u32>(0xF050, 2).await.unwrap(),
            standard_b,
            "axis B unchanged"
        );
        // axis B's ip layout (objects at +800h) in channel 2
        let (rx_b, tx_b) = drive_ecat::PdoLayout::Ip.axis_entries(1);
        let rx_b: Vec<u32> = rx_b.iter().map(|e| e.mapping_value()).collect();
        let tx_b: Vec<u32> = tx_b.iter().map(|e| e.mapping_value()).collect();
        remap(0x1601, &rx_b).await;
        remap(0x1A01, &tx_b).await;
        assert_eq!(
            sd.sdo_read::<u32>(0xF050, 2).await.unwrap(),
            drive_ecat::module_ident(drive_ecat::PdoLayout::Ip, 1),
            "axis B in ip"
        );
        assert_eq!(
            sd.sdo_read::<u32>(0xF050, 1).await.unwrap(),
            ip,
            "axis A unchanged"
        );
        // a user configuration
        remap(0x1A00, &[m(0x6041, 0, 16), m(0x606C, 0, 32)]).await;
        let user = sd.sdo_read::<u32>(0xF050, 1).await.unwrap();
        assert_eq!(
            user & drive_ecat::USER_MODULE,
            drive_ecat::USER_MODULE,
            "{user:08X}h is a user module"
        );
        remap(0x1A00, &[m(0x6041, 0, 16), m(0x6064, 0, 32)]).await;
        let other = sd.sdo_read::<u32>(0xF050, 1).await.unwrap();
        assert_ne!(other, user, "another configuration, another ident");
        remap(0x1A00, &[m(0x6041, 0, 16), m(0x606C, 0, 32)]).await;
        assert_eq!(
            sd.sdo_read::<u32>(0xF050, 1).await.unwrap(),
            user,
            "the same again"
        );
        // axis B's channel emptied
        remap(0x1601, &[]).await;
        remap(0x1A01, &[]).await;
        assert_eq!(
            sd.sdo_read::<u32>(0xF050, 2).await.unwrap(),
            0,
            "no module on axis B"
        );
        let mut c = CoeClient::new();
        assert_eq!(
            c.download(&sd, 0xF050, 1, &ip.to_le_bytes()).await,
            Err(SdoAbort::READ_ONLY.0)
        );
        // (read with the same client: ethercrab's own mailbox counter no longer matches)
        assert_eq!(
            c.upload(&sd, 0xF050, 1).await,
            Ok(user.to_le_bytes().to_vec()),
            "unchanged"
        );
    });
}
