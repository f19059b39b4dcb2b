//! The settled step ([`DeviceControl::step`] returning the outputs it kept)
//! against a machine that runs every step: a seeded random walk over the
//! inputs, faults raised and option changes, compared step by step.

use super::*;
use crate::options::Decel;

/// xorshift64*: deterministic, no dependency.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }

    fn chance(&mut self, per_mille: u64) -> bool {
        self.below(1000) < per_mille
    }
}

/// The controlwords a master sends (the commands of spec §5.2, with halt,
/// the fault-reset bit and the mode bits 4/5 on top).
const CONTROLWORDS: [u16; 12] = [
    0x0000, 0x0006, 0x0007, 0x000F, 0x0002, 0x000B, 0x0080, 0x010F, 0x001F, 0x003F, 0x0086, 0x008F,
];
const MODES: [i8; 6] = [8, 9, 10, 1, 3, 6];

fn flip(rng: &mut Rng, inp: &mut Inputs) {
    match rng.below(14) {
        // half the time the next command of the enable sequence, so the walk
        // reaches Operation enabled and the stops from there
        0..=2 if rng.chance(500) => {
            inp.controlword = match inp.controlword & 0x008F {
                0x0006 => 0x0007,
                0x0007 | 0x000F => 0x000F,
                _ => 0x0006,
            }
        }
        0..=2 => inp.controlword = CONTROLWORDS[rng.below(CONTROLWORDS.len() as u64) as usize],
        3 => inp.mode_request = MODES[rng.below(MODES.len() as u64) as usize],
        // the conditions of a working drive hold most of the time
        4 => inp.initialised = rng.chance(950),
        5 => inp.additional_enable = rng.chance(900),
        6 => inp.supply_ok = rng.chance(900),
        7 => inp.sto_active = rng.chance(100),
        8 => inp.standstill = !inp.standstill,
        9 => inp.fault_present = rng.chance(100),
        10 => inp.motion_command = !inp.motion_command,
        11 => inp.target_reached = !inp.target_reached,
        12 => inp.mode_bit13 = !inp.mode_bit13,
        _ => inp.brake_override = !inp.brake_override,
    }
}

fn options(rng: &mut Rng) -> Options {
    let decel = [Decel::SlowDown, Decel::QuickStop, Decel::CurrentLimit][rng.below(3) as usize];
    Options {
        quick_stop: [
            QuickStopOption::Coast,
            QuickStopOption::ThenDisable(decel),
            QuickStopOption::ThenHold(decel),
        ][rng.below(3) as usize],
        shutdown: [DisableOption::Coast, DisableOption::SlowDown][rng.below(2) as usize],
        disable_operation: [DisableOption::Coast, DisableOption::SlowDown][rng.below(2) as usize],
        fault_reaction: [FaultReaction::Coast, FaultReaction::Stop(decel)][rng.below(2) as usize],
        quick_stop_on_enable_loss: rng.chance(500),
        enable_from_ready: rng.chance(500),
        brake_close: Nanos::from_ns(rng.below(3) * 2_000_000),
        stop_timeout: Nanos::from_ns(rng.below(3) * 5_000_000),
        ..Options::default()
    }
}

/// Everything of the machine but the kept step.
fn state_of(dc: &DeviceControl) -> impl PartialEq + core::fmt::Debug {
    (
        dc.options,
        dc.state,
        dc.mode,
        dc.prev_fault_reset,
        dc.prev_enable,
        dc.brake_released,
        dc.stop,
        dc.pending_fault,
        dc.fault,
    )
}

/// C-002…C-017 (the transitions) and C-018 (the statusword): the outputs and
/// the state of a machine that keeps settled steps equal, at every step,
/// those of the same machine that runs every step, over 200,000 steps of
/// inputs that mostly stand and sometimes change, faults raised between
/// steps and option codes changed. The walk must reach every state and keep
/// many steps, or it proves nothing.
#[test]
fn c002_c017_c018_settled_steps_equal_the_machine_run_every_step() {
    let mut rng = Rng(0x9E37_79B9_7F4A_7C15);
    let first = options(&mut rng);
    let mut kept = DeviceControl::new(first);
    let mut full = DeviceControl::new(first);
    let mut inp = Inputs {
        initialised: true,
        additional_enable: true,
        supply_ok: true,
        remote: true,
        ..Inputs::default()
    };
    let mut now = Nanos::ZERO;
    let (mut reused, mut states) = (0u32, [false; 8]);
    for step in 0..200_000u32 {
        now = now.wrapping_add(Nanos::from_ns(1_000_000));
        if rng.chance(60) {
            flip(&mut rng, &mut inp);
        }
        if rng.chance(2) {
            let event = FaultEvent {
                code: 0x7300,
                reaction: if rng.chance(300) {
                    Some(FaultReaction::Coast)
                } else {
                    None
                },
            };
            kept.raise_fault(event);
            full.raise_fault(event);
        }
        if rng.chance(10) {
            let o = options(&mut rng);
            *kept.options_mut() = o;
            *full.options_mut() = o;
        }
        let will_reuse = kept.settled.is_some_and(|(last, _)| last == inp) && kept.pending_fault.is_none();
        let a = kept.step(&inp, now);
        let b = full.step_machine(&inp, now);
        assert_eq!(a, b, "outputs at step {step} ({inp:?})");
        assert_eq!(state_of(&kept), state_of(&full), "state after step {step}");
        reused += u32::from(will_reuse);
        if let Some(seen) = states.get_mut(a.state as usize) {
            *seen = true;
        }
    }
    assert!(reused > 100_000, "only {reused} kept steps");
    // every state but Not ready to switch on, left in the first step (T1)
    assert!(
        states.iter().filter(|&&s| s).count() >= 7,
        "states reached: {states:?}"
    );
}
