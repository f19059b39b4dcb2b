//! Process data through a real master (spec §5.4, E-032…E-035): the RxPDO a
//! master writes reaches the drive's objects in Op only, the TxPDO follows the
//! drive's objects in Safe-Op and Op, leaving Op falls back to the declared
//! defaults, and a remapped layout is decoded and encoded as mapped.

use drive_ecat::DriveObjects;
use drive_tests::al::{OP, SAFEOP};
use drive_tests::step::set;
use drive_tests::{al_status, init, line, map_pdo, with_master};
use ethercrab::subdevice_group::HasPdi;
use ethercrab::{DefaultLock, MainDevice, SubDeviceGroup};
use hil_sim::sim::Simulation;
use std::cell::RefCell;

/// Mapping entry: index << 16 | sub << 8 | bit length.
const fn m(index: u16, sub: u8, bits: u8) -> u32 {
    (index as u32) << 16 | (sub as u32) << 8 | bits as u32
}

/// Default RxPDO (spec §5.4): 6040h @0, 6060h @2, 607Ah @3, 60FFh @7, …, 60FEh:01 @19.
fn default_outputs(controlword: u16, mode: i8, target_position: i32) -> [u8; 23] {
    let mut out = [0u8; 23];
    out[0..2].copy_from_slice(&controlword.to_le_bytes());
    out[2] = mode as u8;
    out[3..7].copy_from_slice(&target_position.to_le_bytes());
    out[7..11].copy_from_slice(&(-5000i32).to_le_bytes()); // 60FFh target velocity
    out[19..23].copy_from_slice(&0x8000_0001u32.to_le_bytes()); // 60FEh:01
    out
}

/// `n` process-data frames of the master, the simulated time standing.
async fn frames<S: HasPdi>(md: &MainDevice<'_>, group: &SubDeviceGroup<8, 512, DefaultLock, S>, n: usize) {
    for _ in 0..n {
        group.tx_rx(md).await.expect("cycle");
    }
}

fn get(sim: &RefCell<Simulation>, index: u16, sub: u8) -> i64 {
    sim.borrow().drives()[0]
        .drive
        .objects()
        .get(index, sub)
        .unwrap_or_else(|e| panic!("{index:04X}h:{sub}: {e:?}"))
}

fn default_of(index: u16, sub: u8) -> i64 {
    DriveObjects::new().get(index, sub).unwrap()
}

/// The RxPDO set-points of the default map (not persistent): they fall back
/// to their declared defaults. 6060h (a parameter, A541) falls back to its
/// value before Op.
const RX_OBJECTS: [(u16, u8); 4] = [(0x6040, 0), (0x607A, 0), (0x60FF, 0), (0x60FE, 1)];

fn assert_rx_defaults(sim: &RefCell<Simulation>, what: &str) {
    for (index, sub) in RX_OBJECTS {
        assert_eq!(
            get(sim, index, sub),
            default_of(index, sub),
            "{index:04X}h:{sub} at its default ({what})"
        );
    }
}

#[test]
fn e034_op_rxpdo_set_values_reach_the_objects() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let group = group.into_op(md).await.expect("OP");
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(al_status(&sd).await, (OP, 0));
        sd.outputs_raw_mut()
            .copy_from_slice(&default_outputs(0x000F, 8, -123_456));
        frames(md, &group, 3).await;
        assert_eq!(get(&sim, 0x6040, 0), 0x000F, "controlword");
        assert_eq!(get(&sim, 0x6060, 0), 8, "modes of operation csp");
        assert_eq!(get(&sim, 0x607A, 0), -123_456, "target position, signed");
        assert_eq!(get(&sim, 0x60FF, 0), -5000, "target velocity");
        assert_eq!(get(&sim, 0x60FE, 1), 0x8000_0001, "digital outputs, unsigned");

        // every cycle is evaluated (E-034): the next value follows at once
        sd.outputs_raw_mut()[3..7].copy_from_slice(&7i32.to_le_bytes());
        frames(md, &group, 2).await;
        assert_eq!(get(&sim, 0x607A, 0), 7);
    });
}

#[test]
fn e032_e034_txpdo_follows_the_drives_objects_in_safeop_and_op() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let group = group.into_safe_op(md).await.expect("SAFE-OP");
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(al_status(&sd).await, (SAFEOP, 0));
        // default TxPDO: 6041h @0, 6061h @2, 6064h @3, 606Ch @7, 6077h @11
        set(&sim, 0x6041, 0, 0x0237);
        set(&sim, 0x6061, 0, -1);
        set(&sim, 0x6064, 0, -2_000_000);
        set(&sim, 0x6077, 0, -300);
        frames(md, &group, 3).await;
        {
            let io = sd.io_raw();
            let inputs = io.inputs();
            assert_eq!(inputs.len(), 29);
            assert_eq!(&inputs[0..2], &0x0237u16.to_le_bytes(), "statusword");
            assert_eq!(inputs[2], 0xFF, "modes of operation display -1");
            assert_eq!(&inputs[3..7], &(-2_000_000i32).to_le_bytes(), "position actual");
            assert_eq!(&inputs[11..13], &(-300i16).to_le_bytes(), "torque actual");
        }

        let group = group.into_op(md).await.expect("OP");
        let sd = group.subdevice(md, 0).unwrap();
        set(&sim, 0x6064, 0, 0x1234_5678);
        set(&sim, 0x606C, 0, -42);
        // within a cycle or two (the drive fills SM3 after the frame)
        frames(md, &group, 2).await;
        let io = sd.io_raw();
        let inputs = io.inputs();
        assert_eq!(&inputs[3..7], &0x1234_5678i32.to_le_bytes(), "position actual");
        assert_eq!(&inputs[7..11], &(-42i32).to_le_bytes(), "velocity actual");
        assert_eq!(&inputs[0..2], &0x0237u16.to_le_bytes(), "statusword kept");
    });
}

#[test]
fn e032_safeop_ignores_the_rxpdo() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let group = group.into_safe_op(md).await.expect("SAFE-OP");
        let sd = group.subdevice(md, 0).unwrap();
        sd.outputs_raw_mut()
            .copy_from_slice(&default_outputs(0x000F, 8, 99_999));
        set(&sim, 0x6064, 0, 555);
        frames(md, &group, 5).await;
        assert!(
            sim.borrow().drives()[0].drive.slave().outputs_received() > 0,
            "RxPDO frames did reach SM2"
        );
        assert_rx_defaults(&sim, "Safe-Op");
        assert_eq!(get(&sim, 0x6060, 0), default_of(0x6060, 0));
        // while the TxPDO is updated
        assert_eq!(&sd.io_raw().inputs()[3..7], &555i32.to_le_bytes());
        assert_eq!(al_status(&sd).await, (SAFEOP, 0));
    });
}

#[test]
fn e035_op_to_safeop_falls_back_to_the_defaults() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        // the configured mode of operation (A541 = 6060h, a parameter): csv
        group
            .subdevice(md, 0)
            .unwrap()
            .sdo_write(0x6060, 0, 9i8)
            .await
            .expect("6060h = 9 in Pre-Op");
        let group = group.into_op(md).await.expect("OP");
        let sd = group.subdevice(md, 0).unwrap();
        sd.outputs_raw_mut()
            .copy_from_slice(&default_outputs(0x000F, 1, 4321));
        frames(md, &group, 3).await;
        assert_eq!(get(&sim, 0x6040, 0), 0x000F);
        assert_eq!(get(&sim, 0x6060, 0), 1, "pp from the RxPDO");
        assert_eq!(get(&sim, 0x607A, 0), 4321);

        // O→S: set values no longer evaluated, defaults in force
        let group = group.into_safe_op(md).await.expect("OP -> SAFE-OP");
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(al_status(&sd).await, (SAFEOP, 0));
        assert_rx_defaults(&sim, "after O->S");
        assert_eq!(get(&sim, 0x6060, 0), 9, "the configured mode again");
        // the master keeps sending the old outputs: still ignored
        set(&sim, 0x6064, 0, -9);
        frames(md, &group, 3).await;
        assert_rx_defaults(&sim, "Safe-Op after Op");
        assert_eq!(get(&sim, 0x6060, 0), 9);
        assert_eq!(
            &sd.io_raw().inputs()[3..7],
            &(-9i32).to_le_bytes(),
            "TxPDO still updated"
        );

        // back in Op the set values are evaluated again
        let group = group.into_op(md).await.expect("SAFE-OP -> OP");
        let sd = group.subdevice(md, 0).unwrap();
        sd.outputs_raw_mut()
            .copy_from_slice(&default_outputs(0x0006, 8, 77));
        frames(md, &group, 3).await;
        assert_eq!(get(&sim, 0x6040, 0), 0x0006);
        assert_eq!(get(&sim, 0x607A, 0), 77);
    });
}

#[test]
fn e048_e034_a_remapped_layout_is_decoded_and_encoded_as_mapped() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        // RxPDO: target velocity first, then controlword; TxPDO: velocity
        // actual, statusword
        map_pdo(&sd, 0x1600, &[m(0x60FF, 0, 32), m(0x6040, 0, 16)]).await;
        map_pdo(&sd, 0x1A00, &[m(0x606C, 0, 32), m(0x6041, 0, 16)]).await;
        let group = group.into_op(md).await.expect("OP with the new layout");
        let sd = group.subdevice(md, 0).unwrap();
        {
            let s = sim.borrow();
            let drive = &s.drives()[0].drive;
            let image = drive.pdo_image();
            assert_eq!(drive.pdo_image_error(), None);
            assert_eq!((image.rx().bytes(), image.tx().bytes()), (6, 6));
        }
        sd.outputs_raw_mut()
            .copy_from_slice(&[0x78, 0x56, 0x34, 0x12, 0x07, 0x00]);
        // the axis runtime owns 606Ch and 6041h now: the TxPDO must carry what it wrote
        frames(md, &group, 3).await;
        assert_eq!(get(&sim, 0x60FF, 0), 0x1234_5678, "target velocity @0");
        assert_eq!(get(&sim, 0x6040, 0), 7, "controlword @4");
        assert_eq!(get(&sim, 0x607A, 0), default_of(0x607A, 0), "unmapped: untouched");
        let mut expected = (get(&sim, 0x606C, 0) as i32).to_le_bytes().to_vec();
        expected.extend_from_slice(&(get(&sim, 0x6041, 0) as u16).to_le_bytes());
        assert_eq!(
            sd.io_raw().inputs(),
            &expected[..],
            "velocity actual @0, statusword @4"
        );
        assert_eq!(
            get(&sim, 0x6041, 0) & 0x6F,
            0x40,
            "statusword: switch on disabled"
        );
        assert_eq!(al_status(&sd).await, (OP, 0));
    });
}
