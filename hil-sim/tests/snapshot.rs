//! `Simulation::try_clone`: a copy of a line answers exactly as the line it
//! was copied from (the fuzz targets start every input from one), and the
//! two then run apart without sharing state.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::indexing_slicing)]

use hil_sim::sim::Simulation;
use nanos::Nanos;

/// One datagram frame to the first slave (`cmd` 2 APWR, 4 FPRD, 5 FPWR).
fn frame(cmd: u8, adp: u16, ado: u16, data: &[u8]) -> Vec<u8> {
    hil_sim::sim::datagram_frame([0x10; 6], cmd, 0, adp, ado, data, 0)
}

fn send(sim: &mut Simulation, cmd: u8, adp: u16, ado: u16, data: &[u8]) -> Vec<u8> {
    let mut f = frame(cmd, adp, ado, data);
    sim.exchange(&mut f);
    f
}

/// Station address 1000h, SM0/SM1 mailboxes at 1000h/1100h, PRE-OP.
fn preop() -> Simulation {
    let mut sim = Simulation::new(1);
    send(
        &mut sim,
        2,
        0,
        esc::regs::STATION_ADDRESS,
        &0x1000u16.to_le_bytes(),
    );
    let sm = |start, control| esc::SyncManager {
        start,
        length: 256,
        control,
        status: 0,
        activate: 1,
        pdi_control: 0,
    };
    let mut both = sm(0x1000, 0x26).to_bytes().to_vec();
    both.extend_from_slice(&sm(0x1100, 0x22).to_bytes());
    send(&mut sim, 2, 0, esc::regs::sm(0), &both);
    send(&mut sim, 2, 0, esc::regs::AL_CONTROL, &2u16.to_le_bytes());
    let t = sim.now() + Nanos::from_ms(1);
    sim.advance_to(t);
    sim
}

/// An SDO upload of `index`:`sub` through SM0, the answer read from SM1.
fn upload(sim: &mut Simulation, counter: u8, index: u16, sub: u8) -> Vec<u8> {
    let mut m = [0u8; 256];
    m[0] = 10; // length
    m[5] = 0x03 | counter << 4; // CoE
    m[6..8].copy_from_slice(&0x2000u16.to_le_bytes()); // SDO request
    m[8] = 0x40; // initiate upload
    m[9..11].copy_from_slice(&index.to_le_bytes());
    m[11] = sub;
    send(sim, 5, 0x1000, 0x1000, &m);
    let t = sim.now() + Nanos::from_us(500);
    sim.advance_to(t);
    send(sim, 4, 0x1000, 0x1100, &[0u8; 256])
}

#[test]
fn sim_snapshot_answers_like_the_line_it_was_copied_from() {
    let mut line = preop();
    let mut copy = line.try_clone().expect("no IP stack, no capture");
    assert_eq!(copy.now(), line.now());
    // the same requests, the same answers, frame for frame
    for (k, (index, sub)) in [(0x1018, 1), (0x6041, 0), (0x1000, 0), (0x5000, 0)]
        .into_iter()
        .enumerate()
    {
        let counter = k as u8 % 7 + 1;
        let a = upload(&mut line, counter, index, sub);
        let b = upload(&mut copy, counter, index, sub);
        assert_eq!(a, b, "{index:04X}h:{sub}");
        assert_eq!(a[26 + 5] & 0x0F, 3, "a CoE answer in SM1: {:02x?}", &a[26..42]);
    }
    assert_eq!(copy.now(), line.now());
    // apart: a request to Init on the copy leaves the line in PRE-OP
    send(&mut copy, 5, 0x1000, esc::regs::AL_CONTROL, &1u16.to_le_bytes());
    for s in [&mut line, &mut copy] {
        let t = s.now() + Nanos::from_ms(2);
        s.advance_to(t);
    }
    let al = |s: &mut Simulation| {
        let f = send(s, 4, 0x1000, esc::regs::AL_STATUS, &[0, 0]);
        u16::from_le_bytes([f[26], f[27]]) & 0x0F
    };
    assert_eq!(al(&mut copy), 1, "the copy in Init");
    assert_eq!(al(&mut line), 2, "the line still in PRE-OP");
    // a drive with an IP stack cannot be copied
    let mut with_net = Simulation::new(1);
    with_net.drives_mut()[0].bind_net([2, 0, 0, 0, 0, 1], 1, Nanos::ZERO);
    assert!(with_net.try_clone().is_none());
}
