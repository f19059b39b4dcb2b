//! The DC configuration checks at Pre-Op → Safe-Op (spec §3.3, §11.3,
//! §11.4, §11.7, §12).

use dcsync::validate::{A150_VALUES_NS, MAX_SYNC0_CYCLE_NS};
use dcsync::{al, validate, DiagCode, SyncError};

#[test]
fn e112_sync0_cycle_must_be_multiple_of_a150() {
    assert_eq!(validate(1_000_000, 1_000_000, 1_000_000, 1_000_000), Ok(1));
    assert_eq!(validate(2_000_000, 500_000, 2_000_000, 2_000_000), Ok(4));
    assert_eq!(validate(8_000_000, 250_000, 0, 0), Ok(32));
    let e = validate(1_250_000, 500_000, 0, 0).unwrap_err();
    assert_eq!(
        e,
        SyncError::Sync0NotMultipleOfA150 {
            sync0_ns: 1_250_000,
            a150_ns: 500_000
        }
    );
    assert_eq!(e.al_status_code(), al::DC_SYNC0_CYCLE_TIME);
    assert_eq!(e.diag_code(), DiagCode::PllStartFailed);
    // SYNC0 shorter than A150 is not a multiple either.
    assert!(matches!(
        validate(500_000, 1_000_000, 0, 0),
        Err(SyncError::Sync0NotMultipleOfA150 { .. })
    ));
}

#[test]
fn e112_sync0_cycle_at_most_8ms() {
    assert_eq!(validate(MAX_SYNC0_CYCLE_NS, 2_000_000, 0, 0), Ok(4));
    let e = validate(10_000_000, 2_000_000, 0, 0).unwrap_err();
    assert_eq!(e, SyncError::Sync0CycleTooLong { sync0_ns: 10_000_000 });
    assert_eq!(e.al_status_code(), 0x0036);
}

#[test]
fn e116_a261_codes_1_2_3_from_the_checks() {
    let e = validate(1_000_000, 1_000_000, 1_000_000, 2_000_000).unwrap_err();
    assert_eq!(e.diag_code(), DiagCode::SmCycleMismatch);
    assert_eq!(e.diag_code() as u16, 1);
    assert_eq!(e.al_status_code(), al::INVALID_DC_SYNC_CONFIG);

    let e = validate(200_000, 200_000, 0, 0).unwrap_err();
    assert_eq!(e, SyncError::CycleTooShort { cycle_ns: 200_000 });
    assert_eq!(e.diag_code() as u16, 2);
    assert_eq!(e.al_status_code(), al::DC_INVALID_CYCLE_TIME);

    let e = validate(1_100_000, 1_000_000, 0, 0).unwrap_err();
    assert_eq!(e, SyncError::CycleNotOnGrid { cycle_ns: 1_100_000 });
    assert_eq!(e.diag_code() as u16, 3);
    assert_eq!(e.al_status_code(), al::DC_INVALID_CYCLE_TIME);

    // SM2 cycle off the grid.
    let e = validate(1_000_000, 1_000_000, 1_100_000, 0).unwrap_err();
    assert_eq!(e.diag_code() as u16, 3);

    // SYNC0 not active.
    let e = validate(0, 1_000_000, 0, 0).unwrap_err();
    assert_eq!(e, SyncError::Sync0Inactive);
    assert_eq!(e.al_status_code(), 0x0030);
}

#[test]
fn e125_drive_cycle_times() {
    for a150 in A150_VALUES_NS {
        assert_eq!(validate(8_000_000, a150, 0, 0), Ok(8_000_000 / a150), "{a150}");
    }
    let e = validate(1_500_000, 750_000, 0, 0).unwrap_err();
    assert_eq!(e, SyncError::UnsupportedDriveCycle { a150_ns: 750_000 });
    assert_eq!(e.al_status_code(), 0x0030);
    assert!(matches!(
        validate(1_000_000, 125_000, 0, 0),
        Err(SyncError::CycleTooShort { .. })
    ));
}
