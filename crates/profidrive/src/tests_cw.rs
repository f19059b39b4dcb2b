use crate::cw1::*;
use crate::zsw1::{self, State, Status};

const POS: Context = Context {
    mode: Mode::Positioning,
    homing_active: false,
};
const HOMING: Context = Context {
    mode: Mode::Positioning,
    homing_active: true,
};
const SPEED: Context = Context {
    mode: Mode::Speed,
    homing_active: false,
};

fn pos(d: &mut Cw1Decoder, cw1: u16, ctx: Context) -> PosCommands {
    match d.decode(Some(cw1), ctx).mode {
        ModeCommands::Positioning(p) => p,
        other => panic!("{other:?}"),
    }
}

#[test]
fn p077_bits_0_to_3_and_7_are_the_cia402_controlword_bits() {
    let mut d = Cw1Decoder::new();
    for (cw1, cw) in [
        (0x0406, 0x0006),
        (0x0407, 0x0007),
        (0x040F, 0x000F),
        (0x0487, 0x0087),
        (0x7F7F, 0x000F),
    ] {
        let t = d.decode(Some(cw1), POS);
        assert_eq!(
            (t.controlword, t.evaluated, t.control_requested),
            (cw, true, true),
            "{cw1:04x}"
        );
    }
    // mode bits never reach the controlword
    assert_eq!(d.decode(Some(0x3F70), POS).controlword, 0);
}

#[test]
fn p078_p080_bit_4_0_cancels_and_bit_5_0_stops_in_between() {
    let mut d = Cw1Decoder::new();
    let p = pos(&mut d, 0x042F, POS);
    assert!(p.cancel && !p.intermediate_stop);
    let p = pos(&mut d, 0x041F, POS);
    assert!(!p.cancel && p.intermediate_stop);
    let p = pos(&mut d, 0x043F, POS);
    assert!(!p.cancel && !p.intermediate_stop);
}

#[test]
fn p082_bit_6_rising_starts_only_with_bits_4_and_5_and_no_homing() {
    let mut d = Cw1Decoder::new();
    pos(&mut d, 0x043F, POS);
    assert!(pos(&mut d, 0x047F, POS).start);
    assert!(!pos(&mut d, 0x047F, POS).start, "held: no new start");
    pos(&mut d, 0x043F, POS);
    assert!(!pos(&mut d, 0x046F, POS).start, "bit 4 = 0");
    pos(&mut d, 0x043F, POS);
    assert!(!pos(&mut d, 0x045F, POS).start, "bit 5 = 0");
    pos(&mut d, 0x043F, POS);
    assert!(!pos(&mut d, 0x047F, HOMING).start, "homing active");
}

#[test]
fn p083_a_falling_edge_of_bit_6_has_no_effect() {
    let mut d = Cw1Decoder::new();
    pos(&mut d, 0x047F, POS);
    assert_eq!(pos(&mut d, 0x043F, POS), PosCommands::default());
}

#[test]
fn p086_p087_p088_jog_bits_are_levels_ignored_during_homing() {
    let mut d = Cw1Decoder::new();
    let p = pos(&mut d, 0x053F, POS);
    assert!(p.jog_positive && !p.jog_negative);
    let p = pos(&mut d, 0x063F, POS);
    assert!(!p.jog_positive && p.jog_negative);
    let p = pos(&mut d, 0x073F, HOMING);
    assert!(!p.jog_positive && !p.jog_negative);
}

#[test]
fn p089_with_bit_10_0_cw1_is_not_evaluated_and_the_last_state_stays() {
    let mut d = Cw1Decoder::new();
    d.decode(Some(0x043F), POS);
    let t = d.decode(Some(0x0070), POS);
    assert_eq!(
        (t.controlword, t.evaluated, t.control_requested),
        (0x000F, false, false)
    );
    match t.mode {
        ModeCommands::Positioning(p) => assert!(!p.start && !p.cancel && !p.intermediate_stop),
        other => panic!("{other:?}"),
    }
    assert_eq!(d.last(), 0x043F);
    // the edge counts against the last evaluated CW1
    assert!(pos(&mut d, 0x047F, POS).start);
    // no CW1 at all: the same
    let t = d.decode(None, POS);
    assert_eq!((t.controlword, t.evaluated), (0x000F, false));
}

#[test]
fn p090_bit_11_rising_starts_homing_and_falling_cancels_a_run() {
    let mut d = Cw1Decoder::new();
    pos(&mut d, 0x043F, POS);
    assert!(pos(&mut d, 0x0C3F, POS).homing_start);
    let p = pos(&mut d, 0x0C3F, HOMING);
    assert!(!p.homing_start && !p.homing_cancel);
    assert!(pos(&mut d, 0x043F, HOMING).homing_cancel);
    pos(&mut d, 0x0C3F, POS);
    assert!(
        !pos(&mut d, 0x043F, POS).homing_cancel,
        "no run: nothing to cancel"
    );
}

#[test]
fn p091_p092_bits_12_and_13_select_relative_and_change_immediately() {
    let mut d = Cw1Decoder::new();
    let p = pos(&mut d, 0x147F, POS);
    assert!(p.start && p.relative && !p.immediate);
    pos(&mut d, 0x043F, POS);
    let p = pos(&mut d, 0x247F, POS);
    assert!(p.start && !p.relative && p.immediate);
}

#[test]
fn p079_p081_p084_speed_mode_bits_4_5_6() {
    let mut d = Cw1Decoder::new();
    let s = |d: &mut Cw1Decoder, c: u16| match d.decode(Some(c), SPEED).mode {
        ModeCommands::Speed(s) => s,
        other => panic!("{other:?}"),
    };
    assert_eq!(
        s(&mut d, 0x047F),
        SpeedCommands {
            rfg_enable: true,
            rfg_freeze: false,
            setpoint_enable: true
        }
    );
    assert!(s(&mut d, 0x045F).rfg_freeze, "bit 5 = 0 freezes (Q-04)");
    assert!(!s(&mut d, 0x046F).rfg_enable);
    assert!(!s(&mut d, 0x043F).setpoint_enable);
    let other = d.decode(
        Some(0x047F),
        Context {
            mode: Mode::Other,
            homing_active: false,
        },
    );
    assert_eq!(other.mode, ModeCommands::Other);
}

#[test]
fn p094_bits_14_and_15_are_ignored() {
    let mut a = Cw1Decoder::new();
    let mut b = Cw1Decoder::new();
    for c in [0x0406u16, 0x043F, 0x047F, 0x0C3F] {
        assert_eq!(a.decode(Some(c), POS), b.decode(Some(c | 0xC000), POS));
    }
}

fn status(state: State) -> Status {
    Status::of(state)
}

#[test]
fn p096_p126_the_state_in_mask_0x47() {
    for (state, bits) in [
        (State::SwitchOnDisabled, 0x40),
        (State::ReadyToSwitchOn, 0x01),
        (State::SwitchedOn, 0x03),
        (State::OperationEnabled, 0x07),
        (State::QuickStopActive, 0x40),
        (State::NotReady, 0x00),
    ] {
        assert_eq!(zsw1::encode(&status(state)) & zsw1::STATE_MASK, bits, "{state:?}");
    }
    // no S5: a running quick stop shows bit 5 = 0 in switching on inhibited
    assert_eq!(zsw1::encode(&status(State::QuickStopActive)) & 0x20, 0);
}

#[test]
fn p097_a_fault_is_switching_on_inhibited_with_bit_3() {
    for state in [State::Fault, State::FaultReactionActive] {
        let z = zsw1::encode(&status(state));
        assert_eq!((z & zsw1::STATE_MASK, z & zsw1::FAULT), (zsw1::SOI, zsw1::FAULT));
    }
    assert_eq!(zsw1::encode(&status(State::OperationEnabled)) & zsw1::FAULT, 0);
}

#[test]
fn p098_p099_bits_4_and_5_are_set_without_coast_or_quick_stop() {
    let mut s = status(State::OperationEnabled);
    assert_eq!(zsw1::encode(&s) & 0x30, 0x30);
    s.coast_stop = true;
    assert_eq!(zsw1::encode(&s) & 0x30, 0x20);
    s.coast_stop = false;
    s.quick_stop = true;
    assert_eq!(zsw1::encode(&s) & 0x30, 0x10);
}

type Flag = (fn(&mut Status), u16);

#[test]
fn p100_p101_p103_p104_p107_p108_p109_each_flag_has_its_bit() {
    let base = status(State::SwitchOnDisabled);
    let z0 = zsw1::encode(&base);
    let flags: [Flag; 7] = [
        (|s| s.warning = true, 7),
        (|s| s.within_tolerance = true, 8),
        (|s| s.control_requested = true, 9),
        (|s| s.reached = true, 10),
        (|s| s.homed = true, 11),
        (|s| s.task_ack = true, 12),
        (|s| s.stopped = true, 13),
    ];
    for (set, bit) in flags {
        let mut s = base;
        set(&mut s);
        assert_eq!(zsw1::encode(&s) ^ z0, 1 << bit);
    }
}

#[test]
fn p068_the_manuals_dump_zsw1_0x2b70() {
    let s = Status {
        within_tolerance: true,
        control_requested: true,
        homed: true,
        stopped: true,
        ..status(State::SwitchOnDisabled)
    };
    assert_eq!(zsw1::encode(&s), 0x2B70);
}
