//! The power stage's data and the DC-link window (issue 34, `objects/stage.rs`):
//! declared defaults, the refusals where they are written, 6079h.

use crate::params::{A21, A22, A35, A38, A40, A41};
use crate::stage::{set_dc_link_voltage, StageData};
use crate::*;
use od::{CommState, Dictionary as _, SdoAbort};

const PREOP: CommState = CommState::PreOp;

fn wr(d: &mut DriveObjects, index: u16, v: u32, n: usize) -> Result<(), SdoAbort> {
    d.write(index, 0, &v.to_le_bytes()[..n], PREOP)
}

fn rd(d: &mut DriveObjects, index: u16) -> u32 {
    let mut buf = [0u8; 8];
    let n = d.read(index, 0, &mut buf, PREOP).unwrap();
    let mut b = [0u8; 4];
    b[..n].copy_from_slice(&buf[..n]);
    u32::from_le_bytes(b)
}

/// The declared defaults read as `StageData::default()` (which the loop's
/// `foc::Protection::default_stage` mirrors); A21 = 100 Ω as the seeds' example.
#[test]
fn stage_data_defaults_are_the_declared_ones() {
    let d = DriveObjects::new();
    assert_eq!(StageData::read(&d), StageData::default());
    assert_eq!(d.get(A21, 0), Ok(100));
}

/// The window refused where it is written (SDO abort 0609 0031h above,
/// 0609 0032h below), nothing changed; consistent values accepted and read
/// back; the stage's hardware data read-only (0601 0002h).
#[test]
fn stage_window_refusals_change_nothing() {
    let mut d = DriveObjects::new();
    // threshold at or above the over-voltage trip (800 V)
    assert_eq!(wr(&mut d, A38, 800, 2), Err(SdoAbort::VALUE_TOO_HIGH));
    // threshold − hysteresis at or below the under-voltage limit (400 V)
    assert_eq!(wr(&mut d, A38, 420, 2), Err(SdoAbort::VALUE_TOO_LOW));
    // under-voltage limit at or above threshold − hysteresis (740 V)
    assert_eq!(wr(&mut d, A35, 740, 2), Err(SdoAbort::VALUE_TOO_HIGH));
    // beyond the declared range
    assert_eq!(wr(&mut d, A21, 10_001, 2), Err(SdoAbort::VALUE_TOO_HIGH));
    assert_eq!(wr(&mut d, A22, 0, 4), Err(SdoAbort::VALUE_TOO_LOW));
    assert_eq!(StageData::read(&d), StageData::default(), "nothing changed");
    // read-only hardware data
    assert_eq!(wr(&mut d, A40, 900, 2), Err(SdoAbort::READ_ONLY));
    assert_eq!(wr(&mut d, A41, 9_000, 4), Err(SdoAbort::READ_ONLY));
    // consistent values
    wr(&mut d, A38, 700, 2).unwrap();
    wr(&mut d, A35, 679, 2).unwrap();
    wr(&mut d, A21, 0, 2).unwrap();
    let s = StageData::read(&d);
    assert_eq!(
        (s.chopper_on_v, s.under_voltage_v, s.brake_resistor_ohm),
        (700.0, 679.0, 0.0)
    );
    assert_eq!(rd(&mut d, A38), 700);
    // and the window now refuses the threshold that needs a lower limit
    assert_eq!(wr(&mut d, A38, 699, 2), Err(SdoAbort::VALUE_TOO_LOW));
}

/// 6079h "DC link circuit voltage" (A566, mV) shows the measured link on
/// both axes.
#[test]
fn a566_dc_link_voltage_reads_the_measured_link() {
    let mut d = DriveObjects::new();
    set_dc_link_voltage(&mut d, 565_250);
    assert_eq!(rd(&mut d, 0x6079), 565_250);
    assert_eq!(rd(&mut d, 0x6079 + AXIS_B_CIA402), 565_250);
}
