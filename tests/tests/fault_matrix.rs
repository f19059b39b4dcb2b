//! The fault matrix (issue 19, docs/fault-matrix.md): each case brings a
//! drive to the state the case needs through a real master (ethercrab,
//! in-process), makes the fault happen (lost frames, SYNC0 gone, a master
//! that stops reading its mailbox or restarts mid-transfer, power cut at
//! every flash operation, encoder fault, STO, undervoltage, a limit switch
//! during homing, a second master), and checks the end the spec names:
//! AL state and status code, the CiA 402 state, EMCY, 603Fh, the
//! diagnosis history, and that nothing is lost. Each test ends with
//! [`drive_tests::fault_row!`], which leaves its row for the printed table
//! (`scripts/fault-matrix`). Cases elsewhere join the table the same way:
//! SYNC0 loss (dc_sync/esm.rs), power cut during a save (save.rs).

#[path = "fault_matrix/axis.rs"]
mod axis;
#[path = "fault_matrix/bus.rs"]
mod bus;
#[path = "fault_matrix/chopper.rs"]
mod chopper;
#[path = "fault_matrix/electrical.rs"]
mod electrical;
#[path = "fault_matrix/flash.rs"]
mod flash;
#[path = "fault_matrix/mailbox.rs"]
mod mailbox;

use drive_tests::matrix::Row;
pub use drive_tests::step::advance;
use drive_tests::CoeClient;
use ethercrab::SubDeviceRef;
use hil_sim::sim::Simulation;
use std::cell::RefCell;

/// A row of the table run by the in-process ethercrab master.
pub fn ethercrab(
    order: &'static str,
    case: &'static str,
    spec: &'static str,
    expected: &'static str,
) -> Row<'static> {
    Row {
        order,
        case,
        spec,
        peer: "ethercrab",
        expected,
    }
}

/// E47: the first cause of Switch on disabled (C-015).
pub const E47: u16 = drive_ecat::parameter_index(4, 47);

/// The end of a fault as the master reads it: "EMCYs; 603Fh; E47; the
/// newest diagnosis message; AL state" (the EMCYs first: an SDO read of the
/// master would take them out of the mailbox).
pub async fn fault_end<S>(sd: &SubDeviceRef<'_, S>, sim: &RefCell<Simulation>) -> String
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    let em = drive_tests::matrix::emcys(&emcys(sd).await);
    let code: u16 = sd.sdo_read(0x603F, 0).await.unwrap();
    let e47 = get(sim, E47, 0);
    let diag = newest_diag(sd).await;
    let al = drive_tests::matrix::al(drive_tests::al_status(sd).await);
    format!("{em}; 603Fh {code:04X}h; E47 {e47}; {diag}; {al}")
}

/// Controlword 0 for 2 cycles, then a fault reset (bit 7) for 10; the last
/// TxPDO.
pub async fn fault_reset(m: &mut drive_tests::Cyclic<'_>) -> drive_tests::TxPdo {
    m.set_controlword(0);
    m.run(2).await;
    m.set_controlword(drive_tests::axis::CW_FAULT_RESET);
    m.run(10).await
}

/// The end of a fault in motion after its last TxPDO `tx`: the CiA 402
/// state and [`fault_end`], then a [`fault_reset`] while the cause lasts:
/// "its state (E47 n)" and its last TxPDO.
pub async fn end_then_reset<S>(
    m: &mut drive_tests::Cyclic<'_>,
    sd: &SubDeviceRef<'_, S>,
    sim: &RefCell<Simulation>,
    tx: drive_tests::TxPdo,
) -> (&'static str, String, String, drive_tests::TxPdo)
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    let state = drive_tests::matrix::cia402_state(tx.statusword);
    let end = fault_end(sd, sim).await;
    let tx = fault_reset(m).await;
    let lasting = format!(
        "{} (E47 {})",
        drive_tests::matrix::cia402_state(tx.statusword),
        get(sim, E47, 0)
    );
    (state, end, lasting, tx)
}

/// After the cause ended: a [`fault_reset`], controlword 0 for 2 cycles,
/// the enable sequence; the CiA 402 state it ends in.
pub async fn reset_and_enable(m: &mut drive_tests::Cyclic<'_>) -> &'static str {
    fault_reset(m).await;
    m.set_controlword(0);
    m.run(2).await;
    drive_tests::matrix::cia402_state(m.enable().await.statusword)
}

/// An object of the first drive, read locally.
pub fn get(sim: &RefCell<Simulation>, index: u16, sub: u8) -> i64 {
    sim.borrow().drives()[0].drive.objects().get(index, sub).unwrap()
}

/// The EMCYs queued for the master, collected while it uploads 1000h a
/// few times.
pub async fn emcys<S>(sd: &SubDeviceRef<'_, S>) -> Vec<Vec<u8>>
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    let mut c = CoeClient::new();
    for _ in 0..4 {
        c.upload(sd, 0x1000, 0).await.unwrap();
    }
    // ethercrab's next request must not look like a repeat of ours
    c.hand_over(sd).await;
    c.emergencies
}

/// The newest message of the diagnosis history 10F3h: "history: error
/// E800h|code, axis, event/cause" for an axis fault, "history: error
/// AL xxxxh" for a refused or lost state, "history empty".
pub async fn newest_diag<S>(sd: &SubDeviceRef<'_, S>) -> String
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    let newest: u8 = sd.sdo_read(0x10F3, 2).await.expect("10F3h:02");
    if newest == 0 {
        return "history empty".into();
    }
    let mut c = CoeClient::new();
    let msg = c.upload(sd, 0x10F3, newest).await.expect("message");
    c.hand_over(sd).await;
    let code = u32::from_le_bytes(msg[0..4].try_into().unwrap());
    let kind = match u16::from_le_bytes([msg[4], msg[5]]) & 0x0F {
        0 => "info",
        1 => "warning",
        _ => "error",
    };
    if code & 0xFFFF == drive_ecat::runtime::DIAG_EMCY {
        // parameters: flags u16 + u32 each, after the 16 fixed bytes
        let param = |k: usize| u32::from_le_bytes(msg[18 + 6 * k..22 + 6 * k].try_into().unwrap());
        let (axis, ev) = (param(0), param(1));
        format!(
            "history: {kind} {:04X}h axis {} event {}/{}",
            code >> 16,
            if axis == 0 { "A" } else { "B" },
            ev >> 8,
            ev & 0xFF
        )
    } else if code & 0xFFFF_0000 == drive_ecat::runtime::DIAG_AL_STATUS {
        format!("history: {kind} AL {:04X}h", code & 0xFFFF)
    } else {
        format!("history: {kind} {code:08X}h")
    }
}
