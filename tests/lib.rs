//! Helpers shared by the end-to-end tests in `tests/tests/`: a real EtherCAT
//! master (ethercrab) talks to the simulated line in-process, in simulated time.

use ethercrab::{MainDevice, SubDeviceGroup, SubDeviceRef, Timeouts};
use hil_sim::sim::Simulation;
use std::cell::RefCell;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

/// Timeouts for in-process runs: every answer is immediate, so short ones
/// make a refusal fail fast instead of hanging.
pub fn timeouts() -> Timeouts {
    Timeouts {
        state_transition: Duration::from_millis(500),
        mailbox_response: Duration::from_millis(500),
        ..Timeouts::default()
    }
}

/// A line of `n` simulated drives.
pub fn line(n: usize) -> RefCell<Simulation> {
    RefCell::new(Simulation::new(n))
}

/// Runs the master's `body` against `sim`.
pub fn with_master<T>(
    sim: &RefCell<Simulation>,
    body: impl for<'a> AsyncFnOnce(&'a MainDevice<'a>, &'a AtomicU64) -> T,
) -> T {
    hil_sim::master::run(sim, timeouts(), body)
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
    let st: u16 = sd
        .register_read(esc::regs::AL_STATUS)
        .await
        .unwrap_or_else(|e| panic!("read AL status: {e}"));
    let code: u16 = sd
        .register_read(esc::regs::AL_STATUS_CODE)
        .await
        .unwrap_or_else(|e| panic!("read AL code: {e}"));
    (st, code)
}

/// Writes AL control (a raw state request, as a master's start-up would), then
/// reads AL status once more so the slave firmware has polled after the write.
pub async fn request<S>(sd: &SubDeviceRef<'_, S>, ctrl: u16) {
    sd.register_write(esc::regs::AL_CONTROL, ctrl)
        .await
        .unwrap_or_else(|e| panic!("write AL control: {e}"));
    let _: u16 = sd
        .register_read(esc::regs::AL_STATUS)
        .await
        .unwrap_or_else(|e| panic!("read AL status: {e}"));
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
