//! Device control checklist tests, named after the items of
//! `shared/spec/features-cia402.md` ("Device control state machine", "Operating modes –
//! general"). Tests without an item prefix check `[std]` behaviour the checklist does not
//! list (halt, controlword decoding, instances).
//!
//! Here: the test rig; the tests, by checklist area, in the modules.

use cia402::controlword::{DISABLE_VOLTAGE, ENABLE_OPERATION, FAULT_RESET, QUICK_STOP, SHUTDOWN, SWITCH_ON};
use cia402::*;
use nanos::Nanos;

mod faults;
mod modes;
mod outputs;
mod std_extras;
mod transitions;

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
