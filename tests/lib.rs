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
    // 100 instead of 10 000 DC static-sync frames: the simulated clocks do not drift yet
    let config = ethercrab::MainDeviceConfig {
        dc_static_sync_iterations: 100,
        ..Default::default()
    };
    hil_sim::master::run_with(sim, timeouts(), config, body)
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

/// Length of the drive's mailboxes (SM0 and SM1), bytes.
pub const MAILBOX_LEN: usize = 256;

/// A raw mailbox client: builds mailbox frames from the spec's byte layouts
/// and moves them through SM0/SM1 with plain register reads and writes of a
/// real master. ethercrab itself only sends expedited SDO downloads; this is
/// how the tests send segmented, normal and complete-access transfers, SDO
/// Info requests and malformed mailboxes.
pub struct RawMailbox {
    counter: u8,
}

impl Default for RawMailbox {
    fn default() -> Self {
        Self::new()
    }
}

impl RawMailbox {
    /// Counter starts at 1 and cycles 1..7 (ETG.1000.4 §5.6).
    pub fn new() -> Self {
        Self { counter: 0 }
    }

    /// Sends one mailbox message (`kind` 3 = CoE, ...) and returns the
    /// response's mailbox data (after the 6-byte header) and its type, or
    /// `None` when no response arrives within 50 reads.
    pub async fn exchange<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        kind: u8,
        data: &[u8],
    ) -> Option<(u8, Vec<u8>)> {
        self.counter = self.counter % 7 + 1;
        let mut frame = [0u8; MAILBOX_LEN];
        let len = data.len().min(MAILBOX_LEN - 6);
        frame[0..2].copy_from_slice(&(len as u16).to_le_bytes());
        frame[5] = (kind & 0x0F) | (self.counter << 4);
        frame[6..6 + len].copy_from_slice(&data[..len]);
        self.send_raw(sd, frame).await;
        self.receive(sd).await
    }

    /// Writes a whole, possibly malformed, SM0 buffer.
    pub async fn send_raw<S>(&mut self, sd: &SubDeviceRef<'_, S>, frame: [u8; MAILBOX_LEN]) {
        let ok = sd.register_write(0x1000u16, frame).await.is_ok();
        assert!(ok, "write SM0 mailbox");
    }

    /// Waits for SM1 to fill and reads the response.
    pub async fn receive<S>(&mut self, sd: &SubDeviceRef<'_, S>) -> Option<(u8, Vec<u8>)> {
        for _ in 0..50 {
            let status: u8 = sd.register_read(esc::regs::sm(1) + 5).await.ok()?;
            if status & esc::sm::status::MAILBOX_FULL != 0 {
                let buf: [u8; MAILBOX_LEN] = sd.register_read(0x1100u16).await.ok()?;
                let len = usize::from(u16::from_le_bytes([buf[0], buf[1]])).min(MAILBOX_LEN - 6);
                return Some((buf[5] & 0x0F, buf[6..6 + len].to_vec()));
            }
        }
        None
    }

    /// An SDO request (CoE service 2): CoE header then the 8-byte SDO part and
    /// optional extra data; returns the CoE response (header included).
    pub async fn sdo<S>(&mut self, sd: &SubDeviceRef<'_, S>, sdo: &[u8]) -> Vec<u8> {
        let mut req = vec![0x00, 0x20]; // number 0, service 2 (SDO request)
        req.extend_from_slice(sdo);
        match self.exchange(sd, 3, &req).await {
            Some((3, resp)) => resp,
            other => panic!("no CoE response: {other:?}"),
        }
    }
}
