//! AL status codes of E-047 through a real master: 0051h when the ESC could
//! not load its configuration from the SII EEPROM.

use drive_tests::al::{ERR, INIT, PREOP};
use drive_tests::{line, with_master};
use esc::AlStatusCode;
use std::sync::atomic::Ordering;

/// E-047: a damaged SII configuration area (its checksum, word 7, wrong):
/// the ESC flags the checksum error at load (0502h bit 11) and the drive
/// refuses Init → Pre-Op with AL 0051h "EEPROM error"; it stays in Init with
/// the error flag. With the checksum repaired and reloaded, the same drive
/// goes to Pre-Op.
#[test]
fn e047_sii_checksum_error_refuses_preop_with_0051() {
    let sim = line(1);
    {
        let mut s = sim.borrow_mut();
        let esc = &mut s.drives_mut()[0].esc;
        esc.sii_mut()[14] ^= 0xFF;
        esc.reload_sii();
    }
    with_master(&sim, async |md, clock| {
        let r = md
            .init_single_group::<8, 512>(|| clock.load(Ordering::Relaxed))
            .await;
        assert!(r.is_err(), "the master cannot bring the line to Pre-Op");
    });
    {
        let s = sim.borrow();
        let esc = &s.drives()[0].esc;
        assert_eq!(esc.al_status(), INIT | ERR, "Init with the error flag");
        assert_eq!(esc.al_status_code(), AlStatusCode::EEPROM_ERROR.0);
    }
    {
        let mut s = sim.borrow_mut();
        let esc = &mut s.drives_mut()[0].esc;
        esc.sii_mut()[14] ^= 0xFF;
        esc.reload_sii();
    }
    with_master(&sim, async |md, clock| {
        let group = drive_tests::init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(drive_tests::al_status(&sd).await, (PREOP, 0));
    });
}
