//! What each RTIC task does, independent of the board.
//!
//! | task | trigger | priority | body |
//! |---|---|---|---|
//! | `sync0` | ESC SYNC0 output | 3 | [`sync0`]: acknowledge, PLL measurement |
//! | `control` | control-cycle timer | 3 | [`control`]: one cycle of both axes, then [`scope`]: the scope's sample |
//! | `esc` | ESC PDI interrupt (AL event) | 2 | [`esc_event`]: ESM, process data, monitoring |
//! | `mailbox` | pended by `esc`, and by `idle` when the IP stack's timers are due | 1 | [`mailbox_net`]: one CoE/EoE/FoE request, EMCY, the IP stack ([`mailbox`] without it; the board answers group T through its recorder, [`mailbox_scoped`]) |
//! | `idle` | — | 0 | [`background`]: a requested save, the flash written outside the drive's lock (QEMU: also the simulated world) |
//!
//! `sync0` and `control` share the priority so they never preempt each
//! other (both touch the PLL); `esc` locks the drive for one poll without
//! the mailbox, `mailbox` for one request, then for the IP stack's poll,
//! then for the answer's first fragment. See docs/architecture.md for the
//! worst-case paths.

use core::borrow::BorrowMut;

use drive_ecat::axis::{AxisCommand, AxisIo};
use ecat::StateChange;
use esc::{regs, Pdi, PdiExt};
use nanos::Nanos;
use rtic_core::Mutex;

use crate::cycle::CycleTimer;
pub use crate::net::NetPoll;
use crate::Drive;

/// SYNC0 at local time `now`: reads 0x098E (acknowledges the pulse in
/// the ESC), hands the edge to the PLL and lets the timer follow it.
pub fn sync0<P: Pdi>(
    drive: &mut Drive,
    timer: &mut CycleTimer,
    pdi: &mut P,
    now: Nanos,
) -> Result<(), P::Error> {
    let _ack = pdi.read_u8(regs::dc::SYNC0_STATUS)?;
    drive.on_sync0(pdi, now)?;
    timer.follow_pll(drive);
    Ok(())
}

/// The control-cycle timer fired at local time `now`: one cycle of both
/// axes with the hardware inputs `io`; returns the power-stage commands.
pub fn control(drive: &mut Drive, timer: &mut CycleTimer, now: Nanos, io: &[AxisIo; 2]) -> [AxisCommand; 2] {
    timer.run(drive, now, io)
}

/// The ESC's PDI interrupt at local time `now`: an SM2 frame is handed to
/// the PLL's frame timing (A261), then the slave stack runs once (AL
/// control, process data, monitoring; the mailbox is the [`mailbox`]
/// task's). Returns the ESM change.
pub fn esc_event<P: Pdi>(
    drive: &mut Drive,
    timer: &mut CycleTimer,
    pdi: &mut P,
    now: Nanos,
) -> Result<Option<StateChange>, P::Error> {
    if pdi.al_event()? & regs::al_event::sm(2) != 0 {
        let _ = drive.on_frame(now);
    }
    let change = drive.poll_esc(pdi, now)?;
    timer.follow_pll(drive);
    Ok(change)
}

/// The mailbox task at local time `now` (pended by the ESC task, runs
/// below it): one mailbox request from SM0 answered into SM1, queued EMCYs
/// and EoE fragments sent.
pub fn mailbox<P: Pdi>(drive: &mut Drive, pdi: &mut P, now: Nanos) -> Result<(), P::Error> {
    drive.poll_mailbox(pdi, now)
}

/// The mailbox task with the IP stack at local time `now`: the mailbox
/// request ([`mailbox`]), then the stack takes the Ethernet frames it
/// brought and queues its answers, then a second mailbox poll puts the
/// first answer fragment into SM1 if it is free (the master's next read
/// raises the next ESC event, which pends this task again for the rest).
/// Also run when the stack's own timers are due ([`NetPoll::poll_at`]).
/// With [`NoNet`](crate::net::NoNet) it is [`mailbox`].
///
/// The firmware's mailbox task runs the same three steps with the drive
/// locked for each on its own ([`mailbox`], [`NetPoll::poll`], [`mailbox`]):
/// the control cycle and the ESC task, which lock the drive too, then wait
/// for one step at most (the stack's poll with a UDP parameter request, about
/// 11,000 instructions on QEMU) instead of the whole run (about 15,000;
/// docs/architecture.md, CPU load). The steps touch nothing the higher tasks
/// hand over between them: the mailbox, the EoE queue and the stack.
pub fn mailbox_net<P: Pdi, N: NetPoll>(
    drive: &mut Drive,
    net: &mut N,
    pdi: &mut P,
    now: Nanos,
) -> Result<(), P::Error> {
    drive.poll_mailbox(pdi, now)?;
    if N::ACTIVE {
        net.poll(drive, now);
        drive.poll_mailbox(pdi, now)?;
    }
    Ok(())
}

/// The drive's scope (group T, issue 35) as the firmware holds it: the
/// recorder over a buffer in a RAM bank of its own (the board's DSRAM2,
/// section `.scope_ram`).
pub type Scope = drive_ecat::scope::Recorder<&'static mut [u32]>;

/// After the control cycle: one scope sample of the cycle just run (the
/// objects' values and both axes' internal signals on the inputs `io`).
/// One compare and branch while the recorder is idle or complete.
pub fn scope<S: AsRef<[u32]> + AsMut<[u32]>>(
    drive: &Drive,
    scope: &mut drive_ecat::scope::Recorder<S>,
    io: &[AxisIo; 2],
) {
    scope.sample(drive.objects(), || {
        let [a, b] = drive.axes();
        let s = drive_ecat::scope::Signals::of;
        [s(a, &io[0]), s(b, &io[1])]
    });
}

/// [`mailbox`] with the scope: its objects (group T) are read and written
/// through the recorder (without it they answer 0800 0022h); a trace armed
/// by the request gets its channels' accesses prepared here
/// ([`Recorder::prepare`](drive_ecat::scope::Recorder::prepare)).
pub fn mailbox_scoped<P: Pdi, S: AsRef<[u32]> + AsMut<[u32]>>(
    drive: &mut Drive,
    scope: &mut drive_ecat::scope::Recorder<S>,
    pdi: &mut P,
    now: Nanos,
) -> Result<(), P::Error> {
    drive.poll_mailbox_with(pdi, now, scope)?;
    // a trace armed by this request: its channels' accesses here, not in
    // the control cycle's first sample
    scope.prepare(drive.objects());
    Ok(())
}

/// Background work from the idle loop: a save requested over the bus (A00,
/// 1010h) is written to the parameter store. The drive is locked only to
/// take the values and the store out
/// ([`Drive::begin_save`](drive_ecat::runtime::Drive::begin_save)) and to hand
/// the store back with the result; the flash is erased and programmed
/// without the lock, so the control and ESC tasks keep running.
/// (The resource holds the drive or, in the firmware, a `&'static mut` to
/// it.)
pub fn background<D: BorrowMut<Drive>>(drive: &mut impl Mutex<T = D>) {
    if let Some(mut job) = drive.lock(|d| d.borrow_mut().begin_save()) {
        job.write();
        drive.lock(|d| d.borrow_mut().end_save(job));
    }
}

/// The running firmware image's confirmation point (issue 18, docs/flashing.md
/// "Boot flow"), called from the idle loop until it returns `true`: the first
/// time the EtherCAT state machine is in Op — a master configured the drive and
/// exchanges process data with this image, so the image runs and can be reached
/// for the next update — the image confirms itself
/// ([`Drive::confirm_firmware`](drive_ecat::runtime::Drive::confirm_firmware)): an
/// image on trial is kept from then on instead of being rolled back at the next
/// reset. A drive without firmware slots has nothing to confirm (still `true`
/// once in Op).
pub fn confirm_point(drive: &mut Drive) -> bool {
    if drive.slave().state() != esc::AlState::Op {
        return false;
    }
    let _ = drive.confirm_firmware();
    true
}
