//! ESM requests and mailbox types as masters other than ours and the
//! conformance test tool send them (issue 33): repeated
//! requests, SyncManagers switched off, device identification.

use super::*;

/// Polls `ms` times (1 ms each); every `every` ms the master writes AL
/// control `ctrl` again (0 = never). Returns (AL status, code) at the end.
fn run(r: &mut Rig, ms: u32, every: u32, ctrl: u16, frames: bool) -> (u16, u16) {
    for i in 1..=ms {
        if every != 0 && i % every == 0 {
            r.esc.request(ctrl);
        }
        if frames {
            r.esc.set_events(r.esc.events() | al_event::sm(2));
        }
        r.poll();
    }
    (r.esc.status(), r.esc.code())
}

#[test]
fn e033_e047_repeated_op_request_keeps_the_steady_wait() {
    for every in [0, 1, 5, 50] {
        let mut r = Rig::new();
        r.app.pdo_timeout = crate::PdoTimeout::Ms(10);
        r.goto(AlState::SafeOp);
        // no RxPDO: S→O waits without error …
        assert_eq!(r.req(8), (4, 0), "every {every} ms");
        assert!(r.slave.op_pending());
        // … while the master rewrites the same request, up to 200 ms after the first …
        assert_eq!(run(&mut r, 199, every, 8, false), (4, 0), "every {every} ms");
        assert!(r.slave.op_pending());
        // … and is refused on time: 002Bh, no valid outputs since the request
        assert_eq!(
            run(&mut r, 2, every, 8, false),
            (0x14, 0x002B),
            "every {every} ms"
        );
        assert!(!r.slave.op_pending());
        // the refusal stays until acknowledged; an unacknowledged Op changes nothing
        assert_eq!(run(&mut r, 20, 5, 8, false), (0x14, 0x002B));
        // an acknowledged Op is a new request: a new 200 ms wait, granted
        // once the RxPDO is steady
        assert_eq!(r.req(0x18), (4, 0));
        assert!(r.slave.op_pending());
        assert_eq!(run(&mut r, 5, every, 8, true), (8, 0), "every {every} ms");
    }
}

#[test]
fn e033_e044_another_request_ends_the_wait_and_op_starts_a_new_one() {
    let mut r = Rig::new();
    r.app.pdo_timeout = crate::PdoTimeout::Ms(10);
    r.goto(AlState::SafeOp);
    assert_eq!(r.req(8), (4, 0));
    assert_eq!(run(&mut r, 150, 5, 8, false), (4, 0));
    // Safe-Op requested: the wait ends …
    assert_eq!(r.req(4), (4, 0));
    assert!(!r.slave.op_pending());
    // … and the next Op waits its full 200 ms again
    assert_eq!(r.req(8), (4, 0));
    assert_eq!(run(&mut r, 199, 5, 8, false), (4, 0));
    assert_eq!(run(&mut r, 2, 5, 8, false), (0x14, 0x002B));
    // RxPDO that comes but not regularly: 001Bh, also with repeated requests
    assert_eq!(r.req(0x14), (4, 0));
    assert_eq!(r.req(8), (4, 0));
    for i in 1..=201 {
        if i % 5 == 0 {
            r.esc.request(8);
        }
        if i % 40 == 0 {
            r.esc.set_events(r.esc.events() | al_event::sm(2));
        }
        r.poll();
    }
    assert_eq!((r.esc.status(), r.esc.code()), (0x14, 0x001B));
}

/// Switches SyncManager `n` off as a master does (activate register bit 0).
fn sm_off(r: &mut Rig, n: u8) {
    r.esc.mem[regs::sm(n) as usize + 6] &= !activate::ENABLE;
}

#[test]
fn e025_e045_e038_sm_switched_off_falls_back_with_its_code() {
    // (SM, state, expected state afterwards, AL status code); None = stays
    type Fallback = Option<(AlState, u16)>;
    let cases: [(u8, AlState, Fallback); 12] = [
        (0, AlState::PreOp, Some((AlState::Init, 0x0016))),
        (0, AlState::SafeOp, Some((AlState::Init, 0x0016))),
        (0, AlState::Op, Some((AlState::Init, 0x0016))),
        (1, AlState::PreOp, Some((AlState::Init, 0x0016))),
        (1, AlState::SafeOp, Some((AlState::Init, 0x0016))),
        (1, AlState::Op, Some((AlState::Init, 0x0016))),
        (2, AlState::PreOp, None),
        (2, AlState::SafeOp, Some((AlState::PreOp, 0x001D))),
        (2, AlState::Op, Some((AlState::PreOp, 0x001D))),
        (3, AlState::PreOp, None),
        (3, AlState::SafeOp, Some((AlState::PreOp, 0x001E))),
        (3, AlState::Op, Some((AlState::PreOp, 0x001E))),
    ];
    for (n, state, expected) in cases {
        let mut r = Rig::new();
        r.goto(state);
        sm_off(&mut r, n);
        let c = r.poll();
        let what = std::format!("SM{n} off in {state:?}");
        match expected {
            None => {
                assert_eq!(c, None, "{what}");
                assert_eq!((r.esc.status(), r.esc.code()), (state.code().into(), 0), "{what}");
            }
            Some((to, code)) => {
                let c = c.expect(&what);
                assert_eq!(
                    (c.from, c.to, c.code.0, c.unsolicited),
                    (state, to, code, true),
                    "{what}"
                );
                assert_eq!(
                    (r.esc.status(), r.esc.code()),
                    (u16::from(to.code()) | 0x10, code),
                    "{what}"
                );
                assert_eq!(r.slave.err_led(), crate::led::Pattern::SingleFlash, "{what}");
                // once: the next poll changes nothing
                assert_eq!(r.poll(), None, "{what}");
                // the master sets the SM up again and acknowledges: the way up is open
                r.esc.mem[regs::sm(n) as usize + 6] |= activate::ENABLE;
                let back = u16::from(to.code()) | 0x10;
                assert_eq!(r.req(back), (to.code().into(), 0), "{what}");
                r.goto(state);
            }
        }
    }
    // outputs are zero again once Op is left
    let mut r = Rig::new();
    r.goto(AlState::Op);
    sm_off(&mut r, 2);
    r.poll();
    assert!(r.slave.outputs().iter().all(|&b| b == 0));
}

#[test]
fn e025_no_mailbox_sm_check_in_init() {
    // in Init the SMs are the master's to set up: nothing happens
    let mut r = Rig::new();
    for n in 0..4 {
        sm_off(&mut r, n);
    }
    assert_eq!(r.poll(), None);
    assert_eq!((r.esc.status(), r.esc.code()), (1, 0));
}

#[test]
fn e027_reserved_and_unspoken_mailbox_types_get_unsupported_protocol() {
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    // AoE (1), SoE (5), VoE (15) and the reserved types 6..14, each with a
    // new counter: mailbox error 0002h "unsupported protocol"
    for (k, ty) in [1u8, 5, 6, 7, 9, 14, 15].into_iter().enumerate() {
        let counter = (k % 7) as u8 + 1;
        r.esc
            .mbx_write(&[4, 0, 0, 0, 0, ty | (counter << 4), 0x11, 0x22, 0x33, 0x44]);
        r.poll();
        let got = r.esc.mbx_read().expect("an answer");
        assert_eq!(got[5] & 0x0F, 0, "type {ty}: a mailbox error reply");
        assert_eq!(&got[..2], &[4, 0], "type {ty}");
        assert_eq!(
            (
                u16::from_le_bytes([got[6], got[7]]),
                u16::from_le_bytes([got[8], got[9]])
            ),
            (0x0001, 0x0002),
            "type {ty}: 0002h"
        );
    }
    // the mailbox still serves CoE afterwards
    assert!(r.upload(0x1008, 0, 1).is_some());
}

#[test]
fn e026_explicit_device_identification_shows_the_alias_in_0134() {
    let mut r = Rig::new();
    let alias = regs::STATION_ALIAS as usize;
    r.esc.mem[alias..alias + 2].copy_from_slice(&0x1234u16.to_le_bytes());
    // Init + ID request: the ID in 0x0134, AL status bit 5, no error
    assert_eq!(r.req(0x21), (0x21, 0x1234));
    assert!(!r.slave.error());
    // with a transition: shown in the new state
    assert_eq!(r.req(0x22), (0x22, 0x1234));
    assert_eq!(r.slave.state(), AlState::PreOp);
    // a request without the bit ends it
    assert_eq!(r.req(0x02), (0x02, 0));
    // a refused request shows its error, not the ID
    assert_eq!(r.req(0x28), (0x12, 0x0011));
    assert_eq!(r.req(0x31), (0x21, 0x1234), "acknowledge + Init + ID");
    // a settable ID replaces the alias
    r.slave.set_identification(Some(0xBEEF));
    assert_eq!(r.req(0x21), (0x21, 0xBEEF));
    r.slave.set_identification(None);
    assert_eq!(r.req(0x21), (0x21, 0x1234));
    assert_eq!(r.req(0x01), (0x01, 0));
}
