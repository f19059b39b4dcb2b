//! Frame building shared by the fuzz targets: real EtherCAT frames into the
//! simulated line, exactly as a master would send them.

use hil_sim::sim::Simulation;

/// One datagram frame: Ethernet + EtherCAT header + datagram + WKC, the
/// data cut to 1,400 bytes.
pub fn frame(cmd: u8, adp: u16, ado: u16, data: &[u8]) -> Vec<u8> {
    let data = &data[..data.len().min(1400)];
    hil_sim::sim::datagram_frame([0x10; 6], cmd, 0, adp, ado, data, 0)
}

/// APWR (auto-increment write) to the first slave.
pub fn apwr(sim: &mut Simulation, ado: u16, data: &[u8]) {
    let mut f = frame(2, 0, ado, data);
    sim.exchange(&mut f);
}

thread_local! {
    /// [`build_preop_line`] once per process: each input starts from a copy.
    static PREOP: Simulation = build_preop_line();
    /// [`build_op_line`] once per process.
    static OP: Simulation = build_op_line();
}

/// The station address [`build_preop_line`] gives the drive.
#[allow(dead_code)] // the frame target's
pub const PREOP_STATION: u16 = 0x1000;

/// A copy of the line in Op ([`build_op_line`]).
#[allow(dead_code)] // the frame target's
pub fn op_line() -> Simulation {
    OP.with(|s| s.try_clone()).unwrap_or_else(build_op_line)
}

/// A one-slave line as the QEMU run's scripted master leaves it once both
/// axes are enabled: Pre-Op start-up SDOs, both channels assigned, DC
/// SYNC0 at 1 ms, the PDOs mapped at logical 0x0000/0x0800, Op, csp.
pub fn build_op_line() -> Simulation {
    use hil_sim::script::{Progress, Script, SimLink, CYCLE};
    let mut sim = Simulation::new(1);
    let mut script = Script::new();
    let mut t = nanos::Nanos::from_ns(CYCLE.as_ns() / 2);
    while !script.finished() && t < nanos::Nanos::from_secs(5) {
        t += CYCLE;
        sim.advance_to(t);
        if script.step(&mut SimLink(&mut sim)) == Progress::Enabled {
            return sim;
        }
    }
    panic!("the scripted master did not enable the drive")
}

/// A one-slave line in PRE-OP: a copy of the one built once per process
/// ([`Simulation::try_clone`]), so an input costs its own frames only.
#[allow(dead_code)] // the line targets' (the mailbox targets copy the drive)
pub fn preop_line() -> Simulation {
    PREOP.with(|s| s.try_clone()).unwrap_or_else(build_preop_line)
}

/// A one-slave line brought to PRE-OP the way a master does it: station
/// address, mailbox SyncManagers from the SII defaults, AL control = 2.
pub fn build_preop_line() -> Simulation {
    let mut sim = Simulation::new(1);
    apwr(&mut sim, esc::regs::STATION_ADDRESS, &PREOP_STATION.to_le_bytes());
    let sm0 = esc::SyncManager {
        start: 0x1000,
        length: 256,
        control: 0x26,
        status: 0,
        activate: 1,
        pdi_control: 0,
    };
    let sm1 = esc::SyncManager {
        start: 0x1100,
        length: 256,
        control: 0x22,
        status: 0,
        activate: 1,
        pdi_control: 0,
    };
    let mut both = sm0.to_bytes().to_vec();
    both.extend_from_slice(&sm1.to_bytes());
    apwr(&mut sim, esc::regs::sm(0), &both);
    apwr(&mut sim, esc::regs::AL_CONTROL, &2u16.to_le_bytes());
    sim.advance_to(sim.now() + nanos::Nanos::from_ms(1));
    sim
}

/// The datagram data and working counter of a one-datagram frame built by
/// [`frame`], after the exchange.
#[allow(dead_code)] // the mailbox target's
pub fn reply(f: &[u8]) -> (&[u8], u16) {
    let len = usize::from(u16::from_le_bytes([f[22], f[23]]) & 0x07FF);
    let data = &f[26..26 + len];
    (data, u16::from_le_bytes([f[26 + len], f[27 + len]]))
}
