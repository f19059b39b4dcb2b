//! The FB model against the spec's tables and against the drive's own
//! profile code (`profidrive`): the telegram layouts of the shipped
//! defaults, the CW1 decoder, the ZSW1 encoder, the PKW mailbox.

use super::pkw::{Access, Outcome, PkwClient};
use super::*;
use profidrive::cw1::{Context, Cw1Decoder, Mode, ModeCommands};
use profidrive::telegram::{Entries, CW1, FB_DEFAULTS, PAD16, PAD32, PAD8, PKW, UNUSED, ZSW1};
use profidrive::zsw1::{self, State, Status};
use profidrive::{Addr, Completion, Describe, ParamAccess, PdError};
use std::collections::HashMap;

/// A response telegram with `zsw1` and operation mode `mode`.
fn response(mode: u8, zsw1: u16) -> [u8; 36] {
    let mut t = [0u8; 36];
    t[0] = 0xF0;
    t[1] = mode;
    t[2..4].copy_from_slice(&zsw1.to_be_bytes());
    t
}

fn enabled() -> FbInputs {
    FbInputs {
        drive_enable: true,
        ..FbInputs::default()
    }
}

#[test]
fn p219_the_enable_sequence_steps_on_zsw1_and_keeps_bit_10() {
    let mut fb = ExampleFb::new();
    let off = FbInputs::default();
    assert_eq!(fb.cw1(&off) & 0x000F, CMD_DISABLED, "disabled: coast stop");
    assert_eq!(fb.cw1(&off), 0x0430, "the manual's dump at rest (§4.4)");
    let on = enabled();
    let mut seen = Vec::new();
    for zsw1 in [0x0040u16, 0x0001, 0x0003, 0x0007, 0x0007] {
        seen.push(fb.cw1(&on) & 0x040F);
        fb.response(&response(OPMODE_POS, zsw1 | 0x0230), true).unwrap();
    }
    assert_eq!(
        seen,
        [0x0406, 0x0406, 0x0407, 0x040F, 0x040F],
        "§7.3: 0x0406 → 0x0407 → 0x040F"
    );
    assert!(fb.outputs().drive_is_enabled);
    // the next command waits for its state: SO does not skip ON
    let mut fb2 = ExampleFb::new();
    fb2.response(&response(OPMODE_POS, 0x0003), true).unwrap();
    assert_eq!(fb2.cw1(&on) & 0x000F, CMD_OFF, "SO before RTSO: still OFF");
    // a fault drops the state: the sequence starts again at OFF
    fb.response(&response(OPMODE_POS, 0x0048), true).unwrap();
    assert!(fb.outputs().fault && !fb.outputs().drive_is_enabled);
    assert_eq!(fb.cw1(&on) & 0x000F, CMD_OFF);
    // drive_enable = false resets it
    fb.response(&response(OPMODE_POS, 0x0001), false).unwrap();
    assert_eq!(fb.enable_step(), EnableStep::Off);
    for i in [off, on] {
        assert_ne!(fb.cw1(&i) & profidrive::cw1::CONTROL_BY_PLC, 0, "bit 10 always");
    }
}

/// The size of an entry of the FB's telegrams (spec §4.5 types).
fn size(a: Addr) -> usize {
    match a {
        PAD8 => 1,
        PAD16 | CW1 | ZSW1 => 2,
        PAD32 => 4,
        PKW => 8,
        UNUSED => 0,
        Addr { index: 1050, .. } | Addr { index: 1500, .. } => 1,
        Addr { index: 0x6071, .. } | Addr { index: 0x6077, .. } => 2,
        _ => 4,
    }
}

/// The byte offset of `addr` in a telegram laid out from `entries`.
fn offset(entries: &Entries, addr: Addr) -> usize {
    let mut at = 1;
    for e in entries {
        if *e == addr {
            return at;
        }
        at += size(*e);
    }
    panic!("{addr:?} not in the telegram")
}

fn be(t: &[u8], at: usize, n: usize) -> i64 {
    t[at..at + n].iter().fold(0i64, |v, b| (v << 8) | i64::from(*b))
}

/// Entries of a telegram and the values expected there.
type Fields = Vec<(Addr, i64)>;

#[test]
fn p220_the_telegrams_follow_the_drives_shipped_layouts() {
    let fb = ExampleFb::new();
    let i = FbInputs {
        homing_method: 33,
        target_position: 0x0102_0304,
        profile_velocity: 0x0506_0708,
        end_velocity: 0x090A_0B0C,
        all_accelerations_positioning: 0x0D0E_0F10,
        jogging_velocity: 0x1112_1314,
        current_limit: 0x1516_1718,
        target_velocity: 0x191A_1B1C,
        all_accelerations_velocity: 0x1D1E_1F20,
        target_torque: 0x2122,
        velocity_limit: 0x2324_2526,
        pkw_access_control: 0x41,
        pkw_object_main_index: 0x2728,
        pkw_object_sub_index: 0x29,
        pkw_write_value: 0x2A2B_2C2D,
        ..enabled()
    };
    let a = Addr::new;
    let expect: [(u8, u8, Fields); 3] = [
        (
            OPMODE_POS,
            0xE0,
            vec![
                (a(1050, 0), 33),
                (a(1001, 0), 0x0102_0304),
                (a(1001, 1), 0x0506_0708),
                (a(1001, 2), 0x090A_0B0C),
                (a(1001, 5), 0x0D0E_0F10),
                (a(1040, 0), 0x1112_1314),
                (a(0x2415, 2), 0x1516_1718),
            ],
        ),
        (
            OPMODE_VELO,
            0xE1,
            vec![
                (a(1010, 0), 0x191A_1B1C),
                (a(1011, 2), 0x1D1E_1F20),
                (a(1040, 0), 0x1112_1314),
                (a(0x2415, 2), 0x1516_1718),
            ],
        ),
        (
            OPMODE_TORQUE,
            0xE2,
            vec![(a(0x6071, 0), 0x2122), (a(0x2416, 2), 0x2324_2526)],
        ),
    ];
    for (n, (mode, id, fields)) in expect.into_iter().enumerate() {
        let t = fb.receive_telegram(&FbInputs {
            operation_mode: mode,
            ..i
        });
        let entries = &FB_DEFAULTS.receive[n];
        assert_eq!(t[0], id);
        assert_eq!(offset(entries, CW1), 2, "CW1 at bytes 2–3 (§4.2)");
        assert_eq!(
            be(&t, 2, 2),
            i64::from(fb.cw1(&FbInputs {
                operation_mode: mode,
                ..i
            }))
        );
        for (addr, v) in fields {
            let at = offset(entries, addr);
            assert_eq!(be(&t, at, size(addr)), v, "telegram {id:#x}: {addr:?} at {at}");
        }
        let pkw = offset(entries, PKW);
        assert_eq!(pkw, 24);
        assert_eq!(
            &t[pkw..pkw + 8],
            &[0x41, 0x27, 0x28, 0x29, 0x2A, 0x2B, 0x2C, 0x2D]
        );
    }
}

#[test]
fn p220_p219_the_response_telegram_becomes_the_outputs() {
    let tx = &FB_DEFAULTS.response[0];
    assert_eq!(offset(tx, ZSW1), 2);
    let mut t = response(OPMODE_POS, 0x0C37);
    t[offset(tx, Addr::new(1100, 0))..][..4].copy_from_slice(&(-5000i32).to_be_bytes());
    t[offset(tx, Addr::new(1101, 0))..][..4].copy_from_slice(&300i32.to_be_bytes());
    t[offset(tx, Addr::new(0x6077, 0))..][..2].copy_from_slice(&(-14i16).to_be_bytes());
    t[offset(tx, Addr::new(1141, 0))..][..4].copy_from_slice(&0x40u32.to_be_bytes());
    t[offset(tx, PKW)..][..8].copy_from_slice(&[0x42, 0x03, 0xC4, 0, 0, 0, 0x01, 0x15]);
    let mut fb = ExampleFb::new();
    let o = *fb.response(&t, true).unwrap();
    assert_eq!(o.operation_mode_actual, OPMODE_POS);
    assert_eq!(o.position_actual_value, -5000);
    assert_eq!(o.velocity_actual_value, 300);
    assert_eq!(o.current_actual_value, -14);
    assert_eq!(o.digital_inputs, 0x40);
    assert_eq!(
        (
            o.pkw_access_status,
            o.pkw_main_index,
            o.pkw_sub_index,
            o.pkw_read_value
        ),
        (0x42, 964, 0, 277)
    );
    assert!(o.drive_is_enabled && o.target_reached && o.home_valid);
    assert_eq!(fb.response(&t[..35], true), Err(ResponseError::TooShort(35)));
    t[0] = 0xE0;
    assert_eq!(fb.response(&t, true), Err(ResponseError::Identifier(0xE0)));
}

fn status(state: State) -> Status {
    Status {
        control_requested: true,
        ..Status::of(state)
    }
}

/// Every FB output from the drive's own ZSW1 encoder, one bit at a time.
#[test]
fn p219_p222_p223_p227_zsw1_bits_as_the_drive_encodes_them() {
    let out = |mode: u8, s: Status| {
        let mut fb = ExampleFb::new();
        *fb.response(&response(mode, zsw1::encode(&s)), true).unwrap()
    };
    let op = status(State::OperationEnabled);
    assert!(out(OPMODE_POS, op).drive_is_enabled);
    assert!(out(OPMODE_POS, op).control_by_plc);
    for s in [
        State::SwitchOnDisabled,
        State::ReadyToSwitchOn,
        State::SwitchedOn,
        State::Fault,
    ] {
        assert!(!out(OPMODE_POS, status(s)).drive_is_enabled, "{s:?}");
    }
    assert!(out(OPMODE_POS, status(State::Fault)).fault, "P-227: bit 3");
    assert!(!out(OPMODE_POS, op).fault);
    assert!(out(OPMODE_POS, Status { warning: true, ..op }).warning);
    assert!(
        out(OPMODE_POS, Status { homed: true, ..op }).home_valid,
        "P-222: bit 11"
    );
    assert!(out(OPMODE_POS, Status { reached: true, ..op }).target_reached);
    assert!(!out(OPMODE_VELO, Status { reached: true, ..op }).target_reached);
    assert!(
        out(OPMODE_VELO, Status { reached: true, ..op }).velo_exceeded,
        "P-223: bit 10"
    );
    let tol = Status {
        within_tolerance: true,
        ..op
    };
    assert!(out(OPMODE_VELO, tol).velo_reached, "P-223: bit 8 in speed mode");
    assert!(!out(OPMODE_POS, tol).velo_reached);
    assert!(!out(OPMODE_POS, tol).following_error, "E-09: inverted bit 8");
    assert!(out(OPMODE_POS, op).following_error);
    assert!(
        out(OPMODE_POS, Status { stopped: true, ..op }).velo_zero,
        "bit 13"
    );
    assert!(
        out(OPMODE_POS, Status { task_ack: true, ..op }).pos_task_ack,
        "bit 12"
    );
    assert_eq!(state_name(zsw1::encode(&status(State::Fault))), "fault");
    assert_eq!(state_name(zsw1::encode(&status(State::ReadyToSwitchOn))), "RTSO");
}

fn decode(d: &mut Cw1Decoder, fb: &ExampleFb, i: &FbInputs, mode: Mode) -> profidrive::cw1::Translated {
    d.decode(
        Some(fb.cw1(i)),
        Context {
            mode,
            homing_active: false,
        },
    )
}

/// The FB's positioning inputs through the drive's own CW1 decoder.
#[test]
fn p221_p222_p225_positioning_inputs_as_the_drive_decodes_them() {
    let fb = ExampleFb::new();
    let mut d = Cw1Decoder::new();
    let idle = enabled();
    let pos = |t: profidrive::cw1::Translated| match t.mode {
        ModeCommands::Positioning(p) => p,
        m => panic!("{m:?}"),
    };
    let p = pos(decode(&mut d, &fb, &idle, Mode::Positioning));
    assert!(!p.cancel && !p.intermediate_stop && !p.start);
    let start = FbInputs {
        start_pos: true,
        relative: true,
        ..idle
    };
    let p = pos(decode(&mut d, &fb, &start, Mode::Positioning));
    assert!(
        p.start && p.relative && !p.immediate,
        "P-221: rising start_pos, relative"
    );
    let p = pos(decode(&mut d, &fb, &start, Mode::Positioning));
    assert!(!p.start, "only the rising edge starts");
    let imm = FbInputs {
        change_immediatly: true,
        ..idle
    };
    assert!(pos(decode(&mut d, &fb, &imm, Mode::Positioning)).immediate);
    let stop = FbInputs {
        intermediate_stop: true,
        ..idle
    };
    assert!(pos(decode(&mut d, &fb, &stop, Mode::Positioning)).intermediate_stop);
    let hold = FbInputs {
        hold: true,
        jog_pos: true,
        ..idle
    };
    let p = pos(decode(&mut d, &fb, &hold, Mode::Positioning));
    assert!(p.cancel && !p.jog_positive, "hold clears bits 4, 8, 9");
    let jog = FbInputs {
        jog_neg: true,
        ..idle
    };
    let p = pos(decode(&mut d, &fb, &jog, Mode::Positioning));
    assert!(p.jog_negative && !p.jog_positive, "P-225");
    let home = FbInputs {
        start_homing: true,
        ..idle
    };
    assert!(
        pos(decode(&mut d, &fb, &home, Mode::Positioning)).homing_start,
        "P-222"
    );
}

#[test]
fn p223_p227_speed_inputs_and_fault_reset_as_the_drive_decodes_them() {
    let fb = ExampleFb::new();
    let mut d = Cw1Decoder::new();
    let speed = FbInputs {
        operation_mode: OPMODE_VELO,
        ..enabled()
    };
    match decode(&mut d, &fb, &speed, Mode::Speed).mode {
        ModeCommands::Speed(s) => assert!(s.rfg_enable && !s.rfg_freeze && s.setpoint_enable),
        m => panic!("{m:?}"),
    }
    let reset = FbInputs {
        fault_reset: true,
        ..speed
    };
    let t = decode(&mut d, &fb, &reset, Mode::Speed);
    assert!(t.evaluated);
    assert_eq!(
        t.controlword & 0x80,
        0x80,
        "P-227: fault_reset is the CiA 402 bit 7"
    );
}

/// A parameter store for the drive's own PKW mailbox.
#[derive(Default)]
struct Params(HashMap<(u16, u8), i64>);

impl ParamAccess for Params {
    fn describe(&self, addr: Addr) -> Result<Describe, PdError> {
        if !self.0.contains_key(&(addr.index, addr.sub)) {
            return Err(PdError::IMPERMISSIBLE_PNU);
        }
        Ok(Describe {
            data_type: profidrive::DataType::U32,
            readable: true,
            writable: addr.index != 964,
        })
    }
    fn read(&mut self, addr: Addr) -> Result<i64, PdError> {
        self.0
            .get(&(addr.index, addr.sub))
            .copied()
            .ok_or(PdError::IMPERMISSIBLE_PNU)
    }
    fn write(&mut self, addr: Addr, value: i64, _cyclic: bool) -> Result<Completion, PdError> {
        self.0.insert((addr.index, addr.sub), value);
        Ok(Completion::Done)
    }
}

/// Runs accesses through FB telegrams against the drive's PKW mailbox;
/// returns the outcomes and every request code sent.
fn pkw_run(accesses: &[Access]) -> (Vec<Outcome>, Vec<u8>) {
    let mut params = Params::default();
    params.0.insert((964, 0), 277);
    params.0.insert((0x6065, 0), 1000);
    let mut mailbox = profidrive::pkw::Pkw::new();
    let mut fb = ExampleFb::new();
    let mut client = PkwClient::new();
    let mut inputs = enabled();
    let (mut outcomes, mut codes) = (Vec::new(), Vec::new());
    for a in accesses {
        client.start(*a);
        for _ in 0..20 {
            client.inputs(&mut inputs);
            let t = fb.receive_telegram(&inputs);
            codes.push(t[24]);
            let req: [u8; 8] = t[24..32].try_into().unwrap();
            let mut r = response(OPMODE_POS, 0x0637);
            r[24..32].copy_from_slice(&mailbox.step(req, &mut params));
            client.outputs(fb.response(&r, true).unwrap());
            if let Some(o) = client.take_result() {
                outcomes.push(o);
                break;
            }
        }
        assert!(!client.busy(), "{a:?} did not end");
    }
    (outcomes, codes)
}

#[test]
fn p226_pkw_reads_and_writes_a_pnu_and_a_canopen_object() {
    let (out, _) = pkw_run(&[
        Access::Read { index: 964, sub: 0 },
        Access::Read {
            index: 0x6065,
            sub: 0,
        },
        Access::Write {
            index: 0x6065,
            sub: 0,
            value: 20_000,
        },
        Access::Read {
            index: 0x6065,
            sub: 0,
        },
        Access::Read { index: 999, sub: 0 },
        Access::Write {
            index: 964,
            sub: 0,
            value: 1,
        },
    ]);
    assert_eq!(
        out,
        [
            Outcome::Done(277),
            Outcome::Done(1000),
            Outcome::Done(20_000),
            Outcome::Done(20_000),
            Outcome::Refused(u32::from(PdError::IMPERMISSIBLE_PNU.0)),
            Outcome::Refused(u32::from(PdError::CANNOT_CHANGE.0)),
        ]
    );
}

/// Two accesses of the same type: 0x00 goes out between them and the
/// second waits for its mirror (§9.2); different types follow at once.
#[test]
fn p226_p193_two_reads_in_a_row_keep_the_toggle_rule() {
    let read = |index| Access::Read { index, sub: 0 };
    let (out, codes) = pkw_run(&[read(964), read(0x6065)]);
    assert_eq!(
        out,
        [Outcome::Done(277), Outcome::Done(1000)],
        "the second is not the first's echo"
    );
    let first = codes.iter().position(|c| *c == 0x41).unwrap();
    let again = codes.iter().rposition(|c| *c == 0x41).unwrap();
    assert!(
        codes[first..again].contains(&0x00),
        "0x00 between the two reads: {codes:02x?}"
    );
    let (_, codes) = pkw_run(&[
        read(964),
        Access::Write {
            index: 0x6065,
            sub: 0,
            value: 5,
        },
    ]);
    let r = codes.iter().position(|c| *c == 0x41).unwrap();
    assert_eq!(
        codes[r + 1],
        0x42,
        "a write after a read needs no 0x00: {codes:02x?}"
    );
}
