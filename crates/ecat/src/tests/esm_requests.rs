//! ESM requests as masters other than ours send them (issue 33): repeated
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
