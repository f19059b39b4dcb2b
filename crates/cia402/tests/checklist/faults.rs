//! Transitions the drive makes itself: losing the additional enable, supply and STO, the fault
//! reaction and the fault reset (C-013..C-017).

use super::*;

#[test]
fn c013_losing_additional_enable() {
    for (from, number) in [(State::ReadyToSwitchOn, 7), (State::SwitchedOn, 10)] {
        let mut r = Rig::new();
        r.goto(from);
        r.inp.additional_enable = false;
        r.step_through(number, from, State::SwitchOnDisabled);
    }

    // A44 ≠ 1: Operation enabled → Switch on disabled at once (T9).
    let mut r = Rig::moving(Options::default());
    r.inp.additional_enable = false;
    let out = r.step_through(9, State::OperationEnabled, State::SwitchOnDisabled);
    assert!(!out.power_stage);

    // A44 = 1: quick stop (T11) that runs to standstill although A60 stays off.
    let mut r = Rig::moving(Options {
        quick_stop_on_enable_loss: true,
        ..Options::default()
    });
    r.inp.additional_enable = false;
    r.step_through(11, State::OperationEnabled, State::QuickStopActive);
    for _ in 0..3 {
        let out = r.step();
        assert_eq!(out.state, State::QuickStopActive);
        assert!(out.power_stage);
    }
    r.inp.standstill = true;
    assert_eq!(r.step().transition.map(|t| t.number), Some(12));
}

#[test]
fn c014_losing_additional_enable_in_quick_stop() {
    let mut r = Rig::new();
    r.goto(State::QuickStopActive);
    assert_eq!(r.step().state, State::QuickStopActive);
    r.inp.additional_enable = false;
    let out = r.step_through(12, State::QuickStopActive, State::SwitchOnDisabled);
    assert!(!out.power_stage);

    // A44 = 1 quick stop: A60 back and lost again also ends it at once.
    let mut r = Rig::moving(Options {
        quick_stop_on_enable_loss: true,
        ..Options::default()
    });
    r.inp.additional_enable = false;
    assert_eq!(r.step().state, State::QuickStopActive);
    r.inp.additional_enable = true;
    assert_eq!(r.step().state, State::QuickStopActive);
    r.inp.additional_enable = false;
    assert_eq!(r.step().transition.map(|t| t.number), Some(12));
}

#[test]
fn c015_supply_and_sto_force_switch_on_disabled() {
    type Cut = fn(&mut Inputs);
    let cuts: [(Cut, u8); 2] = [
        (|i| i.supply_ok = false, SodCauses::SUPPLY),
        (|i| i.sto_active = true, SodCauses::STO),
    ];
    for (cut, cause) in cuts {
        // Blocks T2.
        let mut r = Rig::new();
        r.goto(State::SwitchOnDisabled);
        cut(&mut r.inp);
        for _ in 0..3 {
            let out = r.cw(SHUTDOWN);
            assert_eq!(out.state, State::SwitchOnDisabled);
            assert!(out.sod_causes.contains(cause));
        }
        // Forces T7, T10, T9 and ends a quick stop (T12).
        for (from, number) in [
            (State::ReadyToSwitchOn, 7),
            (State::SwitchedOn, 10),
            (State::OperationEnabled, 9),
            (State::QuickStopActive, 12),
        ] {
            let mut r = Rig::new();
            r.goto(from);
            r.inp.standstill = false;
            cut(&mut r.inp);
            let out = r.step_through(number, from, State::SwitchOnDisabled);
            assert!(!out.power_stage);
            assert!(out.sod_causes.contains(cause));
        }
    }
    // A44 = 1 does not turn a supply loss into a quick stop.
    let mut r = Rig::with(Options {
        quick_stop_on_enable_loss: true,
        ..Options::default()
    });
    r.goto(State::OperationEnabled);
    r.inp.sto_active = true;
    assert_eq!(r.step().transition.map(|t| t.number), Some(9));
    // Statusword bit 4 follows the supply.
    let mut r = Rig::new();
    assert_ne!(r.step().statusword & SW_VOLTAGE_ENABLED, 0);
    r.inp.supply_ok = false;
    assert_eq!(r.step().statusword & SW_VOLTAGE_ENABLED, 0);
}

#[test]
fn c016_fault_reaction_then_fault() {
    // From Operation enabled with the 605Eh default (quick-stop ramp).
    let mut r = Rig::moving(Options::default());
    let ev = FaultEvent {
        code: 0x4210,
        reaction: None,
    };
    r.dc.raise_fault(ev);
    let out = r.cw(ENABLE_OPERATION);
    assert_eq!(
        tr(&out),
        Some((13, State::OperationEnabled, State::FaultReactionActive))
    );
    assert_eq!(out.ramp, Ramp::FaultReaction(Decel::QuickStop));
    assert!(out.power_stage && !out.motion_enabled);
    assert_eq!(out.fault, Some(ev));
    // Commands and reset edges do nothing during the reaction.
    for cw in [ENABLE_OPERATION, DISABLE_VOLTAGE, FAULT_RESET, 0] {
        assert_eq!(r.cw(cw).state, State::FaultReactionActive);
    }
    r.inp.standstill = true;
    let out = r.step_through(14, State::FaultReactionActive, State::Fault);
    assert!(!out.power_stage && !out.brake_release);
    assert_eq!(out.fault, Some(ev));

    // From every other state: no torque, so the reaction is immediate (coast).
    for from in [State::SwitchOnDisabled, State::ReadyToSwitchOn, State::SwitchedOn] {
        let mut r = Rig::new();
        r.goto(from);
        r.dc.raise_fault(ev);
        let out = r.step_through(13, from, State::FaultReactionActive);
        assert!(!out.power_stage);
        assert_eq!(out.ramp, Ramp::None);
        assert_eq!(r.step().transition.map(|t| t.number), Some(14));
    }
    // From Not ready to switch on (self-test failed).
    let mut r = Rig::new();
    r.inp.initialised = false;
    r.dc.raise_fault(ev);
    assert_eq!(
        tr(&r.step()),
        Some((13, State::NotReadyToSwitchOn, State::FaultReactionActive))
    );
    // From Quick stop active.
    let mut r = Rig::new();
    r.goto(State::QuickStopActive);
    r.dc.raise_fault(ev);
    let out = r.step();
    assert_eq!(out.transition.map(|t| t.number), Some(13));
    assert_eq!(out.ramp, Ramp::FaultReaction(Decel::QuickStop));
}

#[test]
fn c016_fault_reaction_option_codes() {
    assert_eq!(FaultReaction::try_from(0), Ok(FaultReaction::Coast));
    let decels = [
        Decel::SlowDown,
        Decel::QuickStop,
        Decel::CurrentLimit,
        Decel::VoltageLimit,
    ];
    for (i, d) in decels.iter().enumerate() {
        let n = i as i16 + 1;
        assert_eq!(FaultReaction::try_from(n), Ok(FaultReaction::Stop(*d)));
        assert_eq!(FaultReaction::Stop(*d).code(), n);
    }
    assert_eq!(FaultReaction::try_from(5), Err(OptionCodeError(5)));
    assert_eq!(FaultReaction::try_from(-1), Err(OptionCodeError(-1)));
    assert_eq!(Options::default().fault_reaction.code(), 2);

    // Each 605Eh value from Operation enabled.
    for v in 0i16..=4 {
        let reaction = FaultReaction::try_from(v).unwrap();
        let mut r = Rig::moving(Options {
            fault_reaction: reaction,
            ..Options::default()
        });
        r.dc.raise_fault(FaultEvent {
            code: 0x5000,
            reaction: None,
        });
        let out = r.cw(ENABLE_OPERATION);
        assert_eq!(out.state, State::FaultReactionActive);
        match reaction {
            FaultReaction::Coast => {
                assert!(!out.power_stage);
                assert_eq!(out.ramp, Ramp::None);
                assert_eq!(r.step().state, State::Fault);
            }
            FaultReaction::Stop(d) => {
                assert!(out.power_stage);
                assert_eq!(out.ramp, Ramp::FaultReaction(d));
                assert_eq!(r.step().state, State::FaultReactionActive);
                r.inp.standstill = true;
                assert_eq!(r.step().state, State::Fault);
            }
        }
    }

    // The event's own reaction wins over 605Eh.
    let mut r = Rig::moving(Options::default());
    r.dc.raise_fault(FaultEvent {
        code: 0x2310,
        reaction: Some(FaultReaction::Coast),
    });
    let out = r.step();
    assert!(!out.power_stage);
    assert_eq!(r.step().state, State::Fault);
}

#[test]
fn c016_fault_reaction_cut_short() {
    // A coast event during a ramped reaction.
    let mut r = Rig::new();
    r.goto(State::FaultReactionActive);
    assert_eq!(r.step().state, State::FaultReactionActive);
    r.dc.raise_fault(FaultEvent {
        code: 0x2320,
        reaction: Some(FaultReaction::Coast),
    });
    let out = r.step();
    assert_eq!(out.transition.map(|t| t.number), Some(14));
    // The first fault is kept.
    assert_eq!(out.fault.map(|f| f.code), Some(0x2310));

    // Supply lost during the reaction.
    let mut r = Rig::new();
    r.goto(State::FaultReactionActive);
    r.inp.supply_ok = false;
    let out = r.step();
    assert_eq!(out.transition.map(|t| t.number), Some(14));
    assert!(!out.power_stage);

    // A second fault in Fault changes nothing.
    let mut r = Rig::new();
    r.goto(State::Fault);
    r.dc.raise_fault(FaultEvent {
        code: 0x7000,
        reaction: None,
    });
    let out = r.step();
    assert_eq!(out.transition, None);
    assert_eq!(out.fault.map(|f| f.code), Some(0x2310));
}

#[test]
fn c016_fault_present_level_raises_generic_fault() {
    let mut r = Rig::new();
    r.goto(State::SwitchedOn);
    r.inp.fault_present = true;
    let out = r.step();
    assert_eq!(out.transition.map(|t| t.number), Some(13));
    assert_eq!(out.fault, Some(FaultEvent::GENERIC));
    assert_eq!(r.step().state, State::Fault);
    // Stays in Fault, no second T13.
    assert_eq!(r.step().transition, None);
}

#[test]
fn c016_stop_timeout_ends_reaction_without_standstill() {
    let mut r = Rig::with(Options {
        stop_timeout: Nanos::from_ms(10),
        ..Options::default()
    });
    r.goto(State::FaultReactionActive);
    let mut steps = 0;
    while r.step().state == State::FaultReactionActive {
        steps += 1;
        assert!(steps < 20, "reaction never ended");
    }
    assert_eq!(r.state(), State::Fault);
    assert!(steps >= 9, "ended after {steps} ms");
}

#[test]
fn c017_fault_reset_on_rising_edge_only() {
    let mut r = Rig::new();
    // Bit 7 already high when the fault comes: no edge.
    r.goto(State::OperationEnabled);
    r.cw(ENABLE_OPERATION | FAULT_RESET);
    r.dc.raise_fault(FaultEvent {
        code: 0x3210,
        reaction: Some(FaultReaction::Coast),
    });
    r.step();
    assert_eq!(r.step().state, State::Fault);
    for _ in 0..3 {
        assert_eq!(r.cw(FAULT_RESET).state, State::Fault);
    }
    // Edge while the cause is present: refused, and the held 1 does not count later.
    r.inp.fault_present = true;
    r.cw(0);
    assert_eq!(r.cw(FAULT_RESET).state, State::Fault);
    r.inp.fault_present = false;
    for _ in 0..3 {
        assert_eq!(r.cw(FAULT_RESET).state, State::Fault);
    }
    r.cw(0);
    let out = r.cw(FAULT_RESET);
    assert_eq!(tr(&out), Some((15, State::Fault, State::SwitchOnDisabled)));
    assert_eq!(out.fault, None);
    assert_eq!(r.dc.fault(), None);
    // While bit 7 stays set, Shutdown is not decoded.
    assert_eq!(r.cw(SHUTDOWN | FAULT_RESET).state, State::SwitchOnDisabled);
    assert_eq!(r.cw(SHUTDOWN).state, State::ReadyToSwitchOn);
}

#[test]
fn c017_fault_reset_bit_outside_fault_holds_state() {
    let mut r = Rig::new();
    r.goto(State::OperationEnabled);
    for _ in 0..3 {
        assert_eq!(
            r.cw(ENABLE_OPERATION | FAULT_RESET).state,
            State::OperationEnabled
        );
    }
}
