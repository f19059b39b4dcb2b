//! Unit tests of the cyclic consumer and provider (P-042, P-036).

use super::*;
use crate::wire::EthFrame;

pub(super) const CTL: MacAddr = MacAddr([0x02, 0, 0, 0, 0, 0x01]);
pub(super) const DEV: MacAddr = MacAddr([0x02, 0, 0, 0, 0, 0x02]);
const DAP: [u16; 4] = [0x0001, 0x8000, 0x8001, 0x8002];

fn obj(slot: u16, subslot: u16, offset: u16, len: u16) -> IoDataObject {
    IoDataObject {
        slot,
        subslot,
        offset,
        len,
    }
}

fn iocs(slot: u16, subslot: u16, offset: u16) -> IocsEntry {
    IocsEntry {
        slot,
        subslot,
        offset,
    }
}

fn base(frame_id: u16) -> CrConfig {
    CrConfig {
        frame_id,
        data_length: 42,
        send_clock_factor: 32,
        reduction_ratio: 32,
        phase: 1,
        watchdog_factor: 6,
        data_hold_factor: 6,
        local: DEV,
        remote: CTL,
        tag: Some(0xC000),
        ..CrConfig::default()
    }
}

/// The controller's output CR (controller → drive) as profinet-py lays it
/// out: slot 2 (IN module, 18 words) data + IOPS, then the IOCS of the
/// DAP's subslots and of slot 1.
pub(super) fn output_cr() -> CrConfig {
    let mut c = base(0x8000);
    c.objects.push(obj(2, 1, 0, 36)).unwrap();
    for (i, s) in DAP.iter().enumerate() {
        c.iocs.push(iocs(0, *s, 37 + i as u16)).unwrap();
    }
    c.iocs.push(iocs(1, 1, 41)).unwrap();
    c
}

/// Our input CR (drive → controller): the DAP subslots' IOPS, slot 1 (OUT
/// module, 18 words) data + IOPS, the IOCS for slot 2.
pub(super) fn input_cr() -> CrConfig {
    let mut c = base(0xC001);
    for (i, s) in DAP.iter().enumerate() {
        c.objects.push(obj(0, *s, i as u16, 0)).unwrap();
    }
    c.objects.push(obj(1, 1, 4, 36)).unwrap();
    c.iocs.push(iocs(2, 1, 41)).unwrap();
    c
}

/// A frame of the output CR as the controller sends it.
pub(super) fn ctl_frame(counter: u16, ds: u8, ts: u8, fill: u8) -> std::vec::Vec<u8> {
    let mut f = std::vec::Vec::new();
    f.extend_from_slice(&DEV.0);
    f.extend_from_slice(&CTL.0);
    f.extend_from_slice(&[0x81, 0x00, 0xC0, 0x00, 0x88, 0x92, 0x80, 0x00]);
    f.extend((0..36).map(|i| fill.wrapping_add(i)));
    f.extend_from_slice(&[0x80; 6]);
    f.extend_from_slice(&counter.to_be_bytes());
    f.extend_from_slice(&[ds, ts]);
    f
}

const MS: u64 = 1_000_000;
fn ms(v: u64) -> Nanos {
    Nanos::from_ns(v * MS)
}

#[test]
fn p042_config_cycle_and_validation() {
    let c = output_cr();
    assert_eq!(c.cycle(), ms(32));
    assert_eq!(c.cycle_units(), 1024);
    assert_eq!(c.validate(), Ok(()));
    assert_eq!(c.frame_len(), 18 + 2 + 42 + 4);
    // each case: one change to the good configuration, and its verdict
    type Edit = fn(&mut CrConfig);
    let cases: [(Edit, Result<(), ConfigError>); 10] = [
        (|b| b.frame_id = 0xFC01, Err(ConfigError::FrameId)),
        (|b| b.data_length = 39, Err(ConfigError::DataLength)),
        (|b| b.reduction_ratio = 3, Err(ConfigError::ReductionRatio)),
        // 32 × 512 units = 512 ms: the longest
        (
            |b| {
                b.reduction_ratio = 512;
                b.phase = 1;
            },
            Ok(()),
        ),
        // 1024 ms: too long
        (
            |b| {
                b.reduction_ratio = 512;
                b.phase = 1;
                b.send_clock_factor = 64;
            },
            Err(ConfigError::ReductionRatio),
        ),
        (|b| b.phase = 33, Err(ConfigError::Phase)),
        (|b| b.watchdog_factor = 0, Err(ConfigError::WatchdogFactor)),
        (|b| b.data_hold_factor = 0x1E01, Err(ConfigError::DataHoldFactor)),
        // on the IOPS of slot 2
        (|b| b.iocs.push(iocs(9, 9, 36)).unwrap(), Err(ConfigError::Layout)),
        // IOPS past the end
        (|b| b.objects[0].len = 42, Err(ConfigError::Layout)),
    ];
    for (i, (edit, verdict)) in cases.into_iter().enumerate() {
        let mut bad = c.clone();
        edit(&mut bad);
        assert_eq!(bad.validate(), verdict, "case {i}");
    }
}

#[test]
fn p042_cycle_counter_newer_rule_wraps_at_16_bits() {
    assert!(counter_is_newer(1, 0));
    assert!(counter_is_newer(0, 0xFC00)); // across the wrap
    assert!(counter_is_newer(61_440, 0));
    assert!(!counter_is_newer(0, 0));
    assert!(!counter_is_newer(61_441, 0)); // 4095 units behind
    assert!(!counter_is_newer(0xFFFF, 0));
}

#[test]
fn p042_consumer_accepts_valid_frames_and_hands_out_outputs() {
    let mut c = Consumer::new(output_cr()).unwrap();
    assert_eq!(c.state(), ConsumerState::Waiting);
    assert_eq!(c.poll_at(), Nanos::MAX);
    let f = ctl_frame(1024, 0x35, 0, 1);
    let r = c.receive(ms(0), &EthFrame::parse(&f).unwrap()).unwrap();
    assert!(r.first);
    assert_eq!(
        (r.cycle_counter, r.status, r.changed),
        (1024, DataStatus(0x35), 0x35)
    );
    let out = r.outputs.unwrap();
    assert_eq!(
        out.data(2, 1).unwrap(),
        &(1..=36).collect::<std::vec::Vec<u8>>()[..]
    );
    assert_eq!(out.iops(2, 1), Some(Ioxs::GOOD));
    assert_eq!(out.iocs(1, 1), Some(Ioxs::GOOD));
    assert_eq!(out.iocs(0, 0x8000), Some(Ioxs::GOOD));
    assert_eq!(out.data(1, 1), None);
    assert_eq!(out.objects().count(), 1);
    assert_eq!(c.state(), ConsumerState::Running);
    assert!(c.outputs_valid());
    assert_eq!(c.poll_at(), ms(6 * 32));
    // the next one, one cycle (1024 units) later
    let f = ctl_frame(2048, 0x35, 0, 2);
    let r = c.receive(ms(32), &EthFrame::parse(&f).unwrap()).unwrap();
    assert!(!r.first);
    assert_eq!(r.changed, 0);
    assert_eq!(r.outputs.unwrap().data(2, 1).unwrap()[0], 2);
    assert_eq!((c.stats().accepted, c.stats().valid), (2, 2));
}

#[test]
fn p042_consumer_drops_and_counts_foreign_short_stale_frames_without_state_change() {
    let mut c = Consumer::new(output_cr()).unwrap();
    let f = ctl_frame(5000, 0x35, 0, 1);
    c.receive(ms(0), &EthFrame::parse(&f).unwrap()).unwrap();
    let at = c.poll_at();
    // another FrameID
    let mut other = ctl_frame(6000, 0x35, 0, 1);
    other[19] = 0x01;
    assert_eq!(
        c.receive(ms(10), &EthFrame::parse(&other).unwrap()).unwrap_err(),
        RxError::WrongFrameId
    );
    // one byte short, one byte long
    let f = ctl_frame(6000, 0x35, 0, 1);
    assert_eq!(
        c.receive(ms(10), &EthFrame::parse(&f[..f.len() - 1]).unwrap())
            .unwrap_err(),
        RxError::WrongLength
    );
    let mut long = f.clone();
    long.push(0);
    assert_eq!(
        c.receive(ms(10), &EthFrame::parse(&long).unwrap()).unwrap_err(),
        RxError::WrongLength
    );
    // from someone else
    let mut stranger = f.clone();
    stranger[11] = 0x99;
    assert_eq!(
        c.receive(ms(10), &EthFrame::parse(&stranger).unwrap())
            .unwrap_err(),
        RxError::WrongAddress
    );
    // same and older counters
    for old in [5000u16, 4999, 5000u16.wrapping_sub(4095)] {
        let f = ctl_frame(old, 0x35, 0, 1);
        assert_eq!(
            c.receive(ms(10), &EthFrame::parse(&f).unwrap()).unwrap_err(),
            RxError::Stale
        );
    }
    // TransferStatus and Ignore
    let f = ctl_frame(6000, 0x35, 1, 1);
    assert_eq!(
        c.receive(ms(10), &EthFrame::parse(&f).unwrap()).unwrap_err(),
        RxError::TransferStatus
    );
    let f = ctl_frame(6000, 0xB5, 0, 1);
    assert_eq!(
        c.receive(ms(10), &EthFrame::parse(&f).unwrap()).unwrap_err(),
        RxError::Ignored
    );
    // not PROFINET at all
    let mut ip = f.clone();
    ip[16..18].copy_from_slice(&[0x08, 0x00]);
    assert_eq!(
        c.receive(ms(10), &EthFrame::parse(&ip).unwrap()).unwrap_err(),
        RxError::NotRt
    );
    let s = *c.stats();
    assert_eq!(
        (
            s.wrong_frame_id,
            s.wrong_length,
            s.wrong_address,
            s.stale,
            s.transfer_status,
            s.ignored
        ),
        (2, 2, 1, 3, 1, 1)
    );
    assert_eq!(s.accepted, 1);
    assert_eq!(c.poll_at(), at, "no drop restarted a timer");
    // across the 16-bit wrap is newer
    let mut c = Consumer::new(output_cr()).unwrap();
    for (i, n) in [0xF800u16, 0xFC00, 0x0000, 0x0400].iter().enumerate() {
        let f = ctl_frame(*n, 0x35, 0, 1);
        assert!(c
            .receive(ms(32 * i as u64), &EthFrame::parse(&f).unwrap())
            .is_ok());
    }
}

#[test]
fn p042_consumer_withholds_outputs_that_are_not_valid() {
    let mut c = Consumer::new(output_cr()).unwrap();
    let cases = [
        (0x31, Invalid::DataInvalid),  // DataValid = 0
        (0x34, Invalid::Backup),       // State backup
        (0x25, Invalid::ProviderStop), // ProviderState stop
    ];
    for (i, (ds, why)) in cases.iter().enumerate() {
        let f = ctl_frame(1024 * (i as u16 + 1), *ds, 0, 1);
        let r = c.receive(ms(i as u64), &EthFrame::parse(&f).unwrap()).unwrap();
        assert_eq!(r.outputs.unwrap_err(), *why);
        assert!(!c.outputs_valid());
    }
    // IOPS BAD: the frame is valid but the submodule's data is withheld
    let mut f = ctl_frame(8192, 0x35, 0, 1);
    f[20 + 36] = 0x00;
    let r = c.receive(ms(5), &EthFrame::parse(&f).unwrap()).unwrap();
    let out = r.outputs.unwrap();
    assert_eq!(out.iops(2, 1), Some(Ioxs::BAD));
    assert_eq!(out.data(2, 1), None);
    assert_eq!(out.objects().next().unwrap().2, None);
}

#[test]
fn p036_watchdog_expiry_is_ar_loss_and_data_hold_comes_first() {
    let mut cfg = output_cr();
    cfg.data_hold_factor = 3;
    let mut c = Consumer::new(cfg).unwrap();
    let f = ctl_frame(1024, 0x35, 0, 1);
    c.receive(ms(0), &EthFrame::parse(&f).unwrap()).unwrap();
    assert_eq!(c.poll_at(), ms(96));
    assert_eq!(c.poll(ms(95)), None);
    assert_eq!(c.poll(ms(96)), Some(ConsumerEvent::DataHoldExpired));
    assert!(!c.outputs_valid());
    assert!(!c.exchanging());
    assert_eq!(c.poll(ms(96)), None, "reported once");
    assert_eq!(c.poll_at(), ms(192));
    // an accepted frame that is not valid restarts the watchdog only
    let f = ctl_frame(2048, 0x31, 0, 1);
    c.receive(ms(100), &EthFrame::parse(&f).unwrap()).unwrap();
    assert_eq!(c.poll_at(), ms(292));
    assert_eq!(c.poll(ms(291)), None);
    assert_eq!(c.poll(ms(292)), Some(ConsumerEvent::WatchdogExpired));
    assert_eq!(
        ConsumerEvent::WatchdogExpired.abort_code(),
        Some(crate::alarm::AbortCode::CONSUMER_DHT_EXPIRED)
    );
    assert_eq!(ConsumerEvent::DataHoldExpired.abort_code(), None);
    assert_eq!(c.state(), ConsumerState::Expired);
    assert_eq!(c.poll_at(), Nanos::MAX);
    let f = ctl_frame(3072, 0x35, 0, 1);
    assert_eq!(
        c.receive(ms(300), &EthFrame::parse(&f).unwrap()).unwrap_err(),
        RxError::Expired
    );
    assert_eq!(c.stats().after_expiry, 1);
}

#[test]
fn p036_valid_data_after_data_hold_makes_outputs_current_again() {
    let mut cfg = output_cr();
    cfg.data_hold_factor = 2;
    let mut c = Consumer::new(cfg).unwrap();
    let f = ctl_frame(1024, 0x35, 0, 1);
    c.receive(ms(0), &EthFrame::parse(&f).unwrap()).unwrap();
    assert_eq!(c.poll(ms(64)), Some(ConsumerEvent::DataHoldExpired));
    let f = ctl_frame(4096, 0x35, 0, 1);
    assert!(c
        .receive(ms(70), &EthFrame::parse(&f).unwrap())
        .unwrap()
        .outputs
        .is_ok());
    assert!(c.outputs_valid());
    assert_eq!(c.poll_at(), ms(134));
    // equal factors: both due at once, data hold reported first
    let mut c = Consumer::new(output_cr()).unwrap();
    let f = ctl_frame(1024, 0x35, 0, 1);
    c.receive(ms(0), &EthFrame::parse(&f).unwrap()).unwrap();
    assert_eq!(c.poll(ms(500)), Some(ConsumerEvent::DataHoldExpired));
    assert_eq!(c.poll(ms(500)), Some(ConsumerEvent::WatchdogExpired));
    assert_eq!(c.poll(ms(500)), None);
}

#[test]
fn p042_provider_sends_each_cycle_with_counter_status_iops_iocs_and_vlan_tag() {
    let mut p = Provider::new(input_cr(), ms(1000)).unwrap();
    assert_eq!(p.poll_at(), ms(1000));
    let mut buf = [0u8; 128];
    assert!(p.poll(ms(999), &mut buf).unwrap().is_none());
    p.set_all_iops(Ioxs::GOOD);
    p.set_all_iocs(Ioxs::GOOD);
    assert!(p.set_iops(1, 1, Ioxs::GOOD));
    assert!(!p.set_iops(7, 1, Ioxs::GOOD));
    assert!(!p.set_iocs(7, 1, Ioxs::GOOD));
    let mut f = p.poll(ms(1000), &mut buf).unwrap().unwrap();
    assert!(f.set_data(1, 1, &[0xAB; 36]));
    assert!(!f.set_data(1, 1, &[0xAB; 35]));
    assert!(f.set_data(1, 1, &[0xAB; 36]));
    assert!(!f.set_data(2, 1, &[1]));
    assert_eq!(f.cycle_counter(), 0);
    let b = f.bytes();
    assert_eq!(b.len(), 66);
    assert_eq!(&b[..6], &CTL.0);
    assert_eq!(&b[6..12], &DEV.0);
    assert_eq!(&b[12..20], &[0x81, 0x00, 0xC0, 0x00, 0x88, 0x92, 0xC0, 0x01]);
    assert_eq!(&b[20..24], &[0x80; 4], "IOPS of the DAP's subslots");
    assert_eq!(&b[24..60], &[0xAB; 36]);
    assert_eq!(b[60], 0x80, "IOPS of slot 1");
    assert_eq!(b[61], 0x80, "IOCS for slot 2");
    assert_eq!(&b[62..], &[0x00, 0x00, 0x35, 0x00]);
    assert_eq!(p.poll_at(), ms(1032));
    // the next cycle: the counter advances by SCF × RR = 1024
    p.set_station_problem(true);
    let f = p.poll(ms(1032), &mut buf).unwrap().unwrap();
    assert_eq!(f.cycle_counter(), 1024);
    assert_eq!(&f.bytes()[62..], &[0x04, 0x00, 0x15, 0x00]);
    // a late poll sends the latest due cycle and counts the missed ones
    let f = p.poll(ms(1032 + 3 * 32 + 5), &mut buf).unwrap().unwrap();
    assert_eq!(f.cycle_counter(), 4 * 1024);
    assert_eq!(p.stats().skipped, 2);
    assert_eq!(p.stats().sent, 3);
    assert_eq!(p.poll_at(), ms(1000 + 5 * 32));
    p.set_run(false);
    p.set_data_valid(false);
    p.set_station_problem(false);
    assert_eq!(p.data_status(), DataStatus(0x21));
    assert_eq!(
        p.poll(ms(2000), &mut [0u8; 65]).unwrap_err(),
        TxError::BufferTooShort
    );
}

#[test]
fn p042_provider_counter_wraps_and_phase_offsets_the_send() {
    let mut cfg = input_cr();
    cfg.send_clock_factor = 32;
    cfg.reduction_ratio = 4;
    cfg.phase = 3;
    cfg.tag = None;
    let mut p = Provider::new(cfg, ms(0)).unwrap();
    assert_eq!(p.poll_at(), ms(2), "phase 3: two send clocks in");
    let mut buf = [0u8; 128];
    let mut last = None;
    for k in 0..600u64 {
        let f = p.poll(ms(2 + 4 * k), &mut buf).unwrap().unwrap();
        assert_eq!(f.len(), 62, "untagged");
        let c = f.cycle_counter();
        assert_eq!(c, ((64 + k * 128) % 65536) as u16);
        if let Some(l) = last {
            assert!(counter_is_newer(c, l));
        }
        last = Some(c);
    }
}

#[test]
fn p042_provider_frames_feed_a_consumer() {
    // our own provider as the peer of a consumer: same layout both ways
    let mut cfg = output_cr();
    std::mem::swap(&mut cfg.local, &mut cfg.remote);
    let mut p = Provider::new(cfg, ms(0)).unwrap();
    p.set_all_iops(Ioxs::GOOD);
    let mut c = Consumer::new(output_cr()).unwrap();
    let mut buf = [0u8; 128];
    for k in 0..100u64 {
        let mut f = p.poll(ms(32 * k), &mut buf).unwrap().unwrap();
        f.data_mut(2, 1).unwrap()[0] = k as u8;
        let len = f.len();
        let r = c
            .receive(ms(32 * k + 1), &EthFrame::parse(&buf[..len]).unwrap())
            .unwrap();
        assert_eq!(r.outputs.unwrap().data(2, 1).unwrap()[0], k as u8);
        assert_eq!(c.poll(ms(32 * k + 2)), None);
    }
}

/// A deterministic xorshift for the mutation tests.
pub(crate) fn xorshift(seed: &mut u64) -> u64 {
    *seed ^= *seed << 13;
    *seed ^= *seed >> 7;
    *seed ^= *seed << 17;
    *seed
}

#[test]
fn p042_consumer_never_panics_on_mutated_or_truncated_frames() {
    let good = ctl_frame(1024, 0x35, 0, 1);
    let mut c = Consumer::new(output_cr()).unwrap();
    let mut seed = 0x1234_5678_9ABC_DEF0u64;
    for i in 0..20_000u64 {
        let mut f = good.clone();
        let flips = xorshift(&mut seed) % 4;
        for _ in 0..flips {
            let at = (xorshift(&mut seed) as usize) % f.len();
            f[at] = xorshift(&mut seed) as u8;
        }
        let cut = (xorshift(&mut seed) as usize) % (f.len() + 8);
        f.resize(cut, 0);
        if let Some(e) = EthFrame::parse(&f) {
            let _ = c.receive(ms(i), &e);
        }
        let _ = c.poll(ms(i));
    }
    let s = c.stats();
    assert!(s.accepted > 0 && s.wrong_length > 0 && s.wrong_frame_id > 0);
}
