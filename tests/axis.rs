//! Axis-level helpers of the motion tests (`motion/`, `motion_more.rs`,
//! `cia402_items/`, `homing.rs`): controlword bits, the simulated plant,
//! homing in place.

use crate::{Cyclic, TxPdo};
use hil_sim::sim::{SimDrive, Simulation};
use std::cell::RefCell;

/// Controlword "Enable operation" (bits 0..3).
pub const CW_ENABLED: u16 = 0x000F;
/// Bit 4: new set-point (pp), homing start (hm).
pub const CW_BIT4: u16 = 1 << 4;
/// Bit 5: change set immediately (pp).
pub const CW_BIT5: u16 = 1 << 5;
/// Bit 6: relative (pp).
pub const CW_BIT6: u16 = 1 << 6;
/// Bit 7: fault reset.
pub const CW_FAULT_RESET: u16 = 1 << 7;
/// Bit 8: halt.
pub const CW_HALT: u16 = 1 << 8;

/// Runs `f` on the first drive of the line (conditions, motors, faults).
pub fn with_drive(sim: &RefCell<Simulation>, f: impl FnOnce(&mut SimDrive)) {
    f(&mut sim.borrow_mut().drives_mut()[0]);
}

/// Encoder position of motor `axis` of the first drive, increments (the
/// plant, for cross-checks).
pub fn motor_position(sim: &RefCell<Simulation>, axis: usize) -> i64 {
    sim.borrow().drives()[0].motors[axis].position_inc_i64()
}

/// The speed limits of the torque modes (G472/G475) of axis A raised to
/// `rev_s` by SDO, as a master does (0.1 % of I10, the maximum speed, read
/// by SDO).
pub async fn torque_mode_speed_limit<S>(sd: &ethercrab::SubDeviceRef<'_, S>, rev_s: f32)
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    let i10: u32 = sd.sdo_read(drive_ecat::params::I10, 0).await.expect("I10 by SDO");
    let i10 = i10 as f32;
    let per_mille = (rev_s * crate::REV as f32 / i10 * 1000.0).round() as u16;
    for index in [drive_ecat::params::G472, drive_ecat::params::G475] {
        sd.sdo_write(index, 0, per_mille).await.expect("G472/G475 by SDO");
    }
}

/// Homing method 37 (reference here, no motion) through the standard PDO:
/// mode 6, a 0→1 edge of bit 4; returns the TxPDO once bits 12 and 10 are
/// set. The present position then reads 607Ch.
pub async fn home_here(m: &mut Cyclic<'_>) -> TxPdo {
    m.set_mode(6);
    m.set_controlword(CW_ENABLED);
    m.run(3).await;
    m.set_controlword(CW_ENABLED | CW_BIT4);
    let done = m
        .run_until(50, |t| t.mode_display == 6 && t.bit(12) && t.bit(10))
        .await;
    assert!(done.is_some(), "method 37: {:#06x}", m.tx.statusword);
    m.set_controlword(CW_ENABLED);
    m.run(2).await
}

/// Touch probe 1 as the master reads it by SDO: 60B9h (status), 60BAh
/// (position at the rising edge), 60BBh (at the falling edge).
pub async fn probe1<S>(sd: &ethercrab::SubDeviceRef<'_, S>) -> (u16, i32, i32)
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    let status: u16 = sd.sdo_read(0x60B9, 0).await.expect("60B9h");
    let rising: i32 = sd.sdo_read(0x60BA, 0).await.expect("60BAh");
    let falling: i32 = sd.sdo_read(0x60BB, 0).await.expect("60BBh");
    (status, rising, falling)
}

/// The profile of pp and pv (by SDO): 6081h profile velocity = `velocity`
/// (unless `None`), 6083h acceleration and 6084h deceleration = `accel`.
pub async fn set_profile<S>(sd: &ethercrab::SubDeviceRef<'_, S>, velocity: Option<u32>, accel: u32)
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    if let Some(v) = velocity {
        sd.sdo_write(0x6081, 0, v).await.expect("6081h");
    }
    sd.sdo_write(0x6083, 0, accel).await.expect("6083h");
    sd.sdo_write(0x6084, 0, accel).await.expect("6084h");
}

/// I101/I102 = 1 by SDO, as a master does (issue 40): axis A's limit
/// switches from the inputs.
pub async fn limit_switches_from_inputs<S>(sd: &ethercrab::SubDeviceRef<'_, S>)
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    sd.sdo_write(drive_ecat::parameter_index(8, 101), 0, 1u8)
        .await
        .unwrap();
    sd.sdo_write(drive_ecat::parameter_index(8, 102), 0, 1u8)
        .await
        .unwrap();
}

/// A line of one drive ([`crate::line`]) whose axis A has the inputs
/// `switches` (limit, home and probe switches).
pub fn line_with_switches(switches: hil_sim::motor::Switches) -> RefCell<Simulation> {
    let sim = crate::line(1);
    with_drive(&sim, |d| *d.motors[0].switches_mut() = switches);
    sim
}
