//! A board's world for the firmware's task bodies (`no_std`): what the bus
//! and the power stage are on the board.
//!
//! The world owns the simulated time, two motors and the scripted master
//! ([`crate::script`]); the simulated ESC is kept apart, because the
//! firmware's tasks reach it through the PDI like a real ESC (in the QEMU
//! image it is an RTIC resource). [`World::next`] says which event comes next
//! (a master frame, a SYNC0 pulse or the control-cycle timer); the caller
//! advances the clock to it and runs the task that handles it: the QEMU
//! image's idle loop pends the task's interrupt, the `firmware-tasks` crate's tests
//! call the task body.

use crate::esc::{Esc, EscConfig};
use crate::motor::{Motor, MotorOutputs};
use crate::script::{EscLink, Progress, Script, CYCLE};
use drive_ecat::axis::{AxisCommand, AxisIo};
use nanos::Nanos;

/// What happens next in the world.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Event {
    /// The master sends its frame(s) of this cycle.
    Frame,
    /// The ESC's SYNC0 output fires.
    Sync0,
    /// The control-cycle timer fires.
    Control,
}

/// Simulated time, motors and master.
pub struct World {
    now: Nanos,
    next_frame: Nanos,
    motors: [Motor; 2],
    feedback: [Option<MotorOutputs>; 2],
    script: Script,
    /// Control cycles run.
    pub cycles: u32,
}

impl Default for World {
    fn default() -> Self {
        Self::new()
    }
}

/// The simulated ESC with the SII image generated from the drive's
/// description, its clock without drift (local time = simulation time).
pub fn new_esc() -> Esc {
    let mut sii = [0u8; ecat::sii::EEPROM_BYTES];
    let len = ecat::build_sii(&drive_ecat::DEVICE, &mut sii).unwrap_or(0);
    let mut esc = Esc::new(EscConfig::default(), sii.get(..len).unwrap_or(&[]));
    esc.set_clock(0, 0);
    esc
}

impl World {
    /// Time 0, motors at rest, the master at the start of its script.
    pub fn new() -> Self {
        Self {
            now: Nanos::ZERO,
            next_frame: Nanos::from_ns(CYCLE.as_ns() / 2),
            motors: [Motor::default_servo(), Motor::default_servo()],
            feedback: [None, None],
            script: Script::new(),
            cycles: 0,
        }
    }

    /// The same with the master's EoE step in Pre-Op ([`Script::with_eoe`]):
    /// the firmware polls its IP stack in the mailbox task.
    pub fn with_eoe() -> Self {
        Self {
            script: Script::with_eoe(),
            ..Self::new()
        }
    }

    /// Simulated time (the firmware's clock in QEMU).
    pub fn now(&self) -> Nanos {
        self.now
    }

    /// Whether the master's script ended, and whether it succeeded.
    pub fn finished(&self) -> Option<bool> {
        self.script.finished().then(|| self.script.succeeded())
    }

    /// The next event given the ESC's next SYNC0 and the control timer's
    /// next start (local = simulation time); the clock moves to it. Ties go
    /// SYNC0, control, frame.
    pub fn next(&mut self, next_sync0: Option<Nanos>, next_control: Nanos) -> Event {
        let sync0 = next_sync0.unwrap_or(Nanos::MAX);
        let (t, event) = if sync0 <= next_control && sync0 <= self.next_frame {
            (sync0, Event::Sync0)
        } else if next_control <= self.next_frame {
            (next_control, Event::Control)
        } else {
            (self.next_frame, Event::Frame)
        };
        self.now = self.now.max(t);
        event
    }

    /// The master's frame of this cycle through `esc`; schedules the next.
    pub fn frame(&mut self, esc: &mut Esc) -> Progress {
        let mut link = EscLink { esc, now: self.now };
        let p = self.script.step(&mut link);
        self.next_frame = self.next_frame.saturating_add(CYCLE);
        p
    }

    /// The hardware inputs of both axes for the control cycle now: encoder
    /// positions, enable, supply and STO ready.
    pub fn io(&self) -> [AxisIo; 2] {
        let mut io = [AxisIo::ready(0), AxisIo::ready(0)];
        for ((io, fb), motor) in io.iter_mut().zip(&self.feedback).zip(&self.motors) {
            io.position_inc = match fb {
                Some(out) => out.position_inc,
                None => motor.position_inc_i64() as i32,
            };
        }
        io
    }

    /// One motor step per axis with the control cycle's commands.
    pub fn actuate(&mut self, cmd: &[AxisCommand; 2], cycle: Nanos) {
        self.cycles = self.cycles.wrapping_add(1);
        for ((motor, fb), c) in self.motors.iter_mut().zip(self.feedback.iter_mut()).zip(cmd) {
            let torque = if c.power_stage {
                f64::from(c.torque_nm)
            } else {
                0.0
            };
            *fb = Some(motor.step(torque, !c.brake_release, cycle));
        }
    }
}
