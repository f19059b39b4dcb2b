//! The in-process link between a real EtherCAT master (`ethercrab`) and the
//! simulated line: every frame the master sends goes through
//! [`Simulation::exchange`] and comes straight back, no network, no root.

use crate::sim::{Node, SimDrive, Simulation};
use core::cell::RefCell;
use core::future::Future;
use core::pin::Pin;
use core::sync::atomic::{AtomicU64, Ordering};
use core::task::{Context, Poll};
use ethercrab::{PduRx, PduTx};

/// Longest Ethernet frame the link carries.
const MAX_FRAME: usize = 1536;

/// A future that moves frames between ethercrab's PDU loop and the simulation.
/// It never completes: race it against the master's work
/// (`futures_lite::future::or`).
pub struct InProcessLink<'a, N: Node = SimDrive> {
    tx: PduTx<'a>,
    rx: PduRx<'a>,
    sim: &'a RefCell<Simulation<N>>,
    clock: &'a AtomicU64,
}

impl<'a, N: Node> InProcessLink<'a, N> {
    /// Connects the master's PDU loop halves to `sim`; `clock` is updated with the
    /// simulated time after every frame (hand `|| clock.load(..)` to ethercrab as its time source).
    pub fn new(tx: PduTx<'a>, rx: PduRx<'a>, sim: &'a RefCell<Simulation<N>>, clock: &'a AtomicU64) -> Self {
        Self { tx, rx, sim, clock }
    }
}

impl<N: Node> Future for InProcessLink<'_, N> {
    type Output = ();

    fn poll(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<()> {
        self.tx.replace_waker(cx.waker());
        while let Some(frame) = self.tx.next_sendable_frame() {
            let mut buf = [0u8; MAX_FRAME];
            let mut len = 0;
            let sent = frame.send_blocking(|bytes| {
                len = bytes.len().min(MAX_FRAME);
                buf[..len].copy_from_slice(&bytes[..len]);
                Ok(len)
            });
            if sent.is_err() {
                continue;
            }
            let now = {
                let mut sim = self.sim.borrow_mut();
                sim.exchange(&mut buf[..len]);
                sim.now().as_ns()
            };
            self.clock.store(now, Ordering::Relaxed);
            // A frame the master no longer waits for (timed out) is dropped by ethercrab.
            let _ = self.rx.receive_frame(&buf[..len]);
        }
        Poll::Pending
    }
}

/// Timeouts for an in-process master. ethercrab measures them on the wall
/// clock, but the simulated line answers every frame at once, so they only
/// fire when the host is loaded or the slave really stays silent: generous.
pub fn in_process_timeouts() -> ethercrab::Timeouts {
    use std::time::Duration;
    ethercrab::Timeouts {
        state_transition: Duration::from_secs(2),
        pdu: Duration::from_secs(1),
        eeprom: Duration::from_secs(1),
        wait_loop_delay: Duration::ZERO,
        mailbox_echo: Duration::from_secs(1),
        mailbox_response: Duration::from_millis(500),
    }
}

/// Frames in flight the in-process master can hold.
pub const MAX_FRAMES: usize = 16;
/// Largest PDU payload of one frame.
pub const MAX_PDU_DATA: usize = ethercrab::PduStorage::element_size(1100);

/// Runs `body` with an ethercrab [`MainDevice`](ethercrab::MainDevice) wired to
/// `sim` in-process, on the current thread, and returns its result. The
/// master's time source is the simulated clock (`clock` in the closure; hand
/// `|| clock.load(Ordering::Relaxed)` to `init_single_group`).
pub fn run<N: Node, T, F>(sim: &RefCell<Simulation<N>>, timeouts: ethercrab::Timeouts, body: F) -> T
where
    F: for<'a> AsyncFnOnce(&'a ethercrab::MainDevice<'a>, &'a AtomicU64) -> T,
{
    run_with(sim, timeouts, ethercrab::MainDeviceConfig::default(), body)
}

/// [`run`] with the [`in_process_timeouts`] and ethercrab's default
/// configuration (its DC start-up sends 10 000 static drift-compensation
/// frames).
pub fn run_in_process<N: Node, T, F>(sim: &RefCell<Simulation<N>>, body: F) -> T
where
    F: for<'a> AsyncFnOnce(&'a ethercrab::MainDevice<'a>, &'a AtomicU64) -> T,
{
    run(sim, in_process_timeouts(), body)
}

/// [`run`] with a master configuration (e.g. fewer DC static-sync frames in tests).
pub fn run_with<N: Node, T, F>(
    sim: &RefCell<Simulation<N>>,
    timeouts: ethercrab::Timeouts,
    config: ethercrab::MainDeviceConfig,
    body: F,
) -> T
where
    F: for<'a> AsyncFnOnce(&'a ethercrab::MainDevice<'a>, &'a AtomicU64) -> T,
{
    let storage = ethercrab::PduStorage::<MAX_FRAMES, MAX_PDU_DATA>::new();
    let Ok((tx, rx, pdu_loop)) = storage.try_split() else {
        unreachable!("a fresh PduStorage splits once")
    };
    let clock = AtomicU64::new(sim.borrow().now().as_ns());
    let md = ethercrab::MainDevice::new(pdu_loop, timeouts, config);
    let link = InProcessLink::new(tx, rx, sim, &clock);
    futures_lite::future::block_on(futures_lite::future::or(
        async {
            link.await;
            unreachable!("the in-process link never completes")
        },
        body(&md, &clock),
    ))
}

/// Runs `body` with the first SubDevice of `sim`'s line (brought up as one
/// group of at most 2 SubDevices and 64 bytes of process data, with 100 DC
/// static-sync frames and the [`in_process_timeouts`]) and the master's
/// clock; its result, or the master's error bringing the line up.
pub fn with_first_subdevice<N: Node, T>(
    sim: &RefCell<Simulation<N>>,
    body: impl for<'g> AsyncFnOnce(ethercrab::SubDeviceRef<'g, &'g ethercrab::SubDevice>, &'g AtomicU64) -> T,
) -> Result<T, ethercrab::error::Error> {
    let config = ethercrab::MainDeviceConfig {
        dc_static_sync_iterations: 100,
        ..Default::default()
    };
    run_with(sim, in_process_timeouts(), config, async |md, clock| {
        let group = md
            .init_single_group::<2, 64>(|| clock.load(Ordering::Relaxed))
            .await?;
        let sd = group.subdevice(md, 0)?;
        Ok(body(sd, clock).await)
    })
}

/// A SubDevice of a group in PRE-OP with its process data image.
pub type PdiSubDevice<'a, const PDI: usize> =
    ethercrab::SubDeviceRef<'a, ethercrab::SubDevicePdi<'a, PDI, ethercrab::DefaultLock>>;

/// `group` (in PRE-OP, as ethercrab's init leaves it) with SYNC0 on every
/// SubDevice, brought into PRE-OP with its process data image, `pre_op` run
/// on each SubDevice there, then the DC configuration `dc` written: the
/// group ready for its way to OP; the master's error on the way.
pub async fn into_dc_sync0<const MAX: usize, const PDI: usize>(
    md: &ethercrab::MainDevice<'_>,
    mut group: ethercrab::SubDeviceGroup<MAX, PDI>,
    dc: ethercrab::subdevice_group::DcConfiguration,
    pre_op: impl for<'b> AsyncFn(&'b PdiSubDevice<'b, PDI>),
) -> Result<
    ethercrab::SubDeviceGroup<
        MAX,
        PDI,
        ethercrab::DefaultLock,
        ethercrab::subdevice_group::PreOpPdi,
        ethercrab::subdevice_group::HasDc,
    >,
    ethercrab::error::Error,
> {
    for mut sd in group.iter_mut(md) {
        sd.set_dc_sync(ethercrab::DcSync::Sync0);
    }
    let group = group.into_pre_op_pdi(md).await?;
    for sd in group.iter(md) {
        pre_op(&sd).await;
    }
    group.configure_dc_sync(md, dc).await
}
