//! Helpers shared by the end-to-end tests in `tests/tests/`: a real EtherCAT
//! master (ethercrab) talks to the simulated line in-process, in simulated time.

pub mod axis;
pub mod step;

/// The fault matrix's rows (`hil_sim::matrix`, docs/fault-matrix.md).
pub use hil_sim::{fault_row, matrix};

use ethercrab::{MainDevice, SubDeviceGroup, SubDeviceRef, Timeouts};
use hil_sim::sim::Simulation;
use nanos::Nanos;
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

/// Length of the drive's mailboxes (SM0 and SM1), bytes.
pub const MAILBOX_LEN: usize = 256;

/// A raw mailbox client: builds mailbox frames from the spec's byte layouts
/// and moves them through SM0/SM1 with plain register reads and writes of a
/// real master. ethercrab itself only sends expedited SDO downloads; this is
/// how the tests send segmented, normal and complete-access transfers, SDO
/// Info requests and malformed mailboxes.
pub struct RawMailbox {
    counter: u8,
    /// Send the next message with counter 0 (see [`CoeClient::hand_over`]).
    zero_next: bool,
}

impl Default for RawMailbox {
    fn default() -> Self {
        Self::new()
    }
}

impl RawMailbox {
    /// Counter starts at 1 and cycles 1..7 (ETG.1000.4 §5.6).
    pub fn new() -> Self {
        Self {
            counter: 0,
            zero_next: false,
        }
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
        self.counter = if std::mem::take(&mut self.zero_next) {
            0
        } else {
            self.counter % 7 + 1
        };
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

// ---------------------------------------------------------------------------
// SDO client over `RawMailbox` (tests/tests/coe.rs, tests/tests/pdo.rs)
// ---------------------------------------------------------------------------

/// An SDO abort code (the 32-bit CiA 301 value).
pub type Abort = u32;

/// How an upload came back.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UploadKind {
    /// Expedited (data in the initiate response, ≤ 4 bytes).
    Expedited,
    /// Normal: size indicated, all data in the initiate response.
    Normal,
    /// Segmented: size in the initiate response, data in upload segments.
    Segmented,
}

/// An entry description from SDO Info (Get Entry Description response).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct EntryDesc {
    /// Value info bits supplied.
    pub value_info: u8,
    /// Data type code.
    pub data_type: u16,
    /// Bit length.
    pub bit_len: u16,
    /// Object access bits.
    pub access: u16,
    /// Default / minimum / maximum as supplied (little-endian bytes).
    pub values: Vec<Vec<u8>>,
    /// Name.
    pub name: String,
}

/// An object description from SDO Info (Get Object Description response).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ObjectDesc {
    /// Data type code of the object.
    pub data_type: u16,
    /// Highest subindex.
    pub max_sub: u8,
    /// Object code (7 VAR, 8 ARRAY, 9 RECORD).
    pub code: u8,
    /// Name.
    pub name: String,
}

/// A CoE client built on [`RawMailbox`]: SDO uploads and downloads of every
/// shape (expedited with any size, normal, segmented, complete access) and
/// SDO Information, from the spec's byte layouts (§6.2–6.4, §7).
///
/// The slave drops a request whose mailbox counter equals the previous
/// request's (duplicate detection); when ethercrab's requests are interleaved
/// that can happen by chance, so a request without reply is sent once more
/// with the next counter. Emergencies that arrive before the reply are kept in
/// [`CoeClient::emergencies`].
#[derive(Default)]
pub struct CoeClient {
    mbx: RawMailbox,
    /// EMCY payloads (8 bytes each) received while waiting for replies.
    pub emergencies: Vec<Vec<u8>>,
}

fn coe_service(resp: &[u8]) -> u8 {
    (u16::from_le_bytes([resp[0], resp[1]]) >> 12) as u8
}

impl CoeClient {
    /// A fresh client.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sends one CoE message (CoE header + service data) and returns the CoE
    /// reply (header included); panics on a mailbox error reply.
    pub async fn request<S>(&mut self, sd: &SubDeviceRef<'_, S>, coe: &[u8]) -> Vec<u8> {
        match self.try_request(sd, coe).await {
            Ok(r) => r,
            Err((kind, data)) => panic!("mailbox reply of type {kind}: {data:02x?}"),
        }
    }

    /// Like [`request`](Self::request), but a non-CoE reply (mailbox error)
    /// comes back as `Err((type, data))`.
    pub async fn try_request<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        coe: &[u8],
    ) -> Result<Vec<u8>, (u8, Vec<u8>)> {
        for _ in 0..3 {
            let mut reply = self.mbx.exchange(sd, 3, coe).await;
            loop {
                match reply {
                    Some((3, resp)) if coe_service(&resp) == 1 => {
                        self.emergencies.push(resp[2..].to_vec());
                        reply = self.mbx.receive(sd).await;
                    }
                    Some((3, resp)) => return Ok(resp),
                    Some(other) => return Err(other),
                    None => break,
                }
            }
        }
        panic!("no reply to CoE request {coe:02x?}")
    }

    /// Leaves the mailbox to another master (ethercrab) without a counter
    /// collision: one SDO upload of 1000h with counter 0, which resets the
    /// drive's repeat detection (ETG.1000.4), so whatever counter the other
    /// master sends next is new. Without it ethercrab's next request is
    /// dropped as a repeat whenever its counter equals this client's last.
    pub async fn hand_over<S>(&mut self, sd: &SubDeviceRef<'_, S>) {
        self.mbx.zero_next = true;
        let reply = self
            .request(sd, &[0x00, 0x20, 0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0])
            .await;
        assert_eq!(reply[2] >> 5, 2, "1000h upload: {reply:02x?}");
    }

    /// Sends one CoE message that gets no reply (an SDO abort request).
    pub async fn send_only<S>(&mut self, sd: &SubDeviceRef<'_, S>, coe: &[u8]) {
        let reply = self.mbx.exchange(sd, 3, coe).await;
        assert!(reply.is_none(), "unexpected reply {reply:02x?}");
    }

    /// An SDO request (8-byte SDO part + extra data); returns the SDO part of
    /// the reply (after the CoE header) or the abort code.
    pub async fn sdo<S>(&mut self, sd: &SubDeviceRef<'_, S>, sdo: &[u8]) -> Result<Vec<u8>, Abort> {
        let mut req = vec![0x00, 0x20];
        req.extend_from_slice(sdo);
        let resp = self.request(sd, &req).await;
        let body = resp[2..].to_vec();
        if body[0] == 0x80 {
            assert_eq!(coe_service(&resp), 2, "abort frames carry service 2");
            return Err(u32::from_le_bytes(body[4..8].try_into().unwrap()));
        }
        assert_eq!(coe_service(&resp), 3, "SDO response service");
        Ok(body)
    }

    /// Uploads `index`:`sub` (complete access with `ca`), following the
    /// transfer type the server chooses.
    pub async fn upload_kind<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        index: u16,
        sub: u8,
        ca: bool,
    ) -> Result<(Vec<u8>, UploadKind), Abort> {
        let [i0, i1] = index.to_le_bytes();
        let cmd = if ca { 0x50 } else { 0x40 };
        let r = self.sdo(sd, &[cmd, i0, i1, sub, 0, 0, 0, 0]).await?;
        assert_eq!(r[0] >> 5, 2, "scs = 2: {r:02x?}");
        assert_eq!(
            (u16::from_le_bytes([r[1], r[2]]), r[3]),
            (index, sub),
            "multiplexer echoed"
        );
        if r[0] & 0x02 != 0 {
            assert!(r[0] & 0x01 != 0, "expedited with size indicator");
            let n = 4 - usize::from((r[0] >> 2) & 3);
            return Ok((r[4..4 + n].to_vec(), UploadKind::Expedited));
        }
        assert!(r[0] & 0x01 != 0, "normal upload with size indicator");
        let size = u32::from_le_bytes(r[4..8].try_into().unwrap()) as usize;
        if r.len() > 8 || size == 0 {
            assert_eq!(
                r.len() - 8,
                size,
                "normal upload: all data in the initiate response"
            );
            return Ok((r[8..].to_vec(), UploadKind::Normal));
        }
        let mut data = Vec::new();
        let mut toggle = false;
        loop {
            let t = if toggle { 0x10 } else { 0 };
            let s = self.sdo(sd, &[0x60 | t, 0, 0, 0, 0, 0, 0, 0]).await?;
            assert_eq!(s[0] >> 5, 0, "scs = 0");
            assert_eq!(s[0] & 0x10, t, "toggle echoed");
            let unused = usize::from((s[0] >> 1) & 7);
            let seg = &s[1..];
            assert!(seg.len() >= 7, "segment of at least 7 bytes");
            data.extend_from_slice(&seg[..seg.len() - unused]);
            if s[0] & 1 != 0 {
                break;
            }
            toggle = !toggle;
        }
        assert_eq!(data.len(), size, "segmented upload delivers the announced size");
        Ok((data, UploadKind::Segmented))
    }

    /// Uploads `index`:`sub`.
    pub async fn upload<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        index: u16,
        sub: u8,
    ) -> Result<Vec<u8>, Abort> {
        self.upload_kind(sd, index, sub, false).await.map(|(d, _)| d)
    }

    /// Expedited download of 1..=4 bytes (command 23h/27h/2Bh/2Fh).
    pub async fn download_expedited<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), Abort> {
        assert!((1..=4).contains(&data.len()));
        let [i0, i1] = index.to_le_bytes();
        let cmd = 0x23 | (((4 - data.len()) as u8) << 2);
        let mut req = vec![cmd, i0, i1, sub, 0, 0, 0, 0];
        req[4..4 + data.len()].copy_from_slice(data);
        self.initiate_download(sd, &req).await
    }

    /// Sends the initiate download request `req` (command, index, sub, …)
    /// and checks the initiate download response (60h, index, sub).
    async fn initiate_download<S>(&mut self, sd: &SubDeviceRef<'_, S>, req: &[u8]) -> Result<(), Abort> {
        let r = self.sdo(sd, req).await?;
        assert_eq!(
            r[..4],
            [0x60, req[1], req[2], req[3]],
            "initiate download response"
        );
        Ok(())
    }

    /// The initiate download request of a normal or segmented download
    /// (command 21h, 31h with complete access) announcing `size` bytes.
    fn initiate_sized(index: u16, sub: u8, size: usize, ca: bool) -> Vec<u8> {
        let [i0, i1] = index.to_le_bytes();
        let cmd = if ca { 0x31 } else { 0x21 };
        let mut req = vec![cmd, i0, i1, sub];
        req.extend_from_slice(&(size as u32).to_le_bytes());
        req
    }

    /// Normal download with the data in the initiate request (command 21h, or
    /// 31h with complete access).
    pub async fn download_normal<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        index: u16,
        sub: u8,
        data: &[u8],
        ca: bool,
    ) -> Result<(), Abort> {
        let mut req = Self::initiate_sized(index, sub, data.len(), ca);
        req.extend_from_slice(data);
        self.initiate_download(sd, &req).await
    }

    /// Expedited download for 1..=4 bytes, normal otherwise.
    pub async fn download<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        index: u16,
        sub: u8,
        data: &[u8],
    ) -> Result<(), Abort> {
        if (1..=4).contains(&data.len()) {
            self.download_expedited(sd, index, sub, data).await
        } else {
            self.download_normal(sd, index, sub, data, false).await
        }
    }

    /// Segmented download in CAN-style 7-byte segments (spec §6.3/§6.4):
    /// initiate 21h (31h with complete access) with the size, then segments
    /// with toggle, n and c. Returns the raw replies (SDO parts) of every step.
    pub async fn download_segmented<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        index: u16,
        sub: u8,
        data: &[u8],
        ca: bool,
    ) -> Result<Vec<Vec<u8>>, Abort> {
        let req = Self::initiate_sized(index, sub, data.len(), ca);
        let mut replies = vec![self.sdo(sd, &req).await?];
        let mut toggle = false;
        let chunks: Vec<&[u8]> = data.chunks(7).collect();
        for (k, chunk) in chunks.iter().enumerate() {
            let last = k + 1 == chunks.len();
            let n = (7 - chunk.len()) as u8;
            let cmd = (u8::from(toggle) << 4) | (n << 1) | u8::from(last);
            let mut seg = vec![cmd];
            seg.extend_from_slice(chunk);
            seg.resize(8, 0);
            replies.push(self.sdo(sd, &seg).await?);
            toggle = !toggle;
        }
        Ok(replies)
    }

    /// An SDO Information request (opcode + data after the 4-byte SDO Info
    /// header); returns the reply's opcode (incomplete bit cleared) and the
    /// data of all fragments joined. An SDO Info error comes back as opcode 7.
    pub async fn info<S>(&mut self, sd: &SubDeviceRef<'_, S>, opcode: u8, data: &[u8]) -> (u8, Vec<u8>) {
        let mut req = vec![0x00, 0x80, opcode, 0, 0, 0];
        req.extend_from_slice(data);
        let mut resp = self.request(sd, &req).await;
        let mut out = Vec::new();
        let mut expected_left: Option<u16> = None;
        loop {
            assert_eq!(coe_service(&resp), 8, "SDO Info service");
            let left = u16::from_le_bytes([resp[4], resp[5]]);
            if let Some(e) = expected_left {
                assert_eq!(left, e, "fragments left counts down");
            }
            assert_eq!(
                resp[2] & 0x80 != 0,
                left > 0,
                "incomplete bit while fragments follow"
            );
            out.extend_from_slice(&resp[6..]);
            if left == 0 {
                return (resp[2] & 0x7F, out);
            }
            expected_left = Some(left - 1);
            resp = match self.mbx.receive(sd).await {
                Some((3, r)) => r,
                other => panic!("missing SDO Info fragment: {other:02x?}"),
            };
        }
    }

    /// Get OD List of `list_type`: the indices.
    pub async fn od_list<S>(&mut self, sd: &SubDeviceRef<'_, S>, list_type: u16) -> Vec<u16> {
        let (op, data) = self.info(sd, 1, &list_type.to_le_bytes()).await;
        assert_eq!(op, 2, "OD list response: {data:02x?}");
        assert_eq!(u16::from_le_bytes([data[0], data[1]]), list_type);
        data[2..]
            .chunks(2)
            .map(|c| u16::from_le_bytes([c[0], c[1]]))
            .collect()
    }

    /// Get Object Description of `index`.
    pub async fn object_desc<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        index: u16,
    ) -> Result<ObjectDesc, Abort> {
        let (op, d) = self.info(sd, 3, &index.to_le_bytes()).await;
        if op == 7 {
            return Err(u32::from_le_bytes(d[0..4].try_into().unwrap()));
        }
        assert_eq!(op, 4);
        assert_eq!(u16::from_le_bytes([d[0], d[1]]), index);
        Ok(ObjectDesc {
            data_type: u16::from_le_bytes([d[2], d[3]]),
            max_sub: d[4],
            code: d[5],
            name: String::from_utf8_lossy(&d[6..]).into_owned(),
        })
    }

    /// Get Entry Description of `index`:`sub` asking for `value_info`;
    /// `value_size` is the byte size of each default/min/max value supplied.
    pub async fn entry_desc<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        index: u16,
        sub: u8,
        value_info: u8,
        value_size: usize,
    ) -> Result<EntryDesc, Abort> {
        let [i0, i1] = index.to_le_bytes();
        let (op, d) = self.info(sd, 5, &[i0, i1, sub, value_info]).await;
        if op == 7 {
            return Err(u32::from_le_bytes(d[0..4].try_into().unwrap()));
        }
        assert_eq!(op, 6);
        assert_eq!((u16::from_le_bytes([d[0], d[1]]), d[2]), (index, sub));
        let supplied = d[3];
        let mut pos = 10;
        let mut values = Vec::new();
        for bit in [0x10u8, 0x20, 0x40] {
            if supplied & bit != 0 {
                values.push(d[pos..pos + value_size].to_vec());
                pos += value_size;
            }
        }
        Ok(EntryDesc {
            value_info: supplied,
            data_type: u16::from_le_bytes([d[4], d[5]]),
            bit_len: u16::from_le_bytes([d[6], d[7]]),
            access: u16::from_le_bytes([d[8], d[9]]),
            values,
            name: String::from_utf8_lossy(&d[pos..]).into_owned(),
        })
    }
}

// ---------------------------------------------------------------------------
// Cyclic process data with the default PDO layout (tests/tests/motion.rs)
// ---------------------------------------------------------------------------

/// A SubDevice of an [`OpGroup`].
pub type OpSubDevice<'a> = SubDeviceRef<'a, ethercrab::SubDevicePdi<'a, 512, ethercrab::DefaultLock>>;

/// A group in Op as [`init`] + `into_op` leave it.
pub type OpGroup = ethercrab::SubDeviceGroup<
    8,
    512,
    ethercrab::DefaultLock,
    ethercrab::subdevice_group::Op,
    ethercrab::subdevice_group::NoDc,
>;

/// One master cycle of the simulated line (the drive's A150 default).
pub const MASTER_CYCLE: Nanos = hil_sim::sim::CONTROL_CYCLE;

/// Standard RxPDO length (C-130): 6040h, 6060h, 607Ah, 60FFh, 60B1h, 60B2h, 6071h, 60FEh:01.
pub const RXPDO_LEN: usize = 23;
/// Standard TxPDO length (C-131).
pub const TXPDO_LEN: usize = 29;

/// The standard TxPDO of axis A as the master received it (C-131 offsets).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct TxPdo {
    /// 6041h statusword @0.
    pub statusword: u16,
    /// 6061h modes of operation display @2.
    pub mode_display: i8,
    /// 6064h position actual value @3, inc.
    pub position: i32,
    /// 606Ch velocity actual value @7, inc/s.
    pub velocity: i32,
    /// 6077h torque actual value @11, 0.1 % of 6076h.
    pub torque: i16,
    /// 60F4h following error actual value @13, inc.
    pub following_error: i32,
    /// 60FDh digital inputs @17.
    pub digital_inputs: u32,
    /// 60E4h:01 additional position actual value @21, inc.
    pub additional_position: i32,
    /// E201 @25.
    pub e201: u16,
    /// A67 user statusword @27.
    pub a67: u16,
}

impl TxPdo {
    /// Decodes the 29-byte standard TxPDO.
    pub fn decode(b: &[u8]) -> Self {
        assert_eq!(b.len(), TXPDO_LEN, "standard TxPDO length");
        let u16_ = |o: usize| u16::from_le_bytes([b[o], b[o + 1]]);
        let i32_ = |o: usize| i32::from_le_bytes([b[o], b[o + 1], b[o + 2], b[o + 3]]);
        Self {
            statusword: u16_(0),
            mode_display: b[2] as i8,
            position: i32_(3),
            velocity: i32_(7),
            torque: u16_(11) as i16,
            following_error: i32_(13),
            digital_inputs: i32_(17) as u32,
            additional_position: i32_(21),
            e201: u16_(25),
            a67: u16_(27),
        }
    }

    /// Statusword bits 0–6 with the CiA 402 state mask 0x6F (bit 4 voltage
    /// enabled is not part of the state).
    pub fn state(&self) -> u16 {
        self.statusword & 0x6F
    }

    /// Statusword bit `n`.
    pub fn bit(&self, n: u8) -> bool {
        self.statusword & (1 << n) != 0
    }
}

/// Statusword patterns (& 0x6F) of the CiA 402 states (C-018).
pub mod sw {
    /// Switch on disabled.
    pub const SOD: u16 = 0x0040;
    /// Ready to switch on.
    pub const RTSO: u16 = 0x0021;
    /// Switched on.
    pub const SO: u16 = 0x0023;
    /// Operation enabled.
    pub const OE: u16 = 0x0027;
    /// Quick stop active.
    pub const QSA: u16 = 0x0007;
    /// Fault reaction active.
    pub const FRA: u16 = 0x000F;
    /// Fault.
    pub const FAULT: u16 = 0x0008;
}

/// A master running the standard process data of one drive in Op: each
/// [`cycle`](Self::cycle) writes the outputs, lets the simulated line run one
/// master cycle (1 ms: the drive's control cycle and polls), then exchanges
/// the process data (one LRW) and decodes the drive's TxPDO.
pub struct Cyclic<'a> {
    /// The drive, its group and master.
    pub link: Link<'a>,
    /// The RxPDO image sent every cycle.
    pub out: [u8; RXPDO_LEN],
    /// The last TxPDO received.
    pub tx: TxPdo,
    /// Master cycles run so far.
    pub cycles: u64,
}

/// Drive `slave` of `group` (in Op) on the simulated line `sim` with the
/// master `md`: what [`Cyclic`] and [`RawCyclic`] exchange process data
/// with.
#[derive(Clone, Copy)]
pub struct Link<'a> {
    /// The master.
    pub md: &'a MainDevice<'a>,
    /// The group in Op.
    pub group: &'a OpGroup,
    /// The simulated line.
    pub sim: &'a RefCell<Simulation>,
    /// Position of the drive in the group.
    pub slave: usize,
}

impl Link<'_> {
    /// The lengths of the drive's outputs and inputs as ethercrab configured
    /// them.
    fn lengths(&self) -> (usize, usize) {
        let sd = self.group.subdevice(self.md, self.slave).expect("subdevice");
        let io = sd.io_raw();
        (io.outputs().len(), io.inputs().len())
    }

    /// One master cycle of the drive: `out` written to its outputs, the
    /// simulated time one master cycle on, the frame exchanged (both its
    /// outputs written and inputs read, WKC 3); `read` of its inputs.
    async fn exchange<R>(&self, out: &[u8], read: impl FnOnce(&[u8]) -> R) -> R {
        let sd = self.group.subdevice(self.md, self.slave).expect("subdevice");
        sd.outputs_raw_mut().copy_from_slice(out);
        {
            let mut sim = self.sim.borrow_mut();
            let t = sim.now() + MASTER_CYCLE;
            sim.advance_to(t);
        }
        let r = self.group.tx_rx(self.md).await.expect("process data cycle");
        assert_eq!(r.working_counter, 3, "outputs written and inputs read");
        let io = sd.io_raw();
        read(io.inputs())
    }
}

impl<'a> Cyclic<'a> {
    /// A master on drive `slave` of `group`; the outputs start all zero
    /// (controlword 0, mode 0).
    pub fn new(
        md: &'a MainDevice<'a>,
        group: &'a OpGroup,
        sim: &'a RefCell<Simulation>,
        slave: usize,
    ) -> Self {
        let link = Link {
            md,
            group,
            sim,
            slave,
        };
        let (o, i) = link.lengths();
        assert_eq!(o, RXPDO_LEN, "standard RxPDO length");
        assert_eq!(i, TXPDO_LEN, "standard TxPDO length");
        Self {
            link,
            out: [0; RXPDO_LEN],
            tx: TxPdo::default(),
            cycles: 0,
        }
    }

    fn put(&mut self, offset: usize, bytes: &[u8]) {
        self.out[offset..offset + bytes.len()].copy_from_slice(bytes);
    }

    /// 6040h controlword @0.
    pub fn set_controlword(&mut self, cw: u16) {
        self.put(0, &cw.to_le_bytes());
    }

    /// The controlword being sent.
    pub fn controlword(&self) -> u16 {
        u16::from_le_bytes([self.out[0], self.out[1]])
    }

    /// 6060h modes of operation @2.
    pub fn set_mode(&mut self, mode: i8) {
        self.out[2] = mode as u8;
    }

    /// 607Ah target position @3, inc.
    pub fn set_target_position(&mut self, p: i32) {
        self.put(3, &p.to_le_bytes());
    }

    /// 60FFh target velocity @7, inc/s.
    pub fn set_target_velocity(&mut self, v: i32) {
        self.put(7, &v.to_le_bytes());
    }

    /// 60B1h velocity offset @11, inc/s.
    pub fn set_velocity_offset(&mut self, v: i32) {
        self.put(11, &v.to_le_bytes());
    }

    /// 60B2h torque offset @15, 0.1 %.
    pub fn set_torque_offset(&mut self, t: i16) {
        self.put(15, &t.to_le_bytes());
    }

    /// 6071h target torque @17, 0.1 %.
    pub fn set_target_torque(&mut self, t: i16) {
        self.put(17, &t.to_le_bytes());
    }

    /// One master cycle; returns the TxPDO received.
    pub async fn cycle(&mut self) -> TxPdo {
        self.tx = self.link.exchange(&self.out, TxPdo::decode).await;
        self.cycles += 1;
        self.tx
    }

    /// `n` master cycles; returns the last TxPDO.
    pub async fn run(&mut self, n: usize) -> TxPdo {
        for _ in 0..n {
            self.cycle().await;
        }
        self.tx
    }

    /// Runs up to `max` cycles until `pred` holds for the TxPDO; returns the
    /// number of cycles it took, `None` if it never held.
    pub async fn run_until(&mut self, max: usize, mut pred: impl FnMut(&TxPdo) -> bool) -> Option<usize> {
        for k in 1..=max {
            let tx = self.cycle().await;
            if pred(&tx) {
                return Some(k);
            }
        }
        None
    }

    /// Sends `cw` until the statusword state (& 0x6F) is `state`, at most
    /// `max` cycles; panics otherwise.
    pub async fn command(&mut self, cw: u16, state: u16, max: usize) -> TxPdo {
        self.set_controlword(cw);
        let ok = self.run_until(max, |t| t.state() == state).await;
        assert!(
            ok.is_some(),
            "controlword {cw:#06x}: statusword {:#06x}, expected state {state:#06x}",
            self.tx.statusword
        );
        self.tx
    }

    /// Shutdown (6), switch on (7), enable operation (15), each until its
    /// state shows in the TxPDO.
    pub async fn enable(&mut self) -> TxPdo {
        self.command(0x0006, sw::RTSO, 20).await;
        self.command(0x0007, sw::SO, 20).await;
        self.command(0x000F, sw::OE, 20).await
    }

    /// Controlword 0 for two cycles, the fault reset (bit 7) until Switch on
    /// disabled ([`Self::command`], 20 cycles at most), 0 for two cycles,
    /// then [`Self::enable`].
    pub async fn reset_and_enable(&mut self) -> TxPdo {
        self.set_controlword(0);
        self.run(2).await;
        self.command(axis::CW_FAULT_RESET, sw::SOD, 20).await;
        self.set_controlword(0);
        self.run(2).await;
        self.enable().await
    }

    /// Enabled in csv ([`Self::enable_in`] 9), then `n` cycles at the target
    /// velocity `v` (inc/s).
    pub async fn csv_at(&mut self, v: i32, n: usize) -> TxPdo {
        self.enable_in(9).await;
        self.set_target_velocity(v);
        self.run(n).await
    }

    /// Enabled in csv ([`Self::enable_in`] 9) at the target velocity `v`
    /// (inc/s) until the axis runs within 1/20 rev/s of it (500 cycles at
    /// most; panics otherwise), then 20 cycles more.
    pub async fn csv_reach(&mut self, v: i32) -> TxPdo {
        self.enable_in(9).await;
        self.set_target_velocity(v);
        self.run_until(500, |t| (t.velocity - v).abs() < REV / 20)
            .await
            .unwrap_or_else(|| panic!("running at {v} inc/s"));
        self.run(20).await
    }

    /// Mode `mode` (6060h) for three cycles, then [`Self::enable`].
    pub async fn enable_in(&mut self, mode: i8) -> TxPdo {
        self.set_mode(mode);
        self.run(3).await;
        self.enable().await
    }

    /// Simulated time.
    pub fn now(&self) -> Nanos {
        self.link.sim.borrow().now()
    }
}

// ---------------------------------------------------------------------------
// Cyclic process data with a remapped layout (tests/tests/motion_more.rs)
// ---------------------------------------------------------------------------

/// Writes the mode map `layout` of axis A into 1600h/1A00h by SDO (Pre-Op),
/// the CiA 301 sequence a master's start-up list uses.
pub async fn map_layout<S>(sd: &SubDeviceRef<'_, S>, layout: drive_ecat::PdoLayout)
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    let (rx, tx) = layout.entries();
    for (pdo, entries) in [(0x1600u16, rx), (0x1A00, tx)] {
        let entries: Vec<u32> = entries.iter().map(|e| e.mapping_value()).collect();
        map_pdo(sd, pdo, &entries).await;
    }
}

/// Writes the mapping `entries` (index << 16 | sub << 8 | bits) into `pdo`
/// by SDO (Pre-Op) as a master's start-up list does: sub 0 = 0, the
/// entries from sub 1, sub 0 = their number.
pub async fn map_pdo<S>(sd: &SubDeviceRef<'_, S>, pdo: u16, entries: &[u32])
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    sd.sdo_write(pdo, 0, 0u8).await.expect("sub 0 = 0");
    for (sub, &e) in (1u8..).zip(entries) {
        sd.sdo_write(pdo, sub, e).await.expect("entry");
    }
    sd.sdo_write(pdo, 0, entries.len() as u8)
        .await
        .expect("sub 0 = n");
}

/// A master running any process image of one drive in Op as raw bytes (the
/// ip and vl maps): like [`Cyclic`], without the standard layout. The
/// controlword sits at byte 0 and 6060h at byte 2 of the RxPDO, the
/// statusword at byte 0 of the TxPDO in every map.
pub struct RawCyclic<'a> {
    /// The drive, its group and master.
    pub link: Link<'a>,
    /// The RxPDO image sent every cycle.
    pub out: Vec<u8>,
    /// The last TxPDO received.
    pub inputs: Vec<u8>,
    /// Master cycles run so far.
    pub cycles: u64,
}

impl<'a> RawCyclic<'a> {
    /// A master on the drive of `link` with the lengths ethercrab
    /// configured; the outputs start all zero.
    pub fn new(link: Link<'a>) -> Self {
        let (o, i) = link.lengths();
        Self {
            link,
            out: vec![0; o],
            inputs: vec![0; i],
            cycles: 0,
        }
    }

    /// Writes `bytes` into the RxPDO at `offset`.
    pub fn put(&mut self, offset: usize, bytes: &[u8]) {
        self.out[offset..offset + bytes.len()].copy_from_slice(bytes);
    }

    /// 6040h controlword @0.
    pub fn set_controlword(&mut self, cw: u16) {
        self.put(0, &cw.to_le_bytes());
    }

    /// 6060h modes of operation @2.
    pub fn set_mode(&mut self, mode: i8) {
        self.out[2] = mode as u8;
    }

    /// TxPDO u16 at `o`.
    pub fn u16_at(&self, o: usize) -> u16 {
        u16::from_le_bytes([self.inputs[o], self.inputs[o + 1]])
    }

    /// TxPDO i16 at `o`.
    pub fn i16_at(&self, o: usize) -> i16 {
        self.u16_at(o) as i16
    }

    /// TxPDO i32 at `o`.
    pub fn i32_at(&self, o: usize) -> i32 {
        i32::from_le_bytes(self.inputs[o..o + 4].try_into().expect("4 bytes"))
    }

    /// 6041h statusword @0.
    pub fn statusword(&self) -> u16 {
        self.u16_at(0)
    }

    /// Statusword & 0x6F.
    pub fn state(&self) -> u16 {
        self.statusword() & 0x6F
    }

    /// Statusword bit `n`.
    pub fn bit(&self, n: u8) -> bool {
        self.statusword() & (1 << n) != 0
    }

    /// 6061h @2.
    pub fn mode_display(&self) -> i8 {
        self.inputs[2] as i8
    }

    /// One master cycle (see [`Cyclic::cycle`]).
    pub async fn cycle(&mut self) {
        let inputs = &mut self.inputs;
        self.link.exchange(&self.out, |i| inputs.copy_from_slice(i)).await;
        self.cycles += 1;
    }

    /// `n` master cycles.
    pub async fn run(&mut self, n: usize) {
        for _ in 0..n {
            self.cycle().await;
        }
    }

    /// Runs up to `max` cycles until `pred` holds; returns the cycles it took.
    pub async fn run_until(&mut self, max: usize, mut pred: impl FnMut(&Self) -> bool) -> Option<usize> {
        for k in 1..=max {
            self.cycle().await;
            if pred(self) {
                return Some(k);
            }
        }
        None
    }

    /// Shutdown, switch on, enable operation (the bits in `extra` added to
    /// enable operation), each until its state shows.
    pub async fn enable(&mut self, extra: u16) {
        for (cw, state) in [(0x0006, sw::RTSO), (0x0007, sw::SO), (0x000F | extra, sw::OE)] {
            self.set_controlword(cw);
            let ok = self.run_until(20, |c| c.state() == state).await;
            assert!(
                ok.is_some(),
                "controlword {cw:#06x}: statusword {:#06x}",
                self.statusword()
            );
        }
    }
}

// ---------------------------------------------------------------------------
// FoE firmware update (tests/tests/foe.rs): a drive with firmware slots and
// an FoE client over `RawMailbox` (ethercrab 0.7.1 has no FoE)
// ---------------------------------------------------------------------------

/// The firmware flash of [`FwNode`] (hil-sim's).
pub use hil_sim::sim::FirmwareFlash as FwFlash;

/// The firmware slots of a [`FwNode`].
pub type FwSlots = drive_ecat::boot::BootSlots<FwFlash>;

/// The secret seed of the development key pair (`keys/dev-ed25519.key`),
/// whose public key the drive trusts in the simulator.
pub fn dev_seed() -> [u8; 32] {
    drive_ecat::boot::parse_key_hex(include_str!("../keys/dev-ed25519.key")).expect("keys/dev-ed25519.key")
}

/// The load address of `slot` of a [`FwNode`]'s firmware flash.
pub fn fw_load_address(slot: drive_ecat::boot::Slot) -> u32 {
    FwSlots::new(FwFlash::new()).load_address(slot)
}

/// An image file as the master downloads it: the signed header v2 (length,
/// CRC-32, `version`, the load address of slot B, security counter 1, the
/// development key's signature) and a body of `len` bytes derived from
/// `version`. Slot B is where a [`FwNode::factory`] drive downloads to.
pub fn firmware_file(version: u32, len: usize) -> Vec<u8> {
    signed_file(drive_ecat::boot::Slot::B, version, 1, len, &dev_seed())
}

/// [`firmware_file`] for `slot` with security counter `counter`, signed with `seed`.
pub fn signed_file(
    slot: drive_ecat::boot::Slot,
    version: u32,
    counter: u32,
    len: usize,
    seed: &[u8; 32],
) -> Vec<u8> {
    let body = hil_sim::sim::firmware_body(len, version);
    let mut h = drive_ecat::boot::ImageHeader::for_body(&body, version, fw_load_address(slot), counter);
    h.sign(&body, seed);
    let mut f = h.to_bytes().to_vec();
    f.extend_from_slice(&body);
    f
}

/// A drive with firmware slots behind a simulated ESC (communication only:
/// no motors). [`FwNode::power_cycle`] runs the boot decision again.
pub struct FwNode {
    /// The simulated ESC.
    pub esc: hil_sim::esc::Esc,
    /// The drive runtime with its firmware slots.
    pub drive: drive_ecat::runtime::Drive<hil_sim::sim::SimFlash, FwFlash>,
    /// What the last boot started.
    pub boot: Option<drive_ecat::boot::Decision>,
}

impl FwNode {
    /// Powers on with `param` (parameter flash) and `fw` (firmware flash):
    /// the boot decision, then the drive.
    pub fn power_on(param: hil_sim::sim::SimFlash, fw: FwFlash) -> Self {
        let mut slots = FwSlots::new(fw);
        let boot = slots
            .boot_verified(&drive_ecat::runtime::FIRMWARE_PUBLIC_KEY, 0)
            .expect("boot: read the slots");
        let mut sii = [0u8; ecat::sii::EEPROM_BYTES];
        let n = ecat::build_sii(&drive_ecat::DEVICE, &mut sii).expect("SII");
        Self {
            esc: hil_sim::esc::Esc::new(hil_sim::esc::EscConfig::default(), &sii[..n]),
            drive: drive_ecat::runtime::Drive::with_boot(param, Some(slots)),
            boot,
        }
    }

    /// A drive whose slot A holds a confirmed image of `factory_len` body
    /// bytes, version 1, security counter 1 (the firmware it was delivered with).
    pub fn factory(factory_len: usize) -> Self {
        let mut slots = FwSlots::new(FwFlash::new());
        slots.boot().expect("boot");
        slots.begin().expect("begin");
        let file = signed_file(drive_ecat::boot::Slot::A, 1, 1, factory_len, &dev_seed());
        slots.write(&file).expect("write");
        slots
            .finish_verified(&drive_ecat::runtime::FIRMWARE_PUBLIC_KEY)
            .expect("finish");
        let mut slots = FwSlots::new(slots.into_inner());
        slots.boot().expect("boot");
        slots.confirm().expect("confirm");
        Self::power_on(hil_sim::sim::SimFlash::new(), slots.into_inner())
    }

    /// Switches off and on: only the flashes stay; the boot decides anew.
    pub fn power_cycle(&mut self) {
        let old = std::mem::replace(
            self,
            Self {
                esc: hil_sim::esc::Esc::new(hil_sim::esc::EscConfig::default(), &[]),
                drive: drive_ecat::runtime::Drive::with_boot(hil_sim::sim::SimFlash::new(), None),
                boot: None,
            },
        );
        let (param, fw) = old.drive.into_flashes();
        *self = Self::power_on(param.expect("parameter flash"), fw.expect("firmware flash"));
    }

    /// The firmware slots.
    pub fn slots(&mut self) -> &mut FwSlots {
        self.drive.boot_slots_mut().expect("slots")
    }
}

impl hil_sim::sim::Node for FwNode {
    fn esc_mut(&mut self) -> &mut hil_sim::esc::Esc {
        &mut self.esc
    }
    fn poll(&mut self, now: Nanos) {
        self.esc.tick(now);
        let _ = self.drive.poll(&mut self.esc.pdi(), now);
        if self.drive.restart_due(now) {
            // A09: the device restarts as after a power cycle
            self.power_cycle();
        }
    }
}

/// Pre-Op (ethercrab's init) → Init → Bootstrap.
pub async fn to_boot<S>(sd: &SubDeviceRef<'_, S>) {
    request(sd, al::INIT).await;
    assert_eq!(al_status(sd).await, (al::INIT, 0));
    request(sd, al::BOOT).await;
    assert_eq!(al_status(sd).await, (al::BOOT, 0), "Init -> Bootstrap");
}

/// Runs `body` against the first drive in Bootstrap (and requests Init afterwards).
pub fn in_boot<N: hil_sim::sim::Node, T>(
    sim: &RefCell<Simulation<N>>,
    body: impl for<'a> AsyncFnOnce(&'a MainDevice<'a>, SubDeviceRef<'a, &'a ethercrab::SubDevice>) -> T,
) -> T {
    with_master_on(sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        to_boot(&sd).await;
        let r = body(md, sd).await;
        // back to Init (what a master does after the download)
        request(&group.subdevice(md, 0).unwrap(), al::INIT).await;
        r
    })
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

/// An FoE reply as the client sees it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FoeReply {
    /// ACK with the packet number.
    Ack(u32),
    /// ERROR with the code.
    Error(u32),
    /// BUSY (done, entire).
    Busy(u16, u16),
    /// Something else: mailbox type and data.
    Other(u8, Vec<u8>),
    /// No reply.
    None,
}

/// An FoE client (ETG.1000.6 §5.8) over [`RawMailbox`]: write requests and
/// data packets of `MAILBOX_LEN − 12` bytes.
#[derive(Default)]
pub struct FoeClient {
    mbx: RawMailbox,
    /// BUSY replies seen.
    pub busy: u32,
}

impl FoeClient {
    /// Data bytes per full DATA packet.
    pub const SEGMENT: usize = MAILBOX_LEN - 12;

    /// A fresh client.
    pub fn new() -> Self {
        Self::default()
    }

    /// Sends one FoE message: opcode, the 32-bit field, then `data`.
    pub async fn send<S>(&mut self, sd: &SubDeviceRef<'_, S>, op: u8, field: u32, data: &[u8]) -> FoeReply {
        let mut req = vec![op, 0];
        req.extend_from_slice(&field.to_le_bytes());
        req.extend_from_slice(data);
        match self.mbx.exchange(sd, 4, &req).await {
            Some((4, r)) if r.len() >= 6 => {
                let field = u32::from_le_bytes([r[2], r[3], r[4], r[5]]);
                match r[0] {
                    4 => FoeReply::Ack(field),
                    5 => FoeReply::Error(field),
                    6 => FoeReply::Busy(field as u16, (field >> 16) as u16),
                    _ => FoeReply::Other(4, r),
                }
            }
            Some((kind, r)) => FoeReply::Other(kind, r),
            None => FoeReply::None,
        }
    }

    /// Write request for `name`.
    pub async fn write_request<S>(&mut self, sd: &SubDeviceRef<'_, S>, name: &str) -> FoeReply {
        self.send(sd, 2, 0, name.as_bytes()).await
    }

    /// DATA packet `n` (a BUSY reply is retried with the same packet).
    pub async fn data<S>(&mut self, sd: &SubDeviceRef<'_, S>, n: u32, data: &[u8]) -> FoeReply {
        loop {
            match self.send(sd, 3, n, data).await {
                FoeReply::Busy(..) => self.busy += 1,
                r => return r,
            }
        }
    }

    /// Writes the whole file: write request, DATA packets 1, 2, … (an empty
    /// last one when the length is a multiple of [`Self::SEGMENT`]). Returns
    /// the packets sent, or the first reply that is not the expected ACK.
    pub async fn write_file<S>(
        &mut self,
        sd: &SubDeviceRef<'_, S>,
        name: &str,
        file: &[u8],
    ) -> Result<u32, FoeReply> {
        match self.write_request(sd, name).await {
            FoeReply::Ack(0) => {}
            r => return Err(r),
        }
        let mut chunks: Vec<&[u8]> = file.chunks(Self::SEGMENT).collect();
        if file.len() % Self::SEGMENT == 0 {
            chunks.push(&[]);
        }
        for (i, c) in chunks.iter().enumerate() {
            let n = i as u32 + 1;
            match self.data(sd, n, c).await {
                FoeReply::Ack(a) if a == n => {}
                r => return Err(r),
            }
        }
        Ok(chunks.len() as u32)
    }
}
