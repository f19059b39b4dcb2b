//! `[std]` behaviour the checklist does not list: halt option codes, every transition reachable,
//! two independent instances.

use super::*;

// ---------------------------------------------------------------- [std] extras

#[test]
fn std_halt_option_codes() {
    let decels = [
        Decel::SlowDown,
        Decel::QuickStop,
        Decel::CurrentLimit,
        Decel::VoltageLimit,
    ];
    assert_eq!(HaltOption::try_from(0), Err(OptionCodeError(0)));
    assert_eq!(HaltOption::try_from(5), Err(OptionCodeError(5)));
    assert_eq!(Options::default().halt.code(), 1);
    for (i, d) in decels.iter().enumerate() {
        let halt = HaltOption::try_from(i as i16 + 1).unwrap();
        assert_eq!(halt, HaltOption(*d));
        for mode in [1i8, 3, 6] {
            let mut r = Rig::with(Options {
                halt,
                ..Options::default()
            });
            r.inp.mode_request = mode;
            r.goto(State::OperationEnabled);
            let out = r.cw(ENABLE_OPERATION | CW_HALT);
            assert_eq!(out.ramp, Ramp::Halt(*d), "mode {mode}");
            assert_eq!(out.state, State::OperationEnabled);
            assert_eq!(r.cw(ENABLE_OPERATION).ramp, Ramp::None);
        }
    }
    // Not in the cyclic modes.
    let mut r = Rig::new();
    r.goto(State::OperationEnabled);
    assert_eq!(r.cw(ENABLE_OPERATION | CW_HALT).ramp, Ramp::None);
}

#[test]
fn std_every_transition_reachable() {
    let mut seen = [false; 16];
    let mut note = |out: Outputs| {
        if let Some(t) = out.transition {
            seen[t.number as usize] = true;
        }
    };
    let mut r = Rig::new();
    note(r.step()); // 1
    note(r.cw(SHUTDOWN)); // 2
    note(r.cw(SWITCH_ON)); // 3
    note(r.cw(ENABLE_OPERATION)); // 4
    note(r.cw(SWITCH_ON)); // 5
    note(r.cw(SHUTDOWN)); // 6
    note(r.cw(DISABLE_VOLTAGE)); // 7
    r.cw(SHUTDOWN);
    r.cw(SWITCH_ON);
    note(r.cw(DISABLE_VOLTAGE)); // 10
    r.cw(SHUTDOWN);
    r.cw(SWITCH_ON);
    r.cw(ENABLE_OPERATION);
    note(r.cw(SHUTDOWN)); // 8
    r.cw(SWITCH_ON);
    r.cw(ENABLE_OPERATION);
    note(r.cw(DISABLE_VOLTAGE)); // 9
    r.cw(SHUTDOWN);
    r.cw(SWITCH_ON);
    r.cw(ENABLE_OPERATION);
    note(r.cw(QUICK_STOP)); // 11
    note(r.step()); // 12 (standstill)
    r.dc.raise_fault(FaultEvent::GENERIC);
    note(r.step()); // 13
    note(r.step()); // 14
    r.cw(0);
    note(r.cw(FAULT_RESET)); // 15
    let missing: Vec<usize> = (1..16).filter(|&n| !seen[n]).collect();
    assert!(missing.is_empty(), "missing {missing:?}");
}

#[test]
fn std_two_instances_are_independent() {
    let mut a = Rig::new();
    let mut b = Rig::new();
    a.goto(State::OperationEnabled);
    b.goto(State::ReadyToSwitchOn);
    a.dc.raise_fault(FaultEvent::GENERIC);
    assert_eq!(a.step().state, State::FaultReactionActive);
    assert_eq!(b.step().state, State::ReadyToSwitchOn);
}
