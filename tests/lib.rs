//! Helpers shared by the end-to-end tests in `tests/tests/`: a real EtherCAT
//! master (ethercrab) talks to the simulated line in-process, in simulated time.

pub mod axis;
pub mod cyclic;
pub mod foe;
pub mod mailbox;
pub mod step;

/// The fault matrix's rows (`hil_sim::matrix`, docs/fault-matrix.md).
pub use hil_sim::{fault_row, matrix};

// The helper families of the modules, re-exported where the tests name them.
pub use cyclic::{
    map_layout, map_pdo, sw, Cyclic, Link, OpGroup, OpSubDevice, RawCyclic, TxPdo, MASTER_CYCLE, RXPDO_LEN,
    TXPDO_LEN,
};
pub use foe::{
    dev_seed, firmware_file, fw_load_address, in_boot, signed_file, to_boot, FoeClient, FoeReply, FwFlash,
    FwNode, FwSlots,
};
pub use mailbox::{Abort, CoeClient, EntryDesc, ObjectDesc, RawMailbox, UploadKind, MAILBOX_LEN};

use ethercrab::{MainDevice, SubDeviceGroup, SubDeviceRef, Timeouts};
use hil_sim::sim::Simulation;
use std::cell::RefCell;
use std::sync::atomic::{AtomicU64, Ordering};

/// Timeouts for in-process runs. ethercrab's timeouts run on the wall clock,
/// while the simulated line answers every frame at once: they only fire when
/// the machine is loaded (CI runs tests in parallel on 2 cores) or when the
/// slave really stays silent (a refused mailbox). Generous, so they never flake.
pub fn timeouts() -> Timeouts {
    hil_sim::master::in_process_timeouts()
}

/// AL control/status values the tests write and expect (ETG.1000.6).
pub mod al {
    /// Init.
    pub const INIT: u16 = 1;
    /// Pre-Operational.
    pub const PREOP: u16 = 2;
    /// Bootstrap.
    pub const BOOT: u16 = 3;
    /// Safe-Operational.
    pub const SAFEOP: u16 = 4;
    /// Operational.
    pub const OP: u16 = 8;
    /// AL status: error indication.
    pub const ERR: u16 = 0x10;
    /// AL control: error acknowledge.
    pub const ACK: u16 = 0x10;
}

/// One revolution in increments (2^20, 6092h default feed, C-108).
pub const REV: i32 = 1 << 20;
/// [`REV`] as a float.
pub const REV_F: f64 = REV as f64;

/// The environment variable that picks the device the end-to-end tests run
/// on: `single` for the single-axis SI6A061, anything else (or unset) for the
/// double-axis SC6A062 (issue 20: the suite runs on both variants, CI runs it
/// twice).
pub const VARIANT_ENV: &str = "DRIVE_TESTS_VARIANT";

/// The device this run of the end-to-end tests is about ([`VARIANT_ENV`]).
pub fn variant() -> drive_ecat::Variant {
    match std::env::var(VARIANT_ENV).as_deref() {
        Ok("single") => drive_ecat::Variant::Single,
        _ => drive_ecat::Variant::Double,
    }
}

/// A line of `n` simulated drives of this run's [`variant`].
pub fn line(n: usize) -> RefCell<Simulation> {
    RefCell::new(Simulation::of(variant(), n))
}

/// The device description (identity, SII name, order code) of this run's
/// [`variant`].
pub fn device() -> &'static ecat::Device {
    drive_ecat::device(variant())
}

/// The object dictionary of this run's [`variant`]: the objects the device
/// has, each as the device declares it, in index order.
pub fn objects() -> impl Iterator<Item = &'static drive_ecat::objects::Object> + Clone {
    let v = variant();
    drive_ecat::objects::OBJECTS
        .iter()
        .filter(move |o| v.has_object(o.info.index))
        .map(move |o| v.declared(o))
}

/// `true` when this run's device has axis B. A test about axis B (its
/// objects, its PDO channel, both axes at once) starts with
/// `if !has_axis_b("why") { return; }`: on the single-axis device it says
/// so on stderr and checks nothing (tests/tests/single_axis.rs checks that
/// axis B is absent there).
pub fn has_axis_b(test: &str) -> bool {
    let yes = variant().axes() == 2;
    if !yes {
        eprintln!("skipped on the single-axis device (no axis B): {test}");
    }
    yes
}

/// Runs the master's `body` against `sim`.
pub fn with_master<T>(
    sim: &RefCell<Simulation>,
    body: impl for<'a> AsyncFnOnce(&'a MainDevice<'a>, &'a AtomicU64) -> T,
) -> T {
    with_master_on(sim, body)
}

/// [`with_master`] for a line of any node type.
pub fn with_master_on<N: hil_sim::sim::Node, T>(
    sim: &RefCell<Simulation<N>>,
    body: impl for<'a> AsyncFnOnce(&'a MainDevice<'a>, &'a AtomicU64) -> T,
) -> T {
    // 100 instead of 10 000 DC static-sync frames: the simulated clocks run without drift
    // unless a test sets one (hil-sim/tests/dc.rs uses the full static sync)
    let config = ethercrab::MainDeviceConfig {
        dc_static_sync_iterations: 100,
        ..Default::default()
    };
    hil_sim::master::run_with(sim, timeouts(), config, body)
}

/// Runs `body` on `sim`'s line brought to Op (ethercrab's init, then
/// `into_op`) with the master on its first drive ([`Cyclic`], the outputs
/// all zero) and that drive's SubDevice.
pub fn with_cyclic<T>(
    sim: &RefCell<Simulation>,
    body: impl for<'a> AsyncFnOnce(&mut Cyclic<'a>, &OpSubDevice<'a>) -> T,
) -> T {
    with_master(sim, async |md, clock| {
        let group = init(md, clock).await.into_op(md).await.expect("OP");
        let sd = group.subdevice(md, 0).unwrap();
        let mut m = Cyclic::new(md, &group, sim, 0);
        body(&mut m, &sd).await
    })
}

/// The velocity of `sim`'s first drive's motor `axis` (the plant's), rev/s.
pub fn motor_rev_s(sim: &RefCell<Simulation>, axis: usize) -> f64 {
    sim.borrow().drives()[0].motors[axis].velocity_rad_s() / std::f64::consts::TAU
}

/// A SubDevice of a group in PRE-OP, as [`init`] leaves it.
pub type PreOpSubDevice<'a> = SubDeviceRef<'a, &'a ethercrab::SubDevice>;

/// Runs `body` on `sim`'s line (of any node type) in PRE-OP ([`init`])
/// with its first drive's SubDevice.
pub fn with_preop<N: hil_sim::sim::Node, T>(
    sim: &RefCell<Simulation<N>>,
    body: impl for<'a> AsyncFnOnce(PreOpSubDevice<'a>) -> T,
) -> T {
    with_master_on(sim, async |md, clock| {
        let group = init(md, clock).await;
        body(group.subdevice(md, 0).unwrap()).await
    })
}

/// Runs `body` on `sim`'s line in PRE-OP ([`init`]) with its first drive's
/// SubDevice and a [`CoeClient`] for it.
pub fn with_sdo<T>(
    sim: &RefCell<Simulation>,
    body: impl for<'a> AsyncFnOnce(&PreOpSubDevice<'a>, &mut CoeClient) -> T,
) -> T {
    with_preop(sim, async |sd| body(&sd, &mut CoeClient::new()).await)
}

/// [`with_sdo`] after the master's SyncManager set-up
/// ([`step::sm_set_up`]): PRE-OP again, where a test changes what SAFE-OP
/// checks.
pub fn with_sdo_set_up<T>(
    sim: &RefCell<Simulation>,
    body: impl for<'a> AsyncFnOnce(&PreOpSubDevice<'a>, &mut CoeClient) -> T,
) -> T {
    with_master(sim, async |md, clock| {
        let group = step::sm_set_up(md, init(md, clock).await).await;
        let sd = group.subdevice(md, 0).unwrap();
        body(&sd, &mut CoeClient::new()).await
    })
}

/// Discovers the line and brings it to PRE-OP (ethercrab's init).
pub async fn init<'a>(md: &'a MainDevice<'a>, clock: &'a AtomicU64) -> SubDeviceGroup<8, 512> {
    match md
        .init_single_group::<8, 512>(|| clock.load(Ordering::Relaxed))
        .await
    {
        Ok(g) => g,
        Err(e) => panic!("ethercrab init failed: {e}"),
    }
}

/// AL status (0x0130) and AL status code (0x0134), read by the master.
pub async fn al_status<S>(sd: &SubDeviceRef<'_, S>) -> (u16, u16) {
    let st = register_u16(sd, esc::regs::AL_STATUS, "AL status").await;
    let code = register_u16(sd, esc::regs::AL_STATUS_CODE, "AL code").await;
    (st, code)
}

/// The 16-bit register `reg`, read by the master (`what`: its name, for
/// the failure's message).
async fn register_u16<S>(sd: &SubDeviceRef<'_, S>, reg: u16, what: &str) -> u16 {
    sd.register_read(reg)
        .await
        .unwrap_or_else(|e| panic!("read {what}: {e}"))
}

/// Object `index:sub` as the master's SDO upload reads it must be `want`
/// (`what`: the case, for the failure's message).
pub async fn sdo_is<S, T>(sd: &SubDeviceRef<'_, S>, index: u16, sub: u8, want: T, what: &str)
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
    T: ethercrab::EtherCrabWireReadSized + PartialEq + std::fmt::Debug,
{
    let got: T = sd
        .sdo_read(index, sub)
        .await
        .unwrap_or_else(|e| panic!("{what}: {index:04X}h:{sub}: {e}"));
    assert_eq!(got, want, "{what}");
}

/// Writes AL control (a raw state request, as a master's start-up would), then
/// reads AL status once more so the slave firmware has polled after the write.
pub async fn request<S>(sd: &SubDeviceRef<'_, S>, ctrl: u16) {
    sd.register_write(esc::regs::AL_CONTROL, ctrl)
        .await
        .unwrap_or_else(|e| panic!("write AL control: {e}"));
    register_u16(sd, esc::regs::AL_STATUS, "AL status").await;
}

/// [`request`] `ctrl`, then the AL status and code must be `expected`
/// (`what`: the case, for the failure's message).
pub async fn request_gives<S>(sd: &SubDeviceRef<'_, S>, ctrl: u16, expected: (u16, u16), what: &str) {
    request(sd, ctrl).await;
    expect_al(sd, expected, what).await;
}

/// The AL status and code must be `expected` (`what`: the case, for the
/// failure's message).
pub async fn expect_al<S>(sd: &SubDeviceRef<'_, S>, expected: (u16, u16), what: &str) {
    assert_eq!(al_status(sd).await, expected, "{what}");
}

/// Writes SyncManager `n`'s start, length and control, and enables it.
pub async fn write_sm<S>(sd: &SubDeviceRef<'_, S>, n: u8, start: u16, len: u16, control: u8) {
    let sm = esc::SyncManager {
        start,
        length: len,
        control,
        status: 0,
        activate: 1,
        pdi_control: 0,
    };
    let [s0, s1, l0, l1, c, _, a, _] = sm.to_bytes();
    let base = esc::regs::sm(n);
    let ok = sd
        .register_write(base, u32::from_le_bytes([s0, s1, l0, l1]))
        .await
        .is_ok()
        && sd.register_write(base + 4, c).await.is_ok()
        && sd.register_write(base + 6, a).await.is_ok();
    assert!(ok, "write SM{n}");
}
