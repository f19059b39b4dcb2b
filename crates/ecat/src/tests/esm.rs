//! The EtherCAT state machine: the transition matrix, AL status codes and errors, the SyncManager
//! checks and process data by state (E-021..E-045).

use super::*;

const STATES: [AlState; 4] = [AlState::Init, AlState::PreOp, AlState::SafeOp, AlState::Op];

#[test]
fn e021_e022_e023_transition_matrix() {
    for from in STATES {
        for requested in 0u16..16 {
            let mut r = Rig::new();
            r.goto(from);
            let (status, code) = r.req(requested);
            let legal = match (from.code(), requested) {
                (f, q) if f as u16 == q => Some(q),
                (1, 2) | (2, 4) | (4, 8) => Some(requested),
                (_, 1 | 2 | 4) if (requested as u8) < from.code() => Some(requested),
                _ => None,
            };
            let want = match (legal, requested) {
                (Some(q), _) => (q, 0),
                (None, 3) => (u16::from(from.code()) | 0x10, 0x0013),
                (None, 1 | 2 | 4 | 8) => (u16::from(from.code()) | 0x10, 0x0011),
                (None, _) => (u16::from(from.code()) | 0x10, 0x0012),
            };
            assert_eq!((status, code), want, "{from:?} -> {requested}");
        }
    }
}

#[test]
fn e043_status_code_written_before_status() {
    let mut r = Rig::new();
    r.esc.status_writes.clear();
    r.req(4);
    assert_eq!(r.esc.status_writes, [regs::AL_STATUS_CODE, regs::AL_STATUS]);
}

#[test]
fn e041_error_needs_acknowledge() {
    let mut r = Rig::new();
    assert_eq!(r.req(8), (0x11, 0x0011));
    assert!(r.slave.error());
    // without ack: ignored, even a valid request
    assert_eq!(r.req(2), (0x11, 0x0011));
    assert_eq!(r.slave.state(), AlState::Init);
    // with ack: error cleared and request processed
    assert_eq!(r.req(0x12), (2, 0));
    assert_eq!(r.slave.al_status_code(), AlStatusCode::NO_ERROR);
}

#[test]
fn e021_poll_reports_state_changes() {
    let mut r = Rig::new();
    r.esc.request(2);
    let c = r.poll().unwrap();
    assert_eq!(
        (c.from, c.to, c.code),
        (AlState::Init, AlState::PreOp, AlStatusCode(0))
    );
    r.esc.request(2);
    assert_eq!(r.poll(), None);
    r.esc.request(8);
    let c = r.poll().unwrap();
    assert_eq!((c.from, c.to, c.code.0), (AlState::PreOp, AlState::PreOp, 0x11));
    assert_eq!(
        std::format!("{c}"),
        "PreOp: request 8 refused, AL status code 0x0011"
    );
}

#[test]
fn e025_invalid_mailbox_sm_stays_init() {
    let cases: [(u8, u16, u16, u8, bool); 7] = [
        (0, 0x1004, 128, 0x26, true),  // wrong start
        (0, 0x1000, 256, 0x26, true),  // longer than the SII's
        (0, 0x1000, 8, 0x26, true),    // too short
        (0, 0x1000, 128, 0x22, true),  // wrong direction
        (1, 0x1080, 128, 0x20, true),  // buffered mode
        (1, 0x1080, 128, 0x22, false), // not enabled
        (1, 0x1080, 128, 0x27, true),  // reserved direction
    ];
    for (n, start, len, control, enable) in cases {
        let mut r = Rig::new();
        r.esc.set_sm(n, start, len, control);
        if !enable {
            r.esc.mem[regs::sm(n) as usize + 6] = 0;
        }
        assert_eq!(r.req(2), (0x11, 0x0016), "SM{n} {start:#x} {len} {control:#x}");
        assert_eq!(r.slave.state(), AlState::Init);
    }
    // a shorter, still sane mailbox is accepted
    let mut r = Rig::new();
    r.esc.set_sm(1, 0x1080, 64, 0x22);
    assert_eq!(r.req(2), (2, 0));
}

#[test]
fn e028_e045_process_sm_checks() {
    let cases: [(u8, u16, u16, u8, u16); 9] = [
        (2, 0x1100, 4, 0x64, 0x001D), // RxPDO length mismatch
        (2, 0x1100, 3, 0x66, 0x001D), // mailbox mode
        (2, 0x1100, 3, 0x60, 0x001D), // MasterRead direction
        (2, 0x0F00, 3, 0x64, 0x001D), // outside process RAM
        (2, 0x2FFC, 3, 0x64, 0x001D), // 3 buffers run past the RAM end
        (3, 0x1180, 2, 0x20, 0x001E), // TxPDO length mismatch
        (3, 0x1180, 4, 0x24, 0x001E), // MasterWrite direction
        (2, 0x1100, 3, 0x65, 0x0017), // reserved mode bits
        (3, 0x1104, 4, 0x20, 0x0017), // SM3 overlaps SM2's three buffers
    ];
    for (n, start, len, control, code) in cases {
        let mut r = Rig::new();
        r.goto(AlState::PreOp);
        r.esc.set_sm(n, start, len, control);
        assert_eq!(r.req(4), (0x12, code), "SM{n} {start:#x} {len} {control:#x}");
        assert_eq!(r.slave.state(), AlState::PreOp);
    }
    // SM2 overlapping the read mailbox
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    r.esc.set_sm(2, 0x10F0, 3, 0x64);
    assert_eq!(r.req(4), (0x12, 0x0017));
    // SM2 disabled while outputs are assigned
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    r.esc.mem[regs::sm(2) as usize + 6] = 0;
    assert_eq!(r.req(4), (0x12, 0x001D));
}

#[test]
fn e032_e034_e035_process_data_by_state() {
    let mut r = Rig::new();
    r.goto(AlState::PreOp);
    r.slave.inputs_mut().copy_from_slice(&[1, 2, 3, 4]);
    r.poll();
    assert_eq!(&r.esc.mem[0x1180..0x1184], &[0, 0, 0, 0], "no inputs in Pre-Op");
    r.goto_from_preop_safeop();
    assert_eq!(&r.esc.mem[0x1180..0x1184], &[1, 2, 3, 4], "inputs in Safe-Op");
    // outputs received in Safe-Op are ignored
    r.esc.mem[0x1100..0x1103].copy_from_slice(&[9, 8, 7]);
    r.esc.set_events(al_event::sm(2));
    r.poll();
    assert_eq!(r.slave.outputs(), &[0, 0, 0]);
    assert_eq!(r.slave.outputs_received(), 1);
    assert_eq!(r.req(8), (8, 0));
    assert_eq!(r.slave.outputs(), &[0, 0, 0], "Safe-Op data not carried into Op");
    r.esc.mem[0x1100..0x1103].copy_from_slice(&[5, 6, 7]);
    r.esc.set_events(al_event::sm(2));
    r.poll();
    assert_eq!(r.slave.outputs(), &[5, 6, 7], "outputs applied in Op");
    assert_eq!(r.esc.events() & al_event::sm(2), 0, "whole SM2 area read");
    r.slave.inputs_mut()[0] = 42;
    r.poll();
    assert_eq!(r.esc.mem[0x1180], 42);
    assert_eq!(r.req(4), (4, 0));
    assert_eq!(r.slave.outputs(), &[0, 0, 0], "O->S falls back to defaults");
    assert_eq!(r.req(2), (2, 0));
    r.slave.inputs_mut()[0] = 43;
    r.poll();
    assert_eq!(r.esc.mem[0x1180], 42, "S->P stops inputs");
}

impl Rig {
    fn goto_from_preop_safeop(&mut self) {
        assert_eq!(self.req(4), (4, 0));
    }
}
