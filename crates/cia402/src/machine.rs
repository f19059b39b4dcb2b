//! The device-control state machine (spec §5.1–§5.5, §6.1–§6.2).

use crate::command::{Command, CW_FAULT_RESET, CW_HALT, CW_MODE_BIT4, CW_MODE_BIT5};
use crate::mode::{Mode, ModeError, SUPPORTED_DRIVE_MODES};
use crate::options::{Decel, DisableOption, FaultReaction, HaltOption, QuickStopOption};
use crate::state::{
    State, SW_INTERNAL_LIMIT, SW_MANUFACTURER_MASK, SW_MODE_BIT12, SW_MODE_BIT13, SW_REMOTE,
    SW_TARGET_REACHED, SW_VOLTAGE_ENABLED, SW_WARNING,
};
use nanos::Nanos;

/// Configuration: the option codes and device parameters the state machine reads. All
/// fields may be changed between two [`DeviceControl::step`] calls
/// ([`DeviceControl::options_mut`]); a stop that is already running keeps its deceleration.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Options {
    /// 605Ah (A536) quick stop option code.
    pub quick_stop: QuickStopOption,
    /// 605Bh shutdown option code (T8).
    pub shutdown: DisableOption,
    /// 605Ch disable operation option code (T5).
    pub disable_operation: DisableOption,
    /// 605Dh halt option code (controlword bit 8).
    pub halt: HaltOption,
    /// 605Eh (A540) fault reaction option code, used when a fault event names no reaction.
    pub fault_reaction: FaultReaction,
    /// A44 = 1 "Active": losing A60 in Operation enabled gives a quick stop (T11) instead
    /// of an immediate power-off (T9).
    pub quick_stop_on_enable_loss: bool,
    /// Accept Enable operation (0x0F) in Ready to switch on: T3 is taken, then T4 in the
    /// next step (`[std]`).
    pub enable_from_ready: bool,
    /// 6502h supported drive modes; a 6060h request for a mode without its bit is refused.
    pub supported_modes: u32,
    /// The mode active after start-up (6061h before the first accepted request).
    pub initial_mode: Mode,
    /// Brake closing time: after a ramped stop reaches standstill with the brake
    /// released, the brake is engaged and torque is held this long before the drive
    /// function goes off. 0 = no wait.
    pub brake_close: Nanos,
    /// Longest time a ramped stop (quick stop, fault reaction, disable ramp) may take;
    /// after it the stop counts as finished even without standstill. 0 = no limit.
    pub stop_timeout: Nanos,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            quick_stop: QuickStopOption::DEFAULT,
            shutdown: DisableOption::Coast,
            disable_operation: DisableOption::Coast,
            halt: HaltOption::DEFAULT,
            fault_reaction: FaultReaction::DEFAULT,
            quick_stop_on_enable_loss: false,
            enable_from_ready: true,
            supported_modes: SUPPORTED_DRIVE_MODES,
            initial_mode: Mode::DEFAULT,
            brake_close: Nanos::ZERO,
            stop_timeout: Nanos::ZERO,
        }
    }
}

/// What the application hands to [`DeviceControl::step`] once per control cycle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Inputs {
    /// 6040h controlword.
    pub controlword: u16,
    /// 6060h modes of operation (requested mode).
    pub mode_request: i8,
    /// Initialisation and self-test finished successfully (T1).
    pub initialised: bool,
    /// A60 additional enable signal is active.
    pub additional_enable: bool,
    /// Supply and DC-link voltage present and high enough.
    pub supply_ok: bool,
    /// Safe torque off is active.
    pub sto_active: bool,
    /// The axis stands still (I199: |actual velocity| < C40).
    pub standstill: bool,
    /// A fault cause is still present. In Fault it blocks the fault reset (T15); in any
    /// other state it raises a generic fault ([`FaultEvent::GENERIC`]).
    pub fault_present: bool,
    /// The motion core has an active motion command (releases the brake in csp, csv,
    /// cst, vl, pv, pt).
    pub motion_command: bool,
    /// Brake release override: keeps the brake open in every state.
    pub brake_override: bool,
    /// Statusword bit 10 from the motion core (valid in Operation enabled and Quick stop
    /// active).
    pub target_reached: bool,
    /// Statusword bit 12 from the motion core (valid in Operation enabled).
    pub mode_bit12: bool,
    /// Statusword bit 13 from the motion core (valid in Operation enabled).
    pub mode_bit13: bool,
    /// Statusword bit 7: a warning is pending.
    pub warning: bool,
    /// Statusword bit 9: the controlword is processed (no local control panel).
    pub remote: bool,
    /// Statusword bit 11: an internal limit is active.
    pub internal_limit: bool,
    /// Manufacturer statusword bits; only bits 8, 14 and 15 are used.
    pub manufacturer_bits: u16,
}

impl Default for Inputs {
    /// Controlword 0, mode request 8 (csp), every flag false.
    fn default() -> Self {
        Inputs {
            controlword: 0,
            mode_request: Mode::DEFAULT.code(),
            initialised: false,
            additional_enable: false,
            supply_ok: false,
            sto_active: false,
            standstill: false,
            fault_present: false,
            motion_command: false,
            brake_override: false,
            target_reached: false,
            mode_bit12: false,
            mode_bit13: false,
            warning: false,
            remote: false,
            internal_limit: false,
            manufacturer_bits: 0,
        }
    }
}

/// The stop the motion core must run. "Coast" is not a ramp: it shows as
/// `power_stage == false`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Ramp {
    /// No stop: follow the mode's set-points (if `motion_enabled`).
    None,
    /// Controlword bit 8 halt (605Dh); the state does not change.
    Halt(Decel),
    /// Ramp before Disable operation (T5, 605Ch = 1) or Shutdown (T8, 605Bh = 1).
    Disable(Decel),
    /// Quick stop (605Ah); after standstill with option codes 5..8: hold the position.
    QuickStop(Decel),
    /// Fault reaction (605Eh or the event's own reaction).
    FaultReaction(Decel),
}

/// A state change, numbered as in spec §5.4 (1..15).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Transition {
    /// Transition number.
    pub number: u8,
    /// State before.
    pub from: State,
    /// State after.
    pub to: State,
}

/// A fault raised by the application.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct FaultEvent {
    /// CiA error code (603Fh / EMCY error code).
    pub code: u16,
    /// The event's own reaction; `None` uses 605Eh.
    pub reaction: Option<FaultReaction>,
}

impl FaultEvent {
    /// Generic error 1000h with the 605Eh reaction: raised when `fault_present` is set
    /// outside the fault states without a fault event.
    pub const GENERIC: FaultEvent = FaultEvent {
        code: 0x1000,
        reaction: None,
    };
}

/// Reasons that keep or force the drive in Switch on disabled, as seen in this step
/// (for E47/E49). A bit set.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct SodCauses(pub u8);

impl SodCauses {
    /// Supply or DC-link voltage missing or low.
    pub const SUPPLY: u8 = 1 << 0;
    /// STO active.
    pub const STO: u8 = 1 << 1;
    /// Additional enable A60 inactive.
    pub const ADDITIONAL_ENABLE: u8 = 1 << 2;
    /// Controlword commands Disable voltage.
    pub const DISABLE_VOLTAGE: u8 = 1 << 3;
    /// Controlword commands Quick stop.
    pub const QUICK_STOP: u8 = 1 << 4;

    /// `true` if every bit of `bits` is set.
    pub const fn contains(self, bits: u8) -> bool {
        self.0 & bits == bits
    }
}

/// What [`DeviceControl::step`] tells the rest of the firmware.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Outputs {
    /// Current state (E48).
    pub state: State,
    /// 6041h statusword.
    pub statusword: u16,
    /// 6061h modes of operation display: the mode actually active.
    pub mode_display: i8,
    /// The requested mode was refused (the old mode stays); repeated while requested.
    pub mode_error: Option<ModeError>,
    /// A valid mode change waits for standstill.
    pub mode_pending: bool,
    /// The power stage is switched on.
    pub power_stage: bool,
    /// The controller produces torque (Operation enabled, and the ramped stops).
    pub drive_function: bool,
    /// Set-points are processed and motion commands may run (Operation enabled without a
    /// disable ramp; false in Switched on, Quick stop active and the fault states).
    pub motion_enabled: bool,
    /// Release the holding brake.
    pub brake_release: bool,
    /// The stop the motion core must run.
    pub ramp: Ramp,
    /// The transition taken in this step, if any (at most one per step).
    pub transition: Option<Transition>,
    /// The fault being handled (Fault reaction active and Fault).
    pub fault: Option<FaultEvent>,
    /// Switch-on-disabled causes present in this step.
    pub sod_causes: SodCauses,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Ramping { start: Nanos },
    BrakeClosing { start: Nanos },
    Holding,
}

/// A stop in progress. `ramp == Ramp::None` means coast (power stage off).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Stopping {
    ramp: Ramp,
    hold: bool,
    phase: Phase,
}

/// One axis' CiA 402 device control. Sans-IO: call [`DeviceControl::step`] once per
/// control cycle with the inputs and the time; two axes are two instances.
#[derive(Debug, Clone)]
pub struct DeviceControl {
    options: Options,
    state: State,
    mode: Mode,
    prev_fault_reset: bool,
    prev_enable: bool,
    brake_released: bool,
    stop: Option<Stopping>,
    pending_fault: Option<FaultEvent>,
    fault: Option<FaultEvent>,
    /// The inputs and outputs of the last step when that step was a fixed
    /// point (see [`DeviceControl::step`]); `None` otherwise.
    settled: Option<(Inputs, Outputs)>,
}

impl DeviceControl {
    /// A state machine in Not ready to switch on with the initial mode of `options`.
    pub fn new(options: Options) -> Self {
        DeviceControl {
            options,
            state: State::NotReadyToSwitchOn,
            mode: options.initial_mode,
            // A fault-reset bit already set at start-up is not an edge.
            prev_fault_reset: true,
            prev_enable: false,
            brake_released: false,
            stop: None,
            pending_fault: None,
            fault: None,
            settled: None,
        }
    }

    /// Current state.
    pub fn state(&self) -> State {
        self.state
    }

    /// The active mode (6061h).
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// The configuration.
    pub fn options(&self) -> &Options {
        &self.options
    }

    /// The configuration, for OD writes to the option codes, A44 and 6502h.
    pub fn options_mut(&mut self) -> &mut Options {
        self.settled = None;
        &mut self.options
    }

    /// The fault being handled, if any.
    pub fn fault(&self) -> Option<FaultEvent> {
        self.fault
    }

    /// Raises a fault: the next [`step`](Self::step) takes T13 to Fault reaction active.
    /// Outside the fault states the first event is kept (a later one with a coast
    /// reaction turns the reaction into coast); during a fault reaction a coast event
    /// cuts the running reaction short; in Fault nothing changes.
    pub fn raise_fault(&mut self, event: FaultEvent) {
        let coast = event.reaction == Some(FaultReaction::Coast);
        match self.state {
            State::Fault => {}
            State::FaultReactionActive => {
                if coast {
                    self.coast();
                }
            }
            _ => match self.pending_fault.as_mut() {
                None => self.pending_fault = Some(event),
                Some(p) => {
                    if coast {
                        p.reaction = Some(FaultReaction::Coast);
                    }
                }
            },
        }
    }

    /// One control cycle: decodes the controlword, takes at most one transition, updates
    /// the mode and returns the outputs. `now` is a monotonic time in ns.
    ///
    /// A step that took no transition (a fault taken is T13) and left no stop running ends
    /// in a state the same inputs keep: the edges of the fault-reset bit and of A60 are
    /// gone, a mode switch or a brake release it made is done, and `now` enters only a
    /// running stop or a transition. Its outputs were computed from that state, so the
    /// next step with equal inputs, no fault raised and no option changed in between
    /// returns them without running the machine (issue 36: the cycle while the master's
    /// commands stand).
    pub fn step(&mut self, inp: &Inputs, now: Nanos) -> Outputs {
        if let Some((last, out)) = &self.settled {
            if self.pending_fault.is_none() && last == inp {
                return *out;
            }
        }
        let out = self.step_machine(inp, now);
        let settled = out.transition.is_none() && self.stop.is_none();
        self.settled = if settled { Some((*inp, out)) } else { None };
        out
    }

    fn step_machine(&mut self, inp: &Inputs, now: Nanos) -> Outputs {
        let cw = inp.controlword;
        let reset_bit = cw & CW_FAULT_RESET != 0;
        let reset_edge = reset_bit && !self.prev_fault_reset;
        self.prev_fault_reset = reset_bit;
        let enable_lost = !inp.additional_enable && self.prev_enable;
        self.prev_enable = inp.additional_enable;
        let cmd = Command::decode(cw);

        let (mode_error, mode_pending) = self.update_mode(inp);

        let fault = match self.pending_fault.take() {
            Some(ev) => Some(ev),
            None if inp.fault_present && !self.state.is_fault() => Some(FaultEvent::GENERIC),
            None => None,
        };
        let transition = match fault {
            Some(ev) => Some(self.enter_fault(ev, inp, now)),
            None => self.run_state(cmd, reset_edge, enable_lost, inp, now),
        };

        self.outputs(inp, cmd, transition, mode_error, mode_pending)
    }

    fn update_mode(&mut self, inp: &Inputs) -> (Option<ModeError>, bool) {
        match Mode::check(inp.mode_request, self.options.supported_modes) {
            Err(e) => (Some(e), false),
            Ok(m) if m == self.mode => (None, false),
            Ok(m) => {
                if self.mode.switch_needs_standstill(m) && !inp.standstill {
                    (None, true)
                } else {
                    self.mode = m;
                    (None, false)
                }
            }
        }
    }

    fn go(&mut self, to: State, number: u8) -> Option<Transition> {
        let from = self.state;
        self.state = to;
        self.stop = None;
        self.brake_released = false;
        if to == State::SwitchOnDisabled && from == State::Fault {
            self.fault = None;
        }
        Some(Transition { number, from, to })
    }

    fn coast(&mut self) {
        if let Some(s) = self.stop.as_mut() {
            s.ramp = Ramp::None;
            s.hold = false;
        }
        self.brake_released = false;
    }

    fn enter_fault(&mut self, ev: FaultEvent, inp: &Inputs, now: Nanos) -> Transition {
        let from = self.state;
        let reaction = ev.reaction.unwrap_or(self.options.fault_reaction);
        let torque = match from {
            State::OperationEnabled => true,
            State::QuickStopActive => self.stop.is_some_and(|s| s.ramp != Ramp::None),
            _ => false,
        };
        let powered = inp.supply_ok && !inp.sto_active;
        let ramp = match reaction {
            FaultReaction::Stop(d) if torque && powered => Ramp::FaultReaction(d),
            _ => Ramp::None,
        };
        if ramp == Ramp::None {
            self.brake_released = false;
        }
        self.state = State::FaultReactionActive;
        self.stop = Some(Stopping {
            ramp,
            hold: false,
            phase: Phase::Ramping { start: now },
        });
        self.fault = Some(ev);
        Transition {
            number: 13,
            from,
            to: State::FaultReactionActive,
        }
    }

    fn enter_quick_stop(&mut self, now: Nanos) -> Option<Transition> {
        let from = self.state;
        let (ramp, hold) = match self.options.quick_stop {
            QuickStopOption::Coast => (Ramp::None, false),
            QuickStopOption::ThenDisable(d) => (Ramp::QuickStop(d), false),
            QuickStopOption::ThenHold(d) => (Ramp::QuickStop(d), true),
        };
        if ramp == Ramp::None {
            self.brake_released = false;
        }
        self.state = State::QuickStopActive;
        self.stop = Some(Stopping {
            ramp,
            hold,
            phase: Phase::Ramping { start: now },
        });
        Some(Transition {
            number: 11,
            from,
            to: State::QuickStopActive,
        })
    }

    /// Advances the running stop; `true` once it is finished (coast: at once).
    fn advance_stop(&mut self, inp: &Inputs, now: Nanos) -> bool {
        let opts = self.options;
        let Some(stop) = self.stop.as_mut() else {
            return true;
        };
        if stop.ramp == Ramp::None {
            return true;
        }
        match stop.phase {
            Phase::Ramping { start } => {
                let timed_out = !opts.stop_timeout.is_zero() && now.since(start) >= opts.stop_timeout;
                if !(inp.standstill || timed_out) {
                    return false;
                }
                if stop.hold {
                    stop.phase = Phase::Holding;
                    return false;
                }
                if self.brake_released && !opts.brake_close.is_zero() {
                    self.brake_released = false;
                    stop.phase = Phase::BrakeClosing { start: now };
                    return false;
                }
                true
            }
            Phase::BrakeClosing { start } => now.since(start) >= opts.brake_close,
            Phase::Holding => false,
        }
    }

    /// Shutdown (T8) or Disable operation (T5) from Operation enabled, with the option.
    fn disable_from_enabled(
        &mut self,
        to: State,
        number: u8,
        option: DisableOption,
        inp: &Inputs,
        now: Nanos,
    ) -> Option<Transition> {
        match option {
            DisableOption::Coast => self.go(to, number),
            DisableOption::SlowDown => {
                if self.stop.is_none() {
                    self.stop = Some(Stopping {
                        ramp: Ramp::Disable(Decel::SlowDown),
                        hold: false,
                        phase: Phase::Ramping { start: now },
                    });
                }
                if self.advance_stop(inp, now) {
                    self.go(to, number)
                } else {
                    None
                }
            }
        }
    }

    fn release_trigger(&self, inp: &Inputs) -> bool {
        let cw = inp.controlword;
        match self.mode {
            Mode::CyclicPosition
            | Mode::CyclicVelocity
            | Mode::CyclicTorque
            | Mode::Velocity
            | Mode::ProfileVelocity
            | Mode::ProfileTorque => inp.motion_command,
            Mode::ProfilePosition | Mode::InterpolatedPosition | Mode::Homing => cw & CW_MODE_BIT4 != 0,
            Mode::Jog => cw & (CW_MODE_BIT4 | CW_MODE_BIT5) != 0,
            Mode::NoMode => false,
        }
    }

    fn run_state(
        &mut self,
        cmd: Option<Command>,
        reset_edge: bool,
        enable_lost: bool,
        inp: &Inputs,
        now: Nanos,
    ) -> Option<Transition> {
        let powered = inp.supply_ok && !inp.sto_active;
        let a60 = inp.additional_enable;
        let sod_command = matches!(cmd, Some(Command::DisableVoltage | Command::QuickStop));
        match self.state {
            State::NotReadyToSwitchOn => {
                if inp.initialised {
                    self.go(State::SwitchOnDisabled, 1)
                } else {
                    None
                }
            }
            State::SwitchOnDisabled => {
                if cmd == Some(Command::Shutdown) && a60 && powered {
                    self.go(State::ReadyToSwitchOn, 2)
                } else {
                    None
                }
            }
            State::ReadyToSwitchOn => {
                if !powered || !a60 || sod_command {
                    self.go(State::SwitchOnDisabled, 7)
                } else if cmd == Some(Command::SwitchOn)
                    || (cmd == Some(Command::EnableOperation) && self.options.enable_from_ready)
                {
                    self.go(State::SwitchedOn, 3)
                } else {
                    None
                }
            }
            State::SwitchedOn => {
                if !powered || !a60 || sod_command {
                    self.go(State::SwitchOnDisabled, 10)
                } else if cmd == Some(Command::Shutdown) {
                    self.go(State::ReadyToSwitchOn, 6)
                } else if cmd == Some(Command::EnableOperation) {
                    self.go(State::OperationEnabled, 4)
                } else {
                    None
                }
            }
            State::OperationEnabled => {
                let a44 = self.options.quick_stop_on_enable_loss;
                if !powered || (!a60 && !a44) || cmd == Some(Command::DisableVoltage) {
                    self.go(State::SwitchOnDisabled, 9)
                } else if !a60 || cmd == Some(Command::QuickStop) {
                    self.enter_quick_stop(now)
                } else {
                    match cmd {
                        Some(Command::Shutdown) => self.disable_from_enabled(
                            State::ReadyToSwitchOn,
                            8,
                            self.options.shutdown,
                            inp,
                            now,
                        ),
                        Some(Command::SwitchOn) => self.disable_from_enabled(
                            State::SwitchedOn,
                            5,
                            self.options.disable_operation,
                            inp,
                            now,
                        ),
                        Some(Command::EnableOperation) => {
                            self.stop = None;
                            if !self.brake_released && self.release_trigger(inp) {
                                self.brake_released = true;
                            }
                            None
                        }
                        _ => None,
                    }
                }
            }
            State::QuickStopActive => {
                // Disable voltage, a switch-on-disabled cause or A60 dropping while here
                // end the quick stop at once; otherwise it ends when the stop is done.
                let abort = !powered || cmd == Some(Command::DisableVoltage) || enable_lost;
                if abort || self.advance_stop(inp, now) {
                    self.go(State::SwitchOnDisabled, 12)
                } else {
                    None
                }
            }
            State::FaultReactionActive => {
                if !powered {
                    self.coast();
                }
                if self.advance_stop(inp, now) {
                    self.go(State::Fault, 14)
                } else {
                    None
                }
            }
            State::Fault => {
                if reset_edge && !inp.fault_present {
                    self.go(State::SwitchOnDisabled, 15)
                } else {
                    None
                }
            }
        }
    }

    fn outputs(
        &self,
        inp: &Inputs,
        cmd: Option<Command>,
        transition: Option<Transition>,
        mode_error: Option<ModeError>,
        mode_pending: bool,
    ) -> Outputs {
        let state = self.state;
        let stop_torque = self.stop.is_some_and(|s| s.ramp != Ramp::None);
        let (power_stage, drive_function) = match state {
            State::SwitchedOn => (true, false),
            State::OperationEnabled => (true, true),
            State::QuickStopActive | State::FaultReactionActive => (stop_torque, stop_torque),
            _ => (false, false),
        };
        let motion_enabled = state == State::OperationEnabled && self.stop.is_none();
        let ramp = match self.stop {
            Some(s) => s.ramp,
            None if motion_enabled && inp.controlword & CW_HALT != 0 && self.mode.halt_applies() => {
                Ramp::Halt(self.options.halt.0)
            }
            None => Ramp::None,
        };

        let mut sw = state.state_bits();
        let mut set = |cond: bool, bit: u16| {
            if cond {
                sw |= bit;
            }
        };
        set(inp.supply_ok, SW_VOLTAGE_ENABLED);
        set(inp.warning, SW_WARNING);
        set(inp.remote, SW_REMOTE);
        set(inp.internal_limit, SW_INTERNAL_LIMIT);
        let mode_bits = state == State::OperationEnabled;
        let target_bit = mode_bits || state == State::QuickStopActive;
        set(target_bit && inp.target_reached, SW_TARGET_REACHED);
        set(mode_bits && inp.mode_bit12, SW_MODE_BIT12);
        set(mode_bits && inp.mode_bit13, SW_MODE_BIT13);
        sw |= inp.manufacturer_bits & SW_MANUFACTURER_MASK;

        let mut causes = 0u8;
        let mut cause = |cond: bool, bit: u8| {
            if cond {
                causes |= bit;
            }
        };
        cause(!inp.supply_ok, SodCauses::SUPPLY);
        cause(inp.sto_active, SodCauses::STO);
        cause(!inp.additional_enable, SodCauses::ADDITIONAL_ENABLE);
        cause(cmd == Some(Command::DisableVoltage), SodCauses::DISABLE_VOLTAGE);
        cause(cmd == Some(Command::QuickStop), SodCauses::QUICK_STOP);

        Outputs {
            state,
            statusword: sw,
            mode_display: self.mode.code(),
            mode_error,
            mode_pending,
            power_stage,
            drive_function,
            motion_enabled,
            brake_release: self.brake_released || inp.brake_override,
            ramp,
            transition,
            fault: if state.is_fault() { self.fault } else { None },
            sod_causes: SodCauses(causes),
        }
    }
}

#[cfg(test)]
#[path = "machine_settled_tests.rs"]
mod settled_tests;
