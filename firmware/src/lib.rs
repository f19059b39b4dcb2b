//! Board-independent parts of the RTIC application.
//!
//! The RTIC apps (`src/main.rs` for the reference board, `src/bin/qemu.rs` for
//! QEMU) only wire interrupts, priorities and the board's counters; the task
//! bodies live in the host-tested `firmware-tasks` crate (re-exported here), so both
//! images run the same code. `world` (QEMU only, from `hil-sim`) is the
//! simulated ESC, motors and scripted master that stand in for the bus and
//! the power stage. What several images share besides (statics built in
//! place, the board's power stage and panic stop, the QEMU images' SysTick
//! measurement and exit, the PROFINET event log, the boot loaders' jump)
//! is here once, each part behind the features of the images that use it.
#![no_std]
#![deny(unsafe_code)]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]

pub use firmware_tasks::{clock, cycle, net, tasks, Drive, ParamFlash};

pub mod once;

#[cfg(any(feature = "board", feature = "board-pn"))]
pub mod xmc;

#[cfg(any(
    feature = "qemu",
    feature = "qemu-pn",
    feature = "boot-mps2",
    feature = "mps2-foc"
))]
pub mod systick;

#[cfg(any(
    feature = "qemu",
    feature = "qemu-pn",
    feature = "mps2-pn",
    feature = "boot-mps2",
    feature = "mps2-slot",
    feature = "mps2-foc"
))]
pub mod semihost;

#[cfg(any(feature = "board-pn", feature = "mps2-pn"))]
pub mod pn_log;

/// The IP stack on `drive`'s EoE queue (docs/eoe.md) in its statics
/// (buffers, socket slots, the stack itself: built in place like the
/// drive), for the images that run it (`firmware-net`, the QEMU image).
#[cfg(any(feature = "net", feature = "qemu"))]
#[inline(never)]
pub fn make_net(drive: &mut Drive) -> Option<&'static mut net::NodeNet> {
    use crate::net::{NetBuffers, NodeNet, SocketSlots, BOARD_NET, EMPTY_SLOTS};
    static NET: once::Once<NodeNet> = once::Once::new();
    let slot = NET.take()?;
    let bufs = cortex_m::singleton!(: NetBuffers = NetBuffers::new())?;
    let slots = cortex_m::singleton!(: SocketSlots<'static> = EMPTY_SLOTS)?;
    Some(slot.write(NodeNet::new(drive, BOARD_NET, bufs, slots, nanos::Nanos::ZERO)))
}

#[cfg(any(feature = "boot-board", feature = "boot-mps2"))]
mod boot_start;
#[cfg(any(feature = "boot-board", feature = "boot-mps2"))]
pub use boot_start::start_image;

/// The simulated world of the QEMU image.
#[cfg(feature = "qemu")]
pub use hil_sim::world;
