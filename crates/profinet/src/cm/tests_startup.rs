//! Legacy and advanced startup (IEC 61158-6-10): the RTClass of the IOCRs
//! against ARProperties.StartupMode, their FrameID ranges, the FrameIDs the
//! device assigns and the ARServerBlockRes of an advanced-startup Connect.

use super::tests_connect::{dev, patch};
use super::tests_vectors::*;
use super::*;
use crate::rpc::tests::hex;

/// Offsets into the Connect's NDR args (see `p041_connect_refusals_…`).
const AR_PROPERTIES: usize = 48;
const INPUT_IOCR: usize = 60;
const OUTPUT_IOCR: usize = 60 + 90;
/// IOCRProperties and FrameID within an IOCRBlockReq.
const PROPS: usize = 12;
const FRAME_ID: usize = 18;

/// The Connect with StartupMode advanced (ARProperties 0x4000_0011) or
/// legacy, both IOCRs of `rt_class`, the input CR's FrameID `input`, the
/// output CR's left to the device (0xFFFF).
fn connect(advanced: bool, rt_class: u8, input: u16) -> std::string::String {
    let props = if advanced { 0x4000_0011u32 } else { 0x11 };
    let mut c = patch(CONNECT, AR_PROPERTIES, &props.to_be_bytes());
    for cr in [INPUT_IOCR, OUTPUT_IOCR] {
        c = patch(&c, cr + PROPS, &[0, 0, 0, rt_class]);
    }
    patch(&c, INPUT_IOCR + FRAME_ID, &input.to_be_bytes())
}

#[test]
fn p042_advanced_startup_connect_with_rt_class_2_iocrs_is_accepted() {
    let mut d = dev();
    d.cm.pdev_mut().name = crate::dcp::NameOfStation::new(b"drive-1").unwrap();
    let (status, args) = d.call(&connect(true, 2, 0x8001));
    assert_eq!(status, PnioStatus::OK);
    let ar = d.cm.ar().unwrap();
    assert!(ar.advanced_startup());
    let (i, o) = (ar.input_cr.as_ref().unwrap(), ar.output_cr.as_ref().unwrap());
    assert_eq!((i.rt_class, i.frame_id), (2, 0x8001));
    // The output CR's FrameID comes from the RTClass 2 range: 0x8100 + reference 2.
    assert_eq!((o.rt_class, o.frame_id), (2, 0x8102));
    // ARBlockRes (34), IOCRBlockRes ×2 (12 each) with the FrameIDs, AlarmCRBlockRes
    // (12), then ARServerBlockRes: length 13, name 7 bytes, one byte of padding
    // (6 + 2 + 2 + 7 + 1 = 16 bytes, 32-bit aligned).
    assert_eq!(&args[34..46], &hex("81020008 0100 0001 0001 8001")[..]);
    assert_eq!(&args[46..58], &hex("81020008 0100 0002 0002 8102")[..]);
    let server = &args[34 + 36..];
    assert_eq!(server, &hex("8106 000c 0100 0007 64726976652d31 00")[..]);
}

#[test]
fn p042_advanced_startup_server_block_of_an_unnamed_device_is_empty() {
    let mut d = dev();
    let (status, args) = d.call(&connect(true, 2, 0xFFFF));
    assert_eq!(status, PnioStatus::OK);
    assert_eq!(&args[34 + 36..], &hex("8106 0004 0100 0000")[..]);
    // Both FrameIDs assigned from the RTClass 2 range.
    let ar = d.cm.ar().unwrap();
    assert_eq!(ar.input_cr.as_ref().unwrap().frame_id, 0x8201);
    assert_eq!(ar.output_cr.as_ref().unwrap().frame_id, 0x8102);
}

#[test]
fn p042_legacy_startup_takes_rt_class_1_and_rt_class_2() {
    let mut d = dev();
    let (status, args) = d.call(&connect(false, 1, 0xC001));
    assert_eq!(status, PnioStatus::OK);
    // No ARServerBlockRes in legacy startup: the response ends after the AlarmCRBlockRes.
    assert_eq!(args.len(), 34 + 36);
    let ar = d.cm.ar().unwrap();
    assert!(!ar.advanced_startup());
    assert_eq!(ar.output_cr.as_ref().unwrap().frame_id, 0xC102);
    let mut d = dev();
    assert_eq!(d.call(&connect(false, 2, 0xBBFF)).0, PnioStatus::OK);
    assert_eq!(d.cm.ar().unwrap().input_cr.as_ref().unwrap().frame_id, 0xBBFF);
}

#[test]
fn p042_iocrs_outside_the_startup_mode_or_range_are_refused_naming_the_field() {
    let cases = [
        // advanced startup with RTClass 1 IOCRs: IOCRBlockReq field 7
        (connect(true, 1, 0xC001), PnioStatus::connect(2, 7)),
        // RTClass 3 (IRT) and RTClass UDP are not offered
        (connect(true, 3, 0x0100), PnioStatus::connect(2, 7)),
        (connect(false, 4, 0xC001), PnioStatus::connect(2, 7)),
        // reserved_1 bits set
        (
            patch(&connect(true, 2, 0x8001), INPUT_IOCR + PROPS, &[0, 0, 0x00, 0x12]),
            PnioStatus::connect(2, 7),
        ),
        // FrameIDs outside the RTClass's range: field 9
        (connect(true, 2, 0xC001), PnioStatus::connect(2, 9)),
        (connect(true, 2, 0xBC00), PnioStatus::connect(2, 9)),
        (connect(false, 1, 0x8001), PnioStatus::connect(2, 9)),
        (connect(false, 1, 0xF800), PnioStatus::connect(2, 9)),
    ];
    for (req, want) in cases {
        let mut d = dev();
        let (status, args) = d.call(&req);
        assert_eq!(status, want);
        assert!(args.is_empty());
        assert!(d.cm.ar().is_none());
        assert_eq!(d.cm.poll_event(), None);
    }
    // reserved_2 (bits 13-23) may carry anything.
    let mut d = dev();
    let req = patch(
        &connect(true, 2, 0x8001),
        INPUT_IOCR + PROPS,
        &[0, 0xFF, 0xE0, 0x02],
    );
    assert_eq!(d.call(&req).0, PnioStatus::OK);
}
