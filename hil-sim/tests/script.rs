//! The QEMU end-to-end master sequence (`hil_sim::script`) against the
//! simulated drive on the host: the same script `firmware-qemu` runs, so a
//! failure there can be reproduced here.

use hil_sim::script::{Progress, Script, SimLink, CYCLE, MOVE_INC};
use hil_sim::sim::Simulation;
use nanos::Nanos;

/// Runs `script` against `sim` (at most 5 s of simulated time) until it
/// finishes, which must be with success; what it reported on the way.
fn run(sim: &mut Simulation, mut script: Script) -> Vec<Progress> {
    let mut log = Vec::new();
    // frames half a cycle away from SYNC0 (which the script puts on whole cycles)
    let mut t = Nanos::from_ns(CYCLE.as_ns() / 2);
    while !script.finished() && t < Nanos::from_secs(5) {
        t += CYCLE;
        sim.advance_to(t);
        let p = script.step(&mut SimLink(sim));
        if p != Progress::Busy {
            log.push(p);
        }
    }
    assert!(script.succeeded(), "{log:?}");
    log
}

/// E-107 (DC-Sync selected by the master) through the scripted master: Pre-Op SDOs, DC SYNC0, Op,
/// enable, a csp move on both axes, disable and back to Init.
#[test]
fn e107_scripted_master_selects_dc_sync_and_runs_csp_on_both_axes() {
    let mut sim = Simulation::new(1);
    let log = run(&mut sim, Script::new());
    assert_eq!(log.last(), Some(&Progress::State(1)), "{log:?}");
    assert!(log.contains(&Progress::State(8)), "{log:?}");
    assert!(log.contains(&Progress::Enabled), "{log:?}");
    let Some(Progress::Moved {
        position,
        max_following_error,
    }) = log.iter().copied().find(|p| matches!(p, Progress::Moved { .. }))
    else {
        panic!("no move: {log:?}")
    };
    // both axes arrive within 1° (~2900 inc) of their targets, opposite ways
    assert!((position[0] - MOVE_INC).abs() < 2900, "{position:?}");
    assert!((position[1] + MOVE_INC).abs() < 2900, "{position:?}");
    assert!(
        max_following_error.iter().all(|&f| f > 0 && f < MOVE_INC / 20),
        "{max_following_error:?}"
    );
}

/// E-095/E-096 through the scripted master (the sequence `firmware-qemu`
/// runs): in Pre-Op it sets the drive's IP over EoE, resolves it by ARP,
/// pings it and reads A150 over the UDP parameter service, with frames it
/// builds byte by byte; then the rest of the sequence runs as without EoE.
#[test]
fn e095_e096_scripted_master_pings_and_reads_a_parameter_over_eoe() {
    use hil_sim::script::eoe::DRIVE_IP;
    let mut sim = Simulation::new(1);
    let mac = [0x02, 0x5C, 0x06, 0, 0, 0x01];
    sim.drives_mut()[0].bind_net(mac, 7, Nanos::ZERO);
    let log = run(&mut sim, Script::with_eoe());
    let eoe: Vec<Progress> = log
        .iter()
        .copied()
        .filter(|p| {
            matches!(
                p,
                Progress::IpSet | Progress::Arp(_) | Progress::Pinged | Progress::UdpRead(_)
            )
        })
        .collect();
    // A150 = 1000 µs (the default cycle)
    assert_eq!(
        eoe,
        [
            Progress::IpSet,
            Progress::Arp(mac),
            Progress::Pinged,
            Progress::UdpRead(1000)
        ],
        "{log:?}"
    );
    let ip = sim.drives()[0].net.as_ref().unwrap().stack().ip();
    assert_eq!(ip, Some((DRIVE_IP, 24)));
    // the EoE step came before Safe-Op
    let at = |p: Progress| log.iter().position(|q| *q == p).unwrap();
    assert!(at(Progress::UdpRead(1000)) < at(Progress::State(4)), "{log:?}");
}
