//! CiA 402 items through a real master that the mode scenarios of
//! motion/*.rs / motion_more.rs do not name (features-cia402.md): mode 0,
//! replacing commands, the velocity override A340, the cyclic modes without
//! mode bits, the pp set-point handshake and absolute moves, switch sources
//! from I210, E80, reference retaining I46, the position encoder I02, the
//! user status word A66/A67 and the set-value monitor. Every check reads
//! what the master received (TxPDO or SDO) or the plant's encoder.
//!
//! Here: the parameters and the pp helpers the modules share; the tests, by item, in the modules.

use drive_ecat::parameter_index;
use drive_tests::axis::*;
use drive_tests::{init, line, motor_rev_s, sw, with_cyclic, with_master, Cyclic};
use drive_tests::{REV, REV_F};

mod commands;
mod modes;
mod scaling;
mod status;
mod switches_encoders;

const A66: u16 = parameter_index(0, 66);
const A340: u16 = parameter_index(0, 340);
const E80: u16 = parameter_index(4, 80);
const I02: u16 = parameter_index(8, 2);
const I46: u16 = parameter_index(8, 46);
const I101: u16 = parameter_index(8, 101);
const I102: u16 = parameter_index(8, 102);
const I210: u16 = parameter_index(8, 210);

/// A bit-4 edge in pp with `bits`; returns whether bit 12 acknowledged it
/// within 5 cycles (bit 4 is taken back afterwards).
async fn pp_edge(m: &mut Cyclic<'_>, target: i32, bits: u16) -> bool {
    m.set_target_position(target);
    m.set_controlword(CW_ENABLED | bits);
    m.run(1).await;
    m.set_controlword(CW_ENABLED | bits | CW_BIT4);
    let ack = m.run_until(5, |t| t.bit(12)).await.is_some();
    m.set_controlword(CW_ENABLED | bits);
    m.run(2).await;
    ack
}

/// [`pp_edge`] that must be taken, the move [`settle`]d within `max`
/// cycles, then 20 cycles more.
async fn pp_move(m: &mut Cyclic<'_>, target: i32, bits: u16, max: usize) {
    assert!(pp_edge(m, target, bits).await, "taken");
    settle(m, max).await.expect("arrives");
    m.run(20).await;
}

/// Waits until bit 10 (target reached) and standstill.
async fn settle(m: &mut Cyclic<'_>, max: usize) -> Option<usize> {
    m.run_until(max, |t| t.bit(10) && t.velocity.abs() < REV / 200)
        .await
}
