//! The device control state machine's transitions by controlword command (C-001..C-012).

use super::*;

// ---------------------------------------------------------------- state machine

#[test]
fn c001_init_then_switch_on_disabled() {
    let mut r = Rig::new();
    r.inp.initialised = false;
    r.inp.controlword = SHUTDOWN;
    for _ in 0..3 {
        let out = r.step();
        assert_eq!(out.state, State::NotReadyToSwitchOn);
        assert!(!out.power_stage && !out.brake_release);
    }
    r.inp.initialised = true;
    r.step_through(1, State::NotReadyToSwitchOn, State::SwitchOnDisabled);
    // T2 comes only in the next cycle.
    assert_eq!(r.step().state, State::ReadyToSwitchOn);
}

#[test]
fn c002_shutdown_gives_ready_to_switch_on() {
    let mut r = Rig::new();
    r.goto(State::SwitchOnDisabled);
    // Bit 3 is "don't care" for Shutdown.
    let out = r.cw(0x000E);
    assert_eq!(
        tr(&out),
        Some((2, State::SwitchOnDisabled, State::ReadyToSwitchOn))
    );
    let mut r = Rig::new();
    r.goto(State::SwitchOnDisabled);
    // Switch on / Enable operation are not Shutdown: no T2.
    assert_eq!(r.cw(SWITCH_ON).state, State::SwitchOnDisabled);
    assert_eq!(r.cw(ENABLE_OPERATION).state, State::SwitchOnDisabled);
    // Bit 7 set: no command.
    assert_eq!(r.cw(SHUTDOWN | FAULT_RESET).state, State::SwitchOnDisabled);
    assert_eq!(r.cw(SHUTDOWN).state, State::ReadyToSwitchOn);
}

#[test]
fn c002_controlword_decoding_masks() {
    // the command patterns of CiA 402 (mask, value), the first that matches
    let patterns = [
        (0x0082, 0x0000, Command::DisableVoltage),
        (0x0086, 0x0002, Command::QuickStop),
        (0x0087, 0x0006, Command::Shutdown),
        (0x008F, 0x0007, Command::SwitchOn),
        (0x008F, 0x000F, Command::EnableOperation),
    ];
    for cw in 0u16..=0x01FF {
        let expect = patterns
            .iter()
            .find(|&&(mask, value, _)| cw & mask == value)
            .map(|&(_, _, command)| command);
        assert_eq!(Command::decode(cw), expect, "cw {cw:#06x}");
        // Every controlword with bit 7 clear is exactly one command; bit 7 set is none.
        assert_eq!(Command::decode(cw).is_some(), cw & 0x80 == 0, "cw {cw:#06x}");
    }
}

#[test]
fn c002_the_controlword_constants_request_their_commands() {
    for (cw, command) in [
        (SHUTDOWN, Some(Command::Shutdown)),
        (SWITCH_ON, Some(Command::SwitchOn)),
        (ENABLE_OPERATION, Some(Command::EnableOperation)),
        (DISABLE_VOLTAGE, Some(Command::DisableVoltage)),
        (QUICK_STOP, Some(Command::QuickStop)),
        (FAULT_RESET, None),
    ] {
        assert_eq!(Command::decode(cw), command, "cw {cw:#06x}");
    }
    // the patterns of Tab. 5 with every other bit 0
    assert_eq!([SHUTDOWN, SWITCH_ON, ENABLE_OPERATION], [0x0006, 0x0007, 0x000F]);
    assert_eq!(
        [DISABLE_VOLTAGE, QUICK_STOP, FAULT_RESET],
        [0x0000, 0x0002, 0x0080]
    );
}

#[test]
fn c003_no_transition_without_additional_enable() {
    // T2 blocked.
    let mut r = Rig::new();
    r.goto(State::SwitchOnDisabled);
    r.inp.additional_enable = false;
    for _ in 0..3 {
        assert_eq!(r.cw(SHUTDOWN).state, State::SwitchOnDisabled);
    }
    assert!(r.step().sod_causes.contains(SodCauses::ADDITIONAL_ENABLE));
    r.inp.additional_enable = true;
    assert_eq!(r.cw(SHUTDOWN).state, State::ReadyToSwitchOn);

    // T3, T4, T5, T6, T8 are not taken: losing A60 wins (T7, T10, T9).
    let cases: &[(State, u16, u8)] = &[
        (State::ReadyToSwitchOn, SWITCH_ON, 7),    // T3
        (State::SwitchedOn, ENABLE_OPERATION, 10), // T4
        (State::SwitchedOn, SHUTDOWN, 10),         // T6
        (State::OperationEnabled, SWITCH_ON, 9),   // T5
        (State::OperationEnabled, SHUTDOWN, 9),    // T8
    ];
    for &(from, cw, number) in cases {
        let mut r = Rig::new();
        r.goto(from);
        r.inp.additional_enable = false;
        let out = r.cw(cw);
        assert_eq!(tr(&out), Some((number, from, State::SwitchOnDisabled)));
    }
}

#[test]
fn c004_switch_on_gives_switched_on_and_power_stage() {
    let mut r = Rig::new();
    let before = r.goto(State::ReadyToSwitchOn);
    assert!(!before.power_stage);
    let out = r.cw(SWITCH_ON);
    assert_eq!(tr(&out), Some((3, State::ReadyToSwitchOn, State::SwitchedOn)));
    assert!(out.power_stage);
    assert!(!out.brake_release);
}

#[test]
fn c004_enable_operation_from_ready_takes_t3_then_t4() {
    let mut r = Rig::new();
    r.goto(State::ReadyToSwitchOn);
    let out = r.cw(ENABLE_OPERATION);
    assert_eq!(out.transition.map(|t| t.number), Some(3));
    let out = r.step();
    assert_eq!(out.transition.map(|t| t.number), Some(4));

    let mut r = Rig::with(Options {
        enable_from_ready: false,
        ..Options::default()
    });
    r.goto(State::ReadyToSwitchOn);
    assert_eq!(r.cw(ENABLE_OPERATION).state, State::ReadyToSwitchOn);
}

#[test]
fn c005_enable_operation_gives_operation_enabled() {
    let mut r = Rig::new();
    r.goto(State::SwitchedOn);
    let out = r.cw(ENABLE_OPERATION);
    assert_eq!(tr(&out), Some((4, State::SwitchedOn, State::OperationEnabled)));
    assert!(out.power_stage && out.drive_function && out.motion_enabled);
    assert_eq!(out.ramp, Ramp::None);
}

#[test]
fn c006_disable_operation_gives_switched_on() {
    let mut r = Rig::moving(Options::default()); // default 605Ch = 0: no ramp, at once
    let out = r.cw(SWITCH_ON);
    assert_eq!(tr(&out), Some((5, State::OperationEnabled, State::SwitchedOn)));
    assert!(out.power_stage && !out.drive_function && !out.motion_enabled);
}

#[test]
fn c006_disable_operation_option_codes() {
    assert_eq!(DisableOption::try_from(0), Ok(DisableOption::Coast));
    assert_eq!(DisableOption::try_from(1), Ok(DisableOption::SlowDown));
    assert_eq!(DisableOption::try_from(2), Err(OptionCodeError(2)));
    assert_eq!(DisableOption::try_from(-1), Err(OptionCodeError(-1)));
    assert_eq!(DisableOption::SlowDown.code(), 1);

    // 605Ch = 1: ramp in Operation enabled, T5 at standstill.
    let mut r = Rig::moving(Options {
        disable_operation: DisableOption::SlowDown,
        ..Options::default()
    });
    for _ in 0..3 {
        let out = r.cw(SWITCH_ON);
        assert_eq!(out.state, State::OperationEnabled);
        assert_eq!(out.ramp, Ramp::Disable(Decel::SlowDown));
        assert!(out.drive_function && !out.motion_enabled);
    }
    // Enable operation again cancels the ramp.
    let out = r.cw(ENABLE_OPERATION);
    assert_eq!(out.ramp, Ramp::None);
    assert!(out.motion_enabled);
    r.cw(SWITCH_ON);
    r.inp.standstill = true;
    r.step_through(5, State::OperationEnabled, State::SwitchedOn);
}

#[test]
fn c007_shutdown_from_switched_on_powers_off() {
    let mut r = Rig::new();
    r.goto(State::SwitchedOn);
    let out = r.cw(SHUTDOWN);
    assert_eq!(tr(&out), Some((6, State::SwitchedOn, State::ReadyToSwitchOn)));
    assert!(!out.power_stage);
}

#[test]
fn c008_shutdown_from_operation_enabled() {
    let mut r = Rig::moving(Options::default());
    let out = r.cw(SHUTDOWN);
    assert_eq!(
        tr(&out),
        Some((8, State::OperationEnabled, State::ReadyToSwitchOn))
    );
    assert!(!out.power_stage && !out.drive_function);
}

#[test]
fn c008_shutdown_option_codes() {
    let mut r = Rig::moving(Options {
        shutdown: DisableOption::SlowDown,
        ..Options::default()
    });
    let out = r.cw(SHUTDOWN);
    assert_eq!(out.state, State::OperationEnabled);
    assert_eq!(out.ramp, Ramp::Disable(Decel::SlowDown));
    assert!(out.power_stage);
    r.inp.standstill = true;
    r.step_through(8, State::OperationEnabled, State::ReadyToSwitchOn);
}

#[test]
fn c009_disable_voltage_gives_switch_on_disabled() {
    let cases = [
        (State::ReadyToSwitchOn, 7),
        (State::SwitchedOn, 10),
        (State::OperationEnabled, 9),
    ];
    // Bit 1 = 0 with any other bits (bit 7 clear) is Disable voltage.
    for cw in [DISABLE_VOLTAGE, 0x000D, 0x0005, 0x0079] {
        for (from, number) in cases {
            let mut r = Rig::new();
            r.goto(from);
            r.inp.standstill = false;
            let out = r.cw(cw);
            assert_eq!(tr(&out), Some((number, from, State::SwitchOnDisabled)));
            assert!(!out.power_stage && !out.brake_release);
            assert!(out.sod_causes.contains(SodCauses::DISABLE_VOLTAGE));
        }
    }
}

#[test]
fn c010_quick_stop_from_operation_enabled() {
    for cw in [QUICK_STOP, 0x000B, 0x0003] {
        let mut r = Rig::moving(Options::default());
        let out = r.cw(cw);
        assert_eq!(
            tr(&out),
            Some((11, State::OperationEnabled, State::QuickStopActive))
        );
        assert_eq!(out.ramp, Ramp::QuickStop(Decel::QuickStop));
        assert!(out.power_stage && out.drive_function && !out.motion_enabled);
        assert_eq!(out.statusword & SW_QUICK_STOP, 0);
    }
}

#[test]
fn c010_quick_stop_option_codes() {
    // Conversions of every listed value and the neighbours.
    let decels = [
        Decel::SlowDown,
        Decel::QuickStop,
        Decel::CurrentLimit,
        Decel::VoltageLimit,
    ];
    assert_eq!(QuickStopOption::try_from(0), Ok(QuickStopOption::Coast));
    for (i, d) in decels.iter().enumerate() {
        let n = i as i16 + 1;
        assert_eq!(QuickStopOption::try_from(n), Ok(QuickStopOption::ThenDisable(*d)));
        assert_eq!(
            QuickStopOption::try_from(n + 4),
            Ok(QuickStopOption::ThenHold(*d))
        );
    }
    for v in -1i16..=9 {
        match QuickStopOption::try_from(v) {
            Ok(o) => assert_eq!(o.code(), v),
            Err(e) => assert!(v == -1 || v == 9, "{v} refused: {e:?}"),
        }
    }
    assert_eq!(QuickStopOption::try_from(9), Err(OptionCodeError(9)));
    assert_eq!(Options::default().quick_stop.code(), 2);

    // 0: coast. Power off at once, then Switch on disabled.
    let mut r = Rig::moving(Options {
        quick_stop: QuickStopOption::Coast,
        ..Options::default()
    });
    let out = r.cw(QUICK_STOP);
    assert_eq!(out.state, State::QuickStopActive);
    assert!(!out.power_stage && !out.brake_release);
    assert_eq!(out.ramp, Ramp::None);
    assert_eq!(tr(&r.step()).map(|t| t.0), Some(12));

    // 1..4: ramp with the deceleration, then T12 at standstill.
    for (i, d) in decels.iter().enumerate() {
        let mut r = Rig::moving(Options {
            quick_stop: QuickStopOption::try_from(i as i16 + 1).unwrap(),
            ..Options::default()
        });
        let out = r.cw(QUICK_STOP);
        assert_eq!(out.ramp, Ramp::QuickStop(*d));
        assert_eq!(r.step().state, State::QuickStopActive);
        r.inp.standstill = true;
        let out = r.step_through(12, State::QuickStopActive, State::SwitchOnDisabled);
        assert!(!out.power_stage);
    }

    // 5..8: ramp, then stay in Quick stop active holding; Enable operation does not
    // return (no T16); Disable voltage ends it.
    for (i, d) in decels.iter().enumerate() {
        let mut r = Rig::moving(Options {
            quick_stop: QuickStopOption::try_from(i as i16 + 5).unwrap(),
            ..Options::default()
        });
        r.cw(QUICK_STOP);
        r.inp.standstill = true;
        for cw in [QUICK_STOP, ENABLE_OPERATION, SHUTDOWN, SWITCH_ON] {
            let out = r.cw(cw);
            assert_eq!(out.state, State::QuickStopActive);
            assert_eq!(out.ramp, Ramp::QuickStop(*d));
            assert!(out.power_stage && !out.motion_enabled);
        }
        let out = r.cw(DISABLE_VOLTAGE);
        assert_eq!(
            tr(&out),
            Some((12, State::QuickStopActive, State::SwitchOnDisabled))
        );
    }
}

#[test]
fn c011_quick_stop_ends_in_switch_on_disabled_never_back() {
    let mut r = Rig::new();
    r.goto(State::QuickStopActive);
    // Enable operation during the stop: no T16.
    for _ in 0..5 {
        let out = r.cw(ENABLE_OPERATION);
        assert_eq!(out.state, State::QuickStopActive);
        assert!(!out.motion_enabled);
    }
    r.inp.standstill = true;
    let out = r.step_through(12, State::QuickStopActive, State::SwitchOnDisabled);
    assert!(!out.power_stage && !out.brake_release);
    // Enable operation held: stays in Switch on disabled.
    assert_eq!(r.step().state, State::SwitchOnDisabled);
}

#[test]
fn c011_disable_voltage_ends_quick_stop_at_once() {
    let mut r = Rig::new();
    r.goto(State::QuickStopActive);
    let out = r.cw(DISABLE_VOLTAGE);
    assert_eq!(out.transition.map(|t| t.number), Some(12));
}

#[test]
fn c012_quick_stop_in_ready_or_switched_on() {
    for (from, number) in [(State::ReadyToSwitchOn, 7), (State::SwitchedOn, 10)] {
        let mut r = Rig::new();
        r.goto(from);
        let out = r.cw(QUICK_STOP);
        assert_eq!(tr(&out), Some((number, from, State::SwitchOnDisabled)));
        assert!(out.sod_causes.contains(SodCauses::QUICK_STOP));
    }
    // Quick stop in Switch on disabled blocks T2.
    let mut r = Rig::new();
    r.goto(State::SwitchOnDisabled);
    assert_eq!(r.cw(QUICK_STOP).state, State::SwitchOnDisabled);
}
