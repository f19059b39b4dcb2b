//! Faults on the bus: bursts of lost frames in Op (free run and DC), the
//! SM watchdog, a second master on the line with conflicting AL control.

use super::{advance, emcys, ethercrab, newest_diag};
use drive_tests::al::{ACK, INIT, OP, PREOP};
use drive_tests::matrix::{al, cia402_state, emcys as show_emcys, Row};
use drive_tests::step::op_via_safe_op;
use drive_tests::{al_status, fault_row, init, line, request, with_master, Cyclic, REV};
use ethercrab::subdevice_group::DcConfiguration;
use hil_sim::master::{into_dc_sync0, PdiSubDevice};
use std::time::Duration;

const A258: u16 = drive_ecat::parameter_index(0, 258);

/// The CiA 402 state of axis A from 6041h (read by SDO: the process data
/// may have stopped).
async fn axis_state<S>(sd: &ethercrab::SubDeviceRef<'_, S>) -> &'static str
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    cia402_state(sd.sdo_read::<u16>(0x6041, 0).await.unwrap())
}

/// Axis A enabled in csv at 1 rev/s with A258 = `a258` (free run), then
/// `lost` master cycles (1 ms) whose frames never arrive, then 50 cycles
/// more: the AL state, axis A, the EMCYs, 603Fh, the history, and the
/// process-data cycles after the burst that came back with WKC 3.
fn burst_free_run(a258: u16, lost: u64) -> String {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        sd.sdo_write(A258, 0, a258).await.unwrap();
        let group = op_via_safe_op(md, group, &sim).await;
        let sd = group.subdevice(md, 0).unwrap();
        let mut m = Cyclic::new(md, &group, &sim, 0);
        m.csv_at(REV, 200).await;
        advance(&sim, lost * 1_000_000);
        let mut full = 0;
        for _ in 0..50 {
            sd.outputs_raw_mut().copy_from_slice(&m.out);
            advance(&sim, 1_000_000);
            if group.tx_rx(md).await.unwrap().working_counter == 3 {
                full += 1;
            }
        }
        // the EMCYs first: an SDO read of the master would take them out of the mailbox
        let em = show_emcys(&emcys(&sd).await);
        let code: u16 = sd.sdo_read(0x603F, 0).await.unwrap();
        let status = al_status(&sd).await;
        // the working counter says something about the drive in Op only (the
        // simulated ESC's process-data SyncManagers stay active below Op)
        let frames = if status.0 == OP {
            format!("; the master's frames come back (WKC 3) in {full} of 50 cycles after it")
        } else {
            String::new()
        };
        format!(
            "{}; axis A {}; {em}; 603Fh {code:04X}h; {}{frames}",
            al(status),
            axis_state(&sd).await,
            newest_diag(&sd).await,
        )
    })
}

const KEPT: &str = "Op, AL 0000h; axis A Operation enabled; no EMCY; 603Fh 0000h; history empty; \
                    the master's frames come back (WKC 3) in 50 of 50 cycles after it";
/// Kept on the bus, but longer than the interpolator extrapolates (I423,
/// 10 cycles): the axis faults by itself (C-117).
const EXTRAPOLATION: &str = "Op, AL 0000h; axis A Fault; EMCY 8612h/01h event 78 cause 3; 603Fh 8612h; \
                             history: error 8612h axis A event 78/3; the master's frames come back (WKC 3) \
                             in 50 of 50 cycles after it";
/// Beyond I423 first (the axis' own fault, 603Fh keeps it), then beyond
/// the PDO timeout (event 52's EMCY for the device).
const EXTRAPOLATION_THEN_TIMED_OUT: &str = "Safe-Op + ERR, AL 001Bh; axis A Fault; EMCY 8612h/01h event 78 \
                                            cause 3 + EMCY 7500h/10h event 52 cause 6; 603Fh 8612h; \
                                            history: error AL 001Bh";
const TIMED_OUT: &str = "Safe-Op + ERR, AL 001Bh; axis A Fault; EMCY 7500h/10h event 52 cause 6; \
                         603Fh 7500h; history: error AL 001Bh";

#[test]
fn e126_e128_e129_lost_frames_with_a258_65532_one_tolerated_two_not() {
    fault_row!(
        ethercrab(
            "01",
            "1 lost frame in Op, free run, A258 = 65532 (tolerate 1), axis A moving",
            "E-126",
            KEPT
        ),
        burst_free_run(65532, 1)
    );
    fault_row!(
        ethercrab(
            "02",
            "2 lost frames in a row, free run, A258 = 65532",
            "E-126, E-128, E-129",
            TIMED_OUT
        ),
        burst_free_run(65532, 2)
    );
}

#[test]
fn e126_e128_e129_lost_frames_with_a258_65533_three_tolerated_four_not() {
    fault_row!(
        ethercrab(
            "03",
            "3 lost frames in a row, free run, A258 = 65533 (tolerate 3), axis A moving",
            "E-126",
            KEPT
        ),
        burst_free_run(65533, 3)
    );
    fault_row!(
        ethercrab(
            "04",
            "4 lost frames in a row, free run, A258 = 65533",
            "E-126, E-128, E-129",
            TIMED_OUT
        ),
        burst_free_run(65533, 4)
    );
}

#[test]
fn e126_c117_lost_frames_with_a258_20_ms() {
    fault_row!(
        ethercrab(
            "05",
            "15 lost frames in a row, free run, A258 = 20 ms, axis A moving (longer than I423 = 10 cycles)",
            "E-126, C-117",
            EXTRAPOLATION
        ),
        burst_free_run(20, 15)
    );
    fault_row!(
        ethercrab(
            "06",
            "30 lost frames in a row, free run, A258 = 20 ms, axis A moving",
            "E-126, E-128, C-117",
            EXTRAPOLATION_THEN_TIMED_OUT
        ),
        burst_free_run(20, 30)
    );
}

#[test]
fn e127_c117_lost_frames_with_the_masters_sm_watchdog() {
    fault_row!(
        ethercrab(
            "07",
            "50 lost frames in a row, free run, A258 = 65534 (the ESC's SM watchdog, 100 ms), axis A moving",
            "E-127, C-117",
            EXTRAPOLATION
        ),
        burst_free_run(65534, 50)
    );
    fault_row!(
        ethercrab(
            "08",
            "150 lost frames in a row, free run, A258 = 65534, axis A moving",
            "E-127, E-128, C-117",
            EXTRAPOLATION_THEN_TIMED_OUT
        ),
        burst_free_run(65534, 150)
    );
}

/// The line in Op under DC (SYNC0 1 ms) with A258 = `a258`, then `lost`
/// cycles without frames (SYNC0 goes on), then 50 cycles more: the AL
/// state, axis A, EMCYs, 603Fh and the cycles after the burst that came
/// back with both drives... the one drive in Op.
fn burst_dc(a258: u16, lost: u64) -> String {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let dc = DcConfiguration {
            start_delay: Duration::from_millis(20),
            sync0_period: Duration::from_millis(1),
            sync0_shift: Duration::from_micros(900),
        };
        // the line's one drive: A258 written in Pre-Op
        let a258_in_pre_op = async |sd: &PdiSubDevice<'_, 512>| sd.sdo_write(A258, 0, a258).await.unwrap();
        let group = into_dc_sync0(md, init(md, clock).await, dc, a258_in_pre_op)
            .await
            .expect("SYNC0, PRE-OP with PDI, DC configuration")
            .request_into_op(md)
            .await
            .expect("request OP");
        let mut op_cycles = 0;
        for _ in 0..2000 {
            let r = group.tx_rx_dc(md).await.expect("DC cycle");
            advance(&sim, r.extra.next_cycle_wait.as_nanos() as u64);
            if r.all_op() {
                op_cycles += 1;
                if op_cycles == 100 {
                    break;
                }
            }
        }
        assert_eq!(op_cycles, 100, "Op under DC");
        advance(&sim, lost * 1_000_000);
        let mut op_after = 0;
        for _ in 0..50 {
            let r = group.tx_rx_dc(md).await.expect("DC cycle");
            advance(&sim, r.extra.next_cycle_wait.as_nanos() as u64);
            op_after += usize::from(r.all_op());
        }
        let sd = group.subdevice(md, 0).unwrap();
        let em = show_emcys(&emcys(&sd).await);
        let code: u16 = sd.sdo_read(0x603F, 0).await.unwrap();
        format!(
            "{}; {em}; 603Fh {code:04X}h; {}; Op in {op_after} of 50 cycles after it",
            al(al_status(&sd).await),
            newest_diag(&sd).await,
        )
    })
}

#[test]
fn e126_e107_lost_frames_under_dc_sync0_with_a258_65533() {
    fault_row!(
        ethercrab(
            "09",
            "3 lost frames in a row under DC (SYNC0 1 ms goes on), A258 = 65533",
            "E-126, E-107",
            "Op, AL 0000h; no EMCY; 603Fh 0000h; history empty; Op in 50 of 50 cycles after it"
        ),
        burst_dc(65533, 3)
    );
    fault_row!(
        ethercrab(
            "10",
            "4 lost frames in a row under DC, A258 = 65533",
            "E-126, E-128, E-129",
            "Safe-Op + ERR, AL 001Bh; EMCY 7500h/10h event 52 cause 6; 603Fh 7500h; \
         history: error AL 001Bh; Op in 0 of 50 cycles after it"
        ),
        burst_dc(65533, 4)
    );
}

/// One datagram from another master straight onto the line: FPWR of
/// `data` at `ado` of the drive at `station`; returns the working counter.
fn second_master_write(
    sim: &std::cell::RefCell<hil_sim::sim::Simulation>,
    station: u16,
    ado: u16,
    data: &[u8],
) -> u16 {
    // the second master's MAC; FPWR, index 0x42
    let mac = [0x02, 0, 0, 0, 0, 0x99];
    let mut f = hil_sim::sim::datagram_frame(mac, 5, 0x42, station, ado, data, hil_sim::sim::MIN_FRAME_LEN);
    sim.borrow_mut().exchange(&mut f);
    let w = 16 + 10 + data.len();
    u16::from_le_bytes([f[w], f[w + 1]])
}

#[test]
fn e021_e023_e037_a_second_master_with_conflicting_al_control() {
    let row = Row {
        order: "51",
        case: "a second master on the line writes AL control Init while the first runs axis A in Op, \
               then Op (from Init)",
        spec: "E-021, E-023, E-037, E-128",
        peer: "ethercrab + raw frames",
        expected: "Init: Init, AL 0000h, axis A Switch on disabled; Op from Init: Init + ERR, AL 0011h; master 1 acknowledges and requests Pre-Op: Pre-Op, AL 0000h, \
                   no EMCY; 6065h still 123456; history: error AL 0011h",
    };
    let sim = line(1);
    let seen = with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        sd.sdo_write(0x6065, 0, 123_456u32).await.unwrap();
        let station = sd.configured_address();
        let group = group.into_op(md).await.expect("OP");
        let sd = group.subdevice(md, 0).unwrap();
        let mut m = Cyclic::new(md, &group, &sim, 0);
        m.csv_at(REV, 100).await;
        // master 2: Init
        assert_eq!(second_master_write(&sim, station, 0x0120, &INIT.to_le_bytes()), 1);
        for _ in 0..20 {
            sd.outputs_raw_mut().copy_from_slice(&m.out);
            advance(&sim, 1_000_000);
            group.tx_rx(md).await.unwrap();
        }
        // no mailbox in Init (E-037): the axis read locally
        let after_init = format!(
            "{}, axis A {}",
            al(al_status(&sd).await),
            cia402_state(super::get(&sim, 0x6041, 0) as u16),
        );
        // master 2: Op, straight from Init
        second_master_write(&sim, station, 0x0120, &OP.to_le_bytes());
        advance(&sim, 2_000_000);
        let after_op = al(al_status(&sd).await);
        // master 1 takes the line back to Pre-Op
        request(&sd, INIT | ACK).await;
        request(&sd, PREOP).await;
        advance(&sim, 2_000_000);
        let back = al(al_status(&sd).await);
        let em = show_emcys(&emcys(&sd).await);
        let window: u32 = sd.sdo_read(0x6065, 0).await.unwrap();
        format!(
            "Init: {after_init}; Op from Init: {after_op}; master 1 acknowledges and requests Pre-Op: \
             {back}, {em}; 6065h still {window}; {}",
            newest_diag(&sd).await
        )
    });
    fault_row!(row, seen);
}
