//! DC-Sync end to end: ethercrab (in-process) configures DC (static drift
//! compensation, SYNC0 period and start) on two drives whose oscillators drift
//! by +50 / −80 ppm and brings them to OP; each drive's PLL locks its
//! control-cycle timer to SYNC0 − A292 (E-107, E-109, E-113, E-114); loss of
//! SYNC0 is reported (A298, PLL fault); a late frame counts in A261[2]
//! (E-117, E-118); a SYNC0 cycle the PLL cannot run is refused (A261[0], E-116).
//!
//! Here: the line, its parameters and the DC start-up and cycle helpers; the tests, by area, in
//! the modules.

use drive_ecat::runtime::dcsync;
use drive_ecat::runtime::dcsync::{PllStatus, SyncFault};
use drive_tests::al::{OP, SAFEOP};
use drive_tests::init;
use ethercrab::subdevice_group::DcConfiguration;
use ethercrab::{MainDevice, SubDeviceGroup};
use hil_sim::master::{into_dc_sync0, run_in_process};
use hil_sim::sim::Simulation;
use std::cell::RefCell;
use std::sync::atomic::AtomicU64;
use std::time::Duration;

mod cycle;
mod esm;
mod pll;

/// Oscillator drift of drive 0 (the DC reference) and drive 1, ppm.
const DRIFTS: [f64; 2] = [50.0, -80.0];
/// Local time of each drive at simulation time 0, ns.
const OFFSETS: [u64; 2] = [3_000_000_000, 987_654_321];
/// SYNC0 period = A150, ns.
const SYNC0_NS: u64 = 1_000_000;
/// A292 written by SDO: the drive's aligned cycle starts 100 µs after SYNC0.
const A292_US: i32 = -100;
/// Frames arrive 100 µs before SYNC0 (ethercrab sends at SYNC0 + shift).
const FRAME_LEAD_NS: u64 = 100_000;
const A261: u16 = drive_ecat::parameter_index(0, 261);

/// SYNC0 every `sync0_ns`, starting 20 ms out, frames arriving
/// [`FRAME_LEAD_NS`] before each SYNC0.
fn dc_config(sync0_ns: u64) -> DcConfiguration {
    DcConfiguration {
        start_delay: Duration::from_millis(20),
        sync0_period: Duration::from_nanos(sync0_ns),
        sync0_shift: Duration::from_nanos(sync0_ns - FRAME_LEAD_NS),
    }
}
const A292: u16 = drive_ecat::parameter_index(0, 292);
const A264: u16 = drive_ecat::parameter_index(0, 264);
const A296: u16 = drive_ecat::parameter_index(0, 296);
const A298: u16 = drive_ecat::parameter_index(0, 298);

fn line() -> RefCell<Simulation> {
    RefCell::new(Simulation::with_clocks(&DRIFTS, &OFFSETS))
}

/// The line in Op with DC.
type DcOpGroup = SubDeviceGroup<
    8,
    512,
    ethercrab::DefaultLock,
    ethercrab::subdevice_group::Op,
    ethercrab::subdevice_group::HasDc,
>;

/// The line with DC SYNC0 at [`SYNC0_NS`] on every drive and Op requested
/// (ethercrab's init, Pre-Op with PDI, the DC configuration).
async fn dc_requested_op<'a>(md: &'a MainDevice<'a>, clock: &'a AtomicU64) -> DcOpGroup {
    dc_requested_op_after(md, clock, SYNC0_NS, async |_| {}).await
}

/// [`dc_requested_op`] with SYNC0 every `sync0_ns`, `pre_op` run on every
/// drive in Pre-Op.
async fn dc_requested_op_after<'a>(
    md: &'a MainDevice<'a>,
    clock: &'a AtomicU64,
    sync0_ns: u64,
    pre_op: impl for<'b> AsyncFn(&'b Sd<'b>),
) -> DcOpGroup {
    into_dc_sync0(md, init(md, clock).await, dc_config(sync0_ns), pre_op)
        .await
        .expect("SYNC0, PRE-OP with PDI, DC configuration")
        .request_into_op(md)
        .await
        .expect("request OP")
}

/// Runs `n` `tx_rx_dc` cycles, the clock advanced as ethercrab computes it;
/// calls `probe` after each with the cycle number, whether the group is in
/// OP, and the simulation.
async fn dc_cycles<'a>(
    md: &'a MainDevice<'a>,
    group: &DcOpGroup,
    sim: &RefCell<Simulation>,
    n: usize,
    mut probe: impl FnMut(usize, bool, &Simulation),
) {
    for i in 0..n {
        let r = group.tx_rx_dc(md).await.expect("DC cycle");
        probe(i, r.all_op(), &sim.borrow());
        let wait = r.extra.next_cycle_wait.as_nanos() as u64;
        let mut s = sim.borrow_mut();
        let t = s.now().as_ns() + wait;
        s.advance_to(nanos::Nanos::from_ns(t));
    }
}

/// A drive in the Pre-Op group as the master holds it.
type Sd<'a> = hil_sim::master::PdiSubDevice<'a, 512>;

/// Brings the line to OP with DC (SYNC0 every `sync0_ns`, frames
/// [`FRAME_LEAD_NS`] before SYNC0, A292 = [`A292_US`]) after `pre_op` ran in
/// Pre-Op, runs `n` cycles (see [`dc_cycles`]), then `body`.
fn dc_op<T>(
    sim: &RefCell<Simulation>,
    sync0_ns: u64,
    pre_op: impl for<'a> AsyncFn(&'a Sd<'a>),
    n: usize,
    body: impl for<'a> AsyncFnOnce(&'a MainDevice<'a>, &'a DcOpGroup) -> T,
) -> T {
    run_in_process(sim, async |md, clock| {
        let group = dc_requested_op_after(md, clock, sync0_ns, async |sd| {
            sd.sdo_write(A292, 0, A292_US).await.expect("A292");
            pre_op(sd).await;
        })
        .await;
        let mut op = None;
        dc_cycles(md, &group, sim, n, |i, all_op, _| {
            if all_op && op.is_none() {
                op = Some(i);
            }
        })
        .await;
        assert!(op.is_some(), "the group reached OP");
        body(md, &group).await
    })
}
