//! Unit tests of the diagnosis model and the alarm blocks (P-030…P-035).

use super::*;

fn loc(slot: u16) -> Location {
    Location {
        api: 0,
        slot,
        subslot: 1,
        module_ident: 0x200 + 18,
        submodule_ident: 1,
    }
}

fn err(main: u8, sub: u8) -> DriveError {
    DriveError::new(main, sub).unwrap()
}

/// (alarm type, specifier bits, ChannelErrorType, ExtChannelErrorType,
/// AlarmSpecifier flags) of a notification.
fn summary(n: &Notification) -> (u16, u16, u16, u16, u16) {
    let item = n.item.unwrap();
    (
        n.alarm_type,
        item.properties.specifier_bits(),
        item.error_type,
        item.ext_error_type,
        n.specifier.0,
    )
}

#[test]
fn p031_p032_p033_error_08_6_is_channel_error_0x1008_ext_0x1006() {
    let e = err(8, 6);
    assert_eq!(e.channel_error_type(), 0x1008);
    assert_eq!(e.ext_channel_error_type(), 0x1006);
    let mut d = DiagList::<8>::new();
    d.set_alarms(true);
    d.raise(loc(1), e, Maintenance::Fault, 0).unwrap();
    let n = d.next_alarm().unwrap();
    let item = n.item.unwrap();
    assert_eq!(
        (item.channel, item.error_type, item.ext_error_type),
        (0x8000, 0x1008, 0x1006)
    );
    let mut b = [0u8; 64];
    let len = n.emit(&mut b).unwrap();
    assert_eq!(
        &b[..len],
        &[
            0x00, 0x02, 0x00, 0x24, 0x01, 0x00, // AlarmNotification low, length 36, v1.0
            0x00, 0x01, // AlarmType Diagnosis
            0, 0, 0, 0, // API
            0x00, 0x01, 0x00, 0x01, // slot 1, subslot 1
            0x00, 0x00, 0x02, 0x12, 0x00, 0x00, 0x00, 0x01, // module 0x212, submodule 1
            0xA8, 0x00, // AlarmSpecifier: channel, submodule and AR diagnosis
            0x80, 0x02, // USI extended channel diagnosis
            0x80, 0x00, 0x08, 0x00, // ChannelNumber 0x8000, ChannelProperties appears, fault
            0x10, 0x08, 0x10, 0x06, // 0x1000 + 8, 0x1000 + 6
            0, 0, 0, 0, // ExtChannelAddValue
        ]
    );
}

#[test]
fn p031_q13_main_index_is_added_as_a_binary_number() {
    assert_eq!(err(22, 4).channel_error_type(), 0x1016);
    assert_eq!(err(22, 4).ext_channel_error_type(), 0x1004);
    assert_eq!(err(96, 9).channel_error_type(), 0x1060);
    assert_eq!(err(1, 0).channel_error_type(), 0x1001);
    assert!(DriveError::new(0, 0).is_none());
    assert!(DriveError::new(97, 0).is_none());
    assert!(DriveError::new(8, 15).is_some());
    assert!(DriveError::new(8, 16).is_none());
}

#[test]
fn p030_p035_appears_and_disappears_in_order_one_at_a_time() {
    let mut d = DiagList::<8>::new();
    d.set_alarms(true);
    assert_eq!(d.next_alarm(), None);
    assert!(d.raise(loc(1), err(8, 6), Maintenance::Fault, 0).unwrap());
    assert!(
        !d.raise(loc(1), err(8, 6), Maintenance::Fault, 0).unwrap(),
        "already there"
    );
    d.raise(loc(1), err(22, 4), Maintenance::Fault, 7).unwrap();
    assert!(d.any_present());
    // 08-6 appears
    let n = d.next_alarm().unwrap();
    assert_eq!(summary(&n), (0x0001, 1, 0x1008, 0x1006, 0xA800));
    d.sent();
    assert!(d.in_flight());
    assert_eq!(d.next_alarm(), None, "one outstanding alarm");
    // acknowledged meanwhile: 08-6 clears while its appear is outstanding
    assert!(d.clear(&loc(1), err(8, 6)));
    d.acked();
    // 22-4 appears (it came before the clear)
    let n = d.next_alarm().unwrap();
    assert_eq!(summary(&n), (0x0001, 1, 0x1016, 0x1004, 0xA800));
    assert_eq!(n.item.unwrap().add_value, 7);
    d.sent();
    d.acked();
    // 08-6 disappears; 22-4 remains on the submodule
    let n = d.next_alarm().unwrap();
    assert_eq!(summary(&n), (0x0001, 3, 0x1008, 0x1006, 0xA800));
    d.sent();
    d.acked();
    assert_eq!(d.next_alarm(), None);
    // the last one goes: Diagnosis disappears, no diagnosis left
    d.clear(&loc(1), err(22, 4));
    assert!(!d.any_present());
    let n = d.next_alarm().unwrap();
    assert_eq!(summary(&n), (0x000C, 2, 0x1016, 0x1004, 0x0000));
    d.sent();
    d.acked();
    assert_eq!(d.next_alarm(), None);
    assert_eq!(d.present(&loc(1)).count(), 0);
}

#[test]
fn p035_ar_diagnosis_state_follows_other_submodules() {
    let mut d = DiagList::<8>::new();
    d.set_alarms(true);
    d.raise(loc(1), err(8, 6), Maintenance::Fault, 0).unwrap();
    d.raise(loc(2), err(30, 1), Maintenance::Fault, 0).unwrap();
    for _ in 0..2 {
        d.sent();
        d.acked();
    }
    d.clear(&loc(1), err(8, 6));
    let n = d.next_alarm().unwrap();
    // the submodule is clean, the AR is not
    assert_eq!(summary(&n), (0x000C, 2, 0x1008, 0x1006, 0x8000));
}

#[test]
fn p030_short_lived_errors_and_flapping_cost_no_lost_alarm() {
    let mut d = DiagList::<4>::new();
    d.set_alarms(true);
    // appears and goes before its alarm: nothing owed
    d.raise(loc(1), err(8, 6), Maintenance::Fault, 0).unwrap();
    d.clear(&loc(1), err(8, 6));
    assert_eq!(d.next_alarm(), None);
    // reported, disappears, reappears before the disappear alarm: nothing owed
    d.raise(loc(1), err(8, 6), Maintenance::Fault, 0).unwrap();
    d.sent();
    d.acked();
    d.clear(&loc(1), err(8, 6));
    d.raise(loc(1), err(8, 6), Maintenance::Fault, 0).unwrap();
    assert_eq!(d.next_alarm(), None);
    // disappear in flight, reappears: an appears alarm follows its ack
    d.clear(&loc(1), err(8, 6));
    d.sent();
    d.raise(loc(1), err(8, 6), Maintenance::Fault, 0).unwrap();
    assert!(d.any_present());
    assert_eq!(d.next_alarm(), None);
    d.acked();
    assert_eq!(
        d.next_alarm().unwrap().item.unwrap().properties.specifier_bits(),
        1
    );
    // a full list refuses
    for m in 40..43 {
        d.raise(loc(1), err(m, 0), Maintenance::Fault, 0).unwrap();
    }
    assert_eq!(d.raise(loc(1), err(50, 0), Maintenance::Fault, 0), Err(DiagFull));
}

#[test]
fn p030_without_an_ar_the_list_is_silent_and_a_new_ar_gets_no_replay() {
    let mut d = DiagList::<4>::new();
    d.raise(loc(1), err(8, 6), Maintenance::Fault, 0).unwrap();
    assert_eq!(d.next_alarm(), None);
    assert!(d.any_present());
    d.set_alarms(true);
    assert_eq!(
        d.next_alarm(),
        None,
        "present before the AR: in the record, not alarmed"
    );
    d.raise(loc(1), err(9, 1), Maintenance::Fault, 0).unwrap();
    d.sent();
    // the AR ends with the alarm outstanding
    d.set_alarms(false);
    assert!(!d.in_flight());
    assert_eq!(d.present(&loc(1)).count(), 2);
    d.clear_all(None);
    assert!(!d.any_present());
}

#[test]
fn p034_diagnosis_record_lists_the_present_entries_per_submodule() {
    let mut d = DiagList::<8>::new();
    d.raise(loc(1), err(8, 6), Maintenance::Fault, 0).unwrap();
    d.raise(loc(2), err(22, 4), Maintenance::Fault, 0x11).unwrap();
    d.raise(loc(1), err(40, 1), Maintenance::Required, 0).unwrap();
    let mut b = [0u8; 256];
    let n = d
        .write_record(
            DiagScope::Subslot {
                api: 0,
                slot: 1,
                subslot: 1,
            },
            DiagFilter::Faults,
            &mut b,
        )
        .unwrap();
    assert_eq!(
        &b[..n],
        &[
            0x00, 0x10, 0x00, 0x1C, 0x01, 0x01, // DiagnosisData v1.1, length 28
            0, 0, 0, 0, 0x00, 0x01, 0x00, 0x01, // API 0, slot 1, subslot 1
            0x80, 0x00, 0x08, 0x00, 0x80, 0x02, // ChannelNumber, ChannelProperties, USI
            0x80, 0x00, 0x08, 0x00, 0x10, 0x08, 0x10, 0x06, 0, 0, 0, 0,
        ]
    );
    let n = d.write_record(DiagScope::Ar, DiagFilter::All, &mut b).unwrap();
    assert_eq!(n, 32 + 12 + 32);
    assert_eq!(&b[2..4], &[0x00, 0x28], "slot 1 with both entries");
    assert_eq!(&b[34..36], &[0x0A, 0x00], "appears, maintenance required");
    assert_eq!(&b[44 + 10..44 + 12], &[0x00, 0x02], "then slot 2");
    assert_eq!(
        d.write_record(DiagScope::Slot { api: 0, slot: 3 }, DiagFilter::All, &mut b),
        Ok(0)
    );
    assert_eq!(
        d.write_record(DiagScope::Ar, DiagFilter::All, &mut b[..40]),
        Err(RecordError::BufferTooShort)
    );
    assert_eq!(
        DiagScope::for_record(0x800A, 0, 1, 1),
        Some((
            DiagScope::Subslot {
                api: 0,
                slot: 1,
                subslot: 1
            },
            DiagFilter::Faults
        ))
    );
    assert_eq!(
        DiagScope::for_record(0xC00A, 0, 1, 1),
        Some((DiagScope::Slot { api: 0, slot: 1 }, DiagFilter::Faults))
    );
    assert_eq!(
        DiagScope::for_record(0xE00C, 0, 1, 1),
        Some((DiagScope::Ar, DiagFilter::All))
    );
    assert_eq!(
        DiagScope::for_record(0xF00B, 5, 1, 1),
        Some((DiagScope::Api { api: 5 }, DiagFilter::Faults))
    );
    assert_eq!(DiagScope::for_record(0xAFF0, 0, 1, 1), None);
    assert_eq!(DiagScope::for_record(0x8028, 0, 1, 1), None);
}

#[test]
fn p043_alarm_ack_block_parses_and_matches() {
    let mut n = super::tests_cr::diag_notification();
    n.specifier = n.specifier.with_sequence(0x123);
    let b = super::tests_cr::ack_block(&n, PnioStatus::OK);
    let a = AlarmAck::parse(&b).unwrap();
    assert!(a.matches(&n));
    assert_eq!(a.specifier.sequence(), 0x123);
    let mut other = n;
    other.specifier = other.specifier.with_sequence(0x124);
    assert!(!a.matches(&other));
    assert!(AlarmAck::parse(&b[..21]).is_none());
    let mut wrong = b.clone();
    wrong[1] = 0x02 + 0x10;
    assert!(AlarmAck::parse(&wrong).is_none());
    let p = ChannelProperties::new(
        4,
        true,
        Maintenance::Demanded,
        Specifier::DisappearsOthersRemain,
        ChannelDirection::InputOutput,
    );
    assert_eq!(p.0, 0x04 | 0x100 | 0x400 | 0x1800 | 0x6000);
    assert_eq!(
        (
            p.channel_type(),
            p.accumulative(),
            p.maintenance_bits(),
            p.direction_bits()
        ),
        (4, true, 2, 3)
    );
    assert_eq!(p.with_specifier(Specifier::Appears).specifier_bits(), 1);
    let s = AlarmSpecifier::new(true, true, true, true).with_sequence(0x7FF);
    assert_eq!(s.0, 0xBFFF);
    assert!(s.channel_diagnosis() && s.manufacturer() && s.submodule_diagnosis() && s.ar_diagnosis());
    assert_eq!(
        PnioStatus::rta_abort(AbortCode::CONSUMER_DHT_EXPIRED).0,
        [0xCF, 0x81, 0xFD, 0x05]
    );
    assert!(PnioStatus::OK.is_ok());
}
