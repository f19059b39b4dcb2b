use std::vec::Vec;

use crate::bmp::{self, Refused};
use crate::fake::Fake;
use crate::Addr;

fn serve(f: &mut Fake, req: &[u8]) -> Vec<u8> {
    let mut out = [0u8; 240];
    let n = bmp::serve(req, f, &mut out).expect("answered");
    out[..n].to_vec()
}

/// A read request of `params` (attribute, elements, PNU, subindex).
fn read_req(reference: u8, params: &[(u8, u8, u16, u16)]) -> Vec<u8> {
    let mut v = std::vec![reference, 0x01, 0x01, params.len() as u8];
    for &(attr, n, pnu, sub) in params {
        v.extend_from_slice(&[attr, n]);
        v.extend_from_slice(&pnu.to_be_bytes());
        v.extend_from_slice(&sub.to_be_bytes());
    }
    v
}

fn size(format: u8) -> usize {
    match format {
        0x01 | 0x02 | 0x05 | 0x41 => 1,
        0x03 | 0x06 | 0x42 => 2,
        _ => 4,
    }
}

/// A change request: addresses, then per parameter format, count, values.
fn change_req(reference: u8, params: &[(u16, u16, u8, &[u8])]) -> Vec<u8> {
    let mut v = std::vec![reference, 0x02, 0x01, params.len() as u8];
    for &(pnu, sub, format, values) in params {
        let n = values.len() / size(format);
        v.extend_from_slice(&[0x10, n as u8]);
        v.extend_from_slice(&pnu.to_be_bytes());
        v.extend_from_slice(&sub.to_be_bytes());
    }
    for &(_, _, format, values) in params {
        v.extend_from_slice(&[format, (values.len() / size(format)) as u8]);
        v.extend_from_slice(values);
        if values.len() % 2 == 1 {
            v.push(0);
        }
    }
    v
}

#[test]
fn p206_a_read_answers_format_count_and_the_big_endian_value() {
    let mut f = Fake::drive();
    f.set(Addr::new(1100, 0), -2);
    assert_eq!(
        serve(&mut f, &read_req(7, &[(0x10, 1, 1100, 0)])),
        [7, 0x01, 0x01, 1, 0x04, 1, 0xFF, 0xFF, 0xFF, 0xFE]
    );
    // 0 elements is one element; a U16 and a CANopen object
    f.set(Addr::new(971, 0), 1);
    f.set(Addr::new(0x6077, 0), 300);
    assert_eq!(
        serve(&mut f, &read_req(8, &[(0x10, 0, 971, 0), (0x10, 1, 0x6077, 0)])),
        [8, 0x01, 0x01, 2, 0x06, 1, 0, 1, 0x03, 1, 0x01, 0x2C]
    );
    assert!(f.writes.is_empty());
}

#[test]
fn p206_byte_values_of_odd_count_are_padded_to_a_word() {
    let mut f = Fake::drive();
    f.set(Addr::new(1050, 0), -3);
    f.set(Addr::new(1100, 0), 1);
    assert_eq!(
        serve(&mut f, &read_req(1, &[(0x10, 1, 1050, 0), (0x10, 1, 1100, 0)])),
        [1, 0x01, 0x01, 2, 0x02, 1, 0xFD, 0x00, 0x04, 1, 0, 0, 0, 1]
    );
    let req = change_req(2, &[(1500, 0, 0x05, &[0x08]), (1050, 0, 0x02, &[0xEF])]);
    assert_eq!(req.len(), 4 + 12 + 4 + 4);
    assert_eq!(serve(&mut f, &req), [2, 0x02, 0x01, 2]);
    assert_eq!(
        (f.value(Addr::new(1500, 0)), f.value(Addr::new(1050, 0))),
        (8, -17)
    );
}

#[test]
fn p206_several_elements_read_consecutive_subindices() {
    let mut f = Fake::drive();
    for (s, v) in [(0u8, 10i64), (1, 20), (2, 30)] {
        f.set(Addr::new(1001, s), v);
    }
    assert_eq!(
        serve(&mut f, &read_req(3, &[(0x10, 3, 1001, 0)])),
        [3, 0x01, 0x01, 1, 0x04, 3, 0, 0, 0, 10, 0, 0, 0, 20, 0, 0, 0, 30]
    );
    // elements of different types (1001.4 I32, 1001.5 U32): refused
    assert_eq!(
        serve(&mut f, &read_req(3, &[(0x10, 2, 1001, 4)])),
        [3, 0x81, 0x01, 1, 0x44, 1, 0, 0x16]
    );
}

#[test]
fn p206_a_read_with_a_missing_parameter_answers_its_error_and_the_others() {
    let mut f = Fake::drive();
    f.set(Addr::new(1101, 0), 5);
    let r = serve(
        &mut f,
        &read_req(
            9,
            &[
                (0x10, 1, 0x5555, 0),
                (0x10, 1, 1101, 0),
                (0x10, 1, 1001, 300),
                (0x10, 1, 1001, 9),
            ],
        ),
    );
    assert_eq!(
        r,
        [9, 0x81, 0x01, 4, 0x44, 1, 0, 0x00, 0x04, 1, 0, 0, 0, 5, 0x44, 1, 0, 0x03, 0x44, 1, 0, 0x03]
    );
}

#[test]
fn p206_a_change_writes_and_answers_the_header_only() {
    let mut f = Fake::drive();
    let req = change_req(
        4,
        &[
            (1001, 0, 0x04, &1234i32.to_be_bytes()),
            (1004, 0, 0x42, &[0x03, 0xE8]),
        ],
    );
    assert_eq!(serve(&mut f, &req), [4, 0x02, 0x01, 2]);
    assert_eq!(
        f.writes,
        [
            (Addr::new(1001, 0), 1234, false),
            (Addr::new(1004, 0), 1000, false)
        ]
    );
}

#[test]
fn p206_a_refused_parameter_of_a_change_gets_its_error_and_the_others_are_done() {
    let mut f = Fake::drive();
    let req = change_req(
        5,
        &[
            (1001, 0, 0x04, &7i32.to_be_bytes()),
            (1100, 0, 0x04, &7i32.to_be_bytes()), // read-only
            (1004, 0, 0x06, &[0x07, 0xD1]),       // 2001 > 2000
            (1001, 1, 0x06, &[0, 1]),             // U16 value for an I32
            (0x5555, 0, 0x04, &[0, 0, 0, 1]),     // missing
            (1500, 0, 0x05, &[0x01, 0x02]),       // 2 values for 1 element
        ],
    );
    let mut req = req;
    // the last parameter declares 1 element but carries 2 values
    req[4 + 5 * 6 + 1] = 1;
    assert_eq!(
        serve(&mut f, &req),
        [
            5, 0x82, 0x01, 6, 0x40, 0, 0x44, 1, 0, 0x01, 0x44, 1, 0, 0x02, 0x44, 1, 0, 0x05, 0x44, 1, 0,
            0x00, 0x44, 1, 0, 0x18
        ]
    );
    assert_eq!(f.writes, [(Addr::new(1001, 0), 7, false)]);
}

#[test]
fn p206_a_malformed_request_gets_one_error_and_changes_nothing() {
    let mut f = Fake::drive();
    let good = change_req(6, &[(1001, 0, 0x04, &7i32.to_be_bytes())]);
    let mut cases: Vec<(Vec<u8>, [u8; 8])> = Vec::new();
    let mut bad_ref = good.clone();
    bad_ref[0] = 0;
    cases.push((bad_ref, [0, 0x82, 1, 1, 0x44, 1, 0, 0x65]));
    let mut bad_id = good.clone();
    bad_id[1] = 0x03;
    cases.push((bad_id, [6, 0x81, 1, 1, 0x44, 1, 0, 0x66]));
    for n in [0u8, 40] {
        let mut c = good.clone();
        c[3] = n;
        cases.push((c, [6, 0x82, 1, 1, 0x44, 1, 0, 0x67]));
    }
    cases.push((good[..good.len() - 1].to_vec(), [6, 0x82, 1, 1, 0x44, 1, 0, 0x68]));
    cases.push((good[..7].to_vec(), [6, 0x82, 1, 1, 0x44, 1, 0, 0x68]));
    let mut long = good.clone();
    long.push(0);
    cases.push((long, [6, 0x82, 1, 1, 0x44, 1, 0, 0x68]));
    let mut format = good.clone();
    format[10] = 0x99;
    cases.push((format, [6, 0x82, 1, 1, 0x44, 1, 0, 0x17]));
    // two parameters, the second's values cut off: the first is not written
    let mut two = change_req(
        6,
        &[(1001, 0, 0x04, &[0, 0, 0, 1]), (1001, 1, 0x04, &[0, 0, 0, 2])],
    );
    two.truncate(two.len() - 2);
    cases.push((two, [6, 0x82, 1, 1, 0x44, 1, 0, 0x68]));
    let mut read_long = read_req(6, &[(0x10, 1, 1100, 0)]);
    read_long.push(0);
    cases.push((read_long, [6, 0x81, 1, 1, 0x44, 1, 0, 0x68]));
    for (req, want) in cases {
        assert_eq!(serve(&mut f, &req), want, "{req:02x?}");
    }
    assert!(f.writes.is_empty());
    assert_eq!(f.value(Addr::new(1001, 0)), 0);
    let mut out = [0u8; 64];
    assert_eq!(bmp::serve(&[1, 1, 1], &mut f, &mut out), Err(Refused::TooShort));
    assert_eq!(
        bmp::serve(&good, &mut f, &mut [0u8; 3]),
        Err(Refused::BufferTooSmall)
    );
}

#[test]
fn p206_description_text_and_attribute_checks() {
    let mut f = Fake::drive();
    let r = serve(
        &mut f,
        &read_req(
            1,
            &[
                (0x20, 1, 1100, 1),
                (0x20, 1, 1001, 1),
                (0x20, 1, 1100, 6),
                (0x30, 1, 1100, 0),
                (0x40, 1, 1100, 0),
            ],
        ),
    );
    assert_eq!(
        r,
        [
            1, 0x81, 0x01, 5, 0x42, 1, 0x02, 0x04, 0x42, 1, 0x00, 0x04, 0x44, 1, 0, 0x09, 0x44, 1, 0, 0x0F,
            0x44, 1, 0, 0x16
        ]
    );
    let mut req = change_req(2, &[(1001, 0, 0x04, &[0, 0, 0, 1])]);
    req[4] = 0x20;
    assert_eq!(serve(&mut f, &req), [2, 0x82, 1, 1, 0x44, 1, 0, 0x07]);
    assert!(f.writes.is_empty());
}

#[test]
fn p206_an_unknown_drive_object_and_a_long_response() {
    let mut f = Fake::drive();
    let mut req = read_req(1, &[(0x10, 1, 1100, 0), (0x10, 1, 1101, 0)]);
    req[2] = 5;
    assert_eq!(
        serve(&mut f, &req),
        [1, 0x81, 5, 2, 0x44, 1, 0, 0x19, 0x44, 1, 0, 0x19]
    );
    let mut req = change_req(1, &[(1001, 0, 0x04, &[0, 0, 0, 1])]);
    req[2] = 5;
    assert_eq!(serve(&mut f, &req), [1, 0x82, 5, 1, 0x44, 1, 0, 0x19]);
    assert!(f.writes.is_empty());
    // a response that does not fit: 0x15 for that parameter
    let req = read_req(2, &[(0x10, 5, 1001, 0)]);
    let mut out = [0u8; 12];
    let n = bmp::serve(&req, &mut f, &mut out).expect("error fits");
    assert_eq!(out[..n], [2, 0x81, 1, 1, 0x44, 1, 0, 0x15]);
}
