//! Motion through a real master (spec cia402.md, features-cia402.md C-items):
//! ethercrab runs the standard process data (RxPDO 23 bytes, TxPDO 29 bytes)
//! every simulated millisecond against the simulated drive and motor; every
//! check reads what the master received in the TxPDO (or by SDO), not the
//! drive's internals.
//!
//! Here: the imports the modules share; the tests, by spec area, in the modules.

use drive_tests::axis::*;
use drive_tests::{init, line, motor_rev_s, sw, with_cyclic, with_master, CoeClient, Cyclic, RawMailbox};
use drive_tests::{REV, REV_F};
use hil_sim::motor::PositionInput;
use hil_sim::sim::AxisConditions;

mod axis_b_probe;
mod cyclic;
mod device_control;
mod drive_modes;
mod faults;
