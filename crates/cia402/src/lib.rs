//! CiA 402 device control for one axis, as the SC6/SI6 implements it
//! (`shared/spec/cia402.md` §5, §6.1–§6.4).
//!
//! - [`DeviceControl`]: the state machine (T1..T15, no T16), stepped once per control
//!   cycle with [`Inputs`] and the time, returning [`Outputs`]: statusword 6041h, mode
//!   display 6061h, power stage, brake, the stop [`Ramp`] the motion core must run, and
//!   the [`Transition`] taken (for logging and EMCY on entering/leaving Fault).
//! - [`Command`]: controlword 6040h decoding (spec §5.2).
//! - [`State`]: states and statusword patterns (spec §5.3).
//! - Option codes 605Ah..605Eh: [`QuickStopOption`], [`DisableOption`], [`HaltOption`],
//!   [`FaultReaction`].
//! - [`Mode`]: modes of operation 6060h/6061h, 6502h, the switching condition (§6.2).
//!
//! `#![no_std]`, heap-free, sans-IO: the motion core reports standstill, the power stage
//! and the brake are driven from the outputs, and time is an argument. Two axes are two
//! instances; there is no global state.
#![no_std]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing
    )
)]
#![deny(missing_docs)]

mod command;
mod machine;
mod mode;
mod options;
mod state;

pub use command::{
    controlword, Command, CW_ENABLE_OPERATION, CW_ENABLE_VOLTAGE, CW_FAULT_RESET, CW_HALT, CW_MODE_BIT4,
    CW_MODE_BIT5, CW_MODE_BIT6, CW_QUICK_STOP, CW_SWITCH_ON,
};
pub use machine::{DeviceControl, FaultEvent, Inputs, Options, Outputs, Ramp, SodCauses, Transition};
pub use mode::{Mode, ModeClass, ModeError, SUPPORTED_DRIVE_MODES, SUPPORTED_JOG_BIT};
pub use options::{Decel, DisableOption, FaultReaction, HaltOption, OptionCodeError, QuickStopOption};
pub use state::{
    State, SW_FAULT, SW_INTERNAL_LIMIT, SW_MANUFACTURER_MASK, SW_MODE_BIT12, SW_MODE_BIT13,
    SW_OPERATION_ENABLED, SW_QUICK_STOP, SW_READY_TO_SWITCH_ON, SW_REMOTE, SW_SWITCHED_ON,
    SW_SWITCH_ON_DISABLED, SW_TARGET_REACHED, SW_VOLTAGE_ENABLED, SW_WARNING,
};
