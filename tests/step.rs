//! Stepping the simulated line by hand: simulated time on, process-data
//! cycles of the master, an object set locally, and the action objects A75/A69
//! mapped into the process data (`actions.rs`, `actions_motor.rs`).

use crate::{OpGroup, MASTER_CYCLE};
use ethercrab::subdevice_group::HasPdi;
use ethercrab::{DefaultLock, MainDevice, SubDevice, SubDeviceGroup, SubDeviceRef};
use hil_sim::sim::{Node, Simulation};
use std::cell::RefCell;
use std::sync::atomic::AtomicU64;

/// Runs the line `ns` of simulated time on, without frames.
pub fn advance<N: Node>(sim: &RefCell<Simulation<N>>, ns: u64) {
    let mut s = sim.borrow_mut();
    let t = s.now().as_ns() + ns;
    s.advance_to(nanos::Nanos::from_ns(t));
}

/// `n` process-data cycles, the simulated time advanced one master cycle
/// (1 ms) before each.
pub async fn cycles<S: HasPdi>(
    md: &MainDevice<'_>,
    group: &SubDeviceGroup<8, 512, DefaultLock, S>,
    sim: &RefCell<Simulation>,
    n: usize,
) {
    for _ in 0..n {
        advance(sim, MASTER_CYCLE.as_ns());
        group.tx_rx(md).await.expect("process data cycle");
    }
}

/// `group` (in PRE-OP, as [`init`](crate::init) leaves it) into SAFE-OP,
/// five process-data [`cycles`] there (the drive sees its RxPDO running, as
/// a watchdog A258 wants), then into OP.
pub async fn op_via_safe_op(
    md: &MainDevice<'_>,
    group: SubDeviceGroup<8, 512>,
    sim: &RefCell<Simulation>,
) -> OpGroup {
    let group = group.into_safe_op(md).await.expect("SAFE-OP");
    cycles(md, &group, sim, 5).await;
    group.into_op(md).await.expect("OP")
}

/// `group` (in PRE-OP, as [`init`](crate::init) leaves it) into SAFE-OP
/// and back: the master's SyncManager set-up done, PRE-OP again (where a
/// test changes what SAFE-OP checks).
pub async fn sm_set_up(md: &MainDevice<'_>, group: SubDeviceGroup<8, 512>) -> SubDeviceGroup<8, 512> {
    let group = group.into_safe_op(md).await.expect("SAFE-OP");
    group.into_pre_op(md).await.expect("PRE-OP")
}

/// Object `index:sub` of the first drive set to `value` locally.
pub fn set(sim: &RefCell<Simulation>, index: u16, sub: u8, value: i64) {
    sim.borrow_mut().drives_mut()[0]
        .drive
        .objects_mut()
        .set(index, sub, value)
        .unwrap_or_else(|e| panic!("{index:04X}h:{sub}: {e:?}"));
}

/// Appends A75 (8 bits) to 1600h and A69 (16 bits) to 1A00h by SDO; returns
/// the byte offsets of A75 in the outputs and A69 in the inputs.
pub async fn map_actions(sd: &SubDeviceRef<'_, &SubDevice>) -> (usize, usize) {
    use drive_ecat::actions::{A69, A75};
    let mut offsets = [0usize; 2];
    for (i, (pdo, entry)) in [
        (0x1600u16, u32::from(A75) << 16 | 8),
        (0x1A00, u32::from(A69) << 16 | 16),
    ]
    .into_iter()
    .enumerate()
    {
        let n = sd.sdo_read::<u8>(pdo, 0).await.unwrap();
        for s in 1..=n {
            offsets[i] += (sd.sdo_read::<u32>(pdo, s).await.unwrap() & 0xFF) as usize / 8;
        }
        sd.sdo_write(pdo, 0, 0u8).await.unwrap();
        sd.sdo_write(pdo, n + 1, entry).await.unwrap();
        sd.sdo_write(pdo, 0, n + 1).await.expect("A75/A69 mapped");
    }
    (offsets[0], offsets[1])
}

/// A69 at byte `at` of the inputs.
pub fn a69_of(inputs: &[u8], at: usize) -> u16 {
    u16::from_le_bytes([inputs[at], inputs[at + 1]])
}

/// Init, A75/A69 mapped (see [`map_actions`]), Op: the group and the byte
/// offsets of A75 in the outputs and A69 in the inputs.
pub async fn op_with_actions<'a>(md: &'a MainDevice<'a>, clock: &'a AtomicU64) -> (OpGroup, (usize, usize)) {
    let group = crate::init(md, clock).await;
    let sd = group.subdevice(md, 0).expect("subdevice");
    let offsets = map_actions(&sd).await;
    let group = group.into_op(md).await.expect("Op with A75/A69 mapped");
    (group, offsets)
}

/// Single cycles (see [`cycles`]), at most `max`, while `running(A69)`
/// holds; A69 (byte `at` of drive 0's inputs) each time it changed.
pub async fn follow_a69<S: HasPdi>(
    md: &MainDevice<'_>,
    group: &SubDeviceGroup<8, 512, DefaultLock, S>,
    sim: &RefCell<Simulation>,
    at: usize,
    max: usize,
    running: impl Fn(u16) -> bool,
) -> Vec<u16> {
    let sd = group.subdevice(md, 0).expect("subdevice");
    let mut seen = Vec::new();
    for _ in 0..max {
        cycles(md, group, sim, 1).await;
        let s = a69_of(sd.io_raw().inputs(), at);
        if seen.last() != Some(&s) {
            seen.push(s);
        }
        if !running(s) {
            break;
        }
    }
    seen
}
