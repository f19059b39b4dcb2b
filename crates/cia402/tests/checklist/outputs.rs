//! What a state shows and drives: the statusword, the brake, torque and motion (C-018..C-024).

use super::*;

#[test]
fn c018_statusword_patterns() {
    let expected = [
        (State::NotReadyToSwitchOn, 0x0000),
        (State::SwitchOnDisabled, 0x0040),
        (State::ReadyToSwitchOn, 0x0021),
        (State::SwitchedOn, 0x0023),
        (State::OperationEnabled, 0x0027),
        (State::QuickStopActive, 0x0007),
        (State::FaultReactionActive, 0x000F),
        (State::Fault, 0x0008),
    ];
    for (state, bits) in expected {
        let out = if state == State::NotReadyToSwitchOn {
            let mut r = Rig::new();
            r.inp.initialised = false;
            r.step()
        } else {
            Rig::new().goto(state)
        };
        assert_eq!(out.state, state);
        // Bits 0..3, 5, 6 exactly.
        assert_eq!(out.statusword & 0x006F, bits, "{state:?}");
        let (mask, value) = state.pattern();
        assert_eq!(out.statusword & mask, value);
        assert_eq!(State::from_statusword(out.statusword), Some(state));
        // Voltage enabled and remote from the rig's inputs.
        assert_eq!(out.statusword & 0xFF90, SW_VOLTAGE_ENABLED | SW_REMOTE);
    }
    // Patterns are exclusive.
    for s in State::ALL {
        let matching = State::ALL
            .iter()
            .filter(|o| {
                let (m, v) = o.pattern();
                s.state_bits() & m == v
            })
            .count();
        assert_eq!(matching, 1, "{s:?}");
    }
}

#[test]
fn c018_statusword_extra_and_mode_bits() {
    let set = |r: &mut Rig| {
        r.inp.warning = true;
        r.inp.internal_limit = true;
        r.inp.target_reached = true;
        r.inp.mode_bit12 = true;
        r.inp.mode_bit13 = true;
        r.inp.manufacturer_bits = 0xFFFF;
    };
    let mode_bits = SW_TARGET_REACHED | SW_MODE_BIT12 | SW_MODE_BIT13;
    for state in [
        State::SwitchOnDisabled,
        State::ReadyToSwitchOn,
        State::SwitchedOn,
        State::OperationEnabled,
        State::QuickStopActive,
        State::Fault,
    ] {
        let mut r = Rig::new();
        r.goto(state);
        set(&mut r);
        let sw = r.step().statusword;
        assert_eq!(r.state(), state);
        assert_ne!(sw & SW_WARNING, 0);
        assert_ne!(sw & SW_INTERNAL_LIMIT, 0);
        assert_eq!(sw & SW_MANUFACTURER_MASK, SW_MANUFACTURER_MASK);
        let expect = match state {
            State::OperationEnabled => mode_bits,
            State::QuickStopActive => SW_TARGET_REACHED,
            _ => 0,
        };
        assert_eq!(sw & mode_bits, expect, "{state:?}");
    }
    let mut r = Rig::new();
    r.inp.remote = false;
    assert_eq!(r.step().statusword & SW_REMOTE, 0);
}

#[test]
fn c019_device_state_reported() {
    let mut codes: Vec<u8> = State::ALL.iter().map(|s| s.code()).collect();
    codes.dedup();
    assert_eq!(codes, (0..8).collect::<Vec<u8>>());
    let mut r = Rig::new();
    r.goto(State::SwitchedOn);
    assert_eq!(r.step().state, r.dc.state());
}

#[test]
fn c020_brake_engaged_unless_override() {
    for state in [
        State::SwitchOnDisabled,
        State::ReadyToSwitchOn,
        State::SwitchedOn,
        State::Fault,
    ] {
        let mut r = Rig::new();
        r.inp.motion_command = true;
        r.inp.controlword = 0x10;
        assert!(!r.goto(state).brake_release, "{state:?}");
        r.inp.brake_override = true;
        assert!(r.step().brake_release, "{state:?} override");
    }
    let mut r = Rig::new();
    r.inp.initialised = false;
    assert!(!r.step().brake_release);
    r.inp.brake_override = true;
    assert!(r.step().brake_release);
}

#[test]
fn c021_brake_release_per_mode() {
    // csp, csv, cst, vl, pv, pt: first active motion command.
    for mode in [8i8, 9, 10, 2, 3, 4] {
        let mut r = Rig::new();
        r.inp.mode_request = mode;
        r.goto(State::OperationEnabled);
        assert_eq!(r.step().mode_display, mode);
        assert!(!r.cw(ENABLE_OPERATION | 0x10).brake_release, "mode {mode}: bit 4");
        r.inp.motion_command = true;
        assert!(r.step().brake_release, "mode {mode}");
        r.inp.motion_command = false;
        assert!(r.step().brake_release, "mode {mode} stays released");
    }
    // pp, ip, homing: controlword bit 4.
    for mode in [1i8, 7, 6] {
        let mut r = Rig::new();
        r.inp.mode_request = mode;
        r.goto(State::OperationEnabled);
        r.inp.motion_command = true;
        assert!(!r.step().brake_release, "mode {mode}: motion command");
        assert!(r.cw(ENABLE_OPERATION | CW_MODE_BIT4).brake_release, "mode {mode}");
        assert!(r.cw(ENABLE_OPERATION).brake_release, "mode {mode} stays released");
    }
    // Jog: bit 4 or bit 5.
    for bit in [CW_MODE_BIT4, CW_MODE_BIT5] {
        let mut r = Rig::new();
        r.inp.mode_request = -1;
        r.goto(State::OperationEnabled);
        assert!(!r.step().brake_release);
        assert!(r.cw(ENABLE_OPERATION | bit).brake_release);
    }
    // No mode: never.
    let mut r = Rig::new();
    r.inp.mode_request = 0;
    r.inp.motion_command = true;
    r.goto(State::OperationEnabled);
    assert!(!r.cw(ENABLE_OPERATION | 0x70).brake_release);
    // Leaving Operation enabled engages it.
    let mut r = Rig::new();
    r.inp.motion_command = true;
    r.goto(State::OperationEnabled);
    assert!(r.step().brake_release);
    assert!(!r.cw(SWITCH_ON).brake_release);
}

#[test]
fn c022_brake_in_quick_stop_and_fault_reaction() {
    // Released during the quick stop, engaged after it.
    let mut r = Rig::new();
    r.inp.motion_command = true;
    r.goto(State::OperationEnabled);
    assert!(r.step().brake_release);
    r.inp.standstill = false;
    let out = r.cw(QUICK_STOP);
    assert_eq!(out.state, State::QuickStopActive);
    assert!(out.brake_release);
    assert!(r.step().brake_release);
    r.inp.standstill = true;
    assert!(!r.step().brake_release);

    // Ramped fault reaction keeps it released; coast engages it.
    for (reaction, released) in [
        (None, true),
        (Some(FaultReaction::Stop(Decel::SlowDown)), true),
        (Some(FaultReaction::Coast), false),
    ] {
        let mut r = Rig::new();
        r.inp.motion_command = true;
        r.goto(State::OperationEnabled);
        assert!(r.step().brake_release);
        r.inp.standstill = false;
        r.dc.raise_fault(FaultEvent {
            code: 0x1000,
            reaction,
        });
        let out = r.step();
        assert_eq!(out.state, State::FaultReactionActive);
        assert_eq!(out.brake_release, released, "{reaction:?}");
    }
}

#[test]
fn c022_brake_closes_before_power_off() {
    let mut r = Rig::with(Options {
        brake_close: Nanos::from_ms(5),
        ..Options::default()
    });
    r.inp.motion_command = true;
    r.goto(State::OperationEnabled);
    assert!(r.step().brake_release);
    r.inp.standstill = false;
    r.cw(QUICK_STOP);
    r.inp.standstill = true;
    // Standstill: brake engages, torque held for the closing time.
    let out = r.step();
    assert_eq!(out.state, State::QuickStopActive);
    assert!(!out.brake_release && out.power_stage && out.drive_function);
    let mut held = 0;
    while r.step().state == State::QuickStopActive {
        held += 1;
        assert!(held < 20);
    }
    assert!((4..=5).contains(&held), "held {held} cycles");
    assert!(!r.step().power_stage);
}

#[test]
fn c023_switched_on_no_torque() {
    let mut r = Rig::new();
    r.inp.motion_command = true;
    let out = r.goto(State::SwitchedOn);
    assert!(out.power_stage);
    assert!(!out.drive_function && !out.motion_enabled && !out.brake_release);
    assert_eq!(out.ramp, Ramp::None);
}

#[test]
fn c024_no_motion_in_fault_or_quick_stop() {
    for state in [State::QuickStopActive, State::FaultReactionActive, State::Fault] {
        let mut r = Rig::new();
        r.inp.motion_command = true;
        let out = r.goto(state);
        assert!(!out.motion_enabled, "{state:?}");
        assert!(!r.cw(ENABLE_OPERATION | CW_MODE_BIT4).motion_enabled, "{state:?}");
    }
    let mut r = Rig::new();
    assert!(r.goto(State::OperationEnabled).motion_enabled);
}
