//! The firmware's board-independent task bodies.
//!
//! The RTIC applications in `firmware/` (reference board and QEMU) only wire
//! interrupts, priorities and the board's counters; what each task does is
//! here, generic over the board's [`esc::Pdi`], so it runs — and is tested —
//! on the host too:
//!
//! - [`clock::Clock`]: a wrapping hardware counter extended to 64-bit ns;
//! - [`cycle::CycleTimer`]: the control-cycle timer that follows the
//!   DC-Sync PLL (free-running at A150 without SYNC0);
//! - [`tasks`]: SYNC0, control cycle and ESC event;
//! - [`net`]: the IP stack on the EoE interface, polled by the mailbox task.
#![no_std]

pub mod clock;
pub mod cycle;
pub mod net;
pub mod tasks;

/// The parameter flash of the images: two 3 KiB sectors, one per slot (the
/// saved set is 2,079 bytes since the motor data, F00/F06, I470/I471 and E54
/// joined it: 2 KiB sectors no longer held it; `save_fits_the_parameter_flash`
/// checks it).
///
/// The QEMU image keeps them in RAM; on the reference board the same layout
/// goes on two sectors of the on-chip flash (board bring-up, docs/flashing.md).
pub type ParamFlash = store::RamFlash<3072, 2>;

/// The drive as the firmware runs it.
pub type Drive = drive_ecat::runtime::Drive<ParamFlash>;
