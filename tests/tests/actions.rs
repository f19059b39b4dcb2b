//! Actions over the fieldbus through a real master (spec §14; E-060,
//! E-140…E-142): A75 appended to axis A's RxPDO, A69 to its TxPDO, the
//! action started by Execute in the cyclic data and followed in A69.

use drive_ecat::actions::{state, A69, A75};
use drive_tests::al::OP;
use drive_tests::step::{a69_of, cycles, op_with_actions};
use drive_tests::{al_status, line, with_master, with_sdo};

/// E-060, E-140: A75 = Execute | save (0001b) in the RxPDO; A69 in the
/// TxPDO shows the save running, then done at 100 % with the selector; A00's
/// result is 0 (saved). Execute low: A69 back to idle.
#[test]
fn e060_e140_save_values_through_a75_and_a69_in_the_process_data() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let (group, (a75, a69)) = op_with_actions(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(al_status(&sd).await, (OP, 0));
        sd.outputs_raw_mut()[a75] = 0b0001 << 1 | 1;
        let mut seen = Vec::new();
        for _ in 0..50 {
            group.tx_rx(md).await.expect("cycle");
            let s = a69_of(sd.io_raw().inputs(), a69);
            if seen.last() != Some(&s) {
                seen.push(s);
            }
            if s >> 12 == state::DONE {
                break;
            }
        }
        let done = 100 | 1 << 8 | state::DONE << 12;
        assert_eq!(seen.last(), Some(&done), "A69 over the cycles: {seen:04X?}");
        assert!(
            seen.iter()
                .all(|s| s >> 12 == state::IDLE || s >> 12 == state::RUNNING || *s == done),
            "{seen:04X?}"
        );
        assert_eq!(
            sd.sdo_read::<u8>(0x2000, 3).await.unwrap(),
            0,
            "A00 result: saved"
        );
        sd.outputs_raw_mut()[a75] = 0;
        for _ in 0..5 {
            group.tx_rx(md).await.expect("cycle");
        }
        assert_eq!(a69_of(sd.io_raw().inputs(), a69), 0, "idle once Execute is low");
    });
}

/// E-141: a motor test (test winding, 1101b) needs E48 = 2 (ready to switch
/// on): with the axis switch-on disabled it is refused and A69 says so.
/// E-140: in Ready to switch on, the actions this drive does not have answer
/// "not available" with their selector: grind brake 2 (B302, 0110b: one
/// brake per axis), the safety's brake test (S18, 1001b: no safety module),
/// reset memorised values (A37, 0011b) and delete limit-switch memory (I52,
/// 1000b: nothing memorised).
#[test]
fn e141_e140_test_winding_refused_and_b302_s18_a37_i52_not_available() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let (group, (a75, a69)) = op_with_actions(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        let e48 = sd.sdo_read::<u8>(drive_ecat::params::E48, 0).await.unwrap();
        assert_ne!(e48, 2, "the axis is not ready to switch on");
        sd.outputs_raw_mut()[a75] = 0b1101 << 1 | 1;
        cycles(md, &group, &sim, 5).await;
        let s = a69_of(sd.io_raw().inputs(), a69);
        assert_eq!(s, 0b1101 << 8 | state::REFUSED << 12, "{s:04X}h");
        // shutdown (6040h = 6): ready to switch on; the precondition holds, and
        // grind brake 2 (0110b) and the others are not available on this drive
        {
            let mut out = sd.outputs_raw_mut();
            out[0..2].copy_from_slice(&6u16.to_le_bytes());
            out[a75] = 0;
        }
        cycles(md, &group, &sim, 20).await;
        assert_eq!(sd.sdo_read::<u8>(drive_ecat::params::E48, 0).await.unwrap(), 2);
        for selector in [0b0110u8, 0b1001, 0b0011, 0b1000] {
            sd.outputs_raw_mut()[a75] = selector << 1 | 1;
            cycles(md, &group, &sim, 5).await;
            let s = a69_of(sd.io_raw().inputs(), a69);
            let want = u16::from(selector) << 8 | state::NOT_AVAILABLE << 12;
            assert_eq!(s, want, "{selector:04b}: {s:04X}h");
            sd.outputs_raw_mut()[a75] = 0;
            cycles(md, &group, &sim, 3).await;
            assert_eq!(a69_of(sd.io_raw().inputs(), a69), 0, "idle");
        }
    });
}

/// E-142: A75 written over SDO, not mapped in the axis's channel: action
/// activation is off, nothing starts (A69 over SDO: not activated).
#[test]
fn e142_a75_over_sdo_without_activation_starts_nothing() {
    let sim = line(1);
    with_sdo(&sim, async |sd, _| {
        sd.sdo_write(A75, 0, (0b0001u8 << 1) | 1)
            .await
            .expect("A75 over SDO");
        let s = sd.sdo_read::<u16>(A69, 0).await.unwrap();
        assert_eq!(s, 1 << 8 | state::NOT_ACTIVATED << 12, "{s:04X}h");
        assert!(
            !sim.borrow().drives()[0].drive.objects().requests().save,
            "no save requested"
        );
    });
}
