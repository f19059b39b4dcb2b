//! Board-independent parts of the RTIC application.
//!
//! The RTIC apps (`src/main.rs` for the reference board, `src/bin/qemu.rs` for
//! QEMU) only wire interrupts, priorities and the board's counters; the task
//! bodies live in the host-tested `node` crate (re-exported here), so both
//! images run the same code. `world` (QEMU only, from `hil-sim`) is the
//! simulated ESC, motors and scripted master that stand in for the bus and
//! the power stage.
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

pub use node::{clock, cycle, net, tasks, Drive, ParamFlash};

/// The simulated world of the QEMU image.
#[cfg(feature = "qemu")]
pub use hil_sim::world;
