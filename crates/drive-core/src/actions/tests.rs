//! The action unit's own tests (E-140…E-142): selectors, activation, save.

#![allow(clippy::unwrap_used)]
use super::*;

fn objects_with_a75_mapped() -> DriveObjects {
    let mut od = DriveObjects::new();
    let n = od.get(0x1600, 0).unwrap() as u8;
    let entry = i64::from(u32::from(A75) << 16 | 8);
    let _ = od.set(0x1600, 0, 0);
    od.set(0x1600, n + 1, entry).unwrap();
    od.set(0x1600, 0, i64::from(n + 1)).unwrap();
    od
}

fn execute(od: &mut DriveObjects, axis: usize, selector: u8, on: bool) {
    let v = i64::from(selector << 1 | u8::from(on));
    od.set(A75 + offset(axis), 0, v).unwrap();
}

#[test]
fn e140_save_runs_until_a00_shows_the_end_and_idles_when_execute_drops() {
    let mut od = objects_with_a75_mapped();
    let mut a = Actions::new();
    execute(&mut od, 0, 0b0001, true);
    a.serve(&mut od);
    assert_eq!(a.status(0), status(0, 1, state::RUNNING));
    assert!(od.requests().save);
    a.serve(&mut od);
    assert_eq!(a.status(0) >> 12, state::RUNNING, "until the save ends");
    // the runtime's save: takes the request, shows progress 100 and result 0
    od.take_requests();
    od.set(A00, 2, 100).unwrap();
    od.set(A00, 3, 0).unwrap();
    a.serve(&mut od);
    assert_eq!(a.status(0), status(100, 1, state::DONE));
    assert_eq!(od.get(A69, 0).unwrap(), i64::from(status(100, 1, state::DONE)));
    execute(&mut od, 0, 0b0001, false);
    a.serve(&mut od);
    assert_eq!(a.status(0), 0);
}

#[test]
fn e141_preconditions_on_e48() {
    assert!(!Action::Restart.may_start(4));
    assert!(!Action::Restart.may_start(7));
    assert!(Action::Restart.may_start(2));
    assert!(Action::TestWinding.may_start(2));
    assert!(!Action::TestWinding.may_start(1));
    assert!(Action::Save.may_start(4));
    let mut od = objects_with_a75_mapped();
    let mut a = Actions::new();
    od.set(E48, 0, 4).unwrap();
    execute(&mut od, 0, 0b0010, true);
    a.serve(&mut od);
    assert_eq!(a.status(0), status(0, 2, state::REFUSED));
    assert!(!od.requests().restart, "nothing requested");
}

#[test]
fn e142_without_a75_in_the_axis_channel_nothing_starts() {
    let mut od = DriveObjects::new();
    let mut a = Actions::new();
    execute(&mut od, 0, 0b0001, true);
    a.serve(&mut od);
    assert_eq!(a.status(0), status(0, 1, state::NOT_ACTIVATED));
    assert!(!od.requests().save);
    // axis B's channel does not activate axis A, nor A's axis B
    execute(&mut od, 1, 0b0111, true);
    assert_eq!(a.serve(&mut od), Effects::default());
    assert_eq!(a.status(1) >> 12, state::NOT_ACTIVATED);
}

#[test]
fn e140_clear_reference_and_unknown_selectors() {
    let mut od = objects_with_a75_mapped();
    let mut a = Actions::new();
    execute(&mut od, 0, 0b0111, true);
    let fx = a.serve(&mut od);
    assert_eq!(fx.clear_reference, [true, false]);
    assert_eq!(a.status(0), status(100, 7, state::DONE));
    // held high: no second start
    assert_eq!(a.serve(&mut od), Effects::default());
    // 1111b is B44 (ours): 0000b is the one selector without an action
    execute(&mut od, 0, 0, false);
    a.serve(&mut od);
    execute(&mut od, 0, 0, true);
    a.serve(&mut od);
    assert_eq!(a.status(0) >> 12, state::UNKNOWN, "selector 0000b");
    execute(&mut od, 0, 0, false);
    a.serve(&mut od);
    execute(&mut od, 0, 0b0110, true);
    od.set(E48, 0, 2).unwrap();
    a.serve(&mut od);
    assert_eq!(
        a.status(0) >> 12,
        state::NOT_AVAILABLE,
        "grind brake 2 in E48 = 2"
    );
}

/// E-142 on PROFINET: with [`Actions::by_parameter_access`] A75 written
/// (as PKW does) starts an action without any RxPDO mapping — I38 clear
/// reference, done at once, its effect returned — while the EtherCAT
/// unit ([`Actions::new`]) refuses the same write as not activated.
#[test]
fn e142_parameter_access_is_the_activation_on_profinet() {
    let mut od = DriveObjects::new();
    execute(&mut od, 0, 0b0111, true);
    let mut ecat = Actions::new();
    let fx = ecat.serve(&mut od);
    assert_eq!(ecat.status(0), status(0, 0b0111, state::NOT_ACTIVATED));
    assert!(!fx.clear_reference[0]);
    let mut pn = Actions::by_parameter_access();
    let fx = pn.serve(&mut od);
    assert_eq!(pn.status(0), status(100, 0b0111, state::DONE));
    assert_eq!(fx.clear_reference, [true, false]);
    assert!(!pn.measuring());
}
