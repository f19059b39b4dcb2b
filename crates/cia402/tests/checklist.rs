//! Device control checklist tests, named after the items of
//! `shared/spec/features-cia402.md` ("Device control state machine", "Operating modes –
//! general"). Tests without an item prefix check `[std]` behaviour the checklist does not
//! list (halt, controlword decoding, instances).

use cia402::controlword::{DISABLE_VOLTAGE, ENABLE_OPERATION, FAULT_RESET, QUICK_STOP, SHUTDOWN, SWITCH_ON};
use cia402::*;
use nanos::Nanos;

/// One axis with inputs that allow everything: initialised, supply, A60, no STO, at
/// standstill.
struct Rig {
    dc: DeviceControl,
    inp: Inputs,
    t: Nanos,
}

impl Rig {
    fn new() -> Rig {
        Rig::with(Options::default())
    }

    fn with(opts: Options) -> Rig {
        Rig {
            dc: DeviceControl::new(opts),
            inp: Inputs {
                initialised: true,
                additional_enable: true,
                supply_ok: true,
                standstill: true,
                remote: true,
                ..Inputs::default()
            },
            t: Nanos::ZERO,
        }
    }

    /// In Operation enabled with `opts`, the motor turning (not at standstill).
    fn moving(opts: Options) -> Rig {
        let mut r = Rig::with(opts);
        r.goto(State::OperationEnabled);
        r.inp.standstill = false;
        r
    }

    /// One control cycle of 1 ms.
    fn step(&mut self) -> Outputs {
        self.t += Nanos::from_ms(1);
        self.dc.step(&self.inp, self.t)
    }

    /// A [`Rig::step`] that must make transition `number` from `from` to `to`.
    #[track_caller]
    fn step_through(&mut self, number: u8, from: State, to: State) -> Outputs {
        let out = self.step();
        assert_eq!(tr(&out), Some((number, from, to)));
        out
    }

    fn cw(&mut self, cw: u16) -> Outputs {
        self.inp.controlword = cw;
        self.step()
    }

    fn state(&self) -> State {
        self.dc.state()
    }

    /// Drives the machine into `target` with the ordinary commands.
    fn goto(&mut self, target: State) -> Outputs {
        let mut out = self.step();
        assert_eq!(out.state, State::SwitchOnDisabled);
        let path: &[(u16, State)] = match target {
            State::NotReadyToSwitchOn => unreachable!("goto starts after T1"),
            State::SwitchOnDisabled => &[],
            State::ReadyToSwitchOn => &[(SHUTDOWN, State::ReadyToSwitchOn)],
            State::SwitchedOn => &[(SHUTDOWN, State::ReadyToSwitchOn), (SWITCH_ON, State::SwitchedOn)],
            _ => &[
                (SHUTDOWN, State::ReadyToSwitchOn),
                (SWITCH_ON, State::SwitchedOn),
                (ENABLE_OPERATION, State::OperationEnabled),
            ],
        };
        for &(cw, s) in path {
            out = self.cw(cw);
            assert_eq!(out.state, s);
        }
        match target {
            State::QuickStopActive => {
                self.inp.standstill = false;
                out = self.cw(QUICK_STOP);
            }
            State::FaultReactionActive => {
                self.inp.standstill = false;
                self.dc.raise_fault(FaultEvent {
                    code: 0x2310,
                    reaction: None,
                });
                out = self.step();
            }
            State::Fault => {
                self.dc.raise_fault(FaultEvent {
                    code: 0x2310,
                    reaction: None,
                });
                out = self.step();
                assert_eq!(out.state, State::FaultReactionActive);
                out = self.step();
            }
            _ => {}
        }
        assert_eq!(out.state, target);
        out
    }
}

fn tr(out: &Outputs) -> Option<(u8, State, State)> {
    out.transition.map(|t| (t.number, t.from, t.to))
}

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

// ---------------------------------------------------------------- modes

#[test]
fn c025_mode_values_and_display() {
    for v in [-1i8, 0, 1, 2, 3, 4, 6, 7, 8, 9, 10] {
        let mut r = Rig::new();
        r.inp.mode_request = v;
        let out = r.step();
        assert_eq!(out.mode_display, v);
        assert_eq!(out.mode_error, None);
        assert_eq!(Mode::from_i8(v).map(Mode::code), Some(v));
    }
    // Invalid values: old mode kept, error reported every cycle.
    for v in [5i8, 11, -2, 127, -128] {
        let mut r = Rig::new();
        r.inp.mode_request = 3;
        r.step();
        r.inp.mode_request = v;
        for _ in 0..2 {
            let out = r.step();
            assert_eq!(out.mode_display, 3);
            assert_eq!(out.mode_error, Some(ModeError::Unsupported(v)));
        }
        assert_eq!(
            Mode::check(v, SUPPORTED_DRIVE_MODES),
            Err(ModeError::Unsupported(v))
        );
    }
    // 6502h gates the request.
    let mut r = Rig::with(Options {
        supported_modes: SUPPORTED_DRIVE_MODES & !Mode::ProfilePosition.supported_bit(),
        ..Options::default()
    });
    r.inp.mode_request = 1;
    let out = r.step();
    assert_eq!(out.mode_display, 8);
    assert_eq!(out.mode_error, Some(ModeError::Unsupported(1)));
    // 6502h bits: pp, vl, pv, pt, hm, ip, csp, csv, cst, jog (bit 16).
    assert_eq!(SUPPORTED_DRIVE_MODES, 0x0001_03EF);
    for m in Mode::ALL {
        if m != Mode::NoMode {
            assert_ne!(m.supported_bit() & SUPPORTED_DRIVE_MODES, 0, "{m:?}");
        }
    }
}

#[test]
fn c026_default_mode_is_csp() {
    assert_eq!(Mode::DEFAULT.code(), 8);
    assert_eq!(Inputs::default().mode_request, 8);
    let mut dc = DeviceControl::new(Options::default());
    assert_eq!(dc.mode(), Mode::CyclicPosition);
    assert_eq!(dc.step(&Inputs::default(), Nanos::ZERO).mode_display, 8);
}

#[test]
fn c027_mode_switch_only_at_standstill() {
    let pairs = [
        (8i8, 1i8),
        (7, 3),
        (10, 4),
        (9, 2),
        (1, 8),
        (2, 7),
        (4, 10),
        (3, 9),
    ];
    for (from, to) in pairs {
        let mut r = Rig::new();
        r.inp.mode_request = from;
        r.goto(State::OperationEnabled);
        assert_eq!(r.step().mode_display, from);
        r.inp.standstill = false;
        r.inp.mode_request = to;
        for _ in 0..3 {
            let out = r.step();
            assert_eq!(out.mode_display, from, "{from}->{to}");
            assert!(out.mode_pending);
            assert_eq!(out.mode_error, None);
        }
        r.inp.standstill = true;
        let out = r.step();
        assert_eq!(out.mode_display, to, "{from}->{to}");
        assert!(!out.mode_pending);
    }
    // Within one class, and into/out of homing, jog and no mode: at once (spec §6.2 does
    // not restrict them).
    let free = [
        (8i8, 9i8),
        (7, 10),
        (1, 3),
        (2, 4),
        (8, 6),
        (6, 1),
        (9, -1),
        (-1, 3),
        (8, 0),
    ];
    for (from, to) in free {
        let mut r = Rig::new();
        r.inp.mode_request = from;
        r.goto(State::OperationEnabled);
        r.inp.standstill = false;
        r.inp.mode_request = to;
        let out = r.step();
        assert_eq!(out.mode_display, to, "{from}->{to}");
        assert!(!out.mode_pending);
    }
    // A pending change withdrawn: nothing changes.
    let mut r = Rig::new();
    r.inp.standstill = false;
    r.inp.mode_request = 1;
    assert!(r.step().mode_pending);
    r.inp.mode_request = 8;
    let out = r.step();
    assert!(!out.mode_pending);
    assert_eq!(out.mode_display, 8);
}

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
