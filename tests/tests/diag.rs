//! EtherCAT diagnosis through a real master (spec §13.3, §13.5, §13.6): the
//! LEDs, A254–A257 and the parameter versions; the ESM's data rules that
//! the diagnosis shows (E-024, E-036, E-040).

use drive_tests::al::{ACK, BOOT, ERR, INIT, OP, PREOP, SAFEOP};
use drive_tests::step::{advance, cycles};
use drive_tests::{al_status, init, line, request, with_master, with_preop, with_sdo, write_sm, CoeClient};
use ecat::led::Pattern;
use esc::AlStatusCode;
use hil_sim::sim::Simulation;
use std::cell::RefCell;

const A254: u16 = drive_ecat::parameter_index(0, 254);
const A255: u16 = drive_ecat::parameter_index(0, 255);
const A256: u16 = drive_ecat::parameter_index(0, 256);
const A257: u16 = drive_ecat::parameter_index(0, 257);
const A258: u16 = drive_ecat::parameter_index(0, 258);

/// A257[`element`] by SDO (SDO Info numbering: sub = element + 1), without
/// the zero padding.
async fn a257<S>(sd: &ethercrab::SubDeviceRef<'_, S>, element: u8) -> String
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    let mut c = CoeClient::new();
    let raw = c.upload(sd, A257, element + 1).await.expect("A257");
    let end = raw.iter().position(|&b| b == 0).unwrap_or(raw.len());
    String::from_utf8(raw[..end].to_vec()).expect("ASCII")
}

async fn a255<S>(sd: &ethercrab::SubDeviceRef<'_, S>) -> u8
where
    S: std::ops::Deref<Target = ethercrab::SubDevice>,
{
    // the raw client throughout: ethercrab's own SDO after it could repeat
    // the mailbox counter (see `CoeClient`)
    CoeClient::new().upload(sd, A255, 0).await.expect("A255")[0]
}

fn leds(sim: &RefCell<Simulation>, i: usize) -> drive_ecat::runtime::Leds {
    let s = sim.borrow();
    s.drives()[i].leds(nanos::Nanos::from_ns(s.now().as_ns()))
}

/// The fraction of `span_ns` (sampled every 10 ms of simulated time) in
/// which LED `k` (0 RUN, 1 ERR, 2 IN, 3 OUT) of drive 0 is lit.
fn lit_fraction(sim: &RefCell<Simulation>, k: usize, span_ns: u64) -> f64 {
    let n = span_ns / 10_000_000;
    let mut on = 0;
    for _ in 0..n {
        advance(sim, 10_000_000);
        let s = sim.borrow();
        let now = s.now().as_ns();
        if s.drives()[0]
            .leds(nanos::Nanos::from_ns(now))
            .lit(nanos::Nanos::from_ns(now))[k]
        {
            on += 1;
        }
    }
    on as f64 / n as f64
}

/// E-041 (A255 1/2/4/8, 18/20), E-042 (A257[3] "AL xxxx"), E-133 (RUN LED
/// by state), E-132 (ERR LED: blinking for a refused request, double flash
/// for the PDO timeout, with the ETG.1300 duty cycles) through the master.
#[test]
fn e041_e042_e132_e133_a255_a257_3_and_the_run_and_err_leds() {
    let sim = line(1);
    // in Init before the master starts
    assert_eq!(leds(&sim, 0).run, Pattern::Off);
    assert_eq!(leds(&sim, 0).err, Pattern::Off);
    assert_eq!(sim.borrow().drives()[0].drive.objects().get(A255, 0), Ok(1));
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(a255(&sd).await, 2, "Pre-Op");
        assert_eq!(leds(&sim, 0).run, Pattern::Blinking);
        assert_eq!(a257(&sd, 3).await, "AL 0000");

        // a refused request: Pre-Op + error = 18, the code in A257[3], ERR blinking
        request(&sd, BOOT).await; // Bootstrap only from Init (issue 8): 0011h
        assert_eq!(al_status(&sd).await, (PREOP | ERR, 0x0011));
        assert_eq!(a255(&sd).await, 18);
        assert_eq!(a257(&sd, 3).await, "AL 0011");
        assert_eq!(leds(&sim, 0).err, Pattern::Blinking);
        assert_eq!(leds(&sim, 0).run, Pattern::Blinking);
        let f = lit_fraction(&sim, 1, 2_400_000_000);
        assert!((0.45..=0.55).contains(&f), "blinking: lit {f}");
        request(&sd, PREOP | ACK).await;
        assert_eq!((a255(&sd).await, leds(&sim, 0).err), (2, Pattern::Off));

        let mut c = CoeClient::new();
        c.download(&sd, A258, 0, &50u16.to_le_bytes()).await.unwrap();
        let group = group.into_safe_op(md).await.expect("SAFE-OP");
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(a255(&sd).await, 4, "Safe-Op");
        assert_eq!(leds(&sim, 0).run, Pattern::SingleFlash);
        cycles(md, &group, &sim, 5).await;
        let group = group.into_op(md).await.expect("OP");
        let sd = group.subdevice(md, 0).unwrap();
        cycles(md, &group, &sim, 5).await;
        assert_eq!(a255(&sd).await, 8, "Op");
        assert_eq!(leds(&sim, 0).run, Pattern::On);
        assert_eq!(leds(&sim, 0).err, Pattern::Off);

        // PDO timeout: Safe-Op + error = 20, AL 001Bh, ERR double flash
        advance(&sim, 100_000_000);
        assert_eq!(a255(&sd).await, 20);
        assert_eq!(a257(&sd, 3).await, "AL 001B");
        assert!(a257(&sd, 0).await.starts_with("Er4 "), "A257[0] Er4 watchdog");
        let l = leds(&sim, 0);
        assert_eq!((l.run, l.err), (Pattern::SingleFlash, Pattern::DoubleFlash));
        let f = lit_fraction(&sim, 1, 3_200_000_000);
        assert!((0.2..=0.3).contains(&f), "double flash: lit {f}");
        let f = lit_fraction(&sim, 0, 2_400_000_000);
        assert!((0.12..=0.22).contains(&f), "single flash: lit {f}");
        request(&sd, INIT | ACK).await;
    });
    let s = sim.borrow();
    assert_eq!(s.drives()[0].drive.objects().get(A255, 0), Ok(1), "Init");
    assert_eq!(
        s.drives()[0].leds(nanos::Nanos::from_ns(s.now().as_ns())).run,
        Pattern::Off
    );
}

/// E-134 (LA_EC LEDs per port), E-135 (A256 station address), E-136
/// (A257[0] links), E-137 (A257[1] lost links), E-138 (A257[2] RX errors) on
/// a line of two drives.
#[test]
fn e134_e135_e136_e137_e138_ports_addresses_and_counters() {
    let sim = line(2);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        for i in 0..2 {
            let sd = group.subdevice(md, i).unwrap();
            let a256: u16 = sd.sdo_read(A256, 0).await.unwrap();
            assert_eq!(a256, sd.configured_address(), "A256 drive {i}");
            assert_eq!(a256, 0x1000 + i as u16);
        }
        let (sd0, sd1) = (group.subdevice(md, 0).unwrap(), group.subdevice(md, 1).unwrap());
        // drive 0 has a neighbour on X201, drive 1 is the end of the line
        assert_eq!(a257(&sd0, 0).await, "Er0 L01 L11");
        assert_eq!(a257(&sd1, 0).await, "Er0 L01 L10");
        assert_eq!(a257(&sd0, 1).await, "L0 00 L1 00");
        assert_eq!(a257(&sd0, 2).await, "R0 0000 R1 0000");
        let l = [leds(&sim, 0), leds(&sim, 1)];
        assert_eq!(l[0].ports, [Pattern::Flickering, Pattern::Flickering], "traffic");
        assert_eq!(l[1].ports, [Pattern::Flickering, Pattern::Off], "no link on X201");

        // the cable behind drive 0 is pulled and plugged again (next frame)
        sim.borrow_mut().drives_mut()[0].esc.set_port_link(1, false);
        advance(&sim, 1_000_000);
        assert_eq!(leds(&sim, 0).ports[1], Pattern::Off, "no link");
        assert_eq!(a257(&sd0, 1).await, "L0 00 L1 01", "one link loss on X201");
        assert_eq!(a257(&sd0, 0).await, "Er0 L01 L11", "link back");
        // corrupted frames: 3 invalid frames on X200, 1 RX error on X201
        {
            let mut s = sim.borrow_mut();
            let esc = &mut s.drives_mut()[0].esc;
            for _ in 0..3 {
                esc.inject_rx_error(0, true);
            }
            esc.inject_rx_error(1, false);
        }
        advance(&sim, 1_000_000);
        assert_eq!(a257(&sd0, 2).await, "R0 0003 R1 0001");
        assert_eq!(a257(&sd1, 2).await, "R0 0000 R1 0000", "drive 1 untouched");

        // no frames for 300 ms: link without traffic = on
        advance(&sim, 300_000_000);
        let l = [leds(&sim, 0), leds(&sim, 1)];
        assert_eq!(l[0].ports, [Pattern::On, Pattern::On]);
        assert_eq!(l[1].ports, [Pattern::On, Pattern::Off]);
        let f = lit_fraction(&sim, 2, 500_000_000);
        assert_eq!(f, 1.0, "steady on");
    });
}

/// E-136 (E-025 Er10, E-033 Er6): the A257[0] error code of each refused
/// transition (Er10 mailbox Rx, Er8 RxPDO, Er7 TxPDO, Er6 regular process data missing, Er11 other
/// AL codes) and Er0 again after the acknowledge.
#[test]
fn e025_e033_e136_a257_0_error_codes_of_refused_transitions() {
    let rx = drive_ecat::DEVICE.output_bytes() as u16;
    let tx = drive_ecat::DEVICE.input_bytes() as u16;
    let sim = line(1);
    with_preop(&sim, async |sd| {
        // invalid state change (0011h): Er11, see A257[3]
        request(&sd, OP).await;
        assert_eq!(al_status(&sd).await, (PREOP | ERR, 0x0011));
        assert_eq!(a257(&sd, 0).await, "Er11 L01 L10");
        // SM2 one byte short (001Dh): Er8; SM3 one byte long (001Eh): Er7
        write_sm(&sd, 2, 0x1200, rx - 1, 0x64).await;
        request(&sd, SAFEOP | ACK).await;
        assert_eq!(al_status(&sd).await.1, AlStatusCode::INVALID_OUTPUT_CONFIG.0);
        assert_eq!(a257(&sd, 0).await, "Er8 L01 L10");
        write_sm(&sd, 2, 0x1200, rx, 0x64).await;
        write_sm(&sd, 3, 0x1A00, tx + 1, 0x20).await;
        request(&sd, SAFEOP | ACK).await;
        assert_eq!(al_status(&sd).await.1, AlStatusCode::INVALID_INPUT_CONFIG.0);
        assert_eq!(a257(&sd, 0).await, "Er7 L01 L10");
        write_sm(&sd, 3, 0x1A00, tx, 0x20).await;
        request(&sd, PREOP | ACK).await;
        assert_eq!(a257(&sd, 0).await, "Er0 L01 L10");

        // S→O without process data for 200 ms (A258 on): Er6
        let mut c = CoeClient::new();
        c.download(&sd, A258, 0, &50u16.to_le_bytes()).await.unwrap();
        request(&sd, SAFEOP).await;
        request(&sd, OP).await;
        advance(&sim, 250_000_000);
        // (none at all: 002Bh "no valid inputs and outputs", E-047)
        assert_eq!(al_status(&sd).await, (SAFEOP | ERR, 0x002B));
        assert_eq!(a257(&sd, 0).await, "Er6 L01 L10");
        request(&sd, SAFEOP | ACK).await;
        assert_eq!(a257(&sd, 0).await, "Er0 L01 L10");

        // mailbox SM0 moved (0016h, stays in Init): Er10 (mailbox Rx)
        request(&sd, INIT).await;
        sd.register_write(esc::regs::sm(0), 0x1800u16).await.unwrap();
        request(&sd, PREOP).await;
        assert_eq!(al_status(&sd).await, (INIT | ERR, 0x0016));
    });
    let mut s = sim.borrow_mut();
    let d = &mut s.drives_mut()[0].drive;
    assert_eq!(d.objects().get(A255, 0), Ok(17), "A255 Init + error");
    let mut buf = [0u8; 16];
    let n = d.read_object(A257, 1, &mut buf, od::CommState::PreOp).unwrap();
    let t = String::from_utf8(buf[..n].iter().copied().take_while(|&b| b != 0).collect()).unwrap();
    assert_eq!(t, "Er10 L01 L10", "mailbox Rx SM0");
}

/// E-139: the EtherCAT diagnosis parameters in their S-edition versions:
/// A254 V0 (present), A255 V3 (error states state | 10h, tested above), A256
/// V1, A257 V2 (four texts, [0] without "StX", [3] the AL code), A259 V1
/// (three elements), A261 V1 (four elements), A287 V3 (action with progress
/// and result).
#[test]
fn e139_parameter_versions_follow_the_s_layout() {
    assert_eq!(
        drive_ecat::runtime::PARAMETER_VERSIONS,
        [
            (254, 0),
            (255, 3),
            (256, 1),
            (257, 2),
            (259, 1),
            (261, 1),
            (287, 3)
        ]
    );
    let sim = line(1);
    with_sdo(&sim, async |sd, _| {
        let _: u16 = sd.sdo_read(A254, 0).await.expect("A254 (V0, S only)");
        let _: u16 = sd.sdo_read(A256, 0).await.expect("A256");
        let mut count = Vec::new();
        for line in [257, 259, 261, 287] {
            count.push(
                sd.sdo_read::<u8>(drive_ecat::parameter_index(0, line), 0)
                    .await
                    .unwrap(),
            );
        }
        assert_eq!(count[..3], [4, 3, 4], "A257 V2, A259 V1, A261 V1: elements");
        assert!(count[3] >= 3, "A287 V3: start, progress, result");
        let e0 = a257(sd, 0).await;
        assert!(e0.starts_with("Er") && !e0.contains("St"), "V2 [0]: {e0}");
        assert!(a257(sd, 3).await.starts_with("AL "), "V2 [3]");
        request(sd, BOOT).await;
        let a255 = a255(sd).await;
        assert_eq!(a255, 0x12, "V3: Pre-Op | 10h (V2 had 17…21)");
    });
}

/// E-026 (spec §3.2 I→P, §13.5): the station alias the EEPROM holds (SII
/// word 4, loaded by the ESC) is shown in A254 once the drive is in Pre-Op.
#[test]
fn e026_station_alias_from_the_eeprom_in_a254() {
    let mut img = [0u8; ecat::sii::EEPROM_BYTES];
    let len = ecat::build_sii(&drive_ecat::DEVICE, &mut img).unwrap();
    img[8..10].copy_from_slice(&0x0777u16.to_le_bytes());
    img[14] = esc::sii::config_checksum(&img[..14]);
    let sim = line(1);
    sim.borrow_mut().drives_mut()[0].esc =
        hil_sim::esc::Esc::new(hil_sim::esc::EscConfig::default(), &img[..len]);
    assert_eq!(sim.borrow().drives()[0].esc.station_alias(), 0x0777);
    with_sdo(&sim, async |sd, _| {
        let a254: u16 = sd.sdo_read(A254, 0).await.expect("A254");
        assert_eq!(a254, 0x0777, "A254 = the EEPROM's alias");
    });
}

/// E-024 (spec §3.1): the saved configuration is loaded at power-on, in
/// Init; in Init the drive neither answers the mailbox nor writes process
/// data into the ESC.
#[test]
fn e024_init_loads_the_saved_values_no_mailbox_no_process_data() {
    let sim = line(1);
    with_sdo(&sim, async |sd, _| {
        sd.sdo_write(A258, 0, 77u16).await.unwrap();
        sd.sdo_write(0x1010, 1, u32::from_le_bytes(*b"save"))
            .await
            .unwrap();
    });
    sim.borrow_mut().drives_mut()[0].power_cycle();
    {
        let s = sim.borrow();
        let d = &s.drives()[0].drive;
        assert_eq!(d.startup(), drive_ecat::runtime::Startup::Loaded);
        assert_eq!(d.objects().get(A258, 0), Ok(77), "loaded in Init");
        assert_eq!(d.slave().state(), esc::AlState::Init);
    }
    // mailbox and process-data areas marked; a mailbox request in SM0's area
    let mark = [0xA5u8; 64];
    {
        let mut s = sim.borrow_mut();
        let esc = &mut s.drives_mut()[0].esc;
        // mailbox header (10 bytes CoE, counter 1), CoE SDO request, upload 1000h:00
        let upload = [
            10, 0, 0, 0, 0, 0x13, 0x00, 0x20, 0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0,
        ];
        esc.write_reg(0x1000, &upload);
        esc.write_reg(0x1100, &mark);
        esc.write_reg(0x1A00, &mark[..29]);
    }
    advance(&sim, 20_000_000);
    let s = sim.borrow();
    let esc = &s.drives()[0].esc;
    let mut buf = [0u8; 64];
    esc.read_reg(0x1100, &mut buf);
    assert_eq!(buf, mark, "no mailbox reply in Init");
    esc.read_reg(0x1A00, &mut buf[..29]);
    assert_eq!(buf[..29], mark[..29], "no TxPDO in Init");
    assert_eq!(s.drives()[0].drive.slave().state(), esc::AlState::Init);
}

/// E-036 (spec §3.2): Op → Pre-Op stops the process data both ways: the
/// master's RxPDO frames are not read any more, the TxPDO area is not
/// written (it is in Safe-Op).
#[test]
fn e036_op_to_preop_stops_process_data_both_ways() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await.into_op(md).await.expect("OP");
        let sd = group.subdevice(md, 0).unwrap();
        for _ in 0..5 {
            advance(&sim, 1_000_000);
            group.tx_rx(md).await.unwrap();
        }
        let sm3 = |sim: &RefCell<Simulation>| {
            let mut b = [0u8; 29];
            sim.borrow().drives()[0].esc.read_reg(0x1A00, &mut b);
            b
        };
        let mark = |sim: &RefCell<Simulation>| {
            sim.borrow_mut().drives_mut()[0]
                .esc
                .write_reg(0x1A00, &[0xA5; 29]);
        };
        let received = |sim: &RefCell<Simulation>| sim.borrow().drives()[0].drive.slave().outputs_received();
        // in Op the TxPDO area is rewritten and the RxPDO read
        mark(&sim);
        let before = received(&sim);
        advance(&sim, 1_000_000);
        group.tx_rx(md).await.unwrap();
        assert_ne!(sm3(&sim), [0xA5; 29], "Op: TxPDO written");
        assert!(received(&sim) > before, "Op: RxPDO read");

        request(&sd, PREOP).await;
        assert_eq!(al_status(&sd).await, (PREOP, 0));
        mark(&sim);
        let before = received(&sim);
        for _ in 0..5 {
            advance(&sim, 1_000_000);
            let _ = group.tx_rx(md).await;
        }
        assert_eq!(sm3(&sim), [0xA5; 29], "Pre-Op: no TxPDO");
        assert_eq!(received(&sim), before, "Pre-Op: no RxPDO");
    });
}

/// E-040 (spec §3.3, S §7.2.4): a start-up list's CoE writes are accepted
/// in the order received in the states the master sends them in (I→P and
/// P→S lists in Pre-Op, S→O and S→P lists in Safe-Op, O→S in Op): the last
/// write of an object wins, each takes effect at once.
#[test]
fn e040_startup_list_writes_in_every_transition() {
    let sim = line(1);
    with_master(&sim, async |md, clock| {
        let group = init(md, clock).await;
        let sd = group.subdevice(md, 0).unwrap();
        // I→P / P→S lists (Pre-Op): sync type, mode, PDO timeout twice
        sd.sdo_write(0x1C32, 1, 1u16).await.unwrap();
        sd.sdo_write(0x6060, 0, 9i8).await.unwrap();
        for v in [11u16, 12] {
            sd.sdo_write(A258, 0, v).await.unwrap();
        }
        assert_eq!(sd.sdo_read::<u16>(A258, 0).await.unwrap(), 12);
        let group = group.into_safe_op(md).await.expect("SAFE-OP");
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(
            sim.borrow().drives()[0].drive.slave().sync_status().mode,
            ecat::esm::SyncMode::SmSync,
            "the P→S list's 1C32h:01 took effect"
        );
        // S→O list (Safe-Op)
        for v in [21u16, 22, 0] {
            sd.sdo_write(A258, 0, v).await.unwrap();
        }
        sd.sdo_write(0x6060, 0, 8i8).await.unwrap();
        let group = group.into_op(md).await.expect("OP");
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(sd.sdo_read::<u16>(A258, 0).await.unwrap(), 0);
        // O→S list (Op)
        for v in [31u16, 32] {
            sd.sdo_write(A258, 0, v).await.unwrap();
        }
        assert_eq!(sd.sdo_read::<u16>(A258, 0).await.unwrap(), 32);
        let group = group.into_safe_op(md).await.expect("SAFE-OP");
        let sd = group.subdevice(md, 0).unwrap();
        // S→P list (Safe-Op)
        for v in [41u16, 42] {
            sd.sdo_write(A258, 0, v).await.unwrap();
        }
        let group = group.into_pre_op(md).await.expect("PRE-OP");
        let sd = group.subdevice(md, 0).unwrap();
        assert_eq!(sd.sdo_read::<u16>(A258, 0).await.unwrap(), 42);
        assert_eq!(
            sd.sdo_read::<i8>(0x6060, 0).await.unwrap(),
            8,
            "6060h from the S→O list"
        );
    });
}

/// E-147: a diagnosis message (a refused AL state change) carries time stamp
/// 0 while neither DC nor SNTP gives the time, and the SNTP time (on the DC
/// epoch) once the IP stack's client keeps one.
#[test]
fn e147_message_time_stamp_zero_then_sntp() {
    let sim = line(1);
    let newest = |sim: &RefCell<Simulation>| {
        let s = sim.borrow();
        let d = &s.drives()[0].drive;
        d.diag()
            .message(d.diag().newest_subindex())
            .map(|(_, t)| t.as_ns())
    };
    with_sdo(&sim, async |sd, _| {
        request(sd, OP).await;
        assert_eq!(al_status(sd).await, (PREOP | ERR, 0x0011));
        assert_eq!(newest(&sim), Some(0), "no DC, no SNTP: 0");
        request(sd, PREOP | ACK).await;
        // an SNTP client's time: 2026-11-22 on the DC epoch (2000-01-01)
        let sntp = 847_584_000_000_000_000u64;
        let local = sim.borrow().now().as_ns();
        sim.borrow_mut().drives_mut()[0]
            .drive
            .set_sntp_time(Some(nanos::Nanos::from_ns(sntp)), nanos::Nanos::from_ns(local));
        advance(&sim, 5_000_000);
        request(sd, OP).await;
        assert_eq!(al_status(sd).await, (PREOP | ERR, 0x0011));
        let t = newest(&sim).unwrap();
        let elapsed = sim.borrow().now().as_ns() - local;
        assert!(t > sntp && t <= sntp + elapsed, "{t} vs {sntp} + {elapsed}");
    });
}
